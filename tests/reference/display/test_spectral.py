"""Tests of reference.display.spectral: the spectral display and its Eq. (1) summary."""

from __future__ import annotations

import json

import numpy as np
import pytest

from reference.display.model import XYZ_to_display_counts, display_counts_to_XYZ
from reference.display.spectral import (
    DISPLAY_PRIMARIES,
    display_drives_to_spectra,
    display_drives_to_XYZ,
    load_spectral_display,
    spectral_display,
    spectral_display_from_doc,
    spectral_to_display_model,
    tone_response,
)
from reference.errors import SpecrefError


@pytest.mark.parametrize("key", DISPLAY_PRIMARIES.names())
def test_primary_XYZ_matches_colour_science(key):
    import colour

    # Source: colour.sd_to_XYZ (integration, k = 683) of the scaled primary spectrum.
    d = spectral_display(key, black_cd_m2=0.0)
    for c in range(3):
        drives = np.zeros(3)
        drives[c] = 1.0
        sd = colour.SpectralDistribution(d.primaries[c], d.wavelengths_nm)
        expected = colour.sd_to_XYZ(sd, k=683.0, method="Integration")
        np.testing.assert_allclose(display_drives_to_XYZ(d, drives), expected, rtol=2e-3)


def test_white_and_black_luminance_by_construction():
    d = spectral_display(white_cd_m2=150.0, black_cd_m2=0.3)
    assert d.white_XYZ[1] == pytest.approx(150.0, rel=1e-12)
    assert d.black_XYZ[1] == pytest.approx(0.3, rel=1e-12)


@pytest.mark.parametrize("shape", [(3,), (5, 3), (2, 4, 3)])
def test_drive_shapes(shape, rng):
    d = spectral_display()
    drives = rng.uniform(0, 1, shape)
    assert display_drives_to_spectra(d, drives).shape == (*shape[:-1], 81)
    assert display_drives_to_XYZ(d, drives).shape == shape


def test_channels_add_without_interaction(rng):
    # Property: with no channel drift the display is additive (black counted once).
    d = spectral_display(shift_nm=(0.0, 0.0, 0.0))
    drives = rng.uniform(0, 1, (10, 3))
    parts = sum(display_drives_to_XYZ(d, drives * np.eye(3)[c]) for c in range(3))
    np.testing.assert_allclose(display_drives_to_XYZ(d, drives), parts - 2 * d.black_XYZ)


def test_channel_drift_moves_chromaticity():
    import colour

    drifting, still = spectral_display(), spectral_display(shift_nm=(0.0, 0.0, 0.0))
    low, high = [0.0, 0.0, 0.2], [0.0, 0.0, 1.0]

    def xy(d, drives):
        return colour.XYZ_to_xy(display_drives_to_XYZ(d, drives) - d.black_XYZ)

    assert np.abs(xy(still, low) - xy(still, high)).max() < 1e-12
    assert np.abs(xy(drifting, low) - xy(drifting, high)).max() > 1e-3


def test_tone_response_gain_offset_gamma():
    # Source: Berns 1996, GOG: ((1 - o) d + o)^γ, closed form at d = 0.5.
    r = tone_response([0.5, 0.5, 0.5], [2.0, 2.2, 1.8], [-0.1, 0.0, 0.1])
    np.testing.assert_allclose(r, [0.45**2.0, 0.5**2.2, 0.55**1.8])


def test_derived_display_model_round_trip():
    # The Eq. (1) summary of a display without drift reproduces it at the ramp levels, and
    # counts -> XYZ -> counts is the identity.
    d = spectral_display(shift_nm=(0.0, 0.0, 0.0))
    model = spectral_to_display_model(d)
    levels = np.round(np.linspace(0, 2047, 33)).astype(int)  # the measured ramp levels
    counts = levels[np.array([[32, 32, 32], [16, 8, 24], [0, 0, 0], [1, 31, 15]])]
    expected = display_drives_to_XYZ(d, counts / 2047)
    np.testing.assert_allclose(display_counts_to_XYZ(counts, model), expected, rtol=1e-12)
    back, in_gamut, _ = XYZ_to_display_counts(display_counts_to_XYZ(counts, model), model)
    np.testing.assert_array_equal(back, counts)
    assert in_gamut.all()


def test_bad_drives():
    with pytest.raises(SpecrefError, match=r"display drives: must have shape \(\.\.\., 3\) in"):
        display_drives_to_XYZ(spectral_display(), [1.2, 0.0, 0.0])


def test_display_file_negative_spectra(tmp_path):
    w = list(range(400, 701, 10))
    doc = {"primaries": {"wavelengths_nm": w, "R": [1.0] * 31, "G": [1.0] * 31, "B": [1.0] * 31}}
    doc["primaries"]["G"][4] = -0.5
    path = tmp_path / "lcd.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(SpecrefError, match=r"lcd.json: primaries: G: spectra must be >= 0, got"):
        load_spectral_display(path)


def test_display_file_non_monotonic_ramp():
    ramps = {"drive": [0, 0.5, 1], "R": [0, 0.5, 1], "G": [0, 0.5, 1], "B": [0, 0.7, 0.6]}
    with pytest.raises(SpecrefError, match=r"d.json: ramps.B: must increase with the drive"):
        spectral_display_from_doc({"ramps": ramps}, "d.json")


def test_display_file_unknown_key_and_primaries():
    with pytest.raises(SpecrefError, match=r"d.json: unknown key 'gama'; allowed:"):
        spectral_display_from_doc({"gama": [2, 2, 2]}, "d.json")
    with pytest.raises(SpecrefError, match=r"unknown display primaries 'oled'; allowed:"):
        spectral_display_from_doc({"primaries": "oled"}, "d.json")


def test_display_file_ramps_replace_gog(tmp_path):
    ramps = {"drive": [0, 0.5, 1], "R": [0, 0.25, 1], "G": [0, 0.25, 1], "B": [0, 0.25, 1]}
    path = tmp_path / "d.json"
    path.write_text(json.dumps({"ramps": ramps, "shift_nm": [0, 0, 0], "black_cd_m2": 0.0}))
    d = load_spectral_display(path)
    # Source: the ramp itself: half drive gives a quarter of the white.
    half = display_drives_to_XYZ(d, [0.5, 0.5, 0.5])
    np.testing.assert_allclose(half, 0.25 * d.white_XYZ, rtol=1e-12)

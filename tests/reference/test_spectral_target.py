"""Tests of reference/spectral_target.py: synthetic targets, look-alike removal, target files."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reference.errors import SpecrefError
from reference.spectra import GRID_41
from reference.spectral_target import (
    CAMERAS,
    HELD_OUT_SETS,
    TRAINING_SET,
    camera_noise,
    camera_RGB,
    read_target,
    reflectance_set,
)


@pytest.mark.parametrize("camera", CAMERAS.names())
def test_white_diffuser_is_one(camera):
    for illuminant in ("D65", "A"):
        assert_allclose(camera_RGB(np.ones(81), camera, illuminant), 1.0, rtol=1e-12)


def test_sRGB_camera_against_colour_science():
    # Source: colour-science's sd_to_XYZ (CIE 1931 2°, D65) and XYZ_to_RGB(sRGB), linear.
    import colour

    _, spectra = reflectance_set("ColorChecker N Ohta")
    sd = next(iter(colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"].values()))  # dark skin
    XYZ = colour.sd_to_XYZ(sd, illuminant=colour.SDS_ILLUMINANTS["D65"]) / 100
    expected = colour.XYZ_to_RGB(XYZ, "sRGB", apply_cctf_encoding=False)
    assert_allclose(camera_RGB(spectra[0], "sRGB"), expected, atol=2e-3)


def test_training_set_has_no_look_alikes():
    _, training = reflectance_set(TRAINING_SET, GRID_41)
    for name in HELD_OUT_SETS:
        _, held = reflectance_set(name, GRID_41)
        rms = np.sqrt(((training[:, None] - held[None]) ** 2).mean(axis=-1))
        assert rms.min() >= 0.03


def test_noise_is_seeded_and_sized():
    a = camera_noise(np.full((4000, 3), 1.0), np.random.default_rng(3))
    b = camera_noise(np.full((4000, 3), 1.0), np.random.default_rng(3))
    assert_allclose(a, b)
    # Source: sqrt(0.005² + 0.001²) = 0.0051 for unit RGB
    assert a.std() == pytest.approx(np.hypot(0.005, 0.001), rel=0.05)


def test_read_target_pair(tmp_path):
    (tmp_path / "rgb.csv").write_text("# camera\nname,R,G,B\na,0.1,0.2,0.3\nb,0.3,0.2,0.1\n")
    (tmp_path / "s.csv").write_text("name,370,790\na,0.2,0.6\nb,0.4,0.4\n")
    RGB, spectra = read_target(tmp_path / "rgb.csv", tmp_path / "s.csv")
    assert RGB.shape == (2, 3)
    assert spectra.shape == (2, 41)
    assert_allclose(spectra[0, [0, -1]], [0.2 + 0.4 * 10 / 420, 0.6 - 0.4 * 10 / 420])


def test_read_target_refuses_missing_columns(tmp_path):
    (tmp_path / "t.csv").write_text("R,G,380,780\n0.1,0.2,0.3,0.4\n")
    with pytest.raises(SpecrefError, match=r"t.csv: no column B"):
        read_target(tmp_path / "t.csv")

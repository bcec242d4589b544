"""Tests of reference.display.model: Eq. (1), its inverse, round trips, L_factor fit, bad files."""

from __future__ import annotations

import json

import numpy as np
import pytest

from reference.display.model import (
    XYZ_to_display_counts,
    display_counts_to_XYZ,
    display_from_measurements,
    fit_lfactor,
    lfactor,
    load_display_measurements,
    screen_flare_XYZ,
    virtual_display,
    virtual_display_measurements,
)
from reference.errors import SpecrefError


def test_virtual_display_has_the_papers_figures():
    # Source: Ferwerda 2015, §3.4.1: 320 cd/m² peak, 0.73 cd/m² black, 438:1, 11-bit LUTs.
    d = virtual_display()
    assert d.white_XYZ[1] == pytest.approx(320.0, rel=1e-12)
    assert d.black_XYZ[1] == pytest.approx(0.73, rel=1e-12)
    assert d.luts.shape == (3, 2048)
    white = display_counts_to_XYZ([2047, 2047, 2047], d)
    black = display_counts_to_XYZ([0, 0, 0], d)
    assert white[1] / black[1] == pytest.approx(438.4, abs=0.05)


def test_display_white_point_is_d65():
    import colour

    # Source: colour-science, sRGB primaries and D65 white point (the virtual display's). The
    # IEC 61966-2-1 matrix is printed to 4 digits, so its white is D65 to about 2e-5 in xy.
    xy = colour.XYZ_to_xy(display_counts_to_XYZ([2047, 2047, 2047], virtual_display()))
    np.testing.assert_allclose(xy, colour.RGB_COLOURSPACES["sRGB"].whitepoint, atol=5e-5)


def test_counts_round_trip_is_exact(rng):
    d = virtual_display()
    counts = rng.integers(0, 2048, size=(200, 3))
    for theta, phi in ((0.0, 0.0), (np.radians(25), np.radians(60))):
        XYZ = display_counts_to_XYZ(counts, d, theta, phi)
        back, in_gamut, _ = XYZ_to_display_counts(XYZ, d, theta, phi)
        np.testing.assert_array_equal(back, counts)
        assert in_gamut.all()


def test_XYZ_round_trip_within_quantisation(rng):
    d = virtual_display()
    RGB = rng.uniform(0.05, 0.95, size=(100, 3))
    XYZ = RGB @ d.P.T + d.black_XYZ
    counts, in_gamut, RGB_back = XYZ_to_display_counts(XYZ, d)
    np.testing.assert_allclose(RGB_back, RGB, rtol=1e-12)
    shown = display_counts_to_XYZ(counts, d)
    # One 11-bit step of the steepest LUT segment bounds the error per channel.
    step = np.diff(d.luts, axis=1).max()
    assert np.abs(shown - XYZ).max() <= step * np.abs(d.P).sum(axis=1).max()
    assert in_gamut.all()


def test_off_axis_drive_is_raised_to_compensate():
    d = virtual_display()
    target = np.array([100.0, 100.0, 100.0])
    on_axis = XYZ_to_display_counts(target, d, 0.0, 0.0)[2]
    off_axis = XYZ_to_display_counts(target, d, np.radians(25), 0.0)[2]
    # Source: §3.4.2, off-axis colours get more drive, by 1/L_factor on the black-subtracted part.
    np.testing.assert_array_less(on_axis, off_axis)


def test_out_of_gamut_is_flagged_and_clipped():
    d = virtual_display()
    counts, in_gamut, RGB = XYZ_to_display_counts([[10.0, 5.0, 200.0], [600.0, 600.0, 600.0]], d)
    assert not in_gamut.any()
    assert (counts >= 0).all()
    assert (counts <= 2047).all()
    assert (RGB.max(axis=1) > 1).all() or (RGB.min(axis=1) < 0).any()


def test_fit_lfactor_recovers_a_noisy_paraboloid(rng):
    theta = np.radians(rng.uniform(0, 30, 200))
    phi = rng.uniform(0, 2 * np.pi, 200)
    truth = (1.0, 0.55, 0.8)
    Y = truth[0] - truth[1] * (theta * np.cos(phi)) ** 2 - truth[2] * (theta * np.sin(phi)) ** 2
    sigma = 1e-3
    fitted = fit_lfactor(theta, phi, Y + rng.normal(0, sigma, 200))
    # Least squares with 200 points and noise 1e-3: parameter errors of order 1e-2 at most.
    np.testing.assert_allclose(fitted, truth, atol=0.03)
    assert lfactor(virtual_display(), 0.0, 0.0) == pytest.approx(1.0, abs=1e-12)


def test_screen_flare():
    d = virtual_display()
    # Source: Eq. (3), Ferwerda, with ρ = 0.002: ρ E / π; the specular part peaks at 1.1 % and is
    # 1 % of that at 10° off the mirror direction.
    E = np.array([0.0, 1000.0, 0.0])
    np.testing.assert_allclose(screen_flare_XYZ(d, E), 0.002 * E / np.pi, rtol=1e-15)
    L = np.array([0.0, 5000.0, 0.0])
    peak = screen_flare_XYZ(d, 0 * E, L, 0.0)[1]
    assert peak == pytest.approx(0.011 * 5000.0, rel=1e-12)
    assert screen_flare_XYZ(d, 0 * E, L, 10.0)[1] == pytest.approx(0.01 * peak, rel=1e-9)


def test_load_display_measurements(tmp_path):
    path = tmp_path / "display.json"
    path.write_text(json.dumps(virtual_display_measurements()))
    loaded = load_display_measurements(path)
    np.testing.assert_allclose(loaded.P, virtual_display().P, rtol=1e-12)


@pytest.mark.parametrize(
    ("edit", "match"),
    [
        (lambda d: d["ramps"]["R"]["Y"].__setitem__(10, 0.0), "ramps.R.Y: must increase"),
        (lambda d: d.pop("black_XYZ"), "missing key 'black_XYZ'"),
        (lambda d: d["ramps"]["B"].__setitem__("counts", [0, 5, 100]), "same length"),
        (lambda d: d["primaries_XYZ"].__setitem__("G", d["primaries_XYZ"]["R"]), "dependent"),
        (lambda d: d["front_surface"].__setitem__("diffuse", -1), "front_surface.diffuse"),
        (lambda d: d.__setitem__("bits", 40), "bits: must be 1..16"),
    ],
)
def test_display_measurements_bad_input(edit, match, tmp_path):
    doc = virtual_display_measurements()
    edit(doc)
    with pytest.raises(SpecrefError, match=match):
        display_from_measurements(doc, "display.json")
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(SpecrefError, match=r"bad\.json"):
        load_display_measurements(path)


def test_display_file_errors(tmp_path):
    with pytest.raises(SpecrefError, match="file not found"):
        load_display_measurements(tmp_path / "none.json")
    (tmp_path / "x.json").write_text("{not json")
    with pytest.raises(SpecrefError, match="not a JSON display measurement file"):
        load_display_measurements(tmp_path / "x.json")
    with pytest.raises(SpecrefError, match=r"integers in \[0, 2047\]"):
        display_counts_to_XYZ([0, 0, 4000], virtual_display())

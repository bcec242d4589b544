"""Tests of reference.display.calibration: the targets of docs/display.md ("Calibrating") for every
white and curve."""

from __future__ import annotations

import numpy as np
import pytest

from reference.display.calibration import (
    CALIBRATION_CURVES,
    WHITES,
    calibrate_display,
    calibration_points,
    curve_target,
    verify_calibration,
    white_xy,
)
from reference.display.spectral import spectral_display
from reference.errors import SpecrefError


@pytest.fixture(scope="module")
def display():
    return spectral_display()


@pytest.mark.parametrize("curve", CALIBRATION_CURVES.names())
@pytest.mark.parametrize("white", list(WHITES))
def test_targets_with_the_noise_free_spectroradiometer(display, white, curve):
    # Our targets: Δu'v' <= 0.001 for every gray above 5 % of white, luminance within 1 % of the
    # curve above 1 % of white, measured at all 256 input levels.
    cal = calibrate_display(display, white, curve, points=15, instrument="ideal")
    v = verify_calibration(display, cal)
    assert v["duv"][v["Y_target"] > 0.05 * cal.Y_white].max() <= 0.001
    assert np.abs(v["Y_error"][v["Y_target"] > 0.01 * cal.Y_white]).max() <= 0.01
    # white chromaticity: against colour-science's illuminant chromaticities
    np.testing.assert_allclose(v["xy"][-1], white_xy(white), atol=3e-4)


@pytest.mark.parametrize("instrument", ["ideal", "spectro", "colorimeter"])
def test_lut_monotonic_and_black_left_alone(display, instrument):
    cal = calibrate_display(display, "D50", "gamma2.2", points=12, instrument=instrument)
    assert (np.diff(cal.lut, axis=1) >= 0).all()
    np.testing.assert_array_equal(cal.lut[:, 0], 0.0)
    assert cal.lut.max() <= 1.0
    assert cal.lut[:, -1].max() == 1.0


def test_colorimeter_loses_the_shadows(display):
    # §6, Herbert et al.: colorimeters did not hold x, y below about the quarter tone; the
    # spectroradiometer holds them further down. Both read back with the noise-free instrument.
    worst = {}
    for instrument in ("spectro", "colorimeter"):
        cal = calibrate_display(display, "D65", "lstar", points=15, instrument=instrument)
        v = verify_calibration(display, cal)
        band = (v["Y_target"] > 0.05 * cal.Y_white) & (v["Y_target"] < 0.125 * cal.Y_white)
        worst[instrument] = v["duv"][band].max()
    assert worst["spectro"] < 0.002
    assert worst["colorimeter"] > 0.004


def test_curves_are_the_papers():
    # Source: Herbert et al., Eq. (6) with Gamma 2.2 and Eq. (7), evaluated by hand at G = 128.
    G = 128 / 255
    assert curve_target("gamma2.2", G) == pytest.approx(G**2.2, rel=1e-12)
    assert curve_target("lstar", G) == pytest.approx(((G * 100 + 16) / 116) ** 3, rel=1e-12)
    # Source: ITU-R BT.1886: with no black it is a 2.4 power law.
    assert curve_target("bt1886", G, 0.0) == pytest.approx(G**2.4, rel=1e-12)


def test_points_denser_in_highlights():
    G = calibration_points(15, 0.1)
    assert G[0] == 0.1
    assert G[-1] == 1.0
    assert (np.diff(np.diff(G)) < 0).all()


@pytest.mark.parametrize("n", [1, 65])
def test_points_out_of_range(display, n):
    with pytest.raises(SpecrefError, match=rf"points: must be an integer in 2\.\.64, got {n}"):
        calibrate_display(display, points=n)


def test_unknown_curve(display):
    with pytest.raises(SpecrefError, match=r"unknown calibration curve 'gamma2.4'; allowed:"):
        calibrate_display(display, curve="gamma2.4")


def test_white_outside_the_gamut(display):
    with pytest.raises(SpecrefError, match=r"white: '0.16,0.05' .* outside the display's gamut by"):
        calibrate_display(display, white="0.16,0.05")


@pytest.mark.parametrize("white", ["D66", "0.3", "0.7,0.5", "a,b"])
def test_bad_white(white):
    with pytest.raises(SpecrefError, match="white: must be one of D65, F2, A, D50 or 'x,y'"):
        white_xy(white)

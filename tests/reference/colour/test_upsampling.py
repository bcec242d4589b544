"""Tests of reference.colour.upsampling: RGB → spectrum (Mallett, Jakob, the regression)."""

from __future__ import annotations

from operator import attrgetter

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reference.colour.colorimetry import band_weights, spectra_to_RGB_matrix
from reference.colour.spectra import GRID_31, GRID_41
from reference.colour.upsampling import (
    DEFAULT_UPSAMPLING,
    UPSAMPLING_METHODS,
    RGB_to_radiance_spectra,
    RGB_to_spectra,
    RGB_to_spectra_Jakob2019,
    RGB_to_spectra_Mallett2019,
)
from reference.errors import SpecrefError


def test_mallett2019_matches_colour_science():
    # Source: colour.recovery.RGB_to_sd_Mallett2019 (its basis at the grid's wavelengths).
    import colour

    RGB = np.array([0.7, 0.2, 0.05])
    sd = colour.recovery.RGB_to_sd_Mallett2019(RGB)
    expected = np.interp(GRID_41.wavelengths_nm, sd.wavelengths, sd.values)
    np.testing.assert_allclose(RGB_to_spectra_Mallett2019(RGB, GRID_41), expected, rtol=1e-12)


def test_jakob2019_matches_colour_science():
    # Source: colour.recovery.XYZ_to_sd_Jakob2019 (colour-science's own evaluation of the fitted
    # sigmoid polynomial) of the sRGB colour's XYZ. The texel is divided by twice its largest
    # component (erratum E80: Mitsuba 3, pbrt-v4), so the shape is fitted at (1/2, 1/8, 1/16),
    # which the per-colour fit's 1/64-of-the-largest quantization holds exactly; the spectrum is
    # multiplied back by 2 max = 4 for the texel (2, 1/2, 1/4).
    import colour

    RGB = np.array([0.5, 0.125, 0.0625])
    XYZ = colour.RGB_to_XYZ(RGB, colour.RGB_COLOURSPACES["sRGB"])
    sd = colour.recovery.XYZ_to_sd_Jakob2019(XYZ)
    expected = np.interp(GRID_41.wavelengths_nm, sd.wavelengths, sd.values)
    got = RGB_to_spectra_Jakob2019(4.0 * RGB, GRID_41, lut_size=None)
    np.testing.assert_allclose(got, 4.0 * expected, rtol=1e-6)


def test_upsampling_white_is_flat_and_renders_white():
    # Mallett 2019: the basis sums to 1 within 1e-5 (colour-science data), so white is flat.
    S = RGB_to_spectra(np.array([[3.0, 3.0, 3.0]]), GRID_41)
    np.testing.assert_allclose(S, 3.0, rtol=1e-4)
    # As radiance: times D65/Y(D65), so XYZ (E weights) -> sRGB gives back the white texel.
    # Source: colour-science D65 and sRGB; tolerance: D65 sampled at 10 nm vs its 5 nm table.
    M = spectra_to_RGB_matrix(band_weights(GRID_41, None))
    # A fitted model (Upsampler.exact False) reproduces white only to within its fit: 1 %.
    for name, method in UPSAMPLING_METHODS.items():
        R = RGB_to_radiance_spectra(np.array([[3.0, 3.0, 3.0]]), GRID_41, name)
        np.testing.assert_allclose(R @ M, 3.0, rtol=2e-3 if method.exact else 1e-2)


@pytest.mark.parametrize("method", UPSAMPLING_METHODS.values(), ids=attrgetter("name"))
def test_upsampling_shapes(method):
    assert RGB_to_spectra([0.2, 0.4, 0.6], GRID_31, method.name).shape == (31,)
    assert RGB_to_spectra(np.full((4, 3), 0.5), GRID_41, method.name).shape == (4, 41)
    assert RGB_to_spectra(np.full((2, 3, 3), 0.5), GRID_31, method.name).shape == (2, 3, 31)


@pytest.mark.parametrize("method", UPSAMPLING_METHODS.values(), ids=attrgetter("name"))
def test_upsampling_scales_with_hdr_magnitude(method):
    # Property: both methods are homogeneous of degree 1 (Mallett: linear; Jakob: the module's
    # scale by the largest component), so HDR texels keep their spectral shape; black is 0.
    RGB = np.array([0.6, 0.3, 0.15])
    base = RGB_to_spectra(RGB, GRID_41, method.name)
    np.testing.assert_allclose(RGB_to_spectra(8.0 * RGB, GRID_41, method.name), 8.0 * base)
    np.testing.assert_array_equal(RGB_to_spectra(np.zeros(3), GRID_41, method.name), 0.0)
    assert (base >= 0).all()


def test_mallett2019_is_linear(rng):
    # Property: S(a x + b y) = a S(x) + b S(y) (Eq. (4), Mallett & Yuksel 2019).
    x, y = rng.random(3), rng.random(3)
    left = RGB_to_spectra_Mallett2019(2.0 * x + 0.5 * y, GRID_41)
    right = 2.0 * RGB_to_spectra_Mallett2019(x, GRID_41) + 0.5 * RGB_to_spectra_Mallett2019(
        y, GRID_41
    )
    np.testing.assert_allclose(left, right, rtol=1e-12)


def test_default_method_is_registered():
    assert DEFAULT_UPSAMPLING in UPSAMPLING_METHODS.names()


@pytest.mark.parametrize(
    ("RGB", "method", "match"),
    [
        ([[-1.0, 0.0, 0.0]], DEFAULT_UPSAMPLING, "finite, >= 0"),
        ([[np.nan, 0.0, 0.0]], DEFAULT_UPSAMPLING, "finite, >= 0"),
        ([[0.5, 0.5]], DEFAULT_UPSAMPLING, r"expected \(\.\.\., 3\)"),
        ([[0.5, 0.5, 0.5]], "smits1999", "unknown RGB upsampling 'smits1999'; allowed: jakob2019"),
    ],
)
def test_upsampling_bad_input(RGB, method, match):
    with pytest.raises(SpecrefError, match=match):
        RGB_to_spectra(np.array(RGB), GRID_41, method)


# Linear sRGB of a few ColorChecker-like colours and a grey, inside the gamut.
COLOURS = np.array([[0.18, 0.18, 0.18], [0.4, 0.1, 0.05], [0.05, 0.2, 0.45], [0.3, 0.4, 0.06]])


@pytest.mark.parametrize("method", UPSAMPLING_METHODS.names())
def test_radiance_round_trip(method):
    # Source: the definition of an upsampler; linear sRGB back through the sRGB matrix.
    S = RGB_to_radiance_spectra(COLOURS, GRID_41, method)
    back = S @ spectra_to_RGB_matrix(band_weights(GRID_41, None))
    assert_allclose(back, COLOURS, atol=0.01)


@pytest.mark.parametrize("method", UPSAMPLING_METHODS.names())
def test_shapes_on_both_grids(method):
    for grid in (GRID_41, GRID_31):
        assert RGB_to_radiance_spectra(COLOURS[:1], grid, method).shape == (1, grid.n_bands)

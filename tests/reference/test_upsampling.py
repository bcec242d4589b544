"""Tests of reference/upsampling.py run over the whole registry (the regression included)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reference.colorimetry import band_weights, spectra_to_RGB_matrix
from reference.spectra import GRID_31, GRID_41
from reference.upsampling import UPSAMPLING_METHODS, RGB_to_radiance_spectra

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

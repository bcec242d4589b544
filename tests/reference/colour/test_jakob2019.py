"""Tests of reference.colour.jakob2019: the batched Jakob & Hanika fit and its coefficient table."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from reference.colour.jakob2019 import (
    DEFAULT_TABLE_SIZE,
    fit_coefficients_Jakob2019,
    generate_table_Jakob2019,
    table_Jakob2019,
)
from reference.errors import SpecrefError, SpecrefWarning

LAMBDA = np.arange(380.0, 781.0, 5.0)


def _spectra(c_nm):
    # Eq. (3), Jakob & Hanika 2019, coefficients for wavelength in nm
    x = (c_nm[:, 0:1] * LAMBDA + c_nm[:, 1:2]) * LAMBDA + c_nm[:, 2:3]
    return 0.5 + x / (2.0 * np.sqrt(1.0 + x * x))


def _nm(c):
    from colour.recovery.jakob2019 import SPECTRAL_SHAPE_JAKOB2019, dimensionalise_coefficients

    return dimensionalise_coefficients(c, SPECTRAL_SHAPE_JAKOB2019).T


def _half_max(rng, n):
    """Random linear sRGB colours with largest component 1/2 (what jakob2019 looks up)."""
    RGB = rng.random((n, 3))
    return 0.5 * RGB / RGB.max(axis=1, keepdims=True)


def test_batched_fit_agrees_with_colour_science(rng):
    # Source: colour.recovery.find_coefficients_Jakob2019 (L-BFGS-B, one colour at a time, stops at
    # ΔE76 <= 0.023). Ours reaches 1e-6; spectra agree to colour-science's own stopping error.
    import colour

    RGB = _half_max(rng, 4)
    c, dE = fit_coefficients_Jakob2019(RGB)
    assert (dE < 1e-6).all()
    space = colour.RGB_COLOURSPACES["sRGB"]
    for k in range(len(RGB)):
        reference, error = colour.recovery.find_coefficients_Jakob2019(
            colour.RGB_to_XYZ(RGB[k], space)
        )
        assert error < 0.03
        np.testing.assert_allclose(
            _spectra(_nm(c[k : k + 1])), _spectra(reference[None]), atol=2e-3
        )


def test_fit_reproduces_the_colour(rng):
    # Source: colour.sd_to_XYZ (ASTM E308, D65) of the fitted reflectance against the target.
    import colour

    RGB = _half_max(rng, 3)
    c, _ = fit_coefficients_Jakob2019(RGB)
    space = colour.RGB_COLOURSPACES["sRGB"]
    for k in range(3):
        sd = colour.recovery.sd_Jakob2019(_nm(c[k : k + 1])[0])
        XYZ = colour.sd_to_XYZ(sd, illuminant=colour.SDS_ILLUMINANTS["D65"]) / 100
        dE = colour.delta_E(
            colour.XYZ_to_Lab(XYZ), colour.XYZ_to_Lab(colour.RGB_to_XYZ(RGB[k], space))
        )
        assert dE < 0.05  # ASTM E308 1 nm weights against the fit's 5 nm sums


def test_table_against_the_direct_fit(rng):
    # Source: the direct fit above, at 300 random colours of largest component 1/2 (the only
    # brightness jakob2019 looks up, erratum E80). Measured on 4000 colours: max |ΔR| 0.024,
    # 99th percentile 0.0016, median 0.0002 (reflectance); Mitsuba 3's own 64³ table has 0.023,
    # 0.0016, 0.0004 against the same fit. Tolerances: 0.03, 2e-3 for the 99th percentile.
    RGB = _half_max(rng, 300)
    lut = table_Jakob2019(DEFAULT_TABLE_SIZE)
    c, _ = fit_coefficients_Jakob2019(RGB)
    error = np.abs(_spectra(lut.RGB_to_coefficients(RGB)) - _spectra(_nm(c))).max(axis=1)
    assert error.max() < 0.03
    assert np.percentile(error, 99) < 2e-3


def test_table_against_mitsuba(rng):
    mitsuba = pytest.importorskip("mitsuba", reason="pip install .[mitsuba] (Mitsuba 3)")
    # Source: Mitsuba 3's srgb.coeff (rgb2spec_opt, 360-830 nm), read by colour-science. Tolerance:
    # the two fits' own differences (wavelength range, quadrature), measured max 0.02 over 300.
    from colour.recovery import LUT3D_Jakob2019

    path = Path(mitsuba.__file__).parent / "data" / "srgb.coeff"
    theirs = LUT3D_Jakob2019().read(path)
    RGB = _half_max(rng, 300)
    ours = table_Jakob2019(DEFAULT_TABLE_SIZE)
    a = _spectra(ours.RGB_to_coefficients(RGB))
    b = _spectra(theirs.RGB_to_coefficients(RGB))
    assert np.abs(a - b).max() < 0.04
    assert np.median(np.abs(a - b).max(axis=1)) < 2e-3


def test_table_layout_matches_colour_science_nodes():
    # Source: colour.recovery.LUT3D_Jakob2019's look-up: at a node, the table returns the fit of
    # that node's colour (block 1: green largest; (i+2)%3 = 0 is red, (i+1)%3 = 2 is blue).
    scale, coefficients = generate_table_Jakob2019(4)
    s = np.linspace(0.0, 1.0, 4)
    RGB = scale[2] * np.array([s[1], 1.0, s[3]])
    c, _ = fit_coefficients_Jakob2019(RGB[None])
    np.testing.assert_allclose(coefficients[1, 2, 1, 3], _nm(c)[0], rtol=1e-6)


def test_table_cache_is_written_and_an_unusable_folder_warns(tmp_path, monkeypatch):
    monkeypatch.setenv("SPECREF_CACHE_DIR", str(tmp_path / "cache"))
    table_Jakob2019.cache_clear()
    lut = table_Jakob2019(5)
    assert sorted(os.listdir(tmp_path / "cache")) == ["jakob2019-sRGB-5.coeff"]
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("SPECREF_CACHE_DIR", str(blocker))
    table_Jakob2019.cache_clear()
    with pytest.warns(SpecrefWarning, match="cannot cache the Jakob 2019 table"):
        again = table_Jakob2019(5)
    np.testing.assert_array_equal(again.coefficients, lut.coefficients)
    table_Jakob2019.cache_clear()


@pytest.mark.parametrize("size", [3, 129])
def test_table_size_is_bounded(size):
    with pytest.raises(SpecrefError, match=r"must be in \[4, 128\]"):
        generate_table_Jakob2019(size)

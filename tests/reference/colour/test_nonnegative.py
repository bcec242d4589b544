"""Non-negative spectra from the regression (erratum E106): the projection and where it applies."""

from __future__ import annotations

import numpy as np
import pytest

from reference.colour.spectra import GRID_41
from reference.colour.spectral_regression import (
    SpectralRegression,
    model_XYZ_weights,
    project_nonnegative,
    spectralize_blocks,
)
from reference.data import data_path


def test_projection_is_the_constrained_least_squares_solution(rng):
    # Source: scipy's SLSQP on the same problem stated with explicit constraints: the nearest
    # non-negative spectrum with the same XYZ (a colour inside the locus, so one exists)
    from scipy.optimize import minimize

    model = SpectralRegression("polynomial", 1, np.ones((3, 41)), GRID_41.wavelengths_nm)
    W = model_XYZ_weights(model)
    smooth = 0.5 + 0.3 * np.sin(np.linspace(0, 3, 41))
    spectra = smooth + 0.2 * rng.standard_normal((5, 41))
    spectra[:, 7] = -0.15  # at least one negative value each
    projected, changed = project_nonnegative(spectra, W)
    assert changed["pixels"] == 5
    assert changed["values"] == int((spectra < 0).sum())
    for s, p in zip(spectra, projected, strict=True):
        expected = minimize(
            lambda x, s=s: 0.5 * np.sum((x - s) ** 2),
            np.clip(s, 0, None),
            jac=lambda x, s=s: x - s,
            bounds=[(0, None)] * 41,
            constraints=[{"type": "eq", "fun": lambda x, s=s: (x - s) @ W}],
            method="SLSQP",
            options={"ftol": 1e-14, "maxiter": 500},
        ).x
        np.testing.assert_allclose(p, expected, atol=2e-4)
        assert p.min() >= 0.0
        np.testing.assert_allclose(p @ W, s @ W, rtol=1e-6, atol=1e-9)


def test_spectra_without_a_negative_value_are_untouched(rng):
    model = SpectralRegression("polynomial", 1, np.ones((3, 41)), GRID_41.wavelengths_nm)
    spectra = rng.uniform(0.0, 1.0, (6, 41))
    projected, changed = project_nonnegative(spectra, model_XYZ_weights(model))
    np.testing.assert_array_equal(projected, spectra)
    assert changed == {"values": 0, "pixels": 0, "min": 0.0}


def test_a_real_panorama_spectralizes_without_negative_values():
    # venice_sunset with the shipped model: the raw prediction has 29 negative values in 8 pixels
    # near the sun (down to -285); the spectralized panorama has none, and the same colour
    from reference.colour.upsampling import default_regression
    from reference.images.formats import read_hdr

    model = default_regression()
    RGB = read_hdr(data_path("environments/venice_sunset_1k.hdr"))
    raw = model.predict(RGB)
    assert (raw < 0).sum() == 29
    blocks = spectralize_blocks(model, RGB)
    out = np.concatenate([b.copy() for _, b in blocks])
    assert out.min() >= 0.0
    W = model_XYZ_weights(model)
    bad = (raw < 0).any(axis=-1)
    np.testing.assert_allclose(out[bad] @ W, raw[bad] @ W, rtol=1e-5)
    np.testing.assert_allclose(out[~bad], raw[~bad], rtol=1e-5, atol=1e-5)  # float32 blocks


@pytest.mark.parametrize("suffix", [".exr", ".tif"])
def test_the_command_says_how_many_values_it_projected(tmp_path, capsys, suffix):
    from validation.cli import main

    pano = data_path("environments/venice_sunset_1k.hdr")
    out = tmp_path / f"v{suffix}"
    assert main(["env", "spectralize", str(pano), "--model", "default", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "projected 29 negative band values in 8 pixels (most negative -285.3)" in printed
    # and its preview, the line docs/spectral-environments.md quotes
    assert main(["env", "preview", str(out), "-o", str(tmp_path / "v.png")]) == 0
    printed = capsys.readouterr().out
    quoted = (
        "1024×512 sRGB preview of a 1024×512 spectral image (box filter 1×1, exposure -0.69 EV, "
        "3.5 % of values clipped)"
    )
    assert quoted in printed

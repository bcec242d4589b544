"""Tests of impastor.multispectral: the designs, their ColorChecker accuracy, the shipped data."""

from __future__ import annotations

import json
from operator import attrgetter

import numpy as np
import pytest

from impastor.multispectral import (
    DESIGNS_FILE,
    MS_GRID,
    MULTISPECTRAL_DESIGNS,
    box_sampling_functions,
    channels_to_XYZ,
    light_to_channels,
    load_design,
    render_channels,
    spectra_to_channels,
)
from reference.colour.spectra import spectrum_from_dataset
from reference.errors import SpecrefError


@pytest.mark.parametrize("method", MULTISPECTRAL_DESIGNS.values(), ids=attrgetter("name"))
def test_designs_are_normalised_and_non_negative(method, rng):
    for n in range(3, 11):
        d = method.reference(n)
        assert d.s.shape == (n, MS_GRID.n_bands)
        assert d.M.shape == (3, n)
        assert (d.s >= 0).all()
        np.testing.assert_allclose(d.s.sum(axis=1), 1.0, rtol=1e-9)


@pytest.mark.parametrize(
    ("design", "mean_max", "max_max"), [("box", 0.8, 2.2), ("optimized", 0.25, 0.6)]
)
@pytest.mark.parametrize("light", ["D65", "D50", "A"])
def test_colorchecker_targets(design, mean_max, max_max, light):
    # Source: colour.sd_to_XYZ on the 5 nm N Ohta data
    # (validation.studies.metrics.colorchecker_truth); targets: ours, checked by the report's
    # ImpastoR section too (one matrix for all three lights; the chart is held out of the fit).
    from validation.studies.impastor import design_delta_E

    dE = design_delta_E(design, 6, light)
    assert dE.mean() <= mean_max, dE.mean()
    assert dE.max() <= max_max, dE.max()


def test_white_is_about_one_under_the_fitted_lights():
    # Lights outside the fit (FL2 loses 4.5 %) are reported in the report, not tested here.
    d = load_design("optimized", 6)
    for light in ("D65", "D50", "A"):
        XYZ = render_channels(
            np.ones(MS_GRID.n_bands), spectrum_from_dataset("illuminant", light), d
        )
        assert XYZ[1] == pytest.approx(1.0, abs=0.02), light


def test_shapes_and_spectrum_inputs(rng):
    d = load_design("box", 6)
    R = rng.random((2, 3, MS_GRID.n_bands))
    assert spectra_to_channels(R, d).shape == (2, 3, 6)
    U = spectra_to_channels(R, d) * light_to_channels(spectrum_from_dataset("illuminant", "A"), d)
    assert channels_to_XYZ(U, d).shape == (2, 3, 3)
    lemon = spectrum_from_dataset("colorchecker", "yellow")
    assert spectra_to_channels(lemon, d).shape == (6,)
    assert spectra_to_channels([lemon, lemon], d).shape == (2, 6)


def test_box_functions_follow_their_edges():
    # Source: definition, a box from 400 to 500 nm covers the 5 nm cells centred 405 ... 495
    # fully and the cells at 400 and 500 by half.
    s = box_sampling_functions([380, 400, 500, 780])
    wl = MS_GRID.wavelengths_nm
    inside = (wl > 400) & (wl < 500)
    assert np.allclose(s[1][inside], s[1][inside][0])
    assert s[1][wl == 400][0] == pytest.approx(s[1][inside][0] / 2)
    assert s[1][(wl < 400) | (wl > 500)].sum() == 0


def test_multispectral_bad_input():
    with pytest.raises(SpecrefError, match="channel count must be >= 3, got 2"):
        load_design("optimized", 2)
    with pytest.raises(SpecrefError, match="no 11-channel design"):
        load_design("optimized", 11)
    with pytest.raises(SpecrefError, match="needs at least 3 channels"):
        box_sampling_functions([380, 500, 780])
    with pytest.raises(SpecrefError, match="edges must increase"):
        box_sampling_functions([380, 600, 500, 780])
    with pytest.raises(SpecrefError, match="reflectance: must be >= 0"):
        spectra_to_channels(-np.ones(81), load_design("box", 6))
    with pytest.raises(SpecrefError, match="81 values last"):
        spectra_to_channels(np.ones(41), load_design("box", 6))
    with pytest.raises(SpecrefError, match="unknown multispectral design 'gauss'"):
        MULTISPECTRAL_DESIGNS.lookup("gauss")


def test_shipped_designs_record_their_provenance():
    doc = json.loads(DESIGNS_FILE.read_text())
    assert doc["generator"] == "validation/precompute/impastor_designs.py"
    training = doc["training"]
    # No ColorChecker set is used, and the look-alikes removed are listed.
    assert not any("ColorChecker" in s or "BabelColor" in s for s in training["sets"])
    assert training["removed"]
    assert training["n_kept"] + len(training["removed"]) == 220


def test_regenerating_a_box_design_reproduces_the_shipped_one():
    from validation.precompute.impastor_designs import Problem, fit_box, training_set

    R, _, _ = training_set()
    edges, _, M = fit_box(Problem(R), 4)
    shipped = json.loads(DESIGNS_FILE.read_text())["designs"]["box"]["4"]
    np.testing.assert_allclose(edges, shipped["edges_nm"], atol=1e-3)
    np.testing.assert_allclose(M, shipped["M"], rtol=1e-6, atol=1e-9)

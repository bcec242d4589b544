"""Tests of impastor.painting: the demo painting, its renderer, the horizon cache, missing data."""

from __future__ import annotations

from operator import attrgetter

import numpy as np
import pytest

from impastor import painting as imp
from reference.errors import SpecrefError


def test_render_painting_small(tmp_path):
    painting = imp.impasto_painting(32, seed=3)
    out = imp.render_painting("A", 24, "fis", painting, light_resolution=(32, 16), backend="numpy")
    assert out["sRGB"].shape == (24, 24, 3)
    assert np.isfinite(out["XYZ"]).all()
    d65 = imp.render_painting(
        "D65", 24, "fis", painting, light_resolution=(32, 16), backend="numpy"
    )
    # Under A the picture is yellower than under D65 (no chromatic adaptation): more red than blue.
    ratio_a = out["XYZ"][..., 0].sum() / out["XYZ"][..., 2].sum()
    ratio_d65 = d65["XYZ"][..., 0].sum() / d65["XYZ"][..., 2].sum()
    assert ratio_a > 1.5 * ratio_d65


def test_missing_spectrum_fails_clearly(tmp_path):
    with pytest.raises(SpecrefError, match=r"lemon__nix_export.csv: measured spectrum not found"):
        imp.load_paint_spectra(tmp_path, names=("lemon",))


def test_paint_spectra_are_the_shipped_measurements():
    # Source: reference/data/spectra/physicallybased/lemon__nix_export.csv, its "R550 nm" column
    # read here with the csv module (Nix Spectro 2 export); 550 nm lies on both grids.
    import csv

    from reference.data import measured_spectra_folder

    with open(measured_spectra_folder() / "lemon__nix_export.csv", newline="") as handle:
        rows = list(csv.reader(handle, delimiter=";"))
    at = next(i for i, row in enumerate(rows) if "R550 nm" in row)  # the header row
    expected = float(rows[at + 1][rows[at].index("R550 nm")])
    lemon = imp.load_paint_spectra(names=("lemon",))["lemon"]
    assert lemon[(550 - 380) // 5] == pytest.approx(expected, rel=1e-12)


def test_horizon_map_is_computed_once_per_height_field(monkeypatch):
    from impastor import horizon

    calls = []

    def counting(*args, **kwargs):
        calls.append(args[0].shape)
        return horizon.horizon_map(*args, **kwargs)

    monkeypatch.setattr(imp, "horizon_map", counting)
    monkeypatch.setattr(imp, "_HORIZON_CACHE", type(imp._HORIZON_CACHE)())
    painting = imp.impasto_painting(24, seed=5)
    settings = {"light_resolution": (16, 8), "backend": "numpy"}
    first = imp.render_painting("D65", 16, "median_cut", painting, **settings)
    second = imp.render_painting("A", 16, "fis", painting, **settings)
    assert len(calls) == 1
    # The cached map is the map: a frame equals one rendered with a cold cache.
    imp._HORIZON_CACHE.clear()
    again = imp.render_painting("D65", 16, "median_cut", painting, **settings)
    np.testing.assert_array_equal(again["XYZ"], first["XYZ"])
    assert len(calls) == 2
    # A different height field gets its own map.
    other = dict(painting, height=painting["height"] * 1.5)
    imp.render_painting("D65", 16, "median_cut", other, **settings)
    assert len(calls) == 3
    assert np.isfinite(second["XYZ"]).all()
    cached = imp.cached_horizon_map(painting["height"], painting["pixel_size"], 18, 32, "numpy")
    assert not cached.flags.writeable
    np.testing.assert_array_equal(
        cached, horizon.horizon_map(painting["height"], painting["pixel_size"], 18, 32, "numpy")
    )


@pytest.mark.parametrize("method", imp.PAINTING_LIGHTING_METHODS.values(), ids=attrgetter("name"))
def test_painting_lighting_methods_give_finite_nonnegative_gloss(method, rng):
    inputs = method.example_inputs(rng)
    I_s = method.reference(*inputs)
    assert I_s.shape[0] == len(inputs[0])
    assert np.isfinite(I_s).all()
    assert (I_s >= 0).all()


def test_painting_lighting_method_unknown_key_lists_the_registry():
    with pytest.raises(SpecrefError, match="allowed: fis, hybrid, median_cut, variance_min"):
        imp.render_painting("D65", 8, "nearest")

"""Tests of validation.impastor_lighting: gloss curves, the demo painting, missing shared data."""

from __future__ import annotations

import numpy as np
import pytest

from reference.errors import SpecrefError
from validation import impastor_lighting as imp


def test_gloss_validation_tracks_the_reference():
    result = imp.gloss_validation(gloss=((0.06, 0.02), (0.06, 0.15)), angles_deg=[6, 7.5, 9, 15])
    for sample in result["samples"]:
        peak = int(np.argmax(sample["reference"]))
        assert abs(sample["pipeline"][peak] / sample["reference"][peak] - 1) < 0.1


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


def test_missing_shared_data_fails_clearly(tmp_path, monkeypatch):
    monkeypatch.setenv("SPECREF_SHARED_DATA", str(tmp_path))
    with pytest.raises(SpecrefError, match="measured spectra not found"):
        imp.load_paint_spectra()


def test_horizon_map_is_computed_once_per_height_field(monkeypatch):
    from reference import horizon

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

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

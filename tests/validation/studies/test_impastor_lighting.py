"""Tests of validation.studies.impastor_lighting: gloss curves against brute force."""

from __future__ import annotations

import numpy as np

from validation.studies import impastor_lighting as imp


def test_gloss_validation_tracks_the_reference():
    result = imp.gloss_validation(gloss=((0.06, 0.02), (0.06, 0.15)), angles_deg=[6, 7.5, 9, 15])
    for sample in result["samples"]:
        peak = int(np.argmax(sample["reference"]))
        assert abs(sample["pipeline"][peak] / sample["reference"][peak] - 1) < 0.1

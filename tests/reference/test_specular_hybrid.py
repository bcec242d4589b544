"""Tests of reference.specular_hybrid: the hybrid against the better of point lights and FIS."""

from __future__ import annotations

import numpy as np
import pytest


@pytest.mark.slow
@pytest.mark.xfail(
    strict=True,
    reason="issue 6 target not met: near the crossover (alpha 0.03-0.1, fluorescent booth) the "
    "hybrid is more than 10 % worse than the better method (docs/impastor.md 'The hybrid', errata "
    "E17); test_hybrid_within_the_two_methods_and_best_at_the_ends pins what holds",
)
def test_hybrid_never_worse_than_the_better_method_by_ten_percent():
    from validation.impastor_lighting import specular_error_vs_alpha

    result = specular_error_vs_alpha(
        (0.01, 0.03, 0.05, 0.07, 0.1, 0.3), n_side=5, light_resolution=(64, 32), supersample=8
    )
    best = np.minimum(result["median_cut"], result["fis"])
    # The reference's own error (doubling the supersampling) is far below the methods' errors,
    # so the comparison measures the methods, not the reference.
    assert (np.asarray(result["reference_error"]) < 0.05 * best).all()
    ratio = np.asarray(result["hybrid"]) / best
    assert ratio.max() <= 1.1, dict(zip(result["alpha"], ratio.round(3), strict=True))


@pytest.mark.slow
def test_hybrid_within_the_two_methods_and_best_at_the_ends():
    from validation.impastor_lighting import specular_error_vs_alpha

    result = specular_error_vs_alpha(
        (0.01, 0.03, 0.07, 0.2, 0.5), n_side=4, light_resolution=(64, 32), supersample=6
    )
    pl, fis, hybrid = (np.asarray(result[k]) for k in ("median_cut", "fis", "hybrid"))
    # Never worse than the worse method; within 10 % of the better one away from the crossover.
    assert (hybrid <= 1.05 * np.maximum(pl, fis)).all()
    assert hybrid[0] <= 1.1 * min(pl[0], fis[0])
    assert (hybrid[2:] <= 1.1 * np.minimum(pl[2:], fis[2:])).all()

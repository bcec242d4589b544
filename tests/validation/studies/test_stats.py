"""Tests of validation.studies.stats: chi2_test accepts correct samplers and catches wrong ones.

The only file that calls chi2_test directly (tests/validation/studies/test_chi2_cases.py checks
it): the samplers that must pass run as registered cases of validation.studies.chi2_cases."""

from __future__ import annotations

from operator import attrgetter

import numpy as np
import pytest

from reference.errors import SpecrefError
from validation.studies.chi2_cases import CHI2_CASES, cases_for, run_chi2_case
from validation.studies.stats import chi2_test, sidak_alpha

N_TESTS = len(CHI2_CASES)
_uniform_sphere, _uniform_pdf = CHI2_CASES.lookup("uniform_sphere").make()
_cosine_hemisphere, _cosine_pdf = CHI2_CASES.lookup("cosine_hemisphere").make()


@pytest.mark.parametrize("case", cases_for("validation.studies.stats"), ids=attrgetter("name"))
def test_chi2_accepts_the_controls(case, tmp_path):
    # Source: closed forms, 1/(4π) on the sphere and cos θ/π on the hemisphere.
    result = run_chi2_case(case, tmp_path)
    assert result.passed, result.message
    assert result.expected.sum() == pytest.approx(case.n_samples, rel=1e-10)
    assert result.alpha == pytest.approx(sidak_alpha(0.01, N_TESTS), rel=1e-15)


def test_chi2_rejects_wrong_pdf(tmp_path):
    # Cosine samples tested against the uniform-hemisphere pdf: must fail, and save diagnostics.
    result = chi2_test(
        _cosine_hemisphere,
        lambda d: np.full(len(d), 1 / (2 * np.pi)),
        "hemisphere",
        50_000,
        11,
        seed=4,
        n_tests=N_TESTS,
        name="wrong",
        out_dir=tmp_path,
    )
    assert not result.passed
    assert result.p_value < 1e-10
    assert (tmp_path / "chi2_wrong.npz").exists()
    assert (tmp_path / "chi2_wrong.png").exists()
    assert "chi2_wrong.png" in result.message


def test_chi2_rejects_samples_outside_domain():
    result = chi2_test(
        _uniform_sphere, _uniform_pdf, "hemisphere", 2000, 5, seed=1, n_tests=N_TESTS
    )
    assert not result.passed
    assert "outside the hemisphere" in result.message


def test_chi2_rejects_negative_pdf():
    result = chi2_test(
        _cosine_hemisphere, lambda d: d[:, 0], "hemisphere", 2000, 5, seed=1, n_tests=N_TESTS
    )
    assert not result.passed
    assert "negative" in result.message


def test_chi2_rejects_pdf_mass_above_one():
    result = chi2_test(
        _cosine_hemisphere,
        lambda d: 1.01 * _cosine_pdf(d),
        "hemisphere",
        2000,
        5,
        seed=1,
        n_tests=N_TESTS,
    )
    assert not result.passed
    assert "integrates to 1.01" in result.message


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"domain": "disk"}, "unknown chi2 domain 'disk'"),
        ({"res": 10}, "res: must be an odd integer"),
        ({"n_samples": 10}, "n_samples: must be >= 1000"),
    ],
)
def test_chi2_bad_input(kwargs, match):
    args = {"domain": "hemisphere", "n_samples": 2000, "res": 5}
    args.update(kwargs)
    with pytest.raises(SpecrefError, match=match):
        chi2_test(_cosine_hemisphere, _cosine_pdf, seed=1, n_tests=N_TESTS, **args)


def test_sidak_alpha_limit():
    # Source: closed form; for small α, 1 − (1 − α)^(1/n) → α/n (Bonferroni).
    assert sidak_alpha(1e-6, 10) == pytest.approx(1e-7, rel=1e-6)
    with pytest.raises(SpecrefError, match="alpha: must be in"):
        sidak_alpha(1.5, 1)
    with pytest.raises(SpecrefError, match="n_tests: must be >= 1, got 0"):
        sidak_alpha(0.01, 0)

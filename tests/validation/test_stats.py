"""Tests of validation.stats.chi2_test: it accepts correct samplers and catches wrong ones."""

from __future__ import annotations

import numpy as np
import pytest

from reference.errors import SpecrefError
from validation.stats import chi2_test, sidak_alpha


def _uniform_sphere(u):
    z = 1 - 2 * u[:, 0]
    r = np.sqrt(np.maximum(0, 1 - z * z))
    phi = 2 * np.pi * u[:, 1]
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], -1)


def _cosine_hemisphere(u):
    r = np.sqrt(u[:, 0])
    phi = 2 * np.pi * u[:, 1]
    return np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1 - u[:, 0])], -1)


def _cosine_pdf(d):
    return np.maximum(d[:, 2], 0) / np.pi


def test_chi2_accepts_uniform_sphere():
    # Source: closed form, the uniform density on the sphere is 1/(4π).
    result = chi2_test(
        _uniform_sphere, lambda d: np.full(len(d), 1 / (4 * np.pi)), "sphere", 50_000, 11, seed=3
    )
    assert result.passed, result.message
    assert result.expected.sum() == pytest.approx(50_000, rel=1e-10)


def test_chi2_accepts_cosine_hemisphere():
    result = chi2_test(_cosine_hemisphere, _cosine_pdf, "hemisphere", 50_000, 11, seed=4)
    assert result.passed, result.message


def test_chi2_rejects_wrong_pdf(tmp_path):
    # Cosine samples tested against the uniform-hemisphere pdf: must fail, and save diagnostics.
    result = chi2_test(
        _cosine_hemisphere,
        lambda d: np.full(len(d), 1 / (2 * np.pi)),
        "hemisphere",
        50_000,
        11,
        seed=4,
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
        _uniform_sphere, lambda d: np.full(len(d), 1 / (2 * np.pi)), "hemisphere", 2000, 5, seed=1
    )
    assert not result.passed
    assert "outside the hemisphere" in result.message


def test_chi2_rejects_negative_pdf():
    result = chi2_test(_cosine_hemisphere, lambda d: d[:, 0], "hemisphere", 2000, 5, seed=1)
    assert not result.passed
    assert "negative" in result.message


def test_chi2_rejects_pdf_mass_above_one():
    result = chi2_test(
        _cosine_hemisphere, lambda d: 1.01 * _cosine_pdf(d), "hemisphere", 2000, 5, seed=1
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
        chi2_test(_cosine_hemisphere, _cosine_pdf, seed=1, **args)


def test_sidak_alpha_limit():
    # Source: closed form; for small α, 1 − (1 − α)^(1/n) → α/n (Bonferroni).
    assert sidak_alpha(1e-6, 10) == pytest.approx(1e-7, rel=1e-6)
    with pytest.raises(SpecrefError, match="alpha: must be in"):
        sidak_alpha(1.5)

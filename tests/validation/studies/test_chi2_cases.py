"""Tests of validation.studies.chi2_cases: the registry is every chi-square test of the suite."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from validation.studies.chi2_cases import CHI2_CASES, cases_for, run_chi2_case
from validation.studies.stats import DOMAINS, sidak_alpha

ROOT = Path(__file__).resolve().parents[3]
#: The tests of chi2_test itself: samplers that must fail, bad input.
CHI2_TEST_TESTS = ROOT / "tests" / "validation" / "studies" / "test_stats.py"


def _chi2_calls(path: Path) -> int:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return sum(
        isinstance(node, ast.Call) and getattr(node.func, "id", None) == "chi2_test"
        for node in ast.walk(tree)
    )


def test_no_test_calls_chi2_test_outside_the_registry():
    # The Šidák family is len(CHI2_CASES): a test that called chi2_test itself would run outside
    # the count. The guard sees calls (the tests of chi2_test itself call it 5 times).
    assert _chi2_calls(CHI2_TEST_TESTS) >= 5
    direct = [
        str(path.relative_to(ROOT))
        for path in sorted((ROOT / "tests").rglob("*.py"))
        if path != CHI2_TEST_TESTS and _chi2_calls(path)
    ]
    assert direct == [], f"register a validation.studies.chi2_cases.Chi2Case instead: {direct}"


def test_every_registered_case_is_run_by_its_modules_test_file():
    for module in sorted({case.module for case in CHI2_CASES.values()}):
        *packages, name = module.split(".")
        test_file = ROOT.joinpath("tests", *packages, f"test_{name}.py")
        assert f'cases_for("{module}")' in test_file.read_text(encoding="utf-8"), test_file


def test_cases_are_valid_chi2_arguments():
    for case in CHI2_CASES.values():
        assert case.domain in DOMAINS
        assert case.res % 2 == 1
        assert case.n_samples >= 1000
    assert [c.name for c in cases_for("no.such_module")] == []


def test_run_chi2_case_divides_alpha_among_all_cases():
    # Source: Šidák 1967, 1 − (1 − α)^(1/n) with n the number of registered cases.
    result = run_chi2_case(CHI2_CASES.lookup("cosine_hemisphere"))
    n = len(CHI2_CASES)
    assert result.alpha == pytest.approx(1 - 0.99 ** (1 / n), rel=1e-14)
    assert result.alpha == sidak_alpha(0.01, n)

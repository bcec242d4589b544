"""Tests of the report section "ImpastoR": its images and one check per target of issue 6."""

from __future__ import annotations

import copy

from validation.report.runner import run_report
from validation.sections.impastor import impastor_checks


def _figures(**changes):
    # Figures that meet every target (the limits, with margin), then one changed.
    figures = {
        "channel_table": {
            design: {"6": {light: {"mean": 0.1, "max": 0.3} for light in ("D65", "D50", "A")}}
            for design in ("box", "optimized")
        },
        "metamers": {"A": {"pipeline": 0.1}, "D65": {"pipeline": 4.0}},
        "alpha": {"alpha": [0.01, 0.1], "median_cut": [1.0, 0.1], "fis": [0.1, 1.0],
                  "hybrid": [0.105, 0.105]},
        "shadows": {"sectors": [6, 18], "disagreement": [0.05, 0.01]},
        "round_trip": {"counts_mismatches": 0, "n_counts": 100, "XYZ_error_over_bound": 0.5},
        "albedo": {"albedo": [0.9, 0.99], "error": [1e-3, 1e-3], "theta_deg": [0, 60]},
    }  # fmt: skip
    figures = copy.deepcopy(figures)
    for path, value in changes.items():
        *keys, last = path.split("/")
        node = figures
        for key in keys:
            node = node[int(key) if isinstance(node, list) else key]
        node[int(last) if isinstance(node, list) else last] = value
    return impastor_checks(**figures)


def test_checks_cover_every_target_and_pass_when_met():
    checks = _figures()
    # 2 designs × 3 lights × (mean, max), 2 metamers, hybrid, shadows, 2 display round trips,
    # the Ward–Dür albedo.
    assert len(checks) == 12 + 2 + 1 + 1 + 2 + 1
    assert all(c.passed for c in checks), [c for c in checks if not c.passed]


def test_a_failing_figure_fails_its_check():
    # path: (value just past the limit, words in the check's name, measured as shown)
    cases = {
        "channel_table/optimized/6/A/max": (
            0.61,
            "optimized 6 channels, ColorChecker under A",
            0.61,
        ),
        "channel_table/box/6/D50/mean": (0.81, "box 6 channels, ColorChecker under D50", 0.81),
        "metamers/A/pipeline": (0.6, "metamers rendered under A", 0.6),
        "metamers/D65/pipeline": (2.5, "metamers rendered under D65", 2.5),
        "alpha/hybrid/1": (0.111, "hybrid / better", 0.111 / 0.1),
        "shadows/disagreement/1": (0.021, "horizon map (18 sectors)", "2.1 %"),
        "round_trip/counts_mismatches": (1, "counts → XYZ → counts", 1),
        "round_trip/XYZ_error_over_bound": (1.2, "XYZ → counts → XYZ", 1.2),
        "albedo/albedo/1": (1.002, "Ward–Dür white-furnace albedo", 1.002),
    }
    for path, (value, name, measured) in cases.items():
        failed = [c for c in _figures(**{path: value}) if not c.passed]
        assert len(failed) == 1, (path, failed)
        assert name in failed[0].name
        if isinstance(measured, float):
            assert abs(failed[0].measured - measured) < 1e-12
        else:
            assert failed[0].measured == measured


def test_report_section_quick(tmp_path):
    results = run_report(tmp_path, quick=True, only=["impastor"], progress=False)
    checks = {c["name"]: c for c in results["checks"] if c["section"] == "impastor"}
    assert len(checks) == 19
    # Every target holds: colour, metamers, the hybrid (erratum E17), shadows and display.
    failing = [name for name, c in checks.items() if not c["passed"]]
    assert not failing, failing
    assert (tmp_path / "images" / "impastor-painting-A.png").exists()

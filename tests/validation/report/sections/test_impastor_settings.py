"""The report's study of ImpastoR settings from a tolerance: checks that can fail, and the page."""

import pytest

from validation.report import ReportContext, SectionData
from validation.report.sections.impastor_settings import TINY, checks, present, settings_figures


def _case(fixed_error, rows):
    # rows: (label, tolerance, met, error, frame seconds)
    settings = {"n_lights": 8, "n_samples": 8, "n_sectors": 6, "failsafe": False}
    fixed = {"label": "fixed", "tolerance": None, "met": True, "pilot_error": None,
             "error": fixed_error, "frame_seconds": 2.0, "settings": settings}  # fmt: skip
    chosen = [
        {
            "label": label,
            "tolerance": tolerance,
            "met": met,
            "pilot_error": tolerance / 2,
            "error": error,
            "frame_seconds": seconds,
            "settings": settings,
        }
        for label, tolerance, met, error, seconds in rows
    ]
    from validation.studies.impastor_settings import best_speedup_at_fixed_error

    case = {"seed": 61, "light": "A", "pilot_seconds": 1.0, "eval_pixels": 10}
    case["rows"] = [fixed, *chosen]
    case["speedup_at_fixed_error"] = best_speedup_at_fixed_error(case)
    return case


@pytest.mark.parametrize(
    ("rows", "promise", "speedup"),
    [
        ([("1 %", 0.01, True, 0.009, 0.8)], True, True),  # 2.5× at less error
        ([("1 %", 0.01, True, 0.012, 0.8)], False, False),  # over its tolerance, and the fixed
        ([("2 %", 0.02, True, 0.015, 1.5)], True, False),  # within, but only 1.33× faster
        # missed on the pilot: said so, and not held against the promise
        ([("1 %", 0.01, False, 0.02, 0.5), ("2 %", 0.02, True, 0.015, 1.5)], True, False),
    ],
)
def test_checks_fail_when_the_figures_do(rows, promise, speedup):
    data = SectionData({"cases": [_case(0.01, rows)], "study": {}})
    held, faster = checks(data)
    assert held.passed is promise
    assert faster.passed is speedup


def test_tiny_study_presents_a_chart_and_a_table(tmp_path):
    data = settings_figures(study=TINY)
    (case,) = data.results["cases"]
    assert [r["label"] for r in case["rows"]] == ["fixed", "5 %"]
    assert case["rows"][0]["settings"]["n_lights"] == 32
    blocks = present(ReportContext(tmp_path, section="impastor-settings"), data)
    assert (tmp_path / "images" / "impastor-settings-time-vs-error.png").exists()
    tables = {b.caption.split(" ")[0]: b for b in blocks if hasattr(b, "rows")}
    # the fixed settings, the tolerance, and the settings chosen at the fixed settings' error
    assert len(tables["Settings"].rows) == 3
    assert case["matched"]["pilot_error"] <= case["matched"]["tolerance"]
    # every lighting method's time against its error, and the brute force they are measured on
    assert (tmp_path / "images" / "impastor-settings-methods.png").exists()
    methods = tables["Each"].rows
    names = [row[0] for row in methods]
    assert {"median_cut", "variance_min", "fis", "hybrid", "hybrid, no fail-safe"} <= set(names)
    assert names[-1] == "brute force"
    assert all(row[2] > 0 for row in methods)  # times measured
    assert all(row[3] > 0 for row in methods[:-1])  # errors against the brute force


def test_the_matched_frame_counts_for_the_speed_up_not_the_tolerances():
    case = _case(0.01, [("4 %", 0.04, True, 0.03, 0.4)])
    assert case["speedup_at_fixed_error"] is None  # the ladder's frame is not at the fixed error
    from validation.studies.impastor_settings import best_speedup_at_fixed_error

    matched = dict(
        case["rows"][1], label="matched", tolerance=0.012, error=0.0104, frame_seconds=1.0
    )
    case["matched"] = matched
    case["speedup_at_fixed_error"] = best_speedup_at_fixed_error(case)
    assert case["speedup_at_fixed_error"] == 2.0  # within 5 % of the fixed error, twice as fast
    found = checks(SectionData({"cases": [case], "study": {}, "methods": {}}))
    assert [c.passed for c in found] == [True, True]
    case["matched"]["error"] = 0.013  # over the fixed error: no speed-up at it
    case["speedup_at_fixed_error"] = best_speedup_at_fixed_error(case)
    found = checks(SectionData({"cases": [case], "study": {}, "methods": {}}))
    # its tolerance is the fixed settings' pilot error, not a promise: only the speed-up fails
    assert [c.passed for c in found] == [True, False]

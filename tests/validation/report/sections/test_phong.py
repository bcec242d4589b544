import copy
import json

import pytest

from validation.report import Image, ReportContext, Table
from validation.report.runner import run_report
from validation.report.sections.phong import PhongStudy, checks, phong_speed_accuracy, present
from validation.studies.phong_table1 import target_checks

TARGETS = (
    "error/monotone RMS at 200",
    "error/parabolic RMS at 200",
    "error/linear RMS at 200",
    "--tolerance 0.05",
    "error placement RMS minus best",
    "monotone overshoot",
    "n = 2000",
    "importance p = m, RMS(800)/RMS(200)",
    "error placement, RMS(200)/RMS(800)",
    "shading speed-up",
)

# A benchmark file for one group: the speed-up comes from it (exact 10 ms / table 0.5 ms = 20×)
BENCH = {
    "benchmarks": [
        {"group": "phong R1 far", "name": "test_exact[R1-far]", "stats": {"min": 0.01}},
        {
            "group": "phong R1 far",
            "name": "test_table[R1-far-error-monotone]",
            "stats": {"min": 0.0005},
        },
    ]
}


def _records(error_rms, uniform_rms, overshoot):
    # one row per placement and interpolation at m = 200 (and the same at m = 25)
    rows = []
    for m in (25, 200):
        for interpolation in ("linear", "parabolic", "monotone"):
            for placement, segments, rms in (
                ("error", None, error_rms),
                ("uniform", None, uniform_rms),
                ("importance", m, 1.0),
            ):
                rows.append(
                    {
                        "scene": "R1",
                        "view": "far",
                        "placement": placement,
                        "interpolation": interpolation,
                        "entries": m,
                        "segments": segments,
                        "rms": rms,
                        "overshoot": overshoot if interpolation == "monotone" else 0.5,
                    }
                )
    return rows


def _names(checks):
    return [next(t for t in TARGETS if t in c.name) for c in checks]


def test_target_checks_pass_on_passing_figures():
    # figures that meet every target (limits from docs/phong-tables.md, "Report checks")
    checks = target_checks(
        _records(1e-4, 0.2, 0.0),
        [{"entries": 40, "verified": True}],
        {"n2000_overshoot": 3.6, "importance_rms": [45.0, 44.0], "error_rms": [0.1, 0.001]},
        [12.0, 15.0],
        "in-run",
        " [test]",
    )
    assert _names(checks) == list(TARGETS)
    assert [c.passed for c in checks] == [True] * len(TARGETS)
    assert all(c.name.endswith(" [test]") for c in checks[:-1])
    assert "in-run" in checks[-1].name


def test_target_checks_fail_on_failing_figures():
    # each figure just past its limit: every check fails and shows the measured value
    checks = target_checks(
        _records(0.02, 0.01, 1e-3),
        [{"entries": 80, "verified": True}, {"entries": 30, "verified": False}],
        {"n2000_overshoot": 0.9, "importance_rms": [45.0, 20.0], "error_rms": [0.1, 0.005]},
        [12.0, 9.5],
        "in-run",
    )
    assert _names(checks) == list(TARGETS)
    assert [c.passed for c in checks] == [False] * len(TARGETS)
    measured = {name: c.measured for name, c in zip(TARGETS, checks, strict=True)}
    assert measured["error/monotone RMS at 200"] == 0.02
    assert measured["monotone overshoot"] == 1e-3
    assert measured["n = 2000"] == 0.9
    assert measured["shading speed-up"] == 9.5
    assert measured["importance p = m, RMS(800)/RMS(200)"] == pytest.approx(20.0 / 45.0)
    assert measured["error placement, RMS(200)/RMS(800)"] == pytest.approx(20.0)
    assert measured["--tolerance 0.05"] == float("inf")  # an unverified pick counts as not met
    assert measured["error placement RMS minus best"].startswith("0.01 (R1 far")


def test_target_checks_without_figures_fail():
    checks = target_checks([], [], {}, [], "none")
    assert [c.passed for c in checks] == [False] * len(TARGETS)
    assert checks[0].measured == "not measured"


@pytest.mark.slow
def test_report_phong_section_quick(tmp_path):
    bench_json = tmp_path / "bench.json"
    bench_json.write_text(json.dumps(BENCH))
    results = run_report(
        tmp_path / "r", effort="quick", only=["phong"], bench_json=bench_json, progress=False
    )
    found = results["checks"]
    assert [next(t for t in TARGETS if t in c["name"]) for c in found] == list(TARGETS)
    assert all("quick" in c["name"] for c in found[:-1])
    assert "benchmark JSON" in found[-1]["name"]
    assert found[-1]["measured"] == 20.0
    failed = [c["name"] for c in found if not c["passed"]]
    assert failed == [], failed
    assert results["sections"]["phong"]["nonfinite"] == 0


TINY = PhongStudy(8, False, 1, (25,), ("R1",), ("near",), (10,), (50,), (10,), 64, True)


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    ctx = ReportContext(tmp_path_factory.mktemp("phong"), quick=True, bench=BENCH, section="phong")
    return ctx, phong_speed_accuracy(ctx, TINY)


def test_phong_section_compute_present_checks_on_tiny_settings(tiny):
    ctx, data = tiny
    assert list(data.results) == [
        "R1 near",
        "exponent-scale",
        "exponent-spread",
        "segments",
        "tolerance R1 near",
        "failure_modes",
        "nonfinite",
        "bench",
        "speedups",
    ]
    points = data.results["R1 near"]["points"]
    assert {p["variant"] for p in points} == {
        "importance p=m",
        "importance p=m/10",
        "uniform",
        "error",
    }
    assert {p["interpolation"] for p in points} == {
        "parabolic",
        "parabolic_w",
        "linear",
        "monotone",
    }
    assert data.results["speedups"]["values"] == [20.0]
    assert data.results["nonfinite"] == 0
    found = checks(data)
    assert [next(t for t in TARGETS if t in c.name) for c in found] == list(TARGETS)
    assert found[-1].measured == 20.0
    assert "benchmark JSON" in found[-1].name
    blocks = present(ctx, data)
    images = [b.path for b in blocks if isinstance(b, Image)]
    assert images == [
        f"images/phong-{name}.png"
        for name in ("pareto", "exponent-scale", "exponent-spread", "segments")
    ]
    assert all((ctx.out_dir / path).stat().st_size > 1000 for path in images)
    # each failure chart's caption names the line that ends worst, with its RMS from the run
    captions = {b.path: b.caption for b in blocks if isinstance(b, Image)}
    for name in ("exponent-scale", "exponent-spread"):
        ends = {k: ys[-1] for k, ys in data.results[name]["rms"].items()}
        worst = max(ends, key=ends.get)
        caption = captions[f"images/phong-{name}.png"]
        assert f"the worst is {worst} (RMS {ends[worst]:.3g}" in caption
    assert "the best p is" in captions["images/phong-segments.png"]
    # the targets are shown by the report around the section (folded), not again as a table
    tables = [b for b in blocks if isinstance(b, Table)]
    assert all(t.columns[:2] != ["target", "limit"] for t in tables)


def test_phong_checks_are_a_pure_function_of_the_data(tiny):
    _, data = tiny
    before = checks(data)
    assert [c.passed for c in checks(data)] == [c.passed for c in before]
    changed = copy.deepcopy(data)
    changed.results["failure_modes"]["n2000_overshoot"] = 0.5
    changed.results["speedups"]["values"] = [5.0]
    for record in changed.arrays["records"]:
        if record["placement"] == "error" and record["interpolation"] == "monotone":
            record["overshoot"] = 0.25
    after = checks(changed)
    flipped = [
        next(t for t in TARGETS if t in c.name)
        for c, d in zip(before, after, strict=True)
        if c.passed != d.passed
    ]
    assert flipped == ["monotone overshoot", "n = 2000", "shading speed-up"]
    assert after[-1].measured == 5.0
    assert after[5].measured == 0.25

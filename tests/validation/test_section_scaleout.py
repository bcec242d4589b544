"""The scale-out section reads the benchmarks' JSON: ratios, Amdahl's prediction, the targets."""

import pytest

from validation.report import ReportContext
from validation.sections.scaleout import checks, headlines, scaleout_figures


def _record(group, role, seconds, **extra):
    return {"group": group, "stats": {"min": seconds}, "extra_info": {"role": role, **extra}}


def test_figures_from_benchmarks():
    bench = {
        "benchmarks": [
            _record("scaleout-sweep", "serial", 32.0, tasks=32),
            _record("scaleout-sweep", "distributed", 17.0, tasks=32, workers=2),
            _record("scaleout-zarr", "in-memory", 8.0),
            _record("scaleout-zarr", "zarr-streamed", 10.0, peak_python_bytes=5e7),
        ]
    }
    data = scaleout_figures(ReportContext(out_dir=".", bench=bench))
    sweep = data.results["sweep"]
    assert sweep["speedup"] == pytest.approx(32 / 17)
    assert sweep["task_s"] == pytest.approx(1.0)
    # 17 s = 32 tasks × 1 s / 2 workers + 32 × o  →  o = 1/32 s
    assert sweep["overhead_s"] == pytest.approx(1 / 32)
    # one two-core machine predicts about the measured speed-up (plus one task at the end)
    assert sweep["predicted_speedup"][1] == pytest.approx(32 / 18)
    assert data.results["zarr"]["throughput_ratio"] == pytest.approx(0.8)
    assert [c.passed for c in checks(data)] == [True, True]
    assert "1.88× faster" in headlines(data)[0].text


def test_without_benchmarks_nothing_is_claimed():
    data = scaleout_figures(ReportContext(out_dir="."))
    assert data.results == {"measured": False}
    assert checks(data) == []
    assert "make bench" in headlines(data)[0].text

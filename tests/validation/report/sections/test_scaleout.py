"""The scale-out section reads the benchmarks' JSON: ratios, Amdahl's prediction, the targets."""

import pytest

from validation.report import ReportContext
from validation.report.sections.scaleout import checks, headlines, present, scaleout_figures


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


def test_full_size_panorama_and_layout_figures():
    # The 12k figures (peak memory, throughput against the 2k in-memory projection) and the layout
    # table, from hand-made records: 2M pixels in 0.5 s in memory; 72M pixels in 20 s streamed.
    full = _record(
        "scaleout-zarr-12k",
        "zarr-12k",
        21.0,
        height=6000,
        width=12000,
        bands=41,
        order=100,
        wall_s=20.0,
        peak_rss_bytes=2.5e9,
        imports_rss_bytes=2e8,
        store_bytes=3e9,
        float32_bytes=11.808e9,
        rows_per_chunk=11,
        compression="blosc-lz4",
        generate_s=40.0,
    )
    read = [
        _record(
            "scaleout-zarr-read",
            "read",
            seconds,
            data="spectral",
            compression=compression,
            chunk_bytes=21.5e6,
            ratio=1.5,
            float32_bytes=86e6,
        )
        for compression, seconds in (("zstd", 0.08), ("blosc-lz4", 0.04))
    ]
    bench = {
        "benchmarks": [
            _record("scaleout-sweep", "serial", 32.0, tasks=32),
            _record("scaleout-sweep", "distributed", 17.0, tasks=32, workers=2),
            _record("scaleout-zarr", "in-memory", 0.5, pixels=1024 * 2048),
            _record("scaleout-zarr", "zarr-streamed", 0.6),
            _record("scaleout-zarr", "zarr-streamed-no-readahead", 0.8),
            full,
            *read,
        ]
    }
    ctx = ReportContext(out_dir=".", bench=bench)
    data = scaleout_figures(ctx)
    z = data.results["zarr_12k"]
    assert z["throughput_vs_2k_in_memory"] == pytest.approx((6000 * 12000 / 20) / (2**21 / 0.5))
    assert [r["compression"] for r in data.results["zarr_layout"]] == ["blosc-lz4", "zstd"]
    assert data.results["zarr_layout"][0]["read_gb_s"] == pytest.approx(86e6 / 0.04 / 1e9)
    # 2.5 GB misses the 2 GB bound: the check says so
    memory = checks(data)[-1]
    assert "peak resident memory" in memory.name
    assert memory.measured == pytest.approx(2.5)
    assert not memory.passed
    assert "(62 % without the thread" in present(ctx, data)[0].text
    text = present(ctx, data)[2].text
    assert "12000×6000×41" in text
    assert "2.50 GB" in text


def _cli_records(serial_s=46.0, local_s=29.0, peak=289e6):
    return [
        _record("scaleout-cli", "cli-serial", serial_s, cells=2400),
        _record("scaleout-cli", "cli-local", local_s, cells=2400, workers=2),
        _record(
            "scaleout-cli",
            "convert-memory",
            9.0,
            height=4096,
            width=8192,
            channels=3,
            chunk_bytes=21.5e6,
            float32_bytes=402.7e6,
            peak_rss_bytes=peak,
            baseline_rss_bytes=160e6,
        ),
    ]


def test_command_line_figures_and_their_targets(tmp_path):
    # The cold sweep from the command line (46 s serial, 29 s on two workers: 1.59x, below 1.7)
    # and env convert's memory (129 MB above a tiny map's: 6 chunks of 21.5 MB, above 4)
    data = scaleout_figures(ReportContext(out_dir=tmp_path, bench={"benchmarks": _cli_records()}))
    cli = data.results["cli"]
    assert cli["sweep"]["speedup"] == pytest.approx(46 / 29)
    assert cli["convert"]["above_chunks"] == pytest.approx(129e6 / 21.5e6)
    assert [(c.measured, c.passed) for c in checks(data)] == [
        (pytest.approx(46 / 29), False),
        (pytest.approx(6.0), False),
    ]
    text = present(ReportContext(out_dir=tmp_path), data)[-1].text
    assert "46.0 s serially and 29.0 s on a local cluster of 2 workers: 1.59×" in text
    assert "6.0 chunks of 21.5 MB above it" in text
    # both met
    met = _cli_records(serial_s=60.0, local_s=30.0, peak=230e6)
    data = scaleout_figures(ReportContext(out_dir=tmp_path, bench={"benchmarks": met}))
    assert [c.passed for c in checks(data)] == [True, True]

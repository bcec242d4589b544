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


#: One-cell sweeps (wall, CPU) on local:0 (serial) … local:4 of a 2-core machine, made by the
#: start-up model itself: u(N) = 9 + 1·(N − 1) s of CPU, latency 3.5 s, spread over min(N + 1, 2).
STARTUP = ((5.0, 5.2), (8.0, 9.0), (8.5, 10.0), (9.0, 11.0), (9.5, 12.0))


def _cli_records(serial_s=70.0, runs=(74.0, 42.0), startup=STARTUP, peak=289e6):
    sweep = {"cells": 3840, "shared": 8}
    return [
        _record("scaleout-cli", "cli-serial", serial_s, **sweep),
        *[
            _record("scaleout-cli", "cli-workers", t, workers=n, **sweep)
            for n, t in enumerate(runs, start=1)
        ],
        *[
            _record("scaleout-cli", "cli-startup", wall, workers=n, cores=2, cpu_s=cpu)
            for n, (wall, cpu) in enumerate(startup)
        ],
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
    # The cold sweep from the command line (70 s serial, 42 s on two workers: 1.67x, below 1.7)
    # and env convert's memory (129 MB above a tiny map's: 6 chunks of 21.5 MB, above 4)
    data = scaleout_figures(ReportContext(out_dir=tmp_path, bench={"benchmarks": _cli_records()}))
    cli = data.results["cli"]
    assert cli["sweep"]["speedup"] == {1: pytest.approx(70 / 74), 2: pytest.approx(70 / 42)}
    assert cli["convert"]["above_chunks"] == pytest.approx(129e6 / 21.5e6)
    found = {c.name.split(":")[-1].strip(): (c.measured, c.passed) for c in checks(data)}
    names = list(found)
    assert found[names[0]] == (pytest.approx(70 / 42), False)
    assert found[names[1]] == (70.0, True)  # the sweep is long enough for its targets
    assert found[names[2]] == (pytest.approx(0.0, abs=1e-12), True)  # start-up, held out
    assert [c.basis for c in checks(data)] == ["design"] * 2 + ["held out"] + ["design"] * 2
    assert found[names[3]][1] is False  # 3.5 s of latency in 70 s keeps 16 workers below 8x
    assert found[names[4]] == (pytest.approx(6.0), False)
    parts = present(ReportContext(out_dir=tmp_path), data)
    text = parts[-3].text
    assert "70.0 s serially and 42.0 s on a local cluster of 2 workers: 1.67×" in text
    assert "9.0 s of CPU on one worker and 1.00 s more per further worker" in text
    assert "off by +0 % at 3, +0 % at 4" in text
    assert "6.0 chunks of 21.5 MB above it" in text
    assert [row[0] for row in parts[-2].rows] == [1, 2, 4, 8, 16, 64]
    assert [row[-1] for row in parts[-1].rows] == ["serial", "design", "design", *["held out"] * 2]
    # all met: a shorter start-up and faster workers
    fast = ((2.0, 2.0), (3.0, 3.0), (3.2, 3.4), (3.6, 3.8), (3.8, 4.2))
    met = _cli_records(serial_s=70.0, runs=(71.0, 38.0), startup=fast, peak=230e6)
    data = scaleout_figures(ReportContext(out_dir=tmp_path, bench={"benchmarks": met}))
    assert [c.passed for c in checks(data)] == [True] * 5
    # a sweep shorter than a minute: its targets are not measured as they ask
    short = _cli_records(serial_s=40.0, runs=(41.0, 21.0), startup=fast)
    data = scaleout_figures(ReportContext(out_dir=tmp_path, bench={"benchmarks": short}))
    assert [c.passed for c in checks(data)][:2] == [True, False]


def test_a_benchmark_without_cpu_times_gives_the_speed_ups_and_no_model(tmp_path):
    records = [r for r in _cli_records() if r["extra_info"]["role"] != "cli-startup"] + [
        _record("scaleout-cli", "cli-startup", w, workers=n) for n, (w, _) in enumerate(STARTUP)
    ]
    data = scaleout_figures(ReportContext(out_dir=tmp_path, bench={"benchmarks": records}))
    sweep = data.results["cli"]["sweep"]
    assert sweep["speedup"][2] == pytest.approx(70 / 42)
    assert "predicted_speedup" not in sweep
    assert len(checks(data)) == 3  # the speed-up, the sweep's length, env convert
    present(ReportContext(out_dir=tmp_path), data)


def test_the_split_sweep_is_set_beside_the_cluster_as_the_machines_ceiling(tmp_path):
    # two serial processes of half the sweep each, 36 s: 70/36 = 1.94x; the cluster's 1.67x is
    # 86 % of it. The split is a figure, not a target.
    records = [*_cli_records(), _record("scaleout-cli", "cli-split", 36.0, workers=2)]
    data = scaleout_figures(ReportContext(out_dir=tmp_path, bench={"benchmarks": records}))
    sweep = data.results["cli"]["sweep"]
    assert (sweep["split_parts"], sweep["split_s"]) == (2, 36.0)
    assert len(checks(data)) == 5
    parts = present(ReportContext(out_dir=tmp_path), data)
    assert "into 2 serial processes started at once took 36.0 s (1.94×)" in parts[-3].text
    assert "the cluster reached 86 % of it" in parts[-3].text
    assert ["2 serial processes", 36.0, pytest.approx(70 / 36), None] in parts[-2].rows


def test_the_start_up_model_recovers_its_own_parameters_and_holds_out_the_busy_counts():
    from validation.report.sections.scaleout import startup_model

    model = startup_model(dict(enumerate(STARTUP)), cores=2)
    assert model["latency_s"] == pytest.approx(3.5)
    assert model["cpu_s"] == (pytest.approx(9.0), pytest.approx(1.0))
    assert model["design"] == [1, 2]
    assert model["held_out_error"] == {3: pytest.approx(0.0), 4: pytest.approx(0.0)}
    # a core per worker: the CPU is spread over N, and the start-up tends to L + c
    assert model["predict"](16, 16) == pytest.approx(3.5 + (9.0 + 15.0) / 16)
    # starts that grow faster beyond the cores than the CPU says are caught as held-out misses
    slow = dict(enumerate(STARTUP)) | {3: (11.0, 11.0), 4: (13.0, 12.0)}
    assert min(startup_model(slow, cores=2)["held_out_error"].values()) < -0.15


def test_the_scaling_model_recovers_its_own_parameters():
    # runs made by the model itself (the start-up above, 64 s of work run 1.15× as long on the
    # workers, half a chunk's wait at the end, 20 ms per task) give back those parameters and its
    # speed-ups, also beyond the measured counts (a core per worker there)
    from validation.report.sections.scaleout import _chunks, sweep_scaling_model

    def T(n, cores=2):
        m = _chunks(3840, 8, n)
        tail = 64.0 / (2 * m) if n > 1 else 0.0
        start = 3.5 + (9.0 + (n - 1)) / min(n + 1, cores)
        return start + 1.15 * (64.0 / n + tail) + 0.02 * m / n

    startup = dict(enumerate(STARTUP))
    model = sweep_scaling_model(67.0, startup, {n: T(n) for n in (1, 2, 3)}, 3840, 8, cores=2)
    assert model["work_s"] == pytest.approx(62.0)  # 67 s less the serial one-cell run's 5 s
    assert model["overhead_s"] == pytest.approx(0.02)
    assert model["slowdown"] == pytest.approx(1.15 * 64 / 62)  # the work the model counts is 62 s
    assert model["predicted_speedup"][16] == pytest.approx(67.0 / T(16, 16))
    assert model["predicted_startup_s"][16] == pytest.approx(3.5 + 24.0 / 16)
    # Dask's cost per task measured on its own: o is that, and κ alone is fitted
    runs = {n: T(n) for n in (1, 2)}
    measured = sweep_scaling_model(67.0, startup, runs, 3840, 8, cores=2, task_s=0.02)
    assert measured["overhead_s"] == 0.02
    assert measured["slowdown"] == pytest.approx(1.15 * 64 / 62, rel=0.01)
    # an overhead the start-up and the work already explain is 0, not negative
    faster = sweep_scaling_model(67.0, startup, {1: 60.0, 2: 30.0}, 3840, 8, cores=2)
    assert faster["overhead_s"] == 0.0

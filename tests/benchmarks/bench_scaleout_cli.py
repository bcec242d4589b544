"""Scale-out as a user pays it: commands from the command line, in fresh processes.

Group ``scaleout-cli`` (docs/scale-out.md, "How it scales, and what does not"; the report's
Scale-out section fits its model to these figures):

- ``cli-serial``: ``specref sweep GRID --scheduler serial``, a 6,144-cell Phong sweep (4 materials
  × 2 views × 3 placements × 4 interpolations × 64 table sizes, resolution 512; over a minute
  serially, as the targets ask), in a new process;
- ``cli-workers``: the same sweep with ``--scheduler local:N`` for N = 1 … the cores present: a new
  local cluster of N workers, its start, the workers' imports and the shared exact renders
  included (target ≥ 1.7× on two cores); every CSV must equal the serial one byte for byte;
- ``cli-startup``: a one-cell sweep, serially and on ``local:N`` for N = 1 … the cores present + 2:
  what a run pays whatever its size (process start, imports, the cluster's start, the kernels'
  loading, one exact render), its wall time and the CPU time of its processes (the command's and
  every worker's: ``RUSAGE_CHILDREN``). The report's start-up model is fitted on N ≤ the cores and
  checked on the two counts beyond them, where the workers' starts compete for the cores;
- ``cli-split``: the machine's own ceiling, without a scheduler: the same sweep cut by material
  into as many parts as there are cores (at most the 4 materials), each part a serial
  ``specref sweep`` in its own process, all started at once; the parts' rows are the serial
  sweep's, in order. A cluster can only approach it (it pays its start and its scheduling), so
  the report sets the cluster's speed-up beside it;
- ``cli-task-overhead``: Dask's own cost per task, from 2,000 empty tasks on a warm local cluster
  (the model's ``o``, measured rather than fitted);
- ``convert-memory``: ``specref env convert`` of a 4096 × 8192 RGB EXR in a new process, its peak
  resident set (``VmHWM``), beside the same command's on a 16 × 32 map (what the process holds
  without the map) and the size of one float32 chunk (target: at most four chunks above it, three
  in flight and the output's chunk buffer).

Two rounds of the serial and the cluster sweeps, whose fastest counts (the serial one takes about
a minute, and the machine's speed drifts by a tenth or more between minutes), one of the split,
three of the start-ups; every run records its processes' CPU seconds (``cpu_s``, of its fastest
round).
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

ENTRIES = ", ".join(str(e) for e in range(40, 1064, 16))
GRID = f"""kind = "phong"
[grid]
materials = ["R1", "R2", "R3", "bimodal"]
views = ["near", "far"]
placements = ["importance", "uniform", "error"]
interpolations = ["parabolic", "parabolic_w", "linear", "monotone"]
entries = [{ENTRIES}]
resolution = 512
"""
CELLS, SHARED = 4 * 2 * 3 * 4 * 64, 4 * 2
#: Rounds of the serial and the cluster sweeps (the fastest counts).
SWEEP_ROUNDS = 2
#: One cell of the same sweep: the cost of a run that does not depend on its size.
ONE_CELL = """kind = "phong"
[grid]
materials = ["R1"]
views = ["near"]
placements = ["importance"]
interpolations = ["parabolic"]
entries = [40]
resolution = 512
"""
CORES = os.cpu_count() or 1
SPECREF = os.path.join(os.path.dirname(sys.executable), "specref")
#: A child that runs one specref command and prints its peak resident set size (bytes) last.
PEAK_CHILD = (
    "import sys\n"
    "from validation.cli import main\n"
    "code = main(sys.argv[1:])\n"
    "peak = [l for l in open('/proc/self/status') if l.startswith('VmHWM:')][0].split()[1]\n"
    "print(code, int(peak) * 1024)\n"
)


@pytest.fixture(scope="module")
def grid(tmp_path_factory):
    folder = tmp_path_factory.mktemp("sweep")
    (folder / "grid.toml").write_text(GRID)
    (folder / "one.toml").write_text(ONE_CELL)
    return folder


def _children_cpu_s() -> float:
    # user + system seconds of this process's children that have ended and been waited for (a
    # command's workers are its children, waited for when its cluster closes: counted)
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    return used.ru_utime + used.ru_stime


def _sweep(folder: Path, scheduler: str, name: str = "grid", cpu: list | None = None) -> Path:
    out = folder / f"{name}-{scheduler.replace(':', '-')}.csv"
    argv = [
        SPECREF,
        "sweep",
        str(folder / f"{name}.toml"),
        "--scheduler",
        scheduler,
        "-o",
        str(out),
    ]
    before = _children_cpu_s()
    start = time.perf_counter()
    subprocess.run(argv, check=True, capture_output=True)
    if cpu is not None:  # (wall, CPU) of this run
        cpu.append((time.perf_counter() - start, _children_cpu_s() - before))
    return out


def _serial_csv(folder: Path) -> bytes:
    serial = folder / "grid-serial.csv"
    if not serial.is_file():  # a worker-count test alone
        _sweep(folder, "serial")
    return serial.read_bytes()


def _least_wall_cpu_s(runs: list) -> float:
    # the CPU seconds of the round the benchmark's minimum comes from
    return min(runs)[1]


@pytest.mark.benchmark(group="scaleout-cli")
def test_cli_sweep_serial(benchmark, grid):
    runs: list = []
    benchmark.pedantic(
        _sweep, args=(grid, "serial", "grid", runs), rounds=SWEEP_ROUNDS, iterations=1
    )
    benchmark.extra_info.update(
        {"role": "cli-serial", "cells": CELLS, "shared": SHARED, "cpu_s": _least_wall_cpu_s(runs)}
    )


@pytest.mark.parametrize("workers", range(1, CORES + 1))
@pytest.mark.benchmark(group="scaleout-cli")
def test_cli_sweep_workers(benchmark, grid, workers):
    runs: list = []
    out = benchmark.pedantic(
        _sweep, args=(grid, f"local:{workers}", "grid", runs), rounds=SWEEP_ROUNDS, iterations=1
    )
    assert out.read_bytes() == _serial_csv(grid)
    benchmark.extra_info.update(
        {
            "role": "cli-workers",
            "cells": CELLS,
            "shared": SHARED,
            "workers": workers,
            "cpu_s": _least_wall_cpu_s(runs),
        }
    )


MATERIALS = ["R1", "R2", "R3", "bimodal"]


def _split_grids(folder: Path) -> list[Path]:
    # the grid cut by material into min(cores, 4) parts, in the serial sweep's order
    parts = np.array_split(MATERIALS, min(CORES, len(MATERIALS)))
    paths = []
    for i, part in enumerate(parts):
        names = ", ".join(f'"{m}"' for m in part)
        path = folder / f"part{i}.toml"
        path.write_text(GRID.replace('"R1", "R2", "R3", "bimodal"', names))
        paths.append(path)
    return paths


@pytest.mark.benchmark(group="scaleout-cli")
def test_cli_sweep_split(benchmark, grid):
    paths = _split_grids(grid)
    benchmark.extra_info.update(
        {"role": "cli-split", "cells": CELLS, "shared": SHARED, "workers": len(paths)}
    )

    def run_parts():
        argv = [
            [SPECREF, "sweep", str(p), "--scheduler", "serial", "-o", str(p.with_suffix(".csv"))]
            for p in paths
        ]
        procs = [
            subprocess.Popen(a, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) for a in argv
        ]
        assert [proc.wait() for proc in procs] == [0] * len(procs)

    benchmark.pedantic(run_parts, rounds=1, iterations=1)
    texts = [p.with_suffix(".csv").read_text() for p in paths]
    header = texts[0].splitlines(keepends=True)[0]
    joined = header + "".join(t.split("\n", 1)[1] for t in texts)
    assert joined.encode() == _serial_csv(grid)


@pytest.mark.parametrize("workers", range(CORES + 3))
@pytest.mark.benchmark(group="scaleout-cli")
def test_cli_startup(benchmark, grid, workers):
    # workers = 0: serially, in the command's own process; beyond the cores: the model's held-out
    # counts (validation/report/sections/scaleout.py, startup_model)
    scheduler = f"local:{workers}" if workers else "serial"
    runs: list = []
    benchmark.pedantic(_sweep, args=(grid, scheduler, "one", runs), rounds=3, iterations=1)
    benchmark.extra_info.update(
        {
            "role": "cli-startup",
            "workers": workers,
            "cores": CORES,
            "cpu_s": _least_wall_cpu_s(runs),
        }
    )


#: Empty tasks for Dask's own cost per task (the model's ``o``, measured rather than fitted).
EMPTY_TASKS = 2000


@pytest.mark.benchmark(group="scaleout-cli")
def test_cli_task_overhead(benchmark):
    # a local cluster of the cores present, warmed up; then EMPTY_TASKS tasks one per Dask task
    # (``abs`` of the task: nothing to compute). Each worker runs its share one after another, so
    # one task costs the time × workers / tasks (the scheduler's part included).
    from reference.tasks import dask_client, run_tasks

    workers = min(CORES, 2)
    with dask_client(f"local:{workers}") as client:
        run_tasks(abs, range(50), client=client, progress=False, grain=1)
        result = benchmark.pedantic(
            run_tasks,
            args=(abs, range(EMPTY_TASKS)),
            kwargs={"client": client, "progress": False, "grain": 1},
            rounds=3,
            iterations=1,
        )
    assert result == list(range(EMPTY_TASKS))
    task_s = benchmark.stats.stats.min * workers / EMPTY_TASKS
    benchmark.extra_info.update(
        {"role": "cli-task-overhead", "workers": workers, "tasks": EMPTY_TASKS, "task_s": task_s}
    )


def _convert_peak(source: Path, out: Path) -> int:
    done = subprocess.run(
        [sys.executable, "-c", PEAK_CHILD, "env", "convert", str(source), str(out)],
        check=True,
        capture_output=True,
        text=True,
    )
    code, peak = done.stdout.strip().splitlines()[-1].split()
    assert code == "0", done.stderr
    return int(peak)


@pytest.mark.benchmark(group="scaleout-cli")
def test_cli_env_convert_memory(benchmark, tmp_path):
    from reference.images.formats import write_exr
    from reference.images.zarr_store import rows_per_chunk_for

    height = 4096
    rng = np.random.default_rng(0)
    image = np.empty((height, 2 * height, 3), np.float32)
    for row in range(0, height, 256):
        image[row : row + 256] = rng.random((256, 2 * height, 3), dtype=np.float32) * 10
    big = write_exr(tmp_path / "big.exr", image)
    del image
    small = write_exr(tmp_path / "small.exr", np.ones((16, 32, 3), np.float32))
    baseline = _convert_peak(small, tmp_path / "small.zarr")
    figures = {}

    def convert():
        figures["peak"] = _convert_peak(big, tmp_path / "big.zarr")

    benchmark.pedantic(convert, rounds=1, iterations=1)
    rows = rows_per_chunk_for(2 * height, 3, height)
    benchmark.extra_info.update(
        {
            "role": "convert-memory",
            "height": height,
            "width": 2 * height,
            "channels": 3,
            "peak_rss_bytes": figures["peak"],
            "baseline_rss_bytes": baseline,
            "chunk_bytes": rows * 2 * height * 3 * 4,
            "float32_bytes": height * 2 * height * 3 * 4,
        }
    )
    info = json.dumps(benchmark.extra_info)
    assert figures["peak"] < 2 * 2 * height * height * 3 * 4, info  # never near the whole map

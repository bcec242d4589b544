"""Scale-out as a user pays it: commands from the command line, in fresh processes.

Group ``scaleout-cli`` (docs/scale-out.md, "How it scales, and what does not"; the report's
Scale-out section):

- ``cli-serial``: ``specref sweep GRID --scheduler serial``, a 2,400-cell Phong sweep (4 materials ×
  2 views × 3 placements × 4 interpolations × 25 table sizes, resolution 320), in a new process;
- ``cli-local``: the same sweep with ``--scheduler local``: a new local cluster of one worker per
  core, its start, the workers' imports and exact renders included (target ≥ 1.7× on two cores);
  its CSV must equal the serial one byte for byte;
- ``convert-memory``: ``specref env convert`` of a 4096 × 8192 RGB EXR in a new process, its peak
  resident set (``VmHWM``), beside the same command's on a 16 × 32 map (what the process holds
  without the map) and the size of one float32 chunk (target: at most four chunks above it, three
  in flight and the output's chunk buffer).

One round each: the serial sweep takes most of a minute.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ENTRIES = ", ".join(str(e) for e in range(40, 440, 16))
GRID = f"""kind = "phong"
[grid]
materials = ["R1", "R2", "R3", "bimodal"]
views = ["near", "far"]
placements = ["importance", "uniform", "error"]
interpolations = ["parabolic", "parabolic_w", "linear", "monotone"]
entries = [{ENTRIES}]
resolution = 320
"""
CELLS = 4 * 2 * 3 * 4 * 25
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
    return folder


def _sweep(folder: Path, scheduler: str) -> Path:
    out = folder / f"{scheduler}.csv"
    argv = [SPECREF, "sweep", str(folder / "grid.toml"), "--scheduler", scheduler, "-o", str(out)]
    subprocess.run(argv, check=True, capture_output=True)
    return out


@pytest.mark.benchmark(group="scaleout-cli")
def test_cli_sweep_serial(benchmark, grid):
    benchmark.extra_info.update({"role": "cli-serial", "cells": CELLS})
    benchmark.pedantic(_sweep, args=(grid, "serial"), rounds=1, iterations=1)


@pytest.mark.benchmark(group="scaleout-cli")
def test_cli_sweep_local_cluster(benchmark, grid):
    workers = os.cpu_count() or 1
    benchmark.extra_info.update({"role": "cli-local", "cells": CELLS, "workers": workers})
    out = benchmark.pedantic(_sweep, args=(grid, "local"), rounds=1, iterations=1)
    serial = grid / "serial.csv"
    if not serial.is_file():  # this test alone
        _sweep(grid, "serial")
    assert out.read_bytes() == serial.read_bytes()


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

"""Out of core at full size: a 12k×6k×41 panorama in Zarr projected to L = 100, in bounded memory.

Group ``scaleout-zarr-12k`` (target: peak resident memory <= 2 GB; erratum E49). The store is a
synthetic panorama, 6000 × 12000 × 41 float32 (11.8 GB as float32), generated chunk by chunk by
:func:`panorama_rows` (erratum E49): a smooth analytic sky at half-float precision, as an OpenEXR
half panorama stores it, so that blosc-lz4 packs it about four times and the store fits this
machine's disk and the benchmark's time. The projection's work does not depend on the values
(one FFT per ring, one Legendre transform per band); its reading does, and random data, which
does not compress, is measured on the 2k map of ``bench_scaleout.py``.

Each step runs in a child process of its own (``python bench_zarr_panorama.py generate|project
STORE``) so that its peak resident set size (``VmHWM``, :func:`_peak_rss`) is its own, not
pytest's; the projection shows its progress bar on the terminal (pytest's capture is
suspended for it; tqdm draws nothing when stderr is not a terminal, as under CI). The figures go
to ``bench.json`` (``extra_info``) and the report's Scale-out section.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

HEIGHT, BANDS, ORDER = 6000, 41, 100


def panorama_rows(row0: int, row1: int, height: int, wavelengths_nm) -> np.ndarray:
    """Rows ``row0 <= y < row1`` of the synthetic sky, ``(rows, 2·height, bands)`` float32.

    Radiance ``(1 + ½ cos θ)(0.6 + 0.4 cos 3φ)(0.5 + λ') + 0.2 λ'(1 + sin 7φ)`` with
    ``λ' = (λ − 380 nm) / 400 nm``, rounded to half-float precision.

    Examples
    --------
    >>> rows = panorama_rows(0, 2, 4, [380.0, 780.0])
    >>> rows.shape, rows.dtype.name, bool((rows > 0).all())
    ((2, 8, 2), 'float32', True)
    """
    theta = (np.arange(row0, row1) + 0.5) * np.pi / height
    phi = (np.arange(2 * height) + 0.5) * np.pi / height
    lam = ((np.asarray(wavelengths_nm, dtype=float) - 380.0) / 400.0).astype(np.float32)
    sky = (1.0 + 0.5 * np.cos(theta)).astype(np.float32)[:, None, None] * (
        (0.6 + 0.4 * np.cos(3.0 * phi)).astype(np.float32)[None, :, None] * (0.5 + lam)
    )
    sky += 0.2 * (1.0 + np.sin(7.0 * phi)).astype(np.float32)[None, :, None] * lam
    return sky.astype(np.float16).astype(np.float32)


def _peak_rss() -> int:
    """This process's peak resident set size in bytes: ``VmHWM`` of ``/proc/self/status``.

    Not ``getrusage``'s ``ru_maxrss``: Linux carries the parent's high-water mark across the
    fork and exec that start a child, so a child of a large pytest process would report the
    parent's peak instead of its own.
    """
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) * 1024  # kB
    raise RuntimeError("no VmHWM in /proc/self/status (Linux only)")


def _generate(store: str) -> dict:
    from reference.images.formats import spectral_channel_names
    from reference.images.zarr_store import rows_per_chunk_for, write_zarr_blocks

    wavelengths = np.arange(380.0, 790.0, 10.0)
    width = 2 * HEIGHT
    rows = rows_per_chunk_for(width, BANDS, HEIGHT)
    blocks = (
        panorama_rows(r, min(r + rows, HEIGHT), HEIGHT, wavelengths) for r in range(0, HEIGHT, rows)
    )
    start = time.perf_counter()
    write_zarr_blocks(store, HEIGHT, width, spectral_channel_names(wavelengths), blocks, rows)
    stored = sum(f.stat().st_size for f in Path(store).rglob("*") if f.is_file())
    return {
        "generate_s": time.perf_counter() - start,
        "store_bytes": stored,
        "float32_bytes": HEIGHT * width * BANDS * 4,
        "rows_per_chunk": rows,
        "generate_peak_rss_bytes": _peak_rss(),
    }


def _project(store: str) -> dict:
    from shrm.streamed import project_zarr

    imported = _peak_rss()  # Python, NumPy, Zarr, ducc0 and tqdm loaded
    start = time.perf_counter()
    coeffs = project_zarr(store, ORDER, backend="ducc0", progress=None)  # bar on a terminal
    wall = time.perf_counter() - start
    return {
        "wall_s": wall,
        "peak_rss_bytes": _peak_rss(),
        "imports_rss_bytes": imported,
        "coefficients": list(coeffs.shape),
        "dc_mean": float(coeffs[:, 0].mean()),
    }


def _child(step: str, store: Path, show_progress=None) -> dict:
    # One step in a fresh interpreter; its last stdout line is the JSON of its figures.
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])}
    stderr = None if show_progress else subprocess.DEVNULL
    done = subprocess.run(
        [sys.executable, __file__, step, str(store)],
        stdout=subprocess.PIPE,
        stderr=stderr,
        env=env,
        check=True,
        text=True,
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    import shutil

    folder = tmp_path_factory.mktemp("pano12k")
    path = folder / "sky12k.zarr"
    info = _child("generate", path)
    yield path, info
    shutil.rmtree(folder, ignore_errors=True)  # ~3 GB: not kept among pytest's last runs


@pytest.mark.benchmark(group="scaleout-zarr-12k")
def test_projection_12k_in_bounded_memory(benchmark, store, capsys):
    path, generated = store
    figures = {}

    def project():
        with capsys.disabled():  # the progress bar on the terminal
            figures.update(_child("project", path, show_progress=True))

    benchmark.pedantic(project, rounds=1, iterations=1)
    benchmark.extra_info.update(
        {
            "role": "zarr-12k",
            "height": HEIGHT,
            "width": 2 * HEIGHT,
            "bands": BANDS,
            "order": ORDER,
            "compression": "blosc-lz4",
            **generated,
            **figures,
        }
    )
    assert figures["coefficients"] == [BANDS, (ORDER + 1) ** 2]


if __name__ == "__main__":
    step, target = sys.argv[1], sys.argv[2]
    result = _generate(target) if step == "generate" else _project(target)
    sys.stdout.write(json.dumps(result) + "\n")

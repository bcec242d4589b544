"""The kernels' disk cache (reference.jit): used by every kernel, safe across processes, edits."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from reference.jit import kernel_cache_dir

ROOT = Path(__file__).resolve().parents[2]
KERNEL_FILES = sorted(
    p for package in ("reference", "phong_table", "shrm", "impastor")
    for p in (ROOT / package).rglob("*_kernels.py")
)  # fmt: skip

#: A kernel module, and a script that compiles it and prints its result and the cache's counts.
MODULE = """
from reference.jit import njit


@njit
def step(x):
    return x + {increment}
"""
SCRIPT = """
import cached_module
print(cached_module.step(1.0), sum(cached_module.step.stats.cache_hits.values()))
"""


def _run(folder: Path, cache: Path) -> tuple[float, int]:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "PYTHONPATH": str(folder)}
    env.pop("NUMBA_DISABLE_JIT", None)
    done = subprocess.run(
        [sys.executable, "-c", SCRIPT], cwd=folder, env=env, capture_output=True, text=True,
        timeout=300, check=True,
    )  # fmt: skip
    value, hits = done.stdout.split()
    return float(value), int(hits)


def _write_module(folder: Path, increment: int, stamp: float) -> None:
    path = folder / "cached_module.py"
    path.write_text(textwrap.dedent(MODULE.format(increment=increment)))
    os.utime(path, (stamp, stamp))


def test_cache_folder_follows_numba_then_specref(monkeypatch, tmp_path):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "numba-here"))
    assert kernel_cache_dir() == tmp_path / "numba-here"
    monkeypatch.delenv("NUMBA_CACHE_DIR")
    monkeypatch.setenv("SPECREF_CACHE_DIR", str(tmp_path / "specref"))
    assert kernel_cache_dir() == tmp_path / "specref" / "numba"


@pytest.mark.slow
def test_second_process_loads_and_an_edit_compiles_again(tmp_path):
    cache = tmp_path / "cache"
    _write_module(tmp_path, 1, 1_700_000_000)
    assert _run(tmp_path, cache) == (2.0, 0)  # compiled, written to the cache
    assert _run(tmp_path, cache) == (2.0, 1)  # loaded from the cache
    # The source changes (new modification time and text): the stale entry is not used.
    _write_module(tmp_path, 2, 1_700_000_100)
    assert _run(tmp_path, cache) == (3.0, 0)
    assert _run(tmp_path, cache) == (3.0, 1)
    assert any(cache.rglob("*.nbi")), "numba wrote no cache index in the folder it was given"


@pytest.mark.slow
def test_processes_compiling_at_once_all_get_the_right_kernel(tmp_path):
    cache = tmp_path / "cache"
    _write_module(tmp_path, 5, 1_700_000_000)
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "PYTHONPATH": str(tmp_path)}
    env.pop("NUMBA_DISABLE_JIT", None)
    runs = [
        subprocess.Popen([sys.executable, "-c", SCRIPT], cwd=tmp_path, env=env, text=True,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        for _ in range(4)
    ]  # fmt: skip
    outputs = [run.communicate(timeout=300) for run in runs]
    assert all(run.returncode == 0 for run in runs), [err[-500:] for _, err in outputs]
    assert [float(out.split()[0]) for out, _ in outputs] == [6.0] * 4
    assert _run(tmp_path, cache) == (6.0, 1)  # whatever order they wrote in, the cache is whole


@pytest.mark.parametrize("path", KERNEL_FILES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_kernel_is_cached_and_calls_only_its_own_file(path):
    import ast
    import importlib

    name = ".".join(path.relative_to(ROOT).with_suffix("").parts)
    module = importlib.import_module(name)
    kernels = [v for v in vars(module).values() if hasattr(v, "py_func") and hasattr(v, "_cache")]
    assert kernels, name
    for kernel in kernels:
        assert kernel.py_func.__module__ == name  # no kernel of another file is re-exported
        assert type(kernel._cache).__name__ == "FunctionCache", kernel.py_func.__name__
    imported = {
        node.module or ""
        for node in ast.walk(ast.parse(path.read_text()))
        if isinstance(node, ast.ImportFrom)
    } | {
        alias.name
        for node in ast.walk(ast.parse(path.read_text()))
        if isinstance(node, ast.Import)
        for alias in node.names
    }
    assert not [m for m in imported if m.endswith("_kernels")], imported


@pytest.mark.skipif(os.environ.get("NUMBA_DISABLE_JIT") == "1", reason="numba's signatures")
def test_read_only_broadcast_and_strided_inputs_share_one_compiled_signature():
    # A read-only (cached, broadcast) or strided input would otherwise compile a kernel again:
    # seconds for the Phong table shader, once per layout (kernel_input makes them all one).
    import numpy as np

    from impastor import _kernels as impastor_kernels
    from impastor.arealights import PlaneLight, booth_light_image
    from impastor.point_lights import point_lights_from_plane
    from impastor.specular_lighting import specular_point_lights
    from phong_table import _kernels as phong_kernels
    from phong_table.render import ShadingBuffer, compiled_shader
    from phong_table.scenes import SCENES
    from phong_table.table import build_table

    model = SCENES.lookup("R1").build()
    shade = compiled_shader(model, build_table(model, 32, "uniform"), "linear")
    t = np.linspace(0.5, 1.0, 64)
    read_only = t.copy()
    read_only.flags.writeable = False
    for t_view in (t, t[::-1], read_only, np.linspace(0.0, 1.0, 128)[::2]):
        ones = np.broadcast_to(1.0, t_view.shape)
        shade(ShadingBuffer(None, ones, t_view, ones), np.empty((t_view.size, 3)))
        if t_view is t:
            signatures = len(phong_kernels.TABLE_KERNELS[phong_kernels.LINEAR].signatures)
    assert len(phong_kernels.TABLE_KERNELS[phong_kernels.LINEAR].signatures) == signatures

    image = booth_light_image("fluorescent", 8, 4)
    plane = PlaneLight(image, (-0.6, 0.6, -1.0), (1, 0, 0), (0, 0, 1), 1.2, 0.8)
    lights = point_lights_from_plane(plane, "median_cut", 4)
    P = np.zeros((5, 3))
    up = np.tile([0.0, 1.0, 0.0], (5, 1))
    specular_point_lights(P, up, up, 0.2, lights)
    kernel = impastor_kernels.specular_point_lights_kernel
    signatures = len(kernel.signatures)
    specular_point_lights(P, np.array([0.0, 1.0, 0.0]), up, np.full(5, 0.2), lights)
    specular_point_lights(P[:, ::1], up, np.broadcast_to(up[0], (5, 3)), 0.2, lights)
    assert len(kernel.signatures) == signatures

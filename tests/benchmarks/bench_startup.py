"""What a user pays for the first render: a fresh process, numba's kernel cache cold or warm.

Group ``startup-render`` (target: the first render in a fresh process with a warm kernel cache
within 1.5× the second render in the same process; ``reference.jit``, docs/dependencies.md):

- ``cold``: ``python -c SCRIPT`` with an empty ``NUMBA_CACHE_DIR``: imports specref, loads the
  shipped ``data:examples/phong-sphere.toml`` and renders it twice at its own size (256², 2²
  supersamples) through the compiled Phong-table shader (``options.phong.method = "table"``), so
  the first render compiles the kernels;
- ``warm``: the same, with the cache the cold run filled: the first render loads the kernels.

The benchmark's time is the whole process (what the command line costs); ``extra_info`` holds the
import, first-render and second-render seconds the script measures itself. Three rounds each.

``numba_s`` is numba's own start-up, which any numba program pays once per process whatever its
kernels: the first call of a one-line ``cache=True`` kernel in another fresh process with the same
cache (its typing and target contexts are set up on the first call, not at import). The warm
first render's excess over the second render, less ``numba_s``, is what specref's own kernels and
code add.
"""

import json
import os
import subprocess
import sys
import tempfile

import pytest

SCRIPT = """
import json, time
t0 = time.perf_counter()
import phong_table, shrm
from reference.scene.loader import load_scene
from reference.scene.render import render_scene
scene = load_scene("data:examples/phong-sphere.toml")
t1 = time.perf_counter()
options = {"phong": {"method": "table"}}
render_scene(scene, options=options)
t2 = time.perf_counter()
render_scene(scene, options=options)
t3 = time.perf_counter()
print(json.dumps({"import_s": t1 - t0, "first_s": t2 - t1, "second_s": t3 - t2}))
"""


FLOOR_MODULE = """
import numba


@numba.njit(cache=True)
def one_more(x):
    return x + 1.0
"""

FLOOR_SCRIPT = """
import json, time
import numba, numba_floor
t0 = time.perf_counter()
numba_floor.one_more(1.0)
print(json.dumps({"numba_s": time.perf_counter() - t0}))
"""


def _numba_start_up(cache: str) -> float:
    """Seconds of a trivial cached kernel's first call in a fresh process (numba's own start-up)."""
    folder = os.path.join(cache, "floor")
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "numba_floor.py"), "w") as module:
        module.write(FLOOR_MODULE)
    env = {**os.environ, "NUMBA_CACHE_DIR": cache, "PYTHONPATH": folder}
    env.pop("NUMBA_DISABLE_JIT", None)
    run = [sys.executable, "-c", FLOOR_SCRIPT]
    subprocess.run(run, env=env, capture_output=True, check=True)  # fills the cache
    done = subprocess.run(run, env=env, capture_output=True, text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])["numba_s"]


def _render_process(cache: str) -> dict:
    env = {**os.environ, "NUMBA_CACHE_DIR": cache}
    env.pop("NUMBA_DISABLE_JIT", None)
    done = subprocess.run(
        [sys.executable, "-c", SCRIPT], env=env, capture_output=True, text=True, check=True
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


def _record(benchmark, rounds: list[dict], cache: str) -> None:
    fastest = min(rounds, key=lambda r: r["first_s"])
    with tempfile.TemporaryDirectory() as floor_cache:
        numba_s = min(_numba_start_up(floor_cache) for _ in range(3))
    benchmark.extra_info.update({"cache": cache, **fastest, "numba_s": numba_s})


@pytest.mark.benchmark(group="startup-render")
def test_first_render_cold_cache(benchmark, tmp_path):
    rounds = []

    def fresh():
        return (tempfile.mkdtemp(dir=tmp_path),), {}

    benchmark.pedantic(
        lambda cache: rounds.append(_render_process(cache)), setup=fresh, rounds=3, iterations=1
    )
    _record(benchmark, rounds, "cold")


@pytest.mark.benchmark(group="startup-render")
def test_first_render_warm_cache(benchmark, tmp_path):
    cache = str(tmp_path / "numba")
    _render_process(cache)  # fills the cache
    rounds = []
    benchmark.pedantic(lambda: rounds.append(_render_process(cache)), rounds=3, iterations=1)
    _record(benchmark, rounds, "warm")

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

Each round also runs the script once more with numba started first: after the imports, a one-line
``cache=True`` kernel is called before the first render. ``numba_s`` is that call (numba's own
start-up, which any numba program pays once per process whatever its kernels: its typing and
target contexts are set up on the first call, not at import) and ``first_after_numba_s`` the
first render after it, i.e. what specref's own kernels and code add to the first render.
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

#: SCRIPT with numba started before the first render.
SCRIPT_NUMBA_FIRST = SCRIPT.replace(
    "t1 = time.perf_counter()\n",
    "import numba_floor\ntn = time.perf_counter()\nnumba_floor.one_more(1.0)\n"
    "t1 = time.perf_counter()\nnumba_s = t1 - tn\n",
).replace('"first_s": t2 - t1', '"numba_s": numba_s, "first_after_numba_s": t2 - t1')


def _script_process(cache: str, script: str) -> dict:
    folder = os.path.join(cache, "floor")
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "numba_floor.py"), "w") as module:
        module.write(FLOOR_MODULE)
    env = {**os.environ, "NUMBA_CACHE_DIR": cache, "PYTHONPATH": folder}
    env.pop("NUMBA_DISABLE_JIT", None)
    done = subprocess.run(
        [sys.executable, "-c", script], env=env, capture_output=True, text=True, check=True
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


def _render_process(cache: str) -> dict:
    return _script_process(cache, SCRIPT)


def _record(benchmark, rounds: list[dict], cache: str, caches) -> None:
    """The fastest round's figures, and the fastest of three runs with numba started first."""
    fastest = min(rounds, key=lambda r: r["first_s"])
    after = min(
        (_script_process(c, SCRIPT_NUMBA_FIRST) for c in caches),
        key=lambda r: r["first_after_numba_s"],
    )
    mine = {k: after[k] for k in ("numba_s", "first_after_numba_s")}
    benchmark.extra_info.update({"cache": cache, **fastest, **mine})


@pytest.mark.benchmark(group="startup-render")
def test_first_render_cold_cache(benchmark, tmp_path):
    rounds = []

    def fresh():
        return (tempfile.mkdtemp(dir=tmp_path),), {}

    benchmark.pedantic(
        lambda cache: rounds.append(_render_process(cache)), setup=fresh, rounds=3, iterations=1
    )
    _record(benchmark, rounds, "cold", (tempfile.mkdtemp(dir=tmp_path) for _ in range(3)))


@pytest.mark.benchmark(group="startup-render")
def test_first_render_warm_cache(benchmark, tmp_path):
    cache = str(tmp_path / "numba")
    _render_process(cache)  # fills the cache
    rounds = []
    benchmark.pedantic(lambda: rounds.append(_render_process(cache)), rounds=3, iterations=1)
    _script_process(cache, SCRIPT_NUMBA_FIRST)  # fills the cache for the one-line kernel
    _record(benchmark, rounds, "warm", [cache] * 3)

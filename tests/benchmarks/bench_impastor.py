"""ImpastoR benchmarks (``make bench``): lighting methods, horizon maps and full frames.

Each group measures its own baseline in the same run, so the report shows ratios:

- ``impastor-specular``: every registered specular method on the same 4096 surface points, the
  brute-force sum over the light among them as the baseline;
- ``impastor-horizon``: the NumPy twin of each horizon method (baseline) against its numba kernel;
- ``impastor-frame-512``: a 512×512 frame of the demo painting per lighting method (numba, warm:
  the kernels compiled and the painting's horizon map built before the timing, as in a session).
"""

from __future__ import annotations

import functools
from operator import attrgetter

import numpy as np
import pytest

from impastor import painting as imp
from impastor.horizon import HORIZON_METHODS
from impastor.point_lights import point_lights_from_plane
from impastor.specular_hybrid import SPECULAR_METHODS

#: The group's baseline: the brute-force sum over the light.
BASELINE = SPECULAR_METHODS.lookup("brute_force").name


@pytest.fixture(scope="module")
def specular_scene():
    rng = np.random.default_rng(7)
    painting = imp.impasto_painting(128, seed=2)
    P, N, V = imp.painting_samples(64, painting)
    alpha = rng.uniform(0.02, 0.3, len(P))
    plane = imp.booth_plane_light("fluorescent", 64, 32)
    lights = point_lights_from_plane(plane, "median_cut", 32)
    return P, N, V, alpha, plane, lights


@pytest.mark.parametrize("method", SPECULAR_METHODS.values(), ids=attrgetter("name"))
def test_bench_specular(benchmark, method, specular_scene):
    benchmark.group = "impastor-specular"
    inputs = specular_scene  # the same points for every method, the baseline included
    # 32 FIS samples per point (the report's setting); one sub-pixel per light pixel for the
    # brute-force baseline
    call = functools.partial(method.run, backend="numba", n_samples=32, supersample=1)
    call(inputs)  # JIT warm-up outside the timing
    benchmark.extra_info["points"] = len(inputs[0])
    benchmark(call, inputs)


@pytest.mark.parametrize("method", HORIZON_METHODS.values(), ids=attrgetter("name"))
@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_bench_horizon(benchmark, method, backend):
    benchmark.group = f"impastor-horizon-{method.name}"
    painting = imp.impasto_painting(256, seed=4)
    h, pixel = painting["height"], painting["pixel_size"]
    if method.name == "horizon_map":
        args = (h, pixel, 18, 32)
    else:
        args = (h, pixel, 0.7, np.radians(20.0), 32)
    method.reference(*args, backend=backend)
    benchmark(method.reference, *args, backend=backend)


@pytest.mark.parametrize("method", imp.PAINTING_LIGHTING_METHODS.names())
def test_bench_frame_512(benchmark, method):
    benchmark.group = "impastor-frame-512"
    painting = imp.impasto_painting(512, seed=1)
    spectra = imp.load_paint_spectra()
    # warm-up: the kernels, and this painting's horizon map (built once per height field)
    imp.render_painting("D65", 64, method, painting, spectra=spectra)
    benchmark.pedantic(
        imp.render_painting,
        args=("D65", 512, method, painting),
        kwargs={"spectra": spectra},
        rounds=3,
        iterations=1,
    )

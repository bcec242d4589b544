"""Benchmarks of the Phong tables: shading (build included) against the exact shading, same run."""

import dataclasses

import numpy as np
import pytest

from phong_table import INTERPOLATION_METHODS, PLACEMENT_METHODS, SCENES, VIEWS, build_table
from phong_table.interpolation import interval_index
from phong_table.render import compiled_shader, shading_buffer, sphere_gbuffer
from validation.studies.phong import rising_material

#: Materials outside R1-R3 (erratum E39): the exponent rises steadily across the spectrum to a
#: few thousand (every band its own power), linearly and quadratically
RISING = {
    "rising2000": lambda: rising_material(2000.0),
    "rising5000": lambda: rising_material(5000.0),
    "rising3000^2": lambda: rising_material(3000.0, 2.0),
}
# the rows of Table 1: every scene the registry marks table1, in every view; then the rising sweep
CASES = [(s.name, v) for s in SCENES.values() if s.table1 for v in VIEWS]
CASES += [(name, v) for name in RISING for v in VIEWS]


def _setup(scene, view):
    model = RISING[scene]() if scene in RISING else SCENES.lookup(scene).build()
    buffer = shading_buffer(sphere_gbuffer(view, 512), model)
    return model, buffer, np.empty((buffer.t.size, 3))


@pytest.mark.parametrize(("scene", "view"), CASES)
def test_exact(benchmark, scene, view):
    model, buffer, out = _setup(scene, view)
    benchmark.group = f"phong {scene} {view}"
    shade = compiled_shader(model)
    benchmark(shade, buffer, out)


@pytest.mark.parametrize("interpolation", INTERPOLATION_METHODS.names())
@pytest.mark.parametrize("placement", PLACEMENT_METHODS.names())
@pytest.mark.parametrize(("scene", "view"), CASES)
def test_table(benchmark, scene, view, placement, interpolation):
    model, buffer, out = _setup(scene, view)
    benchmark.group = f"phong {scene} {view}"

    # properties of the cached G-buffer (computed once, like t)
    seen = {"t_range": buffer.t_range, "t_density": buffer.t_density}

    def run():
        table = build_table(
            model, 200, placement, compiled=True, **seen, interpolation=interpolation
        )
        return compiled_shader(model, table, interpolation)(buffer, out)

    run()
    benchmark(run)


@pytest.mark.parametrize("t_value", ["image", "every t = 0", "every t = 0.5"])
def test_table_loop_bound(benchmark, t_value):
    # what bounds the monotone loop (E39): the image's t, then no cubic (every pixel takes the
    # t = 0 branch) and one interval for every pixel (no lookup, no miss, a cubic per pixel)
    model, buffer, out = _setup("rising5000", "far")
    seen = {"t_range": buffer.t_range, "t_density": buffer.t_density}
    table = build_table(model, 200, "error", compiled=True, **seen)
    if t_value != "image":
        t = np.full_like(buffer.t, 0.0 if t_value == "every t = 0" else 0.5)
        buffer = dataclasses.replace(buffer, t=t)
    benchmark.group = "phong loop rising5000 far"
    shade = compiled_shader(model, table, "monotone")
    shade(buffer, out)
    benchmark(shade, buffer, out)


@pytest.mark.parametrize("method", ["binary search", "inverse-map index"])
def test_lookup_index(benchmark, method):
    # the index method for non-uniform tables: np.searchsorted against the kernel's guide index
    model, buffer, out = _setup("R1", "near")
    seen = {"t_range": buffer.t_range, "t_density": buffer.t_density}
    table = build_table(model, 200, "error", compiled=True, **seen)
    benchmark.group = "phong lookup R1 near"
    if method == "binary search":
        benchmark(interval_index, table.nodes, buffer.t)
    else:
        shade = compiled_shader(model, table, "linear")
        shade(buffer, out)
        benchmark(shade, buffer, out)

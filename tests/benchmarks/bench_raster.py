"""Rasterizer speed: the G-buffer of a 100k-triangle mesh at 512×512, against same-run baselines.

Groups (the report's "Rasterizer" section reads them, as ratios to each group's baseline):

- ``raster-gbuffer-512``: the mesh G-buffer by each registered method (numba kernel), the analytic
  sphere's G-buffer (exact ray casting, vectorized NumPy) as the baseline, and ``np.copyto`` of a
  G-buffer's worth of float64 (the memory-bandwidth floor);
- ``raster-backends``: the NumPy reference against the numba kernel on a small mesh (the kernel is
  the baseline).
"""

import numpy as np
import pytest

from reference.geometry.camera import Camera
from reference.geometry.gbuffer import render_gbuffer
from reference.geometry.mesh import uv_sphere_mesh
from reference.geometry.raster import RASTER_METHODS, rasterize_mesh
from reference.geometry.shapes import Sphere

CAMERA = Camera(eye=(0.7, 1.1, 3.3), target=(0.0, 0.0, 0.0), fov_deg=40)
SIZE = 512
N_THETA = 159  # 4·159·158 = 100,488 triangles (n_phi = 2·n_theta)


@pytest.fixture(scope="module")
def mesh_100k():
    mesh = uv_sphere_mesh(N_THETA, 2 * N_THETA)
    rasterize_mesh(mesh, CAMERA, 16, 16)  # JIT warm-up outside the timing
    return mesh


def _info(benchmark, role, triangles, size):
    benchmark.extra_info.update({"role": role, "triangles": triangles, "size": size})


@pytest.mark.benchmark(group="raster-gbuffer-512")
def test_baseline_analytic_sphere(benchmark):
    _info(benchmark, "baseline", 0, SIZE)
    g = benchmark(render_gbuffer, [Sphere()], CAMERA, SIZE, SIZE)
    assert g.mask.any()


@pytest.mark.benchmark(group="raster-gbuffer-512")
def test_floor_copyto(benchmark):
    # A G-buffer holds 13 float64 per pixel (position, normal, view: 3 each; uv: 2; depth: 1) plus
    # ids and the mask.
    source = np.ones((SIZE, SIZE, 13))
    target = np.empty_like(source)
    _info(benchmark, "floor", 0, SIZE)
    benchmark(np.copyto, target, source)


@pytest.mark.parametrize("method", RASTER_METHODS.values(), ids=RASTER_METHODS.names())
@pytest.mark.benchmark(group="raster-gbuffer-512")
def test_mesh_gbuffer_100k(benchmark, mesh_100k, method):
    _info(benchmark, "mesh", mesh_100k.n_faces, SIZE)
    g = benchmark(rasterize_mesh, mesh_100k, CAMERA, SIZE, SIZE, method=method.name)
    assert g.mask.any()


@pytest.mark.parametrize("backend", ["numba", "numpy"])
@pytest.mark.benchmark(group="raster-backends")
def test_backends_small_mesh(benchmark, backend):
    mesh = uv_sphere_mesh(24, 48)
    rasterize_mesh(mesh, CAMERA, 16, 16, backend=backend)
    _info(benchmark, "baseline" if backend == "numba" else backend, mesh.n_faces, 128)
    benchmark(rasterize_mesh, mesh, CAMERA, 128, 128, backend=backend)

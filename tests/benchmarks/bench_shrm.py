"""SHRM and cache speed, as ratios to baselines measured in the same run (report section "SHRMs").

Groups:

- ``shrm-create-<brdf>``: SHRM creation in frequency space against the angular oracle (baseline),
  same environment (32×64 RGB), same texels (8²×6, the size the SH engine's brute-force tests use),
  same P; the error of each against per-pixel brute force at those texels is recorded in
  ``extra_info`` (target: frequency ≥ 100× faster at equal or smaller error). The BRDF's projection
  onto SH, a separate cached stage reused for every environment, is timed apart
  (``extra_info["brdf_projection_seconds"]``);
- ``shrm-extract``: extraction of a reflection map for a new viewpoint against creation of the
  64²×6 SHRM (baseline; target ≥ 50×);
- ``shrm-cache``: a persistent-cache hit on the 64²×6 SHRM against rebuilding it from the inputs:
  projecting the environment and the BRDF and creating the SHRM, which is what a session without
  the cache pays (baseline; target ≥ 20×).
"""

from pathlib import Path

import numpy as np
import pytest

from reference.brdf import BRDF_METHODS
from reference.camera import downsample_box
from reference.cubemap import cubemap_texel_directions
from reference.images import read_image
from shrm.cache import Cache, cache_key
from shrm.shrm import (
    _env_quadrature,
    _reflected_bruteforce,
    brdf_sh_coefficients,
    shrm_create,
    shrm_create_angular,
    shrm_extract,
)
from shrm.transform import project_latlong
from validation.sections.shrm import SUITE

ROOT = Path(__file__).resolve().parents[2]
P, F, SMALL = 6, 24, 8
VIEW = np.array([0.3, 0.4, 0.866]) / np.linalg.norm([0.3, 0.4, 0.866])


@pytest.fixture(scope="module")
def env():
    image = read_image(ROOT.parent / "shared/data/environments/venice_sunset_1k.hdr")
    return downsample_box(image, image.shape[0] // 32)


def _params(name):
    return {k: (np.asarray(v, float) if isinstance(v, list) else v) for k, v in SUITE[name].items()}


def _texel_error(shrm, env, brdf, params):
    n = cubemap_texel_directions(SMALL).reshape(-1, 3)
    truth = _reflected_bruteforce(
        brdf, params, "reflection", n, np.broadcast_to(VIEW, n.shape), _env_quadrature(env)
    )
    front = n @ VIEW > 0.2
    got = shrm_extract(shrm, VIEW).reshape(-1, truth.shape[-1])
    return float(np.abs(got - truth)[front].max() / np.abs(truth).max())


@pytest.mark.parametrize("name", list(SUITE))
def test_create_angular_baseline(benchmark, env, name):
    brdf, params = BRDF_METHODS.lookup(name).reference, _params(name)
    benchmark.group = f"shrm-create-{name}"
    s = benchmark.pedantic(
        shrm_create_angular, (env, brdf, params, P, "reflection", SMALL), rounds=1, iterations=1
    )
    benchmark.extra_info.update({"role": "baseline", "error": _texel_error(s, env, brdf, params)})


@pytest.mark.parametrize("name", list(SUITE))
def test_create_frequency(benchmark, env, name):
    import time

    brdf, params = BRDF_METHODS.lookup(name).reference, _params(name)
    benchmark.group = f"shrm-create-{name}"
    L = project_latlong(env, F, backend="ducc0")
    # The BRDF's projection is its own, cached stage (brdf_coeffs of shrm.session): it is reused
    # for every environment and illuminant, so it is timed apart (extra_info).
    start = time.perf_counter()
    rho = brdf_sh_coefficients(brdf, params, F, P, "reflection")
    rho_seconds = time.perf_counter() - start
    s = benchmark(shrm_create, L, rho, "reflection", SMALL)
    benchmark.extra_info.update(
        {
            "role": "frequency",
            "error": _texel_error(s, env, brdf, params),
            "brdf_projection_seconds": rho_seconds,
        }
    )


@pytest.fixture(scope="module")
def shrm_64(env):
    brdf, params = BRDF_METHODS.lookup("ggx").reference, _params("ggx")
    rho = brdf_sh_coefficients(brdf, params, F, P, "reflection")
    L = project_latlong(env, F, backend="ducc0")
    return L, rho


@pytest.mark.benchmark(group="shrm-extract")
def test_extract_create_baseline(benchmark, shrm_64):
    L, rho = shrm_64
    benchmark.extra_info["role"] = "baseline"
    benchmark(shrm_create, L, rho, "reflection", 64)


@pytest.mark.benchmark(group="shrm-extract")
def test_extract_per_viewpoint(benchmark, shrm_64):
    L, rho = shrm_64
    s = shrm_create(L, rho, "reflection", 64)
    benchmark(shrm_extract, s, VIEW)


@pytest.mark.benchmark(group="shrm-cache")
def test_cache_rebuild_baseline(benchmark, env):
    brdf, params = BRDF_METHODS.lookup("ggx").reference, _params("ggx")
    benchmark.extra_info["role"] = "baseline"

    def rebuild():
        L = project_latlong(env, F, backend="ducc0")
        rho = brdf_sh_coefficients(brdf, params, F, P, "reflection")
        return shrm_create(L, rho, "reflection", 64).coeffs

    benchmark(rebuild)


@pytest.mark.benchmark(group="shrm-cache")
def test_cache_hit(benchmark, shrm_64, tmp_path):
    L, rho = shrm_64
    cache = Cache(tmp_path)
    key = cache_key("shrm.create", "1", {"L": L, "rho": rho, "frame": "reflection", "size": 64})
    cache.put(key, {"coeffs": shrm_create(L, rho, "reflection", 64).coeffs})
    got = benchmark(cache.get, key)
    assert got["coeffs"].shape == (6, 64, 64, 3, (P + 1) ** 2)

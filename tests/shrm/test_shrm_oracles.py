"""Tests of shrm.shrm_oracles: the brute-force oracles against closed forms (they are the sources
that tests/shrm/test_shrm.py and the SHRM report measure against)."""

from __future__ import annotations

import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.materials.brdf import brdf_lambert
from shrm.sh import sh_evaluate
from shrm.shrm_oracles import env_quadrature, reflected_bruteforce


def _unit(rng, n):
    d = rng.normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def test_env_quadrature_integrates_band_limited_functions_exactly(rng):
    # Source: closed form. ∫ Y_lm dω = √(4π) δ_l0 δ_m0, and Fejér-1 × uniform φ is exact for
    # degree < H in cos θ and < W/2 in φ: a random L = 5 sum integrates to √(4π) c_00.
    c = rng.normal(size=36)
    d, w, radiance = env_quadrature(np.ones((12, 24, 2)))
    assert d.shape == (288, 3)
    assert w.shape == (288,)
    assert radiance.shape == (288, 2)
    assert w.sum() == pytest.approx(4 * np.pi, rel=1e-14)
    integral = w @ sh_evaluate(c, d)
    assert integral == pytest.approx(np.sqrt(4 * np.pi) * c[0], rel=1e-12, abs=1e-12)


@pytest.mark.parametrize("frame", ["normal", "reflection"])
def test_lambert_white_furnace(frame, rng):
    # Source: closed form. Under a uniform sky L, a Lambertian surface reflects ρ_d L in every
    # view (∫ ρ_d/π cos θ dω = ρ_d); the clamped cosine is not band-limited, so the quadrature is
    # only as good as its resolution: observed max errors at H = 16, 32, 64 are 8.6e-4, 1.3e-4,
    # 2.2e-5 (a factor of about 6 per doubling).
    views = _unit(rng, 4)
    normals = _unit(rng, 4)
    if frame == "reflection":  # index by the reflection vector r = 2 (n·v) n − v
        normals = 2.0 * (normals * views).sum(-1, keepdims=True) * normals - views
    errors = []
    for height in (16, 32):
        env = env_quadrature(np.full((height, 2 * height, 1), 2.0))
        got = reflected_bruteforce(brdf_lambert, {"rho_d": [0.5]}, frame, normals, views, env)
        errors.append(np.abs(got - 1.0).max())
    assert errors[1] < errors[0] / 4.0
    assert errors[1] < 5e-4


def test_reflected_bruteforce_bad_frame(rng):
    env = env_quadrature(np.ones((4, 8, 1)))
    y = np.array([[0.0, 1.0, 0.0]])
    with pytest.raises(SpecrefError, match="unknown SHRM frame 'tangent'"):
        reflected_bruteforce(brdf_lambert, {"rho_d": [0.5]}, "tangent", y, y, env)

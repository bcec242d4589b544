"""shrm.montecarlo: the importance-sampled estimator of the report's speed–accuracy chart."""

import numpy as np
import pytest

from reference.materials.brdf import BRDF_METHODS, brdf_lambert
from shrm.montecarlo import environment_mc, environment_sampling_probabilities
from shrm.shrm_oracles import env_quadrature
from shrm.split import angular_sum


def _sun_sky():
    sky = np.full((24, 48, 3), 0.5)
    sky[:, :, 2] += np.linspace(0.0, 0.5, 24)[:, None]
    sky[5:7, 30:32] = 800.0
    return env_quadrature(sky)


def _points():
    # normals towards the sky and the sun, views in their upper hemispheres
    rng = np.random.default_rng(4)
    n = np.array([0.0, 1.0, 0.0]) + 0.6 * rng.normal(size=(6, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    v = n + 0.4 * rng.normal(size=(6, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    assert (np.einsum("pi,pi->p", n, v) > 0.2).all()
    return n, v


def test_probabilities_follow_luminance_times_solid_angle():
    _, w, L = _sun_sky()
    q = environment_sampling_probabilities(w, L)
    Y = L @ np.array([0.2126, 0.7152, 0.0722])
    np.testing.assert_allclose(q, Y * w / np.sum(Y * w), rtol=1e-12)


WARD = {"alpha": 0.3, "rho_d": [0.0], "rho_s": [1.0]}


@pytest.mark.parametrize(("brdf", "params"), [("ggx", {"alpha": 0.2}), ("ward_isotropic", WARD)])
def test_estimate_is_unbiased_against_the_brute_force_sum(brdf, params):
    # 40 seeds: the mean is the exact texel sum within 4 standard errors of that mean
    env = _sun_sky()
    n, v = _points()
    f = BRDF_METHODS.lookup(brdf).reference
    full = {**({"rho_d": [0.0], "F_0": [1.0]} if brdf == "ggx" else {}), **params}
    truth = angular_sum(env, f, full, n, v)[:, 0]
    assert (truth > 0).all()
    runs = np.array([environment_mc(env, f, full, n, v, 64, seed)[:, 0] for seed in range(40)])
    z = (runs.mean(axis=0) - truth) / (runs.std(axis=0, ddof=1) / np.sqrt(40))
    assert np.abs(z).max() < 4.0, z.round(2)
    # and it converges: 16x the samples, about a quarter of the error
    err = lambda m: np.abs(environment_mc(env, f, full, n, v, m, 1)[:, 0] - truth).max()  # noqa: E731
    assert err(4096) < 0.5 * err(256)


def test_white_furnace():
    # a constant sky and a white Lambertian surface: the albedo, to sampling noise
    env = env_quadrature(np.ones((16, 32, 1)))
    n = np.array([[0.0, 0.0, 1.0], [0.6, 0.0, 0.8]])
    out = environment_mc(env, brdf_lambert, {"rho_d": [1.0]}, n, n, 20000, 3)
    np.testing.assert_allclose(out[:, 0], 1.0, atol=0.01)

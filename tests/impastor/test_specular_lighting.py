"""Tests of impastor.specular_lighting: twins, convergence, closed forms, edge values."""

from __future__ import annotations

from operator import attrgetter

import numpy as np
import pytest

from impastor.arealights import PlaneLight
from impastor.point_lights import point_lights_from_plane
from impastor.specular_hybrid import SPECULAR_METHODS
from impastor.specular_lighting import (
    mip_lookup,
    mip_pyramid,
    specular_brute_force,
    specular_fis,
    specular_point_lights,
)
from reference.errors import SpecrefError
from reference.geometry.sampling import hammersley

UP = np.array([0.0, 1.0, 0.0])


@pytest.mark.parametrize(
    "method", [m for m in SPECULAR_METHODS.values() if m.kernel], ids=attrgetter("name")
)
def test_specular_numpy_and_numba_twins_agree(method, rng):
    inputs = method.example_inputs(rng)
    reference = method.run(inputs, "numpy")
    kernel = method.run(inputs, "numba")
    np.testing.assert_allclose(kernel, reference, rtol=1e-12, atol=1e-14)


def test_specular_twins_agree_on_edge_values():
    # Grazing view (cos θ_o → 0), α = 1e-3 (a near-mirror) and α = 1 (very rough).
    plane = PlaneLight(np.arange(32.0).reshape(4, 8) + 1, (-1, 1, -1), (1, 0, 0), (0, 0, 1), 2, 2)
    lights = point_lights_from_plane(plane, "median_cut", 4)
    P = np.zeros((3, 3))
    V = np.array([[0.0, 1.0, 0.0], [0.999, 0.0447, 0.0], [0.0, 0.6, 0.8]])
    V /= np.linalg.norm(V, axis=-1, keepdims=True)
    for alpha in (1e-3, 1.0):
        a = np.full(3, alpha)
        for fn in (
            lambda b: specular_point_lights(P, UP, V, a, lights, backend=b),  # noqa: B023
            lambda b: specular_fis(P, UP, V, a, plane, 8, backend=b),  # noqa: B023
            lambda b: specular_brute_force(P, UP, V, a, plane, 2, backend=b),  # noqa: B023
        ):
            np.testing.assert_allclose(fn("numba"), fn("numpy"), rtol=1e-12, atol=1e-14)


def _albedo_normal_incidence(alpha, order=200):
    """∫ lobe cos θ dω at normal view by Gauss–Legendre in θ (independent of the code under test).

    At normal incidence θ_i = 2θ_h, so the integrand depends on θ only.
    """
    x, w = np.polynomial.legendre.leggauss(order)
    theta = (x + 1) * np.pi / 4
    weights = w * np.pi / 4
    theta_h = theta / 2
    f = np.exp(-(np.tan(theta_h) ** 2) / alpha**2) / (4 * np.pi * alpha**2 * np.cos(theta))
    return float(np.sum(f * np.cos(theta) * np.sin(theta) * 2 * np.pi * weights))


def test_brute_force_under_uniform_sky_is_light_times_albedo():
    # Source: closed form, a uniform light covering the whole lobe gives I_s = L · albedo;
    # albedo by Gauss–Legendre quadrature (above). The light is 40 m wide at 1 m: the lobe's
    # tail past its edges (beyond 87°) is below 1e-12 for α = 0.1.
    L, alpha = 100.0, 0.1
    plane = PlaneLight(np.full((64, 64), L), (-20, 1, -20), (1, 0, 0), (0, 0, 1), 40.0, 40.0)
    I_s = specular_brute_force(np.zeros(3), UP, UP, alpha, plane, 16)[0]
    assert I_s == pytest.approx(L * _albedo_normal_incidence(alpha), rel=2e-3)


def test_brute_force_converges_with_supersampling():
    from impastor.painting import booth_plane_light

    plane = booth_plane_light("fluorescent", 32, 16)
    P = np.array([[0.0, 0.0, 0.0], [0.05, 0.0, -0.03]])
    V = np.array([0.0, 0.6, 0.8])
    values = [specular_brute_force(P, UP, V, 0.03, plane, s)[:, 0] for s in (2, 4, 8, 16)]
    diffs = [np.abs(values[k + 1] - values[k]).max() for k in range(3)]
    # The midpoint rule converges at second order: each doubling cuts the change about 4x.
    assert diffs[2] < diffs[1] < diffs[0]
    assert diffs[2] / np.abs(values[3]).max() < 1e-3


def test_fis_and_point_lights_reach_the_reference_in_their_regimes():
    from impastor.painting import booth_plane_light

    plane = booth_plane_light("fluorescent", 64, 32)
    lights = point_lights_from_plane(plane, "median_cut", 32)
    P = np.array([[0.0, 0.0, 0.0], [0.05, 0.0, -0.03], [-0.04, 0.0, 0.02]])
    V = np.array([0.0, 0.6, 0.8])
    for alpha, method, tolerance in ((0.02, "fis", 0.1), (0.3, "point_lights", 0.02)):
        a = np.full(3, alpha)
        reference = specular_brute_force(P, UP, V, a, plane, 8)[:, 0]
        if method == "fis":
            value = specular_fis(P, UP, V, a, plane, 64, backend="numba")[:, 0]
        else:
            value = specular_point_lights(P, UP, V, a, lights, backend="numba")[:, 0]
        assert np.abs(value / reference - 1).max() < tolerance, (method, value, reference)


def test_hammersley_is_stratified():
    u = hammersley(16)
    # Source: definition; the second coordinate is the base-2 radical inverse, a permutation of
    # k/16, so each of the 16 strata in either coordinate holds one point.
    np.testing.assert_array_equal(np.sort(np.floor(u[:, 1] * 16)), np.arange(16))
    np.testing.assert_array_equal(np.floor(u[:, 0] * 16), np.arange(16))


def test_mip_pyramid_preserves_the_mean(rng):
    image = rng.random((8, 16))
    for level in mip_pyramid(image):
        assert level.mean() == pytest.approx(image.mean(), rel=1e-12)
    levels = mip_pyramid(image)
    # Texel centres of level 0 return the texels (bilinear interpolation is exact there).
    a = (np.arange(16) + 0.5) / 16
    np.testing.assert_allclose(mip_lookup(levels, a, np.full(16, 2.5 / 8), 0.0), image[2])


def test_specular_bad_input():
    plane = PlaneLight(np.ones((2, 2)), (-1, 1, -1), (1, 0, 0), (0, 0, 1), 2, 2)
    with pytest.raises(SpecrefError, match="alpha: must be > 0"):
        specular_fis(np.zeros(3), UP, UP, 0.0, plane)
    with pytest.raises(SpecrefError, match="alpha: must be >= 0"):
        specular_fis(np.zeros(3), UP, UP, -0.1, plane)
    with pytest.raises(SpecrefError, match="unknown backend 'cuda'"):
        specular_fis(np.zeros(3), UP, UP, 0.1, plane, backend="cuda")

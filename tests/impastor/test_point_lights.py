"""Tests of impastor.point_lights: SATs, partitions, power conservation, Eqs. (2)-(3)."""

from __future__ import annotations

from operator import attrgetter

import numpy as np
import pytest

from impastor.arealights import PlaneLight, booth_light_image
from impastor.point_lights import (
    LIGHT_SAMPLING_METHODS,
    diffuse_radiance,
    illuminance_point_lights,
    median_cut,
    point_lights_from_latlong,
    point_lights_from_plane,
    region_sums,
    summed_area_table,
    variance_minimization,
)
from reference.errors import SpecrefError


def _ceiling(image, size=(1.2, 0.8)):
    return PlaneLight(image, (-0.6, 0.6, -1.0), (1, 0, 0), (0, 0, 1), *size)


def test_summed_area_table_matches_brute_force_sums(rng):
    image = rng.random((7, 9, 2))
    T = summed_area_table(image)
    for _ in range(20):
        y0, y1 = sorted(rng.choice(8, 2, replace=False))
        x0, x1 = sorted(rng.choice(10, 2, replace=False))
        # Source: brute force, NumPy sum over the block.
        np.testing.assert_allclose(
            T[y1, x1] - T[y0, x1] - T[y1, x0] + T[y0, x0],
            image[y0:y1, x0:x1].sum(axis=(0, 1)),
            rtol=1e-12,
        )


@pytest.mark.parametrize("method", LIGHT_SAMPLING_METHODS.values(), ids=attrgetter("name"))
@pytest.mark.parametrize("n_lights", [1, 5, 8, 32])
def test_partition_covers_image_disjointly(method, n_lights, rng):
    energy = rng.random((16, 32)) ** 4
    regions = method.reference(energy, n_lights)
    assert len(regions) == n_lights
    cover = np.zeros(energy.shape, dtype=int)
    for y0, y1, x0, x1 in regions:
        cover[y0:y1, x0:x1] += 1
    assert (cover == 1).all()


def test_median_cut_halves_energy():
    # Source: Debevec 2005, each cut divides the energy in two; a uniform 8×16 image splits into
    # two 8×8 halves, then four 8×4 (cuts across the longer side).
    regions = median_cut(np.ones((8, 16)), 4)
    np.testing.assert_array_equal(region_sums(np.ones((8, 16)), regions), [32, 32, 32, 32])
    assert sorted(regions) == [(0, 8, 0, 4), (0, 8, 4, 8), (0, 8, 8, 12), (0, 8, 12, 16)]


def test_variance_minimization_has_lower_variance_than_median_cut():
    from impastor.point_lights import _coordinates, _variance

    image = booth_light_image("fluorescent", 64, 32)
    total = {}
    for name, partition in (("mc", median_cut), ("vm", variance_minimization)):
        regions = partition(image, 16)
        X, Y = _coordinates(image.shape, 1.0, 1.0, np.ones(32))
        tables = {
            key: summed_area_table(v)
            for key, v in {
                "E": image,
                "Ex": image * X,
                "Ey": image * Y,
                "Exx": image * X * X,
                "Eyy": image * Y * Y,
            }.items()
        }
        total[name] = sum(_variance(tables, r) for r in regions)
    assert total["vm"] < total["mc"]


@pytest.mark.parametrize("method", LIGHT_SAMPLING_METHODS.names())
def test_point_lights_conserve_power(method):
    plane = _ceiling(booth_light_image("incandescent", 64, 32))
    lights = point_lights_from_plane(plane, method, 32)
    # Exact up to summation order: the regions tile the image.
    assert lights.L.sum() == pytest.approx(plane.image.sum(), rel=1e-12)
    env = np.random.default_rng(3).random((16, 32, 3))
    directional = point_lights_from_latlong(env, method, 12)
    from reference.geometry.envmap import latlong_pixel_solid_angles

    expected = (env * latlong_pixel_solid_angles(16, 32)[..., None]).sum(axis=(0, 1))
    np.testing.assert_allclose(directional.L.sum(axis=0), expected, rtol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(directional.position, axis=-1), 1.0, rtol=1e-12)


def test_illuminance_single_small_patch_is_inverse_square():
    # Source: closed form for a small Lambertian patch: E = L A cos θ_s cos θ_l / d².
    L, side, h, offset = 1000.0, 0.01, 1.0, 0.5
    plane = PlaneLight(np.full((1, 1), L), (offset - side / 2, h, -side / 2), (1, 0, 0),
                       (0, 0, 1), side, side)  # fmt: skip
    lights = point_lights_from_plane(plane, "median_cut", 1)
    d2 = offset**2 + h**2
    cos = h / np.sqrt(d2)
    E = illuminance_point_lights([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], lights)
    assert E[0] == pytest.approx(L * side**2 * cos * cos / d2, rel=1e-12)


def test_illuminance_converges_to_the_rectangle_form_factor():
    # Source: closed form, illuminance below the corner of a uniform rectangle a × b at height c
    # (Lambert): E = (L/2) [a/√(a²+c²) atan(b/√(a²+c²)) + b/√(b²+c²) atan(a/√(b²+c²))].
    L, a, b, c = 500.0, 0.8, 0.6, 0.5
    A2, B2 = np.sqrt(a * a + c * c), np.sqrt(b * b + c * c)
    exact = L / 2 * (a / A2 * np.arctan(b / A2) + b / B2 * np.arctan(a / B2))
    plane = PlaneLight(np.full((64, 64), L), (0, c, 0), (1, 0, 0), (0, 0, 1), a, b)
    errors = []
    for n in (4, 16, 64):
        lights = point_lights_from_plane(plane, "median_cut", n)
        E = illuminance_point_lights([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], lights)[0]
        errors.append(abs(E / exact - 1))
    # Second-order convergence of the one-point (centroid) rule: error falls ~4x per 4x lights.
    assert errors[2] < errors[1] < errors[0]
    assert errors[2] < 2e-3


def test_diffuse_radiance_of_a_white_lambertian():
    # Source: Eq. (3), Ferwerda, L = ρ S E / π; a white diffuser under 1000 lx at S = 1.
    assert diffuse_radiance([1.0], [1.0], [1000.0])[0] == pytest.approx(1000 / np.pi, rel=1e-15)


def test_partition_bad_input():
    with pytest.raises(SpecrefError, match="n_lights: must be an integer"):
        median_cut(np.ones((4, 4)), 0)
    with pytest.raises(SpecrefError, match="lat-long map must be 2:1"):
        point_lights_from_latlong(np.ones((4, 4)), "median_cut", 2)
    with pytest.raises(SpecrefError, match="unknown light sampling 'kmeans'"):
        point_lights_from_plane(_ceiling(np.ones((4, 4))), "kmeans", 2)

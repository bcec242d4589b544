import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.geometry.shapes import Plane, Sphere, intersect_plane, intersect_sphere


def test_sphere_closed_form_hits():
    s = Sphere((1.0, 2.0, 3.0), 2.0)
    o = np.array([[1.0, 2.0, 13.0], [1.0, 2.0, 3.0], [1.0, 4.0, 13.0], [1.0, 4.1, 13.0]])
    d = np.array([[0.0, 0.0, -1.0]] * 4)
    hit = intersect_sphere(s, o, d)
    # Source: geometry: 10 - r from outside; r from the centre; tangent at distance 10; a miss.
    np.testing.assert_allclose(hit.t[:3], [8.0, 2.0, 10.0], atol=1e-12)
    assert np.isinf(hit.t[3])
    np.testing.assert_allclose(hit.normal[0], [0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(hit.normal[1], [0, 0, -1], atol=1e-15)  # from inside: far side
    # uv of the +z normal: the lat-long centre (u = 1/2, v = 1/2).
    np.testing.assert_allclose(hit.uv[0], [0.5, 0.5], atol=1e-15)


def test_sphere_random_rays_land_on_the_sphere(rng):
    s = Sphere((0.3, -0.2, 0.1), 1.5)
    o = rng.normal(size=(500, 3)) * 4
    target = np.asarray(s.center) + rng.normal(size=(500, 3)) * 1.0
    d = target - o
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    hit = intersect_sphere(s, o, d)
    found = np.isfinite(hit.t)
    assert found.sum() > 100
    r = np.linalg.norm(hit.position[found] - s.center, axis=1)
    np.testing.assert_allclose(r, s.radius, rtol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(hit.normal[found], axis=1), 1, rtol=1e-14)
    # Source: the hit is on the ray: o + t d.
    np.testing.assert_allclose(
        o[found] + hit.t[found, None] * d[found], hit.position[found], atol=1e-9
    )
    assert np.isnan(hit.position[~found]).all()


def test_rectangle_bounds_and_uv():
    P = Plane((0, 0, -2), (0, 0, 1), (1, 0, 0), size=(4.0, 2.0))
    o = np.array([[-1.9, 0.9, 1.0], [2.1, 0.0, 1.0], [0.0, 0.0, 1.0]])
    d = np.array([[0.0, 0.0, -1.0]] * 3)
    hit = intersect_plane(P, o, d)
    np.testing.assert_allclose(hit.t[[0, 2]], [3.0, 3.0], atol=1e-15)
    assert np.isinf(hit.t[1])
    # u grows along +x from the left edge; v = 0 at the +y edge (image row 0 on top).
    np.testing.assert_allclose(hit.uv[0], [0.025, 0.05], atol=1e-12)


def test_plane_parallel_and_behind():
    P = Plane((0, 0, 0), (0, 1, 0))
    hit = intersect_plane(
        P, np.array([[0, 1.0, 0], [0, 1.0, 0]]), np.array([[1.0, 0, 0], [0, 1.0, 0]])
    )
    assert np.isinf(hit.t).all()


@pytest.mark.parametrize(
    ("factory", "match"),
    [
        (lambda: Sphere((0, 0, 0), 0.0), "sphere.radius: must be > 0"),
        (lambda: Sphere((0, 0), 1.0), "sphere.center: must be 3 numbers"),
        (lambda: Sphere((0, float("inf"), 0), 1.0), "sphere.center: must be finite"),
        (lambda: Plane(normal=(0, 0, 0)), "plane.normal: must be non-zero"),
        (lambda: Plane(normal=(1, 0, 0), u_axis=(2, 0, 0)), "u_axis: must not be parallel"),
        (lambda: Plane(size=(1.0, -1.0)), "plane.size: must be two numbers > 0"),
    ],
)
def test_geometry_bad_input(factory, match):
    with pytest.raises(SpecrefError, match=match):
        factory()

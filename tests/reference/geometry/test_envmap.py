import numpy as np
import pytest
from scipy import integrate

from reference.errors import SpecrefError
from reference.geometry.envmap import (
    check_latlong_shape,
    direction_to_latlong_uv,
    latlong_lookup_bilinear,
    latlong_pixel_directions,
    latlong_pixel_solid_angles,
    latlong_uv_to_direction,
)


def test_axes_follow_mitsuba3():
    # Source: Mitsuba 3 envmap.cpp (docs/conventions.md): u = atan2(d.x, -d.z)/2π, v = acos(d.y)/π.
    d = np.array([[0, 0, -1], [1, 0, 0], [0, 0, 1], [-1, 0, 0], [0, 1, 0], [0, -1, 0]], float)
    u, v = direction_to_latlong_uv(d)
    np.testing.assert_allclose(u[:4], [0.0, 0.25, 0.5, 0.75], atol=1e-15)
    np.testing.assert_allclose(v, [0.5, 0.5, 0.5, 0.5, 0.0, 1.0], atol=1e-15)


def test_agrees_with_openexr_latlong_orientation(rng):
    # Source: OpenEXR ImfEnvmap.cpp LatLong: longitude = atan2(x, z), latitude = asin(y); pixel
    # x runs from longitude +π (left) to -π (right): u = 1/2 - longitude/2π, v = 1/2 - latitude/π.
    d = rng.normal(size=(1000, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    u, v = direction_to_latlong_uv(d)
    u_exr = (0.5 - np.arctan2(d[:, 0], d[:, 2]) / (2 * np.pi)) % 1.0
    v_exr = 0.5 - np.arcsin(d[:, 1]) / np.pi
    np.testing.assert_allclose(np.exp(2j * np.pi * u), np.exp(2j * np.pi * u_exr), atol=1e-12)
    np.testing.assert_allclose(v, v_exr, atol=1e-12)


def test_round_trip(rng):
    d = rng.normal(size=(4, 50, 3))
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    u, v = direction_to_latlong_uv(d)
    assert u.shape == (4, 50)
    assert ((u >= 0) & (u < 1)).all()
    np.testing.assert_allclose(latlong_uv_to_direction(u, v), d, atol=1e-12)


def test_pixel_directions_are_fejer_nodes():
    H, W = 8, 16
    d = latlong_pixel_directions(H, W)
    theta = np.arccos(d[:, 0, 1])
    # Source: Fejér's first rule nodes θ_j = (j + ½)π/H.
    np.testing.assert_allclose(theta, (np.arange(H) + 0.5) * np.pi / H, atol=1e-14)
    u, _ = direction_to_latlong_uv(d[0])
    np.testing.assert_allclose(u, (np.arange(W) + 0.5) / W, atol=1e-14)


def test_solid_angles_by_quadrature():
    H, W = 6, 12
    omega = latlong_pixel_solid_angles(H, W)
    assert omega.sum() == pytest.approx(4 * np.pi, rel=1e-14)
    # Source: ∫∫ sin θ dθ dφ over each pixel, by scipy quadrature.
    for j in range(H):
        exact, _ = integrate.quad(np.sin, j * np.pi / H, (j + 1) * np.pi / H, epsabs=1e-14)
        assert omega[j, 3] == pytest.approx(exact * 2 * np.pi / W, rel=1e-12)


def test_bilinear_lookup_at_centres_and_across_the_seam(rng):
    image = rng.uniform(0, 1, (4, 8, 2))
    centres = latlong_pixel_directions(4, 8)
    np.testing.assert_allclose(latlong_lookup_bilinear(image, centres), image, atol=1e-12)
    # Halfway between the last and the first column: the mean of the two (wrap-around).
    d = latlong_uv_to_direction(0.0, (1 + 0.5) / 4)
    expected = 0.5 * (image[1, 0] + image[1, 7])
    np.testing.assert_allclose(latlong_lookup_bilinear(image, d), expected, atol=1e-12)
    # Above the first row centre: clamped to the first row (linear in u only).
    top = latlong_lookup_bilinear(image, [0.0, 1.0, 0.0])
    assert top.shape == (2,)


def test_check_latlong_shape():
    check_latlong_shape((1, 2))
    for shape in [(512, 512, 3), (100, 201), (0, 0)]:
        with pytest.raises(SpecrefError, match="must be 2:1"):
            check_latlong_shape(shape, "map.hdr")


def test_mitsuba_rows_resample_a_linear_ramp_exactly(rng):
    # Source: Mitsuba 3 envmap.cpp (rows at v = j/(H-1), linear between rows). A map linear in
    # Mitsuba's v is the function a + b v; resampled, specref's row j holds it at v = (j + 1/2)/H.
    from reference.geometry.envmap import TEXEL_PLACEMENTS, latlong_rows_mitsuba_to_centred

    H, a, b = 9, rng.random(3), rng.random(3)
    v_mitsuba = np.arange(H) / (H - 1)
    image = np.broadcast_to((a + b * v_mitsuba[:, None])[:, None, :], (H, 2 * H, 3))
    v_centred = (np.arange(H) + 0.5) / H
    expected = a + b * v_centred[:, None]
    got = latlong_rows_mitsuba_to_centred(image)
    np.testing.assert_allclose(got[:, 3], expected, rtol=1e-13)
    np.testing.assert_array_equal(TEXEL_PLACEMENTS.lookup("centred").reference(image), image)
    with pytest.raises(SpecrefError, match="at least 2 rows"):
        latlong_rows_mitsuba_to_centred(np.ones((1, 2, 3)))


def test_unknown_texel_placement_is_refused():
    from reference.scene.lights import EnvironmentLight

    with pytest.raises(SpecrefError, match="unknown texel placement 'pbrt'; allowed: centred"):
        EnvironmentLight(np.ones((4, 8, 3)), texel_placement="pbrt")


def test_mitsuba_rows_keep_the_integral_over_v(rng):
    # Source: the trapezoid rule, which is the exact integral of Mitsuba's piecewise-linear rows
    # over v in [0, 1]; specref's rows (width 1/H) are its averages, so their sum keeps it.
    from reference.geometry.envmap import latlong_rows_mitsuba_to_centred

    image = rng.random((7, 14, 2))
    exact = np.trapezoid(image, dx=1.0 / 6.0, axis=0)
    np.testing.assert_allclose(latlong_rows_mitsuba_to_centred(image).sum(axis=0) / 7, exact)

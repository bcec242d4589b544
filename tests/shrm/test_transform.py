"""Tests of shrm.transform: projection and synthesis of lat-long maps, their backends and shapes."""

from __future__ import annotations

from operator import attrgetter

import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.images.formats import read_hdr
from shrm.sh import sh_evaluate
from shrm.transform import SH_BACKENDS, project_function, project_latlong, synthesize_latlong


@pytest.mark.parametrize("backend", SH_BACKENDS.values(), ids=attrgetter("name"))
def test_round_trip_band_limited_L100(backend, rng):
    # A band-limited random L = 100 map, synthesized and projected back, returns its coefficients
    # (Fejér-1 is exact for 2L < H); our bound is RMS ≤ 1e-13 on the map.
    L, H = 100, 202
    c = rng.normal(size=(1, (L + 1) ** 2)) / (L + 1)
    image = synthesize_latlong(c, H, backend=backend.name)
    back = project_latlong(image, L, backend=backend.name)
    again = synthesize_latlong(back, H, backend=backend.name)
    assert np.sqrt(np.mean((again - image) ** 2)) <= 1e-13
    np.testing.assert_allclose(back, c, atol=1e-13)


def test_projection_of_finite_sum_returns_coefficients(rng):
    L = 12
    c = rng.normal(size=(3, (L + 1) ** 2))
    got = project_function(lambda d: sh_evaluate(c, d), L)
    np.testing.assert_allclose(got, c, atol=1e-13)


def test_solid_angle_weights_leave_round_trip_error(rng):
    # The pixel solid-angle rule is a midpoint rule: its error (5e-4 relative) is why it is not
    # the default.
    L = 20
    c = rng.normal(size=(1, (L + 1) ** 2))
    image = synthesize_latlong(c, 64)
    err = np.abs(project_latlong(image, L, weights="solid_angle") - c).max() / np.abs(c).max()
    assert 1e-5 < err < 1e-2


def test_ducc0_agrees_with_numpy_on_real_map(package_data):
    # The fast path against its oracle on venice_sunset_1k.hdr (512×1024, RGB), L = 100: ≤ 1e-13
    # relative to the largest coefficient.
    image = read_hdr(package_data / "environments" / "venice_sunset_1k.hdr")
    a = project_latlong(image, 100, backend="numpy")
    b = project_latlong(image, 100, backend="ducc0")
    assert np.abs(a - b).max() / np.abs(a).max() <= 1e-13


@pytest.mark.parametrize(
    ("image", "order", "message"),
    [
        (np.ones((8, 8, 1)), 2, "2:1"),
        (np.full((8, 16, 1), np.nan), 2, "finite"),
        (np.ones((8, 16, 1)), -1, "order"),
        (np.ones((8, 16, 1)), 8, "order"),
    ],
)
def test_project_bad_input(image, order, message):
    with pytest.raises(SpecrefError, match=message):
        project_latlong(image, order)


def test_unknown_backend():
    with pytest.raises(SpecrefError, match="allowed: ducc0, numba, numpy"):
        project_latlong(np.ones((4, 8, 1)), 1, backend="fortran")


def test_project_function_of_linear_functions_closed_form():
    # Source: closed form. Y_1,-1 = −c x, Y_10 = c y, Y_11 = c z with c = sqrt(3/4π) (y up), so
    # x, y and z each have one coefficient, ∓1/c = ∓sqrt(4π/3).
    c = np.sqrt(4 * np.pi / 3)
    got = project_function(lambda d: d, 1)
    assert got.shape == (3, 4)
    np.testing.assert_allclose(got, [[0, -c, 0, 0], [0, 0, c, 0], [0, 0, 0, c]], atol=1e-14)


@pytest.mark.parametrize("backend", SH_BACKENDS.names())
def test_transform_shapes(backend, rng):
    c = rng.normal(size=(2, 16))
    assert synthesize_latlong(c, 8, backend=backend).shape == (8, 16, 2)
    assert synthesize_latlong(c[0], 8, backend=backend).shape == (8, 16)
    image = rng.random((8, 16, 3))
    assert project_latlong(image, 3, backend=backend).shape == (3, 16)
    assert project_latlong(image[..., 0], 3, backend=backend).shape == (1, 16)


def test_synthesis_agrees_with_direct_evaluation(rng):
    # Source: the basis evaluated directly at the pixel centres (shrm.sh.sh_evaluate, itself
    # checked against mpmath in test_sh.py): synthesis is the same sum by rings and rFFT.
    from reference.geometry.envmap import latlong_pixel_directions

    c = rng.normal(size=(2, 49))
    expected = sh_evaluate(c, latlong_pixel_directions(10, 20))
    for backend in SH_BACKENDS.names():
        np.testing.assert_allclose(
            synthesize_latlong(c, 10, backend=backend), expected, rtol=1e-12, atol=1e-13
        )


def test_synthesize_bad_input():
    with pytest.raises(SpecrefError, match="height must exceed the order 3"):
        synthesize_latlong(np.ones(16), 3)
    with pytest.raises(SpecrefError, match="unknown SH backend 'fortran'"):
        synthesize_latlong(np.ones(4), 4, backend="fortran")
    with pytest.raises(SpecrefError, match="unknown quadrature weights 'simpson'"):
        project_latlong(np.ones((4, 8, 1)), 1, weights="simpson")

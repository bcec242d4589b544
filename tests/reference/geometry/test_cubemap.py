"""Tests of reference.geometry.cubemap: faces, solid angles, lookups, transforms, twins."""

from __future__ import annotations

import itertools
from operator import attrgetter

import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.geometry.cubemap import (
    CUBEMAP_METHODS,
    cubemap_lookup_bilinear,
    cubemap_texel_directions,
    cubemap_texel_solid_angles,
    cubemap_to_latlong,
    latlong_to_cubemap,
)
from shrm.sh import sh_evaluate
from shrm.transform import synthesize_latlong

# Source: OpenGL 4.6 specification, Table 8.19 (cube map face selection): the major axis picks the
# face and (sc, tc, ma) give the face coordinates s = sc/|ma|, t = tc/|ma|.
OPENGL_FACES = {
    0: lambda x, y, z: (-z, -y, x),  # +x
    1: lambda x, y, z: (z, -y, x),  # −x
    2: lambda x, y, z: (x, z, y),  # +y
    3: lambda x, y, z: (x, -z, y),  # −y
    4: lambda x, y, z: (x, -y, z),  # +z
    5: lambda x, y, z: (-x, -y, z),  # −z
}


@pytest.mark.parametrize("size", [1, 2, 5])
def test_cubemap_texel_directions_follow_the_opengl_face_table(size):
    d = cubemap_texel_directions(size)
    assert d.shape == (6, size, size, 3)
    np.testing.assert_allclose(np.linalg.norm(d, axis=-1), 1.0, rtol=1e-15)
    centres = 2.0 * (np.arange(size) + 0.5) / size - 1.0
    for face, selection in OPENGL_FACES.items():
        sc, tc, ma = selection(*np.moveaxis(d[face], -1, 0))
        # The face's own axis is the major one, with the face's sign.
        assert (np.abs(ma) >= np.abs(d[face]).max(axis=-1) - 1e-15).all()
        assert (np.sign(ma) == (1 if face % 2 == 0 else -1)).all()
        np.testing.assert_allclose(sc / np.abs(ma), np.broadcast_to(centres, (size, size)))
        np.testing.assert_allclose(tc / np.abs(ma), np.broadcast_to(centres[:, None], (size, size)))


def test_cubemap_texel_solid_angles_match_quadrature():
    # Source: scipy.integrate.dblquad of the plane-to-sphere Jacobian (1 + s² + t²)^(-3/2) over
    # each texel of one face (the cube face at distance 1 spans [−1, 1]²).
    from scipy.integrate import dblquad

    size = 3
    omega = cubemap_texel_solid_angles(size)
    assert omega.shape == (6, size, size)
    edges = np.linspace(-1.0, 1.0, size + 1)
    for j in range(size):
        for i in range(size):
            value, _ = dblquad(
                lambda t, s: (1.0 + s * s + t * t) ** -1.5,
                edges[i],
                edges[i + 1],
                edges[j],
                edges[j + 1],
                epsabs=1e-14,
                epsrel=1e-13,
            )
            assert omega[0, j, i] == pytest.approx(value, rel=1e-12)
    # Every face alike, and the sphere's 4π (exact: Ω sums telescopically to 6 · 4 atan(1/√3)).
    np.testing.assert_array_equal(omega, np.broadcast_to(omega[0], omega.shape))
    assert abs(cubemap_texel_solid_angles(16).sum() - 4 * np.pi) < 1e-12


@pytest.mark.parametrize("method", CUBEMAP_METHODS.values(), ids=attrgetter("name"))
def test_cubemap_numba_twins_equal_numpy(method, rng):
    args = method.example_inputs(rng)
    if method.name == "gather_bilinear":
        out = np.empty((args[1].shape[0], args[0].shape[1]))
        method.kernel(*args, out)
        np.testing.assert_allclose(out, method.reference(*args), rtol=1e-12, atol=1e-14)
    else:
        out = method.reference(*args, backend="numba")
        np.testing.assert_allclose(out, method.reference(*args), rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_cubemap_lookup_at_texel_centres_returns_the_texels(backend, rng):
    # Bilinear interpolation at a texel centre has weight 1 on that texel (round trip).
    size = 4
    cube = rng.random((6, size, size, 2))
    got = cubemap_lookup_bilinear(cube, cubemap_texel_directions(size), backend=backend)
    np.testing.assert_allclose(got, cube, rtol=1e-12, atol=1e-14)


def test_cubemap_lookup_shapes(rng):
    cube = rng.random((6, 3, 3, 5))
    assert cubemap_lookup_bilinear(cube, [0.0, 0.0, 1.0]).shape == (5,)
    assert cubemap_lookup_bilinear(cube, rng.normal(size=(7, 3))).shape == (7, 5)
    assert cubemap_lookup_bilinear(cube, rng.normal(size=(2, 3, 3))).shape == (2, 3, 5)


def test_cube_lookup_second_order_and_round_trip(rng):
    # Band-limited content (L = 6): the lookup converges; inside faces bilinear is second order, the
    # re-projected taps across face edges are first order, so the max error falls at least 2x.
    c = rng.normal(size=(1, 49))
    d = rng.normal(size=(500, 3))
    exact = sh_evaluate(c, d / np.linalg.norm(d, axis=-1, keepdims=True))
    fine = synthesize_latlong(c, 512)
    errors = [
        np.abs(cubemap_lookup_bilinear(latlong_to_cubemap(fine, S), d) - exact).max()
        for S in (32, 64, 128)
    ]
    assert errors[0] / errors[1] > 2.0
    assert errors[1] / errors[2] > 2.0
    back = cubemap_to_latlong(latlong_to_cubemap(fine, 128), 512)
    assert np.sqrt(np.mean((back - fine) ** 2)) < 1e-2 * np.abs(fine).max()


def test_latlong_to_cubemap_float32_twin_and_out(rng):
    image = rng.random((16, 32, 41)).astype(np.float32)
    fast = latlong_to_cubemap(image, 8)
    assert fast.dtype == np.float32
    np.testing.assert_allclose(fast, latlong_to_cubemap(image, 8, backend="numpy"), rtol=1e-6)
    out = np.empty_like(fast)
    assert latlong_to_cubemap(image, 8, out=out) is out
    with pytest.raises(SpecrefError, match="out must be"):
        latlong_to_cubemap(image, 8, out=np.empty((6, 8, 8, 41)))


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: cubemap_lookup_bilinear(np.ones((5, 2, 2, 1)), [0, 0, 1]), r"\(6, S, S, C\)"),
        (lambda: cubemap_lookup_bilinear(np.ones((6, 2, 3, 1)), [0, 0, 1]), r"\(6, S, S, C\)"),
        (
            lambda: cubemap_lookup_bilinear(np.ones((6, 2, 2, 1)), [0, 0, 1], backend="gpu"),
            "unknown cube-map backend 'gpu'; allowed: numba, numpy",
        ),
        (lambda: latlong_to_cubemap(np.ones((4, 8)), 2), r"expected \(H, W, C\)"),
        (lambda: latlong_to_cubemap(np.ones((4, 4, 1)), 2), "2:1"),
        (lambda: latlong_to_cubemap(np.ones((4, 8, 1)), 0), "cube map size"),
        (lambda: cubemap_texel_solid_angles(-1), "cube map size"),
        (lambda: cubemap_to_latlong(np.ones((6, 2, 2, 1)), 0), "lat-long height"),
    ],
)
def test_cubemap_bad_input(call, match):
    with pytest.raises(SpecrefError, match=match):
        call()


@pytest.mark.parametrize("backend", ["numba", "numpy"])
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_streamed_cubemap_is_bit_identical_to_in_memory(backend, dtype, rng):
    # Blocks of uneven heights, one of a single row (its texels all lie on seams).
    from reference.geometry.cubemap import latlong_blocks_to_cubemap

    image = rng.gamma(0.5, 1.0, (64, 128, 5)).astype(dtype)
    cuts = [0, 7, 8, 30, 31, 64]
    blocks = [(a, image[a:b]) for a, b in itertools.pairwise(cuts)]
    streamed = latlong_blocks_to_cubemap(blocks, 64, 24, backend=backend)
    whole = latlong_to_cubemap(image, 24, backend=backend)
    assert streamed.dtype == whole.dtype == dtype
    np.testing.assert_array_equal(streamed, whole)


def test_streamed_cubemap_refuses_gaps_and_disorder(rng):
    from reference.geometry.cubemap import latlong_blocks_to_cubemap

    image = rng.random((8, 16, 1))
    with pytest.raises(SpecrefError, match=r"block at row 4 .* expected the rows from 3 on"):
        latlong_blocks_to_cubemap([(0, image[:3]), (4, image[4:])], 8, 4)
    with pytest.raises(SpecrefError, match=r"latlong_blocks_to_cubemap: 3 of 8 rows"):
        latlong_blocks_to_cubemap([(0, image[:3])], 8, 4)

import numpy as np
import pytest
from scipy import integrate, optimize

from reference.errors import SpecrefError
from reference.geometry.envmap import latlong_uv_to_direction
from shrm.prefilter import prefilter_bruteforce
from shrm.texel_irradiance import (
    TEXEL_IRRADIANCE_METHODS,
    irradiance_texel_constant,
    phi_breaks,
    texel_weights,
)


def _normals(rng, count):
    d = rng.normal(size=(count, 3))
    d = d / np.linalg.norm(d, axis=-1, keepdims=True)
    # the special cases: straight up and down, horizontal (c = 0), on a column edge
    return np.vstack(
        [d, [[0, 1, 0], [0, -1, 0], [1, 0, 0], [0.6, 0, 0.8], [0, 0.3, -np.sqrt(0.91)]]]
    )


@pytest.mark.parametrize("method", TEXEL_IRRADIANCE_METHODS.values(), ids=lambda m: m.name)
def test_kernel_twins_the_numpy_reference(method, rng):
    image, normals = method.example_inputs(rng)
    normals = np.vstack([normals, _normals(rng, 3)])
    np.testing.assert_allclose(
        method.reference(image, normals, backend="numba"),
        method.reference(image, normals, backend="numpy"),
        rtol=1e-12,
        atol=1e-14,
    )


def test_white_furnace_is_pi_for_every_normal(rng):
    n = _normals(rng, 40)
    for backend in ("numba", "numpy"):
        E = irradiance_texel_constant(np.ones((16, 32, 1)), n, backend=backend)
        assert np.abs(E - np.pi).max() < 1e-7  # the default 3 nodes
        E = irradiance_texel_constant(np.ones((16, 32, 1)), n, nodes=16, backend=backend)
        assert np.abs(E - np.pi).max() < 1e-12


def test_straight_up_is_the_closed_form_of_each_row():
    # n = +y: the cosine is cos θ, so row j takes (2π/W)(sin²θ_{j+1} − sin²θ_j)/2 per column
    H, W = 8, 16
    T = texel_weights([0.0, 1.0, 0.0], H, W)  # no breaks but the columns: exact at 4 nodes
    edges = np.pi * np.arange(H + 1) / H
    row = np.where(edges[1:] <= np.pi / 2, np.pi / W * np.diff(np.sin(edges) ** 2), 0.0)
    np.testing.assert_allclose(T, np.broadcast_to(row[:, None], (H, W)), atol=1e-15)


def _texel_by_adaptive_quadrature(n, j, i, H, W):
    """∫_texel max(0, n·ω) dω by scipy's quad, the horizon found by root-finding on n·ω(θ)."""

    def cosine(theta, phi):
        return float(latlong_uv_to_direction(phi / (2 * np.pi), theta / np.pi) @ n)

    def column(phi):
        lo, hi = np.pi * j / H, np.pi * (j + 1) / H
        points = None
        if cosine(lo, phi) * cosine(hi, phi) < 0:  # the horizon crosses the row here
            points = [optimize.brentq(cosine, lo, hi, args=(phi,), xtol=1e-15)]
        value, _ = integrate.quad(
            lambda t: max(0.0, cosine(t, phi)) * np.sin(t), lo, hi, points=points,
            epsabs=1e-16, epsrel=1e-13,
        )  # fmt: skip
        return value

    edges = 2 * np.pi * i / W, 2 * np.pi * (i + 1) / W
    return integrate.quad(column, *edges, epsabs=1e-16, epsrel=1e-12, limit=200)[0]


def test_a_texel_the_horizon_crosses_against_adaptive_quadrature():
    # independent of the closed form and of the breaks: scipy's adaptive quadrature of
    # max(0, n·ω) sin θ, with the direction from reference.geometry.envmap
    H, W = 8, 16
    n = np.array([0.3, 0.2, -0.9])
    n /= np.linalg.norm(n)
    T = texel_weights(n, H, W, nodes=16)
    crossing = [(j, i) for j in range(H) for i in range(W) if 1e-3 < T[j, i] < 0.01][:4]
    assert crossing, "no texel the horizon crosses"
    for j, i in crossing:
        exact = _texel_by_adaptive_quadrature(n, j, i, H, W)
        assert abs(T[j, i] - exact) < 1e-10 * exact, (j, i)


def test_nodes_converge_and_the_fejer_brute_force_converges_to_it(rng):
    image = rng.random((8, 16, 2))
    n = _normals(rng, 12)
    best = irradiance_texel_constant(image, n, nodes=48)
    assert np.abs(irradiance_texel_constant(image, n) / best - 1).max() < 5e-6  # 3 nodes
    assert np.abs(irradiance_texel_constant(image, n, nodes=8) / best - 1).max() < 1e-10
    # the brute force on the map subdivided k × k: its error at the texels' edges falls as 1/k
    errors = []
    for k in (8, 32):
        fine = np.repeat(np.repeat(image, k, axis=0), k, axis=1)
        errors.append(np.abs(prefilter_bruteforce(fine, "lambert", n) / best - 1).max())
    assert errors[1] < errors[0] / 3
    assert errors[1] < 1e-4
    # and on the map itself it is off by more than the exact rule's own error
    assert np.abs(prefilter_bruteforce(image, "lambert", n) / best - 1).max() > 1e-3


def test_breaks_hold_the_columns_and_the_horizon_crossings():
    breaks = phi_breaks([0.3, 0.2, -0.9], 8, 16)
    assert breaks[0] == 0.0
    assert breaks[-1] == 2 * np.pi
    assert (np.diff(breaks) >= 0).all()
    assert len(breaks) > 17  # the horizon crosses row edges


def test_bad_input_is_refused_in_one_line():
    with pytest.raises(SpecrefError, match="expected \\(H, W, C\\)"):
        irradiance_texel_constant(np.ones((4, 8)), [[0, 1, 0]])
    for nodes in (0, -3, 10**9):
        with pytest.raises(SpecrefError, match="nodes"):
            irradiance_texel_constant(np.ones((4, 8, 1)), [[0, 1, 0]], nodes=nodes)
    with pytest.raises(SpecrefError, match="normals") as error:
        irradiance_texel_constant(np.ones((4, 8, 1)), [[0, np.nan, 0]])
    assert "\n" not in str(error.value)
    with pytest.raises(SpecrefError, match="image"):
        irradiance_texel_constant(np.full((4, 8, 1), np.inf), [[0, 1, 0]])
    with pytest.raises(SpecrefError, match=r"must be \(\.\.\., 3\)"):
        irradiance_texel_constant(np.ones((4, 8, 1)), [[0, 1]])

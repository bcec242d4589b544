import numpy as np
import pytest

from reference.geometry.camera import Camera
from reference.geometry.cubemap import cubemap_texel_directions
from reference.geometry.gbuffer import render_gbuffer
from reference.geometry.shapes import Sphere
from reference.materials.brdf import BRDF_METHODS
from reference.materials.isotropic import brdf_lafortune
from shrm.brdf_sh import brdf_sh_coefficients
from shrm.rotation import rotation_matrix, sh_rotation_blocks
from shrm.sh import sh_evaluate
from shrm.shrm import (
    SHRM,
    polar_rotate,
    render_shrm,
    shade_shrm,
    shrm_create,
    shrm_extract,
)
from shrm.shrm_oracles import (
    env_quadrature,
    reflected_bruteforce,
    render_bruteforce,
    shrm_create_angular,
)
from shrm.transform import synthesize_latlong
from validation.cli import main

# A lobe about the normal, ρ_s (n+2)/(2π) (cos θ_i cos θ_o)^n with n = 2: its transfer function is
# a polynomial of degree 2 in the view (also with the even continuation), so P = 2 is exact.
POLY = {"rho_d": np.array([0.2, 0.4]), "rho_s": 0.5, "C_xy": 0.0, "C_z": 1.0, "n": 2.0}


def _env(rng, order=6, channels=2, height=32):
    c = rng.normal(size=(channels, (order + 1) ** 2)) * 0.2
    c[:, 0] = np.sqrt(4 * np.pi) * 2.0
    return c, synthesize_latlong(c, height)


def test_polar_rotate_matches_wigner_blocks(rng):
    # Source: shrm.rotation's Ivanic–Ruedenberg recursion (an independent construction).
    c = rng.normal(size=(3, 49))
    for a in (0.3, -1.2, 2.9):
        blocks = sh_rotation_blocks(rotation_matrix([0.0, 1.0, 0.0], a), 6)
        expected = np.concatenate(
            [c[:, l * l : (l + 1) ** 2] @ D.T for l, D in enumerate(blocks)], axis=1
        )
        np.testing.assert_allclose(polar_rotate(c, [a])[0], expected, rtol=0, atol=1e-13)


def _poly_closed_form(coeffs, n, v):
    """B(n, v) of the POLY lobe in closed form.

    Source: ρ̃ = ρ_d/π cos⁺θ_i + ρ_s (2/π) cos³⁺θ_i cos²θ_o, so
    B(n, v) = ρ_d/π E_1(n) + (2ρ_s/π) (n·v)² E_3(n), where E_k = ∫ L cos^k⁺ is a radial prefilter
    with Λ_l = 2π ∫_0^1 x^k P_l(x) dx (Gauss–Legendre, exact for these polynomials).
    """
    x, w = np.polynomial.legendre.leggauss(40)
    x, w = (x + 1) / 2, w / 2
    P = np.polynomial.legendre.legvander(x, 6)
    l = np.repeat(np.arange(7), 2 * np.arange(7) + 1)
    E = {k: sh_evaluate(coeffs * (2 * np.pi * (w * x**k) @ P)[l], n) for k in (1, 3)}
    cos_o2 = np.clip(n @ v, 0, None)[..., None] ** 2
    return POLY["rho_d"] / np.pi * E[1] + 2 * POLY["rho_s"] / np.pi * cos_o2 * E[3]


@pytest.mark.parametrize(
    ("view_fit", "ridge", "rtol"),
    # the hemisphere fit is exact without its Tikhonov term; μ = 1e-6 biases it by ~1e-5
    [("sphere", None, 1e-10), ("hemisphere", 0.0, 1e-10), ("hemisphere", None, 1e-4)],
)
def test_frequency_creation_is_exact_for_band_limited_input(rng, view_fit, ridge, rtol):
    coeffs, _ = _env(rng)
    rho = brdf_sh_coefficients(brdf_lafortune, POLY, 6, 2, "normal", view_fit=view_fit, ridge=ridge)
    s = shrm_create(coeffs, rho, "normal", size=3)
    n = cubemap_texel_directions(3)
    for v in ([0.0, 0.0, 1.0], [0.6, 0.0, 0.8], [-0.36, 0.48, 0.8]):
        v = np.array(v)
        front = (n @ v) > 0
        expected = _poly_closed_form(coeffs, n, v)
        np.testing.assert_allclose(
            shrm_extract(s, v)[front], expected[front], rtol=rtol, atol=1e-12
        )


@pytest.mark.parametrize("frame", ["normal", "reflection"])
def test_frequency_creation_against_the_angular_oracle(rng, frame):
    coeffs, env = _env(rng, order=4, height=24)
    m = BRDF_METHODS.lookup("lafortune")
    params = {"rho_d": [0.1, 0.2], "rho_s": 0.6, "C_xy": -1.0, "C_z": 1.0, "n": [4.0, 6.0]}
    angular = shrm_create_angular(env, m.reference, params, 6, frame, size=2)
    errors = []
    for P in (2, 6):
        rho = brdf_sh_coefficients(m.reference, params, 4, P, frame)
        s = shrm_create(coeffs, rho, frame, size=2)
        v = np.array([0.3, 0.5, 0.81])
        v /= np.linalg.norm(v)
        truth = reflected_bruteforce(
            m.reference,
            params,
            frame,
            cubemap_texel_directions(2).reshape(-1, 3),
            np.broadcast_to(v, (24, 3)),
            env_quadrature(env),
        ).reshape(6, 2, 2, 2)
        front = (cubemap_texel_directions(2) @ v) > 0.2
        E = shrm_extract(s, v)
        errors.append(np.abs(E - truth)[front].max() / np.abs(truth).max())
        if P == 6:
            # Same P: the frequency and angular paths agree to the view-expansion tail.
            A = shrm_extract(angular, v)
            assert np.abs(E - A)[front].max() / np.abs(truth).max() < 0.02
    # More view coefficients, less error (convergence in P).
    assert errors[1] < errors[0]
    assert errors[1] < 0.02


def test_render_through_the_gbuffer_converges_to_the_closed_form(rng):
    coeffs, _ = _env(rng, order=6)
    camera = Camera(eye=(0, 0, 5), projection="orthographic", extent=2.2)
    g = render_gbuffer([Sphere()], camera, 12, 12)
    view = np.array([0.0, 0.0, 1.0])
    truth = np.zeros((12, 12, 2))
    truth[g.mask] = _poly_closed_form(coeffs, g.normal[g.mask], view)
    peak = truth[g.mask].max()
    # The SHRM's texels are exact; what is left is the seamless bilinear lookup of
    # reference.geometry.cubemap, second order inside a face and first order at face edges, where a
    # tap across the edge snaps to the neighbouring face's nearest texel (observed rates 0.98,
    # 1.04).
    rho = brdf_sh_coefficients(brdf_lafortune, POLY, 6, 2, "normal")
    errors = [
        np.abs(render_shrm(g, shrm_create(coeffs, rho, "normal", size=S), view) - truth)[
            g.mask
        ].max()
        / peak
        for S in (8, 16, 32)
    ]
    rates = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(rates > 0.8), (errors, rates)
    # The per-pixel oracle sums the environment's pixels: its error falls with the map's rows.
    oracle = [
        np.abs(
            render_bruteforce(g, synthesize_latlong(coeffs, H), brdf_lafortune, POLY, view) - truth
        )[g.mask].max()
        / peak
        for H in (16, 32, 64)
    ]
    assert oracle[2] < oracle[1] < oracle[0], oracle
    assert np.all(render_shrm(g, shrm_create(coeffs, rho, "normal", size=2), view)[~g.mask] == 0)


def test_cli_orbit_refuses_orders_the_tolerance_does_not_allow(tmp_path, capsys):
    argv = ["shrm", "orbit", "--quick", "--brdf", "lafortune", "--no-cache", "-o", str(tmp_path)]
    assert main([*argv, "--frames", "1", "--P", "3"]) == 2
    assert "SHRM: P = 3 is outside what tol 0.05 allows" in capsys.readouterr().err


def test_shrm_extract_is_linear_in_the_view_basis():
    rng = np.random.default_rng(4)
    s = SHRM(rng.normal(size=(6, 2, 2, 1, 9)), "normal", 2, 2)
    from shrm.sh import sh_basis

    v = np.array([0.0, 0.6, 0.8])
    np.testing.assert_allclose(
        shrm_extract(s, v)[..., 0], s.coeffs[..., 0, :] @ sh_basis(2, v[None])[0]
    )


@pytest.mark.parametrize("K", [0, 7, 25])
def test_the_basis_product_equals_one_synthesis_per_function(rng, K, monkeypatch):
    # erratum E97: the texels' values of many functions as one matrix product, in blocks of
    # texels (a small block here, so several), agree with ducc0's synthesis of each function
    import shrm.shrm as shrm_module

    monkeypatch.setattr(shrm_module, "BASIS_BLOCK_BYTES", 8 * (K + 1) ** 2 * 100)
    coeffs = rng.standard_normal((37, (K + 1) ** 2))
    texels = cubemap_texel_directions(8)
    got = shrm_module._synthesize_many(coeffs, K, texels, "ducc0")
    want = sh_evaluate(coeffs, texels, backend="ducc0")
    assert got.shape == want.shape == (6, 8, 8, 37)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-11 * np.abs(want).max())
    # above the product's order, the per-function synthesis itself
    monkeypatch.setattr(shrm_module, "BASIS_PRODUCT_MAX_ORDER", K - 1)
    if K > 0:
        assert np.array_equal(shrm_module._synthesize_many(coeffs, K, texels, "ducc0"), want)


@pytest.mark.parametrize(("grey", "expected_channels"), [(True, 3), (False, 6)])
def test_creation_on_a_channel_basis_equals_one_per_band(rng, grey, expected_channels, monkeypatch):
    # erratum E103: 16 bands that are combinations of 3 lightings (a linearly upsampled map) and,
    # when not grey, of 2 BRDFs: the SHRM is made on the 3 or 6 pairs and mixed back per band
    import shrm.shrm as shrm_module

    lightings = rng.standard_normal((3, 25))
    weights = rng.uniform(0.0, 1.0, (16, 3))
    L = weights @ lightings
    brdf = brdf_sh_coefficients(brdf_lafortune, POLY, 4, 2, "reflection")[:1]  # (1, 5, 3, 3)
    if grey:
        rho = brdf
    else:
        t = np.linspace(0.0, 1.0, 16)[:, None, None, None]
        rho = (1.0 - t) * brdf + t * brdf[..., ::-1] * 0.5
    s = shrm_create(L, rho, "reflection", size=4, lambert=0.2)
    assert s.mixing.shape == (16, expected_channels)
    assert s.coeffs.shape == (6, 4, 4, expected_channels, 9)
    monkeypatch.setattr(shrm_module, "CHANNEL_RANK_RTOL", 0.0)  # every band its own channel
    per_band = shrm_create(L, rho, "reflection", size=4, lambert=0.2)
    assert per_band.mixing is None
    assert per_band.coeffs.shape[3] == 16
    normals = cubemap_texel_directions(5).reshape(-1, 3)
    for v in ([0.0, 0.0, 1.0], [0.6, 0.0, 0.8]):
        E, E_band = shrm_extract(s, v), shrm_extract(per_band, v)
        assert E.shape == E_band.shape == (6, 4, 4, 16)
        np.testing.assert_allclose(E, E_band, rtol=0, atol=1e-12 * np.abs(E_band).max())
        got = shade_shrm(s, E, normals, np.array(v))
        want = shade_shrm(per_band, E_band, normals, np.array(v))
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.abs(want).max())


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_polar_rotation_kernel_equals_the_numpy_reference(rng, axis):
    # shrm._kernels._polar_rotate_each_kernel against shrm.shrm._polar_rotate_each's NumPy path,
    # with the angles along each axis, on a non-contiguous array as shrm_create passes it
    from shrm.shrm import _polar_rotate_each

    P = 4
    x = np.moveaxis(rng.standard_normal((3, 5, 7, 2, (P + 1) ** 2)), 0, 2)  # (5, 7, 3, 2, 25)
    shape = [1] * 5
    shape[axis] = x.shape[axis]
    a = rng.uniform(-np.pi, np.pi, x.shape[axis]).reshape(shape)
    want = _polar_rotate_each(x, a, P, "numpy")
    got = _polar_rotate_each(x, a, P, "numba")
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
    np.testing.assert_allclose(want, polar_rotate_reference(x, a, P), rtol=0, atol=1e-12)


def polar_rotate_reference(x, a, P):
    # the public polar_rotate, one angle at a time along the axis
    axis = int(np.flatnonzero(np.array(a.shape) > 1)[0])
    out = np.empty_like(x)
    for j, angle in enumerate(a.reshape(-1)):
        index = (slice(None),) * axis + (j,)
        out[index] = polar_rotate(x[index], np.array([angle]))[0]
    return out

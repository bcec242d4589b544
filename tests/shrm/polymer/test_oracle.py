import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.materials.fresnel import fresnel_dielectric, fresnel_diffuse
from reference.materials.isotropic import ggx_distribution, ggx_smith_G1
from shrm.polymer.kubelka_munk import km_R_infinity, polymer_constituents, polymer_K_S
from shrm.polymer.oracle import (
    ORACLE_KERNELS,
    body_factors,
    coupled_irradiance,
    gloss_alpha,
    gloss_phong_exponent,
    interface_coupling,
    oracle_bsdf,
    polymer_oracle,
    rough_reflection_albedo,
    smooth_plastic_albedo,
)

HDPE = polymer_constituents()


def _views(count):
    """Unit normals all +y and views from normal to near grazing, in the x-y plane."""
    cos = np.linspace(1.0, 0.08, count)
    V = np.stack([np.sqrt(1 - cos**2), cos, np.zeros(count)], axis=-1)
    return np.tile([0.0, 1.0, 0.0], (count, 1)), V, cos


@pytest.mark.parametrize("name", ORACLE_KERNELS.names())
def test_kernel_matches_reference(name, rng):
    method = ORACLE_KERNELS.lookup(name)
    args = method.example_inputs(rng)
    expected = method.reference(*args)
    got = method.compiled(*args)
    for e, g in zip(expected, got, strict=True):
        np.testing.assert_allclose(g, e, rtol=1e-12, atol=1e-14)


def test_smooth_plastic_closed_form_against_quadrature_of_its_brdf():
    # Source: Weidlich & Wilkie 2007 / Mitsuba 3 plastic (nonlinear): the diffuse BRDF
    # (1-F_i)(1-F_o) rho / (pi n^2 (1 - rho F_dr,int)) integrated by Gauss-Legendre in cos theta_i
    # (the closed form uses 1 - F_dr,int = (1 - F_dr,ext)/n^2, which this checks). The integral is
    # in u = cos^2 theta_i, where the integrand is smooth: 400 nodes agree with 800 to 1e-15.
    n, rho = 1.54, np.array([0.0, 0.3, 0.8, 1.0])
    x, w = np.polynomial.legendre.leggauss(400)
    mu = np.sqrt(0.5 * (x + 1))
    F_dr_int = fresnel_diffuse(n, "inside")
    for cos_o in (1.0, 0.5, 0.1):
        F_o = fresnel_dielectric(cos_o, n)
        f = (
            (1 - fresnel_dielectric(mu, n))[:, None]
            * (1 - F_o)
            * rho
            / (np.pi * n**2 * (1 - rho * F_dr_int))
        )
        # d(omega) cos = 2 pi mu d(mu) = pi du
        albedo = F_o + np.pi * 0.5 * (w[:, None] * f).sum(axis=0)
        np.testing.assert_allclose(smooth_plastic_albedo(cos_o, n, rho), albedo, rtol=1e-10)


def test_opaque_smooth_limit_is_smooth_plastic_in_the_white_furnace():
    # Source: smooth_plastic_albedo (closed form). The oracle integrates the body term over the map
    # pixels (midpoint rule): the error falls ~4.5x per doubling of the map (observed 2e-3, 4.5e-4,
    # 1e-4 for H = 16, 32, 64), so it must shrink by at least 3x and end below 1e-4 relative.
    K, S = polymer_K_S(HDPE, 1.0)
    N, V, cos = _views(5)
    rho = km_R_infinity(K, S)
    expected = smooth_plastic_albedo(cos, 1.54, rho)
    errors = []
    for H in (32, 64):
        out = polymer_oracle(N, V, np.ones((H, 2 * H, K.size)), K, S, 1e4, 1.54, gloss=1.0)
        errors.append(np.abs(out.result / expected - 1).max())
    assert errors[1] < errors[0] / 3
    assert errors[1] < 1e-4


def test_rough_specular_lobe_albedo_against_hemisphere_quadrature():
    # Source: the GGX reflection BRDF F D G1 G1 / (4 cos_i cos_o) (Walter et al. 2007 Eqs. (20),
    # (33), (34), reference.materials.isotropic) integrated over the hemisphere by Gauss-Legendre in
    # cos theta_i x uniform phi; the oracle's table comes from visible-normal sampling instead.
    alpha, n = 0.3, 1.5
    x, w = np.polynomial.legendre.leggauss(300)
    mu, w_mu = 0.5 * (x + 1), 0.5 * w
    phi = (np.arange(600) + 0.5) * 2 * np.pi / 600
    M, P = np.meshgrid(mu, phi, indexing="ij")
    wi = np.stack([np.sqrt(1 - M**2) * np.cos(P), np.sqrt(1 - M**2) * np.sin(P), M], -1)
    for cos_o in (0.9, 0.5, 0.2):
        wo = np.array([np.sqrt(1 - cos_o**2), 0.0, cos_o])
        h = wi + wo
        h /= np.linalg.norm(h, axis=-1, keepdims=True)
        f = (
            fresnel_dielectric(h @ wo, n)
            * ggx_distribution(h[..., 2], alpha)
            * ggx_smith_G1(M, alpha)
            * ggx_smith_G1(cos_o, alpha)
            / (4 * M * cos_o)
        )
        quadrature = (w_mu[:, None] * f * M).sum() * 2 * np.pi / 600
        got = rough_reflection_albedo([cos_o], n, alpha)[0]
        assert abs(got - quadrature) < 2e-4 * quadrature


def test_rough_white_furnace_is_the_lobe_albedo_within_its_standard_error():
    # Source: rough_reflection_albedo (deterministic). The Monte Carlo specular under radiance 1 is
    # an unbiased estimate of it: |mean - E| <= 5 SE (SE from the samples).
    N, V, cos = _views(4)
    out = polymer_oracle(
        N, V, np.ones((16, 32, 1)), [0.0], [0.0], 0.0, 1.5, 0.6, tol=0.0, max_samples=4096
    )
    expected = rough_reflection_albedo(np.clip(cos, 1e-6, 1), 1.5, gloss_alpha(0.6))
    se = out.standard_error[:, 0]
    assert np.all(np.abs(out.specular[:, 0] - expected) <= 5 * se)
    assert out.samples == 4096


@pytest.mark.parametrize("gloss", [1.0, 0.6])
def test_energy_at_most_one_and_exactly_one_without_absorption(gloss):
    # Physics: under radiance 1 from every direction a passive layer returns at most 1; with K = 0
    # nothing is absorbed and the reflected plus transmitted light is 1 (up to the midpoint rule's
    # error, < 1e-3 at H = 64 from the convergence test above, and the Monte Carlo 5 SE).
    N, V, _ = _views(4)
    sky = np.ones((64, 128, 1))
    lossless = polymer_oracle(N, V, sky, [0.0], [2.0], 0.5, 1.54, gloss, tol=0.0, max_samples=2048)
    bound = 5 * lossless.standard_error[:, 0] + 1e-3
    assert np.all(np.abs(lossless.result[:, 0] - 1) <= bound)
    K, S = polymer_K_S(HDPE, 0.3)
    lossy = polymer_oracle(N, V, np.ones((64, 128, K.size)), K, S, 1.0, 1.54, gloss, tol=0.0)
    assert np.all(lossy.result <= 1 + 5 * lossy.standard_error + 1e-3)
    assert np.all(lossy.transmission > 0)


def test_bsdf_reflection_is_reciprocal(rng):
    K, S = polymer_K_S(HDPE, 0.2)

    def hemisphere(count):
        d = rng.normal(size=(count, 3))
        d[:, 2] = np.abs(d[:, 2])
        return d / np.linalg.norm(d, axis=-1, keepdims=True)

    wi, wo = hemisphere(50), hemisphere(50)
    N = np.tile([0.0, 0.0, 1.0], (50, 1))
    for gloss in (1.0, 0.5):
        forward = oracle_bsdf(wi, wo, N, K, S, 1.0, 1.54, gloss)
        np.testing.assert_allclose(oracle_bsdf(wo, wi, N, K, S, 1.0, 1.54, gloss), forward, 1e-12)


def test_transmission_is_reciprocal_between_unlike_surfaces():
    # Reciprocity through a slab with a rough front (r_t) and a smooth back (r_b): the flux through
    # it either way, over (1 - k_e) on the side it leaves, must agree: tau/(1-k_t) = tau'/(1-k_b).
    K, S = polymer_K_S(HDPE, 0.2)
    n = 1.54
    front, back = interface_coupling(n, 0.3), interface_coupling(n, 0.0)
    _, tau = body_factors(K, S, 1.0, front.r_i, back.r_i)
    _, tau_reverse = body_factors(K, S, 1.0, back.r_i, front.r_i)
    np.testing.assert_allclose(tau / (1 - front.k_e), tau_reverse / (1 - back.k_e), rtol=1e-12)


def test_smooth_internal_reflectance_identity():
    # Source: the Stokes/reciprocity identity 1 - F_dr,int = (1 - F_dr,ext)/n^2 (e.g. Weidlich &
    # Wilkie 2007), from two independent quadratures in reference.materials.fresnel.
    for n in (1.3, 1.54, 2.0):
        c = interface_coupling(n, 0.0)
        assert abs((1 - c.r_i) - (1 - c.k_e) / n**2) < 1e-10


def test_standard_error_shrinks_as_one_over_sqrt_n():
    # Seeded convergence: quadrupling the samples halves the standard error (ratio of sample
    # standard deviations, averaged over 40 pixels: 2 within +-10 %), and the seed fixes the image.
    from validation.report.sections.polymer import synthetic_environment

    env = synthetic_environment(16)
    N, V, _ = _views(40)
    runs = {
        m: polymer_oracle(N, V, env, 0.0, 0.0, 0.0, 1.54, 0.5, tol=0.0, samples=m, max_samples=m)
        for m in (256, 1024)
    }
    ratio = np.mean(runs[256].standard_error[:, 17] / runs[1024].standard_error[:, 17])
    assert 1.8 < ratio < 2.2
    difference = np.abs(runs[256].specular - runs[1024].specular)
    assert np.all(difference <= 5 * np.hypot(runs[256].standard_error, runs[1024].standard_error))
    again = polymer_oracle(
        N, V, env, 0.0, 0.0, 0.0, 1.54, 0.5, tol=0.0, samples=256, max_samples=256
    )
    np.testing.assert_array_equal(again.specular, runs[256].specular)


@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_rounds_in_bands_of_pixels_give_the_same_image(monkeypatch, backend):
    # the rounds go a band of pixels at a time (bounded memory, an interrupt heard between
    # bands); the bands draw their random numbers in the same order, so the image is the same
    import shrm.polymer.oracle as oracle
    from validation.report.sections.polymer import synthetic_environment

    env = synthetic_environment(16)
    N, V, _ = _views(9)
    settings = {"tol": 0.0, "samples": 32, "max_samples": 64, "backend": backend}
    whole = polymer_oracle(N, V, env, 0.0, 0.0, 0.0, 1.54, 0.5, **settings)
    calls = []
    real_call = oracle._rough_specular_mis_call if backend == "numba" else None
    monkeypatch.setattr(oracle, "SPECULAR_CHUNK_SAMPLES", 4 * 32 + 1)  # bands of 4 pixels
    if real_call is not None:

        def counted(normal, *args):
            calls.append(len(normal))
            return real_call(normal, *args)

        monkeypatch.setattr(oracle, "_rough_specular_mis_call", counted)
    banded = polymer_oracle(N, V, env, 0.0, 0.0, 0.0, 1.54, 0.5, **settings)
    np.testing.assert_array_equal(banded.specular, whole.specular)
    np.testing.assert_array_equal(banded.standard_error, whole.standard_error)
    if real_call is not None:
        assert calls == [4, 4, 1, 4, 4, 1]  # two rounds of 32 pairs, 9 pixels in bands of 4


def test_rounds_stop_at_the_tolerance():
    N, V, _ = _views(6)
    out = polymer_oracle(N, V, np.ones((16, 32, 1)), [0.1], [1.0], 1.0, 1.54, 0.7, tol=0.01)
    assert out.relative_error <= 0.01
    assert out.samples < 4096


def test_gloss_mapping():
    assert gloss_alpha(1.0) == 0.0
    assert gloss_phong_exponent(1.0) == 1000.0
    # Walter et al. 2007: alpha = sqrt(2 / (s + 2))
    assert np.isclose(np.sqrt(2 / (gloss_phong_exponent(0.5) + 2)), gloss_alpha(0.5))


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"n": 1.0}, "refractive index must be > 1"),
        ({"gloss": 1.5}, r"gloss: must be in \[0, 1\]"),
        ({"d": -1.0}, "d \\(thickness, mm\\)"),
        ({"backend": "cuda"}, "backend"),
    ],
)
def test_bad_input(kwargs, match):
    args = {"d": 1.0, "n": 1.54, "gloss": 1.0, **kwargs}
    N, V, _ = _views(2)
    with pytest.raises(SpecrefError, match=match):
        polymer_oracle(N, V, np.ones((4, 8, 1)), [0.1], [1.0], **args)


@pytest.mark.parametrize("alpha", [0.0, 0.3])
@pytest.mark.parametrize("side", [1.0, -1.0])
def test_coupled_irradiance_weights_kernel_matches_the_lookup(rng, alpha, side):
    # the body and transmission sums: the weights c(cos) max(cos, 0) ω made in one kernel pass
    # (shrm.polymer._kernels._coupled_weights_kernel) against Coupling.lookup's array passes

    N = rng.normal(size=(700, 3))
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    radiance = rng.uniform(0.0, 2.0, (16, 32, 5))
    coupling = interface_coupling(1.5, alpha)
    fast = coupled_irradiance(N, radiance, coupling, side, chunk=256)
    readable = coupled_irradiance(N, radiance, coupling, side, chunk=256, backend="numpy")
    np.testing.assert_allclose(fast, readable, rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda c: coupled_irradiance(np.eye(3), np.ones((8, 16, 1)), c, backend="gpu"), "backend"),
        (lambda c: coupled_irradiance(np.eye(3), np.ones((8, 16, 1)), c, chunk=0), "chunk"),
        (lambda c: coupled_irradiance(np.eye(3), np.ones((8, 16, 1)), c, chunk=-4), "chunk"),
        (lambda c: coupled_irradiance(np.eye(3)[:, :2], np.ones((8, 16, 1)), c), r"\(P, 3\)"),
        (lambda c: coupled_irradiance(np.full((1, 3), np.nan), np.ones((8, 16, 1)), c), "normals"),
        (lambda c: coupled_irradiance(np.eye(3), np.ones((8, 9, 1)), c), "radiance"),
        (lambda c: rough_reflection_albedo([0.5], 1.5, 0.3, backend="gpu"), "backend"),
    ],
)
def test_the_coupling_sums_refuse_bad_input_in_one_line(call, message):
    with pytest.raises(SpecrefError, match=message):
        call(interface_coupling(1.5, 0.3))


def _lamp_map(H=32):
    """A dim sky with a small bright lamp (2 × 2 texels at 8000× the sky) and a coloured spot."""
    env = np.full((H, 2 * H, 2), 0.05)
    env[H // 6 : H // 6 + 2, 5 * H // 8 : 5 * H // 8 + 2] = 400.0
    env[5 * H // 8, 5 * H // 4, 1] = 30.0
    return env


def test_environment_sampling_draws_texels_by_their_power():
    # chi-square of 200,000 drawn directions against the texels' shares L̄ Ω / Σ L̄ Ω
    from scipy.stats import chisquare

    from reference.geometry.envmap import latlong_pixel_solid_angles
    from shrm.polymer.oracle import (
        _environment_directions,
        _texel_of,
        environment_sampling,
    )

    env = _lamp_map(8)
    env[0, 3] = 0.0  # a black texel is never drawn
    cdf, pdf = environment_sampling(env)
    omega = latlong_pixel_solid_angles(8, 16).ravel()
    np.testing.assert_allclose((pdf * omega).sum(), 1.0, rtol=1e-12)
    u = np.random.default_rng(4).random((200_000, 2))
    d, k = _environment_directions(cdf, 8, 16, u[:, 0], u[:, 1])
    np.testing.assert_array_equal(_texel_of(d, 8, 16), k)  # each direction lies in its texel
    counts = np.bincount(k, minlength=8 * 16)
    assert counts[3] == 0
    expected = pdf * omega * k.size
    seen = expected > 5
    chi = chisquare(counts[seen], expected[seen] * counts[seen].sum() / expected[seen].sum())
    assert chi.pvalue > 1e-3, chi


def test_the_map_sampled_too_is_unbiased_and_less_noisy_under_a_small_lamp():
    # Source: the visible normals alone (rough_specular_samples), an independent estimator of
    # the same integral: the two agree within 4.5 standard errors at every pixel and band, and
    # sampling the map too has at least twice smaller standard errors at the lamp's pixels.
    from reference.geometry.envmap import latlong_uv_to_direction
    from shrm.polymer.oracle import rough_specular_samples, rough_specular_samples_mis

    rng = np.random.default_rng(3)
    env = _lamp_map()
    N = rng.normal(size=(6, 3))
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    V = N + 0.6 * rng.normal(size=(6, 3))
    V /= np.linalg.norm(V, axis=1, keepdims=True)
    N[0] = V[0] = latlong_uv_to_direction(21 / 64, 6 / 32)  # facing the lamp
    M = 100_000
    for alpha in (0.05, 0.3):
        t_v, t2_v = rough_specular_samples(N, V, env, alpha, 1.5, rng.random((6, M, 2)))
        t_m, t2_m = rough_specular_samples_mis(N, V, env, alpha, 1.5, rng.random((6, M, 4)))
        mean_v, mean_m = t_v / M, t_m / M
        se_v = np.sqrt(np.maximum(t2_v / M - mean_v**2, 0) / M)
        se_m = np.sqrt(np.maximum(t2_m / M - mean_m**2, 0) / M)
        z = (mean_v - mean_m) / np.hypot(se_v, se_m)
        assert np.abs(z).max() < 4.5, (alpha, z)
        assert np.median(se_v / se_m) > 1.5, (alpha, se_v / se_m)

from operator import attrgetter

import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.materials.brdf import BRDF_METHODS, BRDFMethod
from reference.materials.isotropic import (
    brdf_ggx,
    brdf_lafortune,
    brdf_ward_isotropic,
    ggx_distribution,
    ggx_smith_G1,
    isotropic_angles,
    isotropic_directions,
    register_brdf,
)
from reference.registry import Method

Z = np.array([0.0, 0.0, 1.0])
ISOTROPIC = [m for m in BRDF_METHODS.values() if m.isotropic]


def _upper(rng, n):
    v = rng.normal(size=(n, 3))
    v[:, 2] = np.abs(v[:, 2]) + 0.05
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _rotation_z(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def albedo_quadrature(f, theta_i, order, panels=12):
    """Directional albedo ∫ f cos θ_o dω_o of an isotropic BRDF, by composite Gauss–Legendre.

    θ_o ∈ [0, π/2] and Δφ ∈ [0, π] (doubled: f is even in Δφ) are split into ``panels`` equal
    panels plus breakpoints clustered at the mirror direction (θ_o = θ_i, Δφ = π), where glossy
    lobes sit; each panel gets ``order`` Gauss–Legendre nodes.
    """
    x, w = np.polynomial.legendre.leggauss(order)
    near = 0.02 * 2.0 ** np.arange(7)

    def rule(edges):
        edges = np.unique(edges)
        half, mid = np.diff(edges) / 2, (edges[:-1] + edges[1:]) / 2
        return (mid[:, None] + half[:, None] * x).ravel(), (half[:, None] * w).ravel()

    theta_o, w_t = rule(
        np.clip(
            np.concatenate([np.linspace(0, np.pi / 2, panels + 1), theta_i + near, theta_i - near]),
            0.0,
            np.pi / 2,
        )
    )
    phi_d, w_p = rule(np.concatenate([np.linspace(0, np.pi, panels + 1), np.pi - near]))
    wi, wo = isotropic_directions(theta_i, theta_o[:, None], phi_d[None, :])
    values = f(np.broadcast_to(wi, wo.shape), wo)
    weights = 2.0 * (w_t * np.cos(theta_o) * np.sin(theta_o))[:, None] * w_p[None, :]
    return np.einsum("tpc,tp->c", values, weights)


def test_isotropic_angles_round_trip(rng):
    theta_i, theta_o = rng.uniform(0, np.pi / 2, 50), rng.uniform(0, np.pi / 2, 50)
    phi_d = rng.uniform(0, np.pi, 50)
    wi, wo = isotropic_directions(theta_i, theta_o, phi_d)
    R = _rotation_z(0.7)
    got = isotropic_angles(wi @ R.T, wo @ R.T, Z)
    for a, b in zip(got, (theta_i, theta_o, phi_d), strict=True):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-13)
    # Δφ near π stays accurate (atan2, not arccos): a 1e-10 rad offset is resolved.
    wi, wo = isotropic_directions(0.5, 0.5, np.pi - 1e-10)
    assert abs(isotropic_angles(wi, wo, Z)[2] - (np.pi - 1e-10)) < 1e-15


@pytest.mark.parametrize("method", ISOTROPIC, ids=attrgetter("name"))
def test_reciprocity_and_isotropy_with_random_parameters(method, rng):
    wi, wo = _upper(rng, 300), _upper(rng, 300)
    params = method.example_inputs(rng)
    f = method.reference(wi, wo, Z, **params)
    np.testing.assert_allclose(method.reference(wo, wi, Z, **params), f, rtol=1e-12, atol=0)
    # Isotropy: a rotation about the normal and a mirror image across a plane through it.
    R = _rotation_z(rng.uniform(0, 2 * np.pi))
    np.testing.assert_allclose(method.reference(wi @ R.T, wo @ R.T, Z, **params), f, rtol=1e-9)
    M = np.diag([1.0, -1.0, 1.0])
    np.testing.assert_allclose(method.reference(wi @ M, wo @ M, Z, **params), f, rtol=1e-9)
    below = wo * np.array([1.0, 1.0, -1.0])
    assert np.all(method.reference(wi, below, Z, **params) == 0.0)
    assert np.all(f >= 0.0)


def test_ggx_distribution_is_normalized_and_matches_closed_form():
    # ∫ D cos θ_h dω_h = 1 (Walter et al. 2007, Eq. (4)); D(1) = 1/(π α²).
    x, w = np.polynomial.legendre.leggauss(200)
    for alpha in (0.05, 0.3, 1.0):
        mu = 0.5 * (x + 1)
        total = 2 * np.pi * 0.5 * np.sum(w * ggx_distribution(mu, alpha) * mu)
        assert abs(total - 1.0) < 1e-6
        assert ggx_distribution(1.0, alpha) == pytest.approx(1 / (np.pi * alpha**2), rel=1e-14)
    # Source: closed form Λ for GGX, G_1 = 1/(1 + Λ), Λ = (−1 + sqrt(1 + α² tan²θ))/2.
    tan2 = (1 - 0.3**2) / 0.3**2
    assert ggx_smith_G1(0.3, 0.4) == pytest.approx(1 / (1 + (-1 + np.sqrt(1 + 0.16 * tan2)) / 2))


def test_values_against_closed_forms_at_normal_incidence():
    # Ward at normal incidence, θ_h = 0: ρ_s/(4π α²) (Source: Eq. (4), Ward 1992, by hand).
    assert brdf_ward_isotropic(Z, Z, Z, 0.0, 0.5, 0.2)[0] == pytest.approx(0.5 / (4 * np.pi * 0.04))
    # GGX mirror configuration: F_0 D(1) G_1(1)² / 4 = F_0 / (4π α²).
    assert brdf_ggx(Z, Z, Z, 0.0, 0.3, 0.2)[0] == pytest.approx(0.3 / (4 * np.pi * 0.04))
    # Lafortune Phong lobe at the mirror direction: ρ_s (n+2)/(2π).
    assert brdf_lafortune(Z, Z, Z, 0.0, 1.0, -1.0, 1.0, 8.0)[0] == pytest.approx(10 / (2 * np.pi))


def test_shapes_and_bands(rng):
    wi, wo = _upper(rng, 6).reshape(2, 3, 3), _upper(rng, 6).reshape(2, 3, 3)
    assert brdf_ggx(wi, wo, Z, 0.1, 0.04, 0.3).shape == (2, 3, 1)
    assert brdf_ggx(wi, wo, Z, np.full(5, 0.1), 0.04, 0.3).shape == (2, 3, 5)
    assert brdf_ward_isotropic(wi[0, 0], wo[0, 0], Z, 0.1, 0.2, 0.3).shape == (1,)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: brdf_ggx(Z, Z, Z, 0.1, 0.04, 0.0), "ggx: alpha: must be > 0"),
        (lambda: brdf_ggx(Z, Z, Z, 0.1, 1.5, 0.2), r"ggx: F_0: must be in \[0, 1\]"),
        (lambda: brdf_ggx(Z, Z, Z, -0.1, 0.04, 0.2), "ggx: rho_d: must be >= 0"),
        (lambda: brdf_ward_isotropic(Z, Z, Z, np.nan, 0.1, 0.2), "rho_d: must be finite"),
        (lambda: brdf_lafortune(Z, Z, Z, 0.0, 1.0, np.inf, 1.0, 2.0), "C_xy, C_z: must be finite"),
    ],
)
def test_bad_parameters(call, match):
    with pytest.raises(SpecrefError, match=match):
        call()


def test_register_brdf_refuses_a_different_function_under_a_taken_key():
    import dataclasses

    other = dataclasses.replace(BRDF_METHODS.lookup("ggx"), reference=brdf_lafortune)
    with pytest.raises(SpecrefError, match="brdf 'ggx' is registered twice"):
        register_brdf(other)


def test_brdf_registry_takes_brdf_methods_only():
    # A BRDF without a sampler, pdf and defaults cannot be registered: the registry is typed.
    with pytest.raises(SpecrefError, match="brdf registry takes BRDFMethod entries, got Method"):
        register_brdf(Method("new_brdf", brdf_lafortune, None, "none"))
    with pytest.raises(TypeError, match="unexpected keyword argument 'extra'"):
        BRDFMethod("new_brdf", brdf_lafortune, None, "none", extra={"params": {}})


# --- white furnace ---------------------------------------------------------------------------

FURNACE = [
    # (model, params, bound): the albedo bound each model's source claims.
    ("lafortune", {"rho_d": 0.0, "rho_s": 1.0, "C_xy": -1.0, "C_z": 1.0, "n": 10.0}, 1.0),
    ("lafortune", {"rho_d": 0.2, "rho_s": 0.8, "C_xy": -1.0, "C_z": 0.7, "n": 20.0}, 1.0),
    ("lafortune", {"rho_d": 0.0, "rho_s": 1.0, "C_xy": 1.0, "C_z": 1.0, "n": 5.0}, 1.0),
    ("ggx", {"rho_d": 0.0, "F_0": 1.0, "alpha": 0.1}, 1.0),
    ("ggx", {"rho_d": 0.0, "F_0": 1.0, "alpha": 0.5}, 1.0),
    ("ggx", {"rho_d": 0.5, "F_0": 0.04, "alpha": 0.3}, 1.5),
    ("ward_isotropic", {"rho_d": 0.0, "rho_s": 1.0, "alpha": 0.1}, 1.0),
    ("ward_isotropic", {"rho_d": 0.3, "rho_s": 0.7, "alpha": 0.2}, 1.0),
    (
        "effect_pigment",
        {
            "wavelengths_nm": np.array([420.0, 550.0, 680.0]),
            "thickness_nm": 380.0,
            "n_film": 2.0,
            "n_base": 3.2,
            "k_base": 3.3,
            "rho_base": 1.0,
            "alpha": 0.3,
        },
        1.0,
    ),
]


@pytest.mark.parametrize(("name", "params", "bound"), FURNACE)
def test_white_furnace_albedo_within_the_claimed_bound(name, params, bound):
    method = BRDF_METHODS.lookup(name)
    f = lambda a, b: method.reference(a, b, Z, **params)  # noqa: E731
    # Ward claims its normalization only away from grazing incidence (Ward 1992, §4).
    angles = (0.0, 30.0, 60.0) if name == "ward_isotropic" else (0.0, 30.0, 60.0, 80.0, 89.0)
    for theta_deg in angles:
        a1 = albedo_quadrature(f, np.radians(theta_deg), 6)
        a2 = albedo_quadrature(f, np.radians(theta_deg), 12)
        error = np.abs(a2 - a1) + 1e-14  # the error estimate: doubling the order
        assert np.all(a2 <= bound + error), (theta_deg, a2, error)


def test_white_furnace_closed_forms():
    # Source: closed forms. Lambert-like lobe (n = 0): albedo ρ_s at every incidence; the
    # normalized Phong lobe about the normal at normal incidence: exactly ρ_s.
    flat = lambda a, b: brdf_lafortune(a, b, Z, 0.0, 0.6, -1.0, 1.0, 0.0)  # noqa: E731
    phong = lambda a, b: brdf_lafortune(a, b, Z, 0.0, 0.6, -1.0, 1.0, 30.0)  # noqa: E731
    for theta_deg in (0.0, 50.0):
        a1, a2 = (albedo_quadrature(flat, np.radians(theta_deg), k) for k in (6, 12))
        assert abs(a2[0] - 0.6) <= abs(a2[0] - a1[0]) + 1e-13
    a1, a2 = (albedo_quadrature(phong, 0.0, k) for k in (6, 12))
    assert abs(a2[0] - 0.6) <= abs(a2[0] - a1[0]) + 1e-13

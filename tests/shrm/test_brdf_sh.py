import numpy as np
import pytest

from reference.brdf import BRDF_METHODS, brdf_lambert
from reference.errors import SpecrefError
from shrm.brdf_sh import brdf_sh_coefficients, shrm_brdf_parts, shrm_orders
from shrm.lobes import lambert_Lambda_closed_form
from shrm.shrm import shrm_create


def test_lambert_coefficients_match_the_closed_form():
    # Source: A_l closed form (Ramamoorthi & Hanrahan 2001) via shrm.prefilter:
    # ρ_{l00} = (ρ/π) Λ_l sqrt((2l+1)/4π) · sqrt(4π), and nothing for p > 0.
    rho = brdf_sh_coefficients(brdf_lambert, {"rho_d": [0.7]}, 8, 2, "normal")
    l = np.arange(9)
    expected = 0.7 / np.pi * lambert_Lambda_closed_form(8) * np.sqrt((2 * l + 1) / (4 * np.pi))
    np.testing.assert_allclose(rho[0, :, 0, 0], expected * np.sqrt(4 * np.pi), atol=1e-14)
    assert np.abs(rho[0, :, 1:]).max() < 1e-14


def test_brdf_coefficients_converge_with_the_quadrature():
    m = BRDF_METHODS.lookup("ggx")
    params = {"rho_d": 0.1, "F_0": 0.5, "alpha": 0.3}
    a = brdf_sh_coefficients(m.reference, params, 16, 4, "reflection", quadrature=8)
    b = brdf_sh_coefficients(m.reference, params, 16, 4, "reflection", quadrature=16)
    # The error estimate by doubling the order is small against the coefficients.
    assert np.abs(a - b).max() < 1e-4 * np.abs(b).max()


def test_orders_from_the_tolerance_and_bad_orders():
    m = BRDF_METHODS.lookup("ggx")
    rho = brdf_sh_coefficients(m.reference, {"rho_d": 0.1, "F_0": 0.5, "alpha": 0.3}, 24, 10)
    F, P = shrm_orders(rho, 0.05)
    F2, P2 = shrm_orders(rho, 0.01)
    assert F2 >= F
    assert P2 >= P
    assert 2 <= P <= 10
    with pytest.raises(SpecrefError, match=r"SHRM: P = 1 is outside what tol 0.05 allows"):
        shrm_orders(rho, 0.05, P=1)
    with pytest.raises(SpecrefError, match=rf"SHRM: F = {F - 1} is outside what tol 0.05"):
        shrm_orders(rho, 0.05, F=F - 1)
    with pytest.raises(SpecrefError, match=r"SHRM: tol: must be in \(0, 1\)"):
        shrm_orders(rho, 0.0)
    with pytest.raises(SpecrefError, match="unknown SHRM frame 'half'"):
        brdf_sh_coefficients(brdf_lambert, {"rho_d": 1.0}, 2, 2, "half")
    with pytest.raises(SpecrefError, match="lighting has 3 channels but the BRDF has 2"):
        shrm_create(np.ones((3, 16)), np.ones((2, 4, 3, 3)), "normal", size=1)


def test_brdf_parts_split_the_lambertian_part_and_the_grazing_power():
    # Ward (Eq. (4), Ward 1992): rho_d/pi plus a lobe with 1/sqrt(cos θ_i cos θ_o), k = 1/2
    _, expand, lam, k = shrm_brdf_parts(
        "ward_isotropic", {"rho_d": 0.2, "rho_s": 0.5, "alpha": 0.3}
    )
    assert (expand["rho_d"], lam.tolist(), k) == (0.0, [0.2], 0.5)
    _, expand, lam, k = shrm_brdf_parts(
        "ggx", {"rho_d": 0.1, "F_0": 0.5, "alpha": 0.3}, split=False
    )
    assert (expand["rho_d"], lam, k) == (0.1, None, 0.0)
    assert shrm_brdf_parts("effect_pigment", {"alpha": 0.3})[2] is None  # no Lambertian part
    with pytest.raises(SpecrefError, match="SHRM: BRDF 'ward_duer' is not an isotropic 3-D BRDF"):
        shrm_brdf_parts("ward_duer", {})

import numpy as np
import pytest

from reference.errors import SpecrefError
from shrm.lobes import (
    adaptive_order,
    kernel_table,
    lambert_Lambda_closed_form,
    parse_kernel,
    phong_Lambda_gaussian,
)
from validation.studies.oracles import lambert_Lambda_mp, phong_Lambda_mp


def test_lambert_Lambda_closed_form_and_mpmath():
    # Source: Ramamoorthi & Hanrahan 2001, Eq. (8) (closed form) and mpmath quadrature.
    quad = parse_kernel("lambert").Lambda(40)
    np.testing.assert_allclose(quad, lambert_Lambda_closed_form(40), rtol=1e-12, atol=1e-14)
    for l in (0, 1, 2, 4, 10):
        assert abs(quad[l] - lambert_Lambda_mp(l)) <= 1e-12 * max(1.0, abs(quad[l]))


@pytest.mark.parametrize("s", [1.0, 32.0, 7.5])
def test_phong_Lambda_matches_mpmath(s):
    # Source: mpmath quadrature of (s+1) ∫ t^s P_l(t) dt, 50 dps.
    Lam = parse_kernel(f"phong:{s}").Lambda(20)
    for l in (0, 1, 5, 20):
        assert abs(Lam[l] - phong_Lambda_mp(l, s)) <= 1e-12


@pytest.mark.parametrize("s", [300.0, 1e4, 1e5])
def test_narrow_phong_lobes_up_to_the_documented_maximum(s):
    # Source: the closed recurrence of (s+1) ∫_0^1 t^s P_l(t) dt (Bonnet's recurrence integrated
    # by parts): I_0 = 1/(s+1), I_1 = 1/(s+2), I_l = (s-l+2)/(s+l+1) I_{l-2}, in mpmath at 50
    # digits. s = 1e5, the scene files' maximum, used to fail the quadrature's convergence check.
    import mpmath

    mpmath.mp.dps = 50
    L = 511
    I = [1 / mpmath.mpf(s + 1), 1 / mpmath.mpf(s + 2)]
    for l in range(2, L + 1):
        I.append(mpmath.mpf(s - l + 2) / (s + l + 1) * I[l - 2])
    golden = np.array([float((s + 1) * v) for v in I])
    np.testing.assert_allclose(parse_kernel(f"phong:{s:g}").Lambda(L), golden, rtol=0, atol=1e-12)


def test_gaussian_approximation_is_percent_level_off():
    # Source: mpmath Λ_10 of phong:32; exp(-l²/2s) is 11 % too large there (erratum E10).
    exact = parse_kernel("phong:32").Lambda(10)[10]
    assert abs(exact - phong_Lambda_mp(10, 32)) <= 1e-12
    assert phong_Lambda_gaussian(32, 10)[10] / phong_Lambda_mp(10, 32) - 1 == pytest.approx(
        0.113, abs=5e-4
    )


def test_adaptive_order_lambert_is_cheap():
    assert adaptive_order("lambert", 1e-2) < 20 < adaptive_order("phong:256", 1e-2) < 100


def test_table_kernel_matches_phong_lobe(tmp_path):
    # A finely tabulated cos^4 lobe reproduces the analytic Λ_l (quadrature vs closed lobe).
    g = np.linspace(0, np.pi / 2, 2001)
    path = tmp_path / "cos4.csv"
    path.write_text(
        "angle_rad,value\n"
        + "\n".join(f"{float(a)!r},{float(5 / (2 * np.pi) * np.cos(a) ** 4)!r}" for a in g)
    )
    np.testing.assert_allclose(
        kernel_table(path).Lambda(8), parse_kernel("phong:4").Lambda(8), atol=2e-6
    )


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("angle_rad,value\n0,1\n4,1\n", "at most π"),
        ("angle_rad,value\n0.1,1\n1,1\n", "from 0"),
        ("angle_rad,value\n0,1\n1,-1\n", ">= 0"),
        ("angle_rad,value\n0,1\nx,y\n", "row 3"),
    ],
)
def test_kernel_table_bad_input(text, message, tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(SpecrefError, match=message):
        kernel_table(path)


@pytest.mark.parametrize(
    ("spec", "message"),
    [("ward", "unknown kernel"), ("phong", "needs"), ("phong:x", "number"), ("phong:-3", "1e5")],
)
def test_parse_kernel_bad(spec, message):
    with pytest.raises(SpecrefError, match=message):
        parse_kernel(spec)

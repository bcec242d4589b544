"""Tests of validation.studies.oracles: mpmath oracles against closed forms, convergence."""

from __future__ import annotations

import math

import mpmath
import pytest

from validation.studies.oracles import (
    _legendre_recurrence_mp,
    converged_mp,
    lambert_Lambda_mp,
    phong_Lambda_mp,
    sh_basis_mp,
)

C1 = math.sqrt(3 / (4 * math.pi))
C2 = math.sqrt(15 / (16 * math.pi))

# Source: closed forms of the real orthonormal SH with the Condon–Shortley phase (Ramamoorthi &
# Hanrahan 2001, Eq. (3); Sloan, "Stupid SH tricks", 2008, Appendix A 2), θ from the pole.
CLOSED_FORMS = [
    (0, 0, lambda t, p: 1 / math.sqrt(4 * math.pi)),
    (1, 0, lambda t, p: C1 * math.cos(t)),
    (1, 1, lambda t, p: -C1 * math.sin(t) * math.cos(p)),
    (1, -1, lambda t, p: -C1 * math.sin(t) * math.sin(p)),
    (2, 0, lambda t, p: math.sqrt(5 / (16 * math.pi)) * (3 * math.cos(t) ** 2 - 1)),
    (2, 2, lambda t, p: C2 * math.sin(t) ** 2 * math.cos(2 * p)),
    (2, -2, lambda t, p: C2 * math.sin(t) ** 2 * math.sin(2 * p)),
]


@pytest.mark.parametrize(
    ("degree", "m", "closed_form"), CLOSED_FORMS, ids=[f"l{d}-m{m}" for d, m, _ in CLOSED_FORMS]
)
def test_sh_basis_mp_matches_closed_forms(degree, m, closed_form):
    # Points: the pole region (θ = 1e-8), a generic point, and near the south pole.
    for theta, phi in ((1e-8, 0.4), (0.7, 0.3), (math.pi - 1e-3, 5.0)):
        expected = closed_form(theta, phi)
        assert sh_basis_mp(degree, m, theta, phi) == pytest.approx(expected, rel=1e-14, abs=1e-300)


@pytest.mark.parametrize(
    ("degree", "m", "x"), [(3, 1, "0.3"), (5, 2, "-0.7"), (4, 4, "0.1"), (30, 7, "0.45")]
)
def test_legendre_recurrence_fallback_matches_mpmath_legenp(degree, m, x):
    # Source: mpmath.legenp (Ferrers P_l^m with the Condon–Shortley phase), at 50 dps: the
    # fallback of sh_basis_mp for values beyond the hypergeometric sum agrees to 1e-45.
    with mpmath.workdps(50):
        got = _legendre_recurrence_mp(degree, m, mpmath.mpf(x))
        expected = mpmath.legenp(degree, m, mpmath.mpf(x))
        assert abs(got - expected) <= mpmath.mpf("1e-45") * abs(expected)


def test_lambert_Lambda_mp_matches_ramamoorthi_hanrahan():
    # Source: Ramamoorthi & Hanrahan 2001, Eq. (8): Â_0 = π, Â_1 = 2π/3, Â_n = 0 for odd n > 1,
    # and Â_n = 2π (−1)^(n/2−1) / ((n+2)(n−1)) · n! / (2^n ((n/2)!)²) for even n.
    def even(n):
        sign = (-1) ** (n // 2 - 1)
        ratio = math.factorial(n) / (2**n * math.factorial(n // 2) ** 2)
        return 2 * math.pi * sign / ((n + 2) * (n - 1)) * ratio

    assert lambert_Lambda_mp(0) == pytest.approx(math.pi, rel=1e-15)
    assert lambert_Lambda_mp(1) == pytest.approx(2 * math.pi / 3, rel=1e-15)
    for n in (3, 5, 9):
        assert abs(lambert_Lambda_mp(n)) < 1e-30
    for n in (2, 4, 6, 10):
        assert lambert_Lambda_mp(n) == pytest.approx(even(n), rel=1e-14)


@pytest.mark.parametrize("s", [0.0, 1.0, 32.0, 1e4])
def test_phong_Lambda_mp_matches_closed_forms(s):
    # Source: closed form of (s+1) ∫_0^1 t^s P_l(t) dt for P_0 = 1, P_1 = t, P_2 = (3t² − 1)/2:
    # 1, (s+1)/(s+2) and (s+1)/2 · (3/(s+3) − 1/(s+1)). Exponents from 0 to 10⁴ (STYLE.md §10).
    assert phong_Lambda_mp(0, s) == pytest.approx(1.0, rel=1e-14)
    assert phong_Lambda_mp(1, s) == pytest.approx((s + 1) / (s + 2), rel=1e-14)
    assert phong_Lambda_mp(2, s) == pytest.approx(
        (s + 1) / 2 * (3 / (s + 3) - 1 / (s + 1)), rel=1e-13
    )


def test_oracles_leave_the_global_precision_alone():
    before = mpmath.mp.dps
    sh_basis_mp(3, -2, 0.5, 0.5, dps=80)
    lambert_Lambda_mp(4, dps=70)
    phong_Lambda_mp(3, 8.0, dps=60)
    assert mpmath.mp.dps == before


def test_converged_mp_returns_agreeing_values_and_refuses_others():
    assert converged_mp(lambert_Lambda_mp, 2) == pytest.approx(math.pi / 4, rel=1e-15)

    def drifting(x, dps):  # a value that depends on the precision: not converged
        return x + 10.0 ** (-dps // 10)

    with pytest.raises(AssertionError, match="drifting"):
        converged_mp(drifting, 1.0)

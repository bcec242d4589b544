"""High-precision oracles (mpmath) and brute-force references for the tests and the report.

Every ``*_mp`` function computes inside ``mpmath.workdps(dps)`` (never touching the global
precision) and returns ``float(mpmath.nstr(x, 17))``, which rounds correctly. Run each at two
precisions to check convergence (:func:`converged_mp`).
"""

from __future__ import annotations

import mpmath

__all__ = ["converged_mp", "lambert_Lambda_mp", "phong_Lambda_mp", "sh_basis_mp"]


def _legendre_recurrence_mp(l: int, m: int, x):
    """Unnormalized Ferrers P_l^m(x) (Condon–Shortley phase) by the textbook recurrence."""
    p_mm = (-1) ** m * mpmath.fac2(2 * m - 1) * mpmath.sqrt(1 - x * x) ** m
    if l == m:
        return p_mm
    p1, p2 = (2 * m + 1) * x * p_mm, p_mm
    for k in range(m + 2, l + 1):
        p1, p2 = ((2 * k - 1) * x * p1 - (k + m - 1) * p2) / (k - m), p1
    return p1


def sh_basis_mp(l: int, m: int, theta: float, phi: float, dps: int = 50) -> float:
    """Real orthonormal ``Y_lm(θ, φ)`` with the Condon–Shortley phase, in mpmath.

    Eq. (3), Ramamoorthi & Hanrahan 2001 (the real basis) from mpmath's complex harmonics
    ``mpmath.spherharm`` (hypergeometric series): ``Y_l0 = Re Y_l^0``, ``Y_lm = √2 Re Y_l^m``,
    ``Y_l,-m = √2 Im Y_l^m`` (m > 0). Where the hypergeometric sum cannot resolve a value that is
    far below the float64 range, the factorial-normalized recurrence is evaluated in mpmath
    instead (exact factorials, unbounded exponents).

    Examples
    --------
    >>> round(sh_basis_mp(1, 0, 0.0, 0.0), 12)     # sqrt(3/4π)
    0.488602511903
    """
    with mpmath.workdps(dps):
        theta, phi = mpmath.mpf(theta), mpmath.mpf(phi)
        am = abs(m)
        try:
            y = mpmath.spherharm(l, am, theta, phi)
            radial = mpmath.re(y * mpmath.expj(-am * phi))
        except ValueError:
            norm = mpmath.sqrt((2 * l + 1) / (4 * mpmath.pi) / mpmath.rf(l - am + 1, 2 * am))
            radial = norm * _legendre_recurrence_mp(l, am, mpmath.cos(theta))
        if m == 0:
            value = radial
        elif m > 0:
            value = mpmath.sqrt(2) * radial * mpmath.cos(am * phi)
        else:
            value = mpmath.sqrt(2) * radial * mpmath.sin(am * phi)
        return float(mpmath.nstr(value, 17))


def lambert_Lambda_mp(l: int, dps: int = 50) -> float:
    """``Λ_l = 2π ∫_0^1 t P_l(t) dt`` of the clamped cosine, Eq. (8), Ramamoorthi & Hanrahan 2001.

    Examples
    --------
    >>> round(lambert_Lambda_mp(2), 12)      # π/4
    0.785398163397
    """
    with mpmath.workdps(dps):
        value = 2 * mpmath.pi * mpmath.quad(lambda t: t * mpmath.legendre(l, t), [0, 1])
        return float(mpmath.nstr(value, 17))


def phong_Lambda_mp(l: int, s: float, dps: int = 50) -> float:
    """``Λ_l = (s+1) ∫_0^1 t^s P_l(t) dt`` of the normalized Phong lobe.

    Eq. (7), Ramamoorthi & Hanrahan 2001.

    Examples
    --------
    >>> round(phong_Lambda_mp(1, 32), 12)    # (s+1)/(s+2)
    0.970588235294
    """
    with mpmath.workdps(dps):
        s = mpmath.mpf(s)
        value = (s + 1) * mpmath.quad(lambda t: t**s * mpmath.legendre(l, t), [0, 0.5, 1])
        return float(mpmath.nstr(value, 17))


def converged_mp(oracle, *args, low: int = 50, high: int = 80) -> float:
    """Run ``oracle(*args, dps)`` at two precisions; return the value if they agree to 1e-25.

    Raises
    ------
    AssertionError
        If the two precisions disagree (the oracle has not converged).

    Examples
    --------
    >>> round(converged_mp(sh_basis_mp, 2, 1, 0.3, 0.2), 12)
    -0.302301167505
    """
    a = oracle(*args, low)
    with mpmath.workdps(high):
        b = oracle(*args, high)
    if abs(a - b) > 1e-25 + 1e-15 * abs(b):
        raise AssertionError(f"{oracle.__name__}{args}: {a!r} at {low} dps, {b!r} at {high} dps")
    return b

"""Rotation of real SH coefficient vectors by any rotation matrix (real Wigner-D matrices).

SHRMs and view changes rotate lighting and BRDF expansions (§5.5, Herbert et al.; Ramamoorthi &
Hanrahan 2002 rotate BRDF coefficients into each texel's frame). For a rotation R, the rotated
function ``f'(ω) = f(Rᵀ ω)`` has coefficients ``c'_l = D^l(R) c_l`` degree by degree, with
``D^l_{mn} = ∫ Y_lm(ω) Y_ln(Rᵀ ω) dω``.

The blocks D^l are built by the recursion of Ivanic & Ruedenberg (1996, with the 1998 errata): D^1
is R itself in the real l = 1 basis, and each D^l follows from D^{l-1} and D^1 with O(1) work per
entry, without Euler angles or Wigner small-d sums, so it stays accurate to high order (tested at
l = 100 against projecting the rotated map). Ivanic & Ruedenberg write their real harmonics with
the z axis polar and no Condon–Shortley phase; specref's basis (``docs/conventions.md``) has y
polar, φ = 0 towards −z and the phase, so R is first expressed in their axes, ``(x', y', z') =
(−z, x, y)``, and the result is conjugated by the phase signs ``(−1)^m``.

References
----------
- J. Ivanic, K. Ruedenberg, "Rotation Matrices for Real Spherical Harmonics. Direct Determination by
  Recursion", J. Phys. Chem. 100(15), 6342-6347, 1996; Additions and Corrections, J. Phys. Chem. A
  102(45), 9099-9100, 1998.
- R. Ramamoorthi, P. Hanrahan, "Frequency Space Environment Map Rendering", SIGGRAPH 2002.
"""

from __future__ import annotations

import numpy as np

from reference.errors import require

__all__ = ["rotate_coefficients", "rotation_matrix", "sh_rotation_blocks"]

# World axes -> Ivanic & Ruedenberg's axes: x' = -z, y' = x, z' = y (z' polar).
_Q = np.array([[0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


def rotation_matrix(axis, angle: float) -> np.ndarray:
    """The 3×3 rotation by ``angle`` radians about ``axis`` (right-handed, Rodrigues' formula).

    Examples
    --------
    >>> rotation_matrix([0.0, 1.0, 0.0], np.pi / 2).round(6) + 0.0
    array([[ 0.,  0.,  1.],
           [ 0.,  1.,  0.],
           [-1.,  0.,  0.]])
    """
    a = np.asarray(axis, dtype=np.float64)
    a = a / np.linalg.norm(a)
    K = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * (K @ K)


def _check_rotation(R) -> np.ndarray:
    R = np.asarray(R, dtype=np.float64)
    require(R.shape == (3, 3), f"rotation: expected a 3×3 matrix, got shape {R.shape}")
    require(np.isfinite(R).all(), "rotation: matrix must be finite")
    require(
        np.allclose(R @ R.T, np.eye(3), atol=1e-10) and np.linalg.det(R) > 0,
        "rotation: matrix must be orthogonal with determinant +1",
    )
    return R


def _axis_rotation(axis: int, angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    M = np.eye(3)
    M[i, i], M[i, j], M[j, i], M[j, j] = c, -s, s, c
    return M


def _euler_zyz(Rp: np.ndarray) -> tuple[float, float, float]:
    """Angles with ``Rp = Rz(α) Ry(β) Rz(γ)`` (axes of Ivanic & Ruedenberg)."""
    beta = float(np.arctan2(np.hypot(Rp[0, 2], Rp[1, 2]), Rp[2, 2]))
    if np.sin(beta) < 1e-12:
        M = Rp @ _axis_rotation(1, beta).T
        return float(np.arctan2(M[1, 0], M[0, 0])), beta, 0.0
    alpha = float(np.arctan2(Rp[1, 2], Rp[0, 2]))
    gamma = float(np.arctan2(Rp[2, 1], -Rp[2, 0]))
    return alpha, beta, gamma


def _ir_blocks(Rp: np.ndarray, L: int) -> list[np.ndarray]:
    """Ivanic & Ruedenberg's recursion for a rotation given in their axes (no phase)."""
    # D^1 in Ivanic & Ruedenberg's real basis, ordered m = -1, 0, 1 <-> y', z', x'
    axis = [1, 2, 0]
    R1 = Rp[np.ix_(axis, axis)]
    blocks = [np.ones((1, 1)), R1]
    for l in range(2, L + 1):
        blocks.append(_next_block(R1, blocks[-1], l))
    return blocks[: L + 1]


#: Largest tilt (radians, times L/100) handed to the recursion in one step.
_MAX_STEP = 0.1


def sh_rotation_blocks(R, order: int) -> list[np.ndarray]:
    """Real Wigner-D blocks ``D^l`` (l = 0..L) of a rotation, by Ivanic & Ruedenberg's recursion.

    Eq. (8.7), Ivanic & Ruedenberg 1996: ``D^l_{mn} = u U + v V + w W`` from D^{l-1} and D^1 (with
    the 1998 corrections), vectorized over n. The recursion is exact for rotations about the polar
    axis but its rounding errors grow with l times the tilt (1e-9 at l = 100 for a 0.5 rad tilt),
    so R is split into Euler angles ``Rz(α) Ry(β) Rz(γ)`` about the polar axis, and the tilt
    ``Ry(β)`` into ``2^s`` equal steps of at most ``0.1 · 100/L`` radians, whose block is raised to
    the power ``2^s`` by squaring. This keeps D^l orthogonal to about 1e-13 at l = 100.

    Parameters
    ----------
    R : array_like, shape (3, 3)
        A rotation matrix (world axes, y up).
    order : int
        L >= 0.

    Returns
    -------
    list of ndarray
        ``D[l]`` of shape (2l+1, 2l+1), rows and columns indexed by m, n = -l..l.

    Examples
    --------
    >>> D = sh_rotation_blocks(np.eye(3), 2)
    >>> [bool(np.allclose(d, np.eye(d.shape[0]))) for d in D]
    [True, True, True]
    """
    from shrm.sh import check_order

    R = _check_rotation(R)
    L = check_order(order, "rotation order")
    Rp = _Q @ R @ _Q.T
    alpha, beta, gamma = _euler_zyz(Rp)
    step = _MAX_STEP * min(1.0, 100.0 / max(L, 1))
    s = max(0, int(np.ceil(np.log2(max(abs(beta) / step, 1.0)))))
    first = _ir_blocks(_axis_rotation(2, alpha), L)
    tilt = _ir_blocks(_axis_rotation(1, beta / 2**s), L)
    last = _ir_blocks(_axis_rotation(2, gamma), L)
    out = []
    for l in range(L + 1):
        T = tilt[l]
        for _ in range(s):
            T = T @ T
        D = first[l] @ T @ last[l]
        sign = (-1.0) ** np.abs(np.arange(-l, l + 1))
        # Condon–Shortley phase: Y_lm(ours) = (-1)^m Y_lm(Ivanic & Ruedenberg)
        out.append(sign[:, None] * D * sign[None, :])
    return out


def _next_block(R1: np.ndarray, prev: np.ndarray, l: int) -> np.ndarray:
    """D^l from D^{l-1} (``prev``, indices offset by l-1) and D^1 (offset 1)."""
    n = np.arange(-l, l + 1)

    def r1(i, j):
        return R1[i + 1, j + 1]

    def Pm(i, a):
        """P^l_{i,a,n} for all n (Ivanic & Ruedenberg, Table 2), a in [-(l-1), l-1]."""
        row = prev[a + l - 1]
        res = np.empty(2 * l + 1)
        res[1:-1] = r1(i, 0) * row
        res[-1] = r1(i, 1) * row[-1] - r1(i, -1) * row[0]  # n = l
        res[0] = r1(i, 1) * row[0] + r1(i, -1) * row[-1]  # n = -l
        return res

    D = np.zeros((2 * l + 1, 2 * l + 1))
    den = np.where(np.abs(n) < l, (l + n) * (l - n), (2 * l) * (2 * l - 1)).astype(np.float64)
    for m in range(-l, l + 1):
        d = 1.0 if m == 0 else 0.0
        am = abs(m)
        # Eq. (8.7), Ivanic & Ruedenberg 1996: coefficients u, v, w (Table 1)
        u = np.sqrt((l + m) * (l - m) / den)
        v = 0.5 * np.sqrt((1.0 + d) * (l + am - 1.0) * (l + am) / den) * (1.0 - 2.0 * d)
        w = -0.5 * np.sqrt((l - am - 1.0) * (l - am) / den) * (1.0 - d)
        row = np.zeros(2 * l + 1)
        if abs(m) < l:
            row += u * Pm(0, m)
        # V term (Table 2, with the 1998 corrections)
        if m == 0:
            V = Pm(1, 1) + Pm(-1, -1)
        elif m > 0:
            V = Pm(1, m - 1) * np.sqrt(1.0 + (m == 1))
            if m != 1:
                V = V - Pm(-1, -m + 1)
        else:
            V = Pm(-1, -m - 1) * np.sqrt(1.0 + (m == -1))
            if m != -1:
                V = V + Pm(1, m + 1)
        row += v * V
        # W term, zero when w = 0 (m = 0 or |m| >= l - 1)
        if m != 0 and am < l - 1:
            W = Pm(1, m + 1) + Pm(-1, -m - 1) if m > 0 else Pm(1, m - 1) - Pm(-1, -m + 1)
            row += w * W
        D[m + l] = row
    return D


def rotate_coefficients(coeffs, R) -> np.ndarray:
    """Coefficients of the rotated function ``f'(ω) = f(Rᵀ ω)``: ``c'_l = D^l(R) c_l``.

    Eq. (8.7), Ivanic & Ruedenberg 1996 (the blocks), applied degree by degree.

    Parameters
    ----------
    coeffs : array_like, shape (..., (L+1)²)
    R : array_like, shape (3, 3)
        Rotation matrix.

    Returns
    -------
    ndarray, shape (..., (L+1)²)

    Examples
    --------
    >>> c = np.zeros(4); c[3] = 1.0                        # Y_11 ∝ z
    >>> R = rotation_matrix([0.0, 1.0, 0.0], np.pi / 2)    # z -> x
    >>> rotate_coefficients(c, R).round(12) + 0.0          # ∝ x = -Y_1,-1
    array([ 0., -1.,  0.,  0.])
    """
    from shrm.sh import order_of

    c = np.asarray(coeffs, dtype=np.float64)
    L = order_of(c.shape[-1])
    out = np.empty_like(c)
    for l, D in enumerate(sh_rotation_blocks(R, L)):
        s = slice(l * l, (l + 1) * (l + 1))
        out[..., s] = c[..., s] @ D.T
    return out

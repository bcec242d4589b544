"""Spherical-harmonic reflection maps (SHRMs) for isotropic 3-D BRDFs under distant environments.

§5.5, Herbert et al.: "SHRMs are (angular-space) cubemaps which contain for each pixel
SH-coefficients, which encode view-dependent reflection maps [...] typically 64x64x6, and the SH
order typically between 2 and 10. We create global SHRMs, assuming a distant viewer." §5.6: a
reflection map for a viewpoint is "obtained from SHRMs by simply expanding the series for each
coefficients-bearing pixel". specref follows Ramamoorthi & Hanrahan 2002 ("Frequency Space
Environment Map Rendering"), with one change of bookkeeping noted below.

**Reflected radiance.** A texel holds the radiance ``B(n, v)`` leaving a surface whose *index
direction* is ``n`` towards the viewer ``v``:

    B(n, v) = ∫ L(ω) ρ̃(R_nᵀ ω, R_nᵀ v) dω        (the reflection equation, R&H 2002)

where ``R_n`` rotates the local polar axis (+y) to ``n`` and ``ρ̃`` is the *transfer function*, the
BRDF times the cosine. Two frames (R&H 2002, "reparameterization"):

- ``frame="normal"``: ``n`` is the surface normal; ``ρ̃(ω_i, ω_o) = f(ω_i, ω_o; y) max(0, ω_i·y)``.
- ``frame="reflection"``: ``n`` is the reflection vector ``r = 2(N·v)N − v`` of the surface normal
  ``N``; in the local frame the normal is the bisector ``N' = (y + ω_o)/|y + ω_o|`` and
  ``ρ̃(ω_i, ω_o) = f(ω_i, ω_o; N') max(0, ω_i·N')``. Lobes that follow the mirror direction (Phong,
  Ward, GGX) then stay centred on the pole for every view and change little with it, so far fewer
  view coefficients P are needed.

Views below the horizon never reach a texel; there the transfer function is continued evenly
(``ω_o`` mirrored across the tangent plane) so that no jump slows the convergence in P.

**BRDF coefficients.** Isotropy makes ``ρ̃`` depend on ``(θ_i, θ_o, Δφ)`` only, so its double SH
expansion ``ρ̃ = Σ ρ_{lm,pq} Y_lm(ω_i) Y_pq(ω_o)`` has ``ρ_{lm,pq} = δ_mq ρ_{lp|m|}`` with

    ρ_{lpm} = 2π ∫∫∫ ρ̃(θ_i, θ_o, Δφ) cos(mΔφ) λ_lm(cos θ_i) λ_pm(cos θ_o) dcos θ_i dcos θ_o dΔφ

(R&H 2002, the isotropic BRDF coefficients, in specref's real basis; ``λ_lm`` are the normalized
Legendre functions of ``shrm.sh``). :func:`brdf_sh_coefficients` computes it by composite
Gauss–Legendre quadrature in ``cos θ_i`` and ``cos θ_o`` and the trapezoid rule in Δφ. The orders F
(lighting) and P (view) come from a tolerance on the coefficients' tails (:func:`choose_orders`).

**Frequency-space creation** (:func:`shrm_create`). With the lighting ``L_lm`` rotated into the
texel's frame, ``B^loc_pq(n) = Σ_l ρ_{lp|q|} [D(R_nᵀ) L]_lq`` (R&H 2002, the SHRM coefficients).
specref then rotates the view expansion back to world axes, ``B_pq(n) = [D(R_n) B^loc(n)]_pq``: the
texel's own frame (whose twist about ``n`` is arbitrary) drops out, so neighbouring texels can be
filtered bilinearly and extraction needs one set of ``Y_pq(v)`` for the whole map. ``B_pq(n)`` is a
band-limited function of ``n`` (degree ≤ F + P), so specref evaluates it on a Fejér-1 lat-long grid,
where ``R_n = R_y(−φ) R_x(−θ)`` factors into a rotation per row and a rotation about the pole per
column (an FFT over φ), projects it onto SH exactly and synthesizes it at the cube-map texels
(ducc0). Rotations use the Wigner-D blocks of ``shrm.rotation`` through the identity ``R_x(θ) = Qᵀ
R_y(θ) Q`` (Q a fixed quarter turn), so only rotations about the pole vary per row.

**Extraction** (:func:`shrm_extract`, §5.6, Herbert et al.): ``E_v(n) = Σ_pq B_pq(n) Y_pq(v)``,
one dot product per texel. **Rendering** (:func:`render_shrm`): each G-buffer pixel looks up
``E_v`` at its normal (or reflection vector) with seamless bilinear filtering. The oracles are
:func:`shrm_create_angular` (every texel by brute-force integration over the environment pixels,
for a Fejér grid of views, projected onto ``Y_pq``) and :func:`render_bruteforce` (every pixel
integrates BRDF × environment).

References
----------
- F. Herbert, J. Kirkenaer, O. Unter Ecker, "Achieving a Multi-spectral Virtual Reality", 2004.
- R. Ramamoorthi, P. Hanrahan, "Frequency Space Environment Map Rendering", SIGGRAPH 2002.
- R. Ramamoorthi, P. Hanrahan, "A Signal-Processing Framework for Inverse Rendering", SIGGRAPH
  2001.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from reference.errors import require, require_choice
from shrm.rotation import rotation_matrix, sh_rotation_blocks
from shrm.sh import (
    fejer1_weights,
    latlong_ring_angles,
    legendre_table,
    sh_basis,
    sh_degrees_orders,
    sh_evaluate,
)
from shrm.transform import project_latlong

__all__ = [
    "FRAMES",
    "P_RANGE",
    "SHRM",
    "brdf_sh_coefficients",
    "choose_orders",
    "polar_rotate",
    "render_bruteforce",
    "render_shrm",
    "shrm_create",
    "shrm_create_angular",
    "shrm_extract",
    "shrm_orders",
    "transfer_function",
]

#: The index frames of a SHRM (module docstring).
FRAMES = ("normal", "reflection")
#: View orders P that §5.5, Herbert et al. allows: "typically between 2 and 10".
P_RANGE = (2, 10)
_Y = np.array([0.0, 1.0, 0.0])
# A quarter turn about z maps x to y: R_x(a) = Qᵀ R_y(a) Q.
_Q = rotation_matrix([0.0, 0.0, 1.0], np.pi / 2)


def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


def transfer_function(brdf, params: dict, wi, wo, frame: str = "reflection") -> np.ndarray:
    """The transfer function ρ̃ = BRDF × cosine in a texel's local frame (polar axis +y).

    The integrand of the reflection equation (R&H 2002), in the frame of the module
    docstring; views below the horizon are mirrored above it.

    Parameters
    ----------
    brdf : callable
        ``brdf(wi, wo, normal, **params) -> (..., C)`` (the :data:`reference.brdf.BRDF_METHODS`
        convention).
    params : dict
        Its parameters.
    wi, wo : ndarray, shape (..., 3)
        Local incident and view directions (unit).
    frame : {"normal", "reflection"}

    Returns
    -------
    ndarray, shape (..., C)

    Examples
    --------
    >>> from reference.brdf import brdf_lambert
    >>> y = np.array([0.0, 1.0, 0.0])
    >>> transfer_function(brdf_lambert, {"rho_d": [np.pi]}, y, y, "normal")
    array([1.])
    """
    require_choice(frame, FRAMES, "SHRM frame")
    wi, wo = np.asarray(wi, dtype=np.float64), np.asarray(wo, dtype=np.float64)
    if frame == "normal":
        normal = np.broadcast_to(_Y, wo.shape)
        # Views below the horizon never occur: continue ρ̃ evenly across the tangent plane.
        wo = wo * np.where(wo[..., 1:2] < 0.0, np.array([1.0, -1.0, 1.0]), 1.0)
    else:
        # Reflection frame: the surface normal bisects the pole (the reflection vector) and the view
        h = wo + _Y
        normal = h / np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), 1e-300)
    cosine = np.maximum(_dot(wi, normal), 0.0)[..., None]
    return brdf(wi, wo, normal, **params) * cosine


def _panels_gauss(edges, order):
    x, w = np.polynomial.legendre.leggauss(order)
    edges = np.unique(np.asarray(edges, dtype=np.float64))
    half, mid = np.diff(edges) / 2, (edges[:-1] + edges[1:]) / 2
    return (mid[:, None] + half[:, None] * x).ravel(), (half[:, None] * w).ravel()


def _lambda_blocks(order: int, theta: np.ndarray) -> list[np.ndarray]:
    """λ_lm(cos θ) as a list over m of arrays (L+1-m, N) (l = m..L)."""
    table = legendre_table(order, theta)
    starts = np.cumsum([0] + [order + 1 - m for m in range(order + 1)])
    return [table[starts[m] : starts[m + 1]] for m in range(order + 1)]


def brdf_sh_coefficients(
    brdf,
    params: dict,
    F: int,
    P: int,
    frame: str = "reflection",
    quadrature: int = 8,
    n_phi: int = 64,
) -> np.ndarray:
    """The isotropic BRDF's double SH coefficients ``ρ_{lpm}`` (lighting l ≤ F, view p ≤ P).

    R&H 2002, the isotropic BRDF coefficients:
    ``ρ_{lpm} = 2π ∫∫∫ ρ̃ cos(mΔφ) λ_lm(cos θ_i) λ_pm(cos θ_o)`` over
    ``cos θ_i, cos θ_o ∈ [−1, 1]`` and ``Δφ ∈ [0, 2π)``.

    Parameters
    ----------
    brdf : callable
        The BRDF (``BRDF_METHODS`` convention).
    params : dict
        Its parameters.
    F, P : int
        Lighting and view orders, >= 0.
    frame : {"normal", "reflection"}
    quadrature : int
        Gauss–Legendre nodes per panel; θ_i has panels clustered at the pole (0.01·2^k rad) plus
        ``max(8, F/2)`` uniform ones, θ_o ``max(8, P)`` uniform ones. Doubling it estimates the
        error.
    n_phi : int
        Trapezoid nodes in Δφ (exact for the cos(mΔφ) moments of trigonometric polynomials of
        degree < n_phi − m).

    Returns
    -------
    ndarray, shape (C, F+1, P+1, min(F, P)+1)
        ``rho[c, l, p, m]``, zero where ``m > min(l, p)``.

    Examples
    --------
    >>> from reference.brdf import brdf_lambert
    >>> rho = brdf_sh_coefficients(brdf_lambert, {"rho_d": [1.0]}, 2, 2, "normal")
    >>> rho.shape, round(float(rho[0, 0, 0, 0]), 4)   # ∫∫ ρ̃ Y00 Y00 = (1/4π) · 1 · 4π
    ((1, 3, 3, 3), 1.0)
    """
    require_choice(frame, FRAMES, "SHRM frame")
    require(isinstance(F, int) and F >= 0, f"SHRM: F: must be an integer >= 0, got {F!r}")
    require(isinstance(P, int) and P >= 0, f"SHRM: P: must be an integer >= 0, got {P!r}")
    M = min(F, P)
    near = 0.01 * 2.0 ** np.arange(8)
    theta_i, w_i = _panels_gauss(
        np.clip(np.concatenate([np.linspace(0, np.pi, max(8, F // 2) + 1), near]), 0, np.pi),
        quadrature,
    )
    theta_o, w_o = _panels_gauss(np.linspace(0, np.pi, max(8, P) + 1), quadrature)
    # The panels are in θ; dcos θ = sin θ dθ
    w_i, w_o = w_i * np.sin(theta_i), w_o * np.sin(theta_o)
    phi = 2.0 * np.pi * np.arange(n_phi) / n_phi
    lam_i, lam_o = _lambda_blocks(F, theta_i), _lambda_blocks(P, theta_o)
    cos_m_phi = np.cos(np.arange(M + 1)[:, None] * phi[None, :]) * (2.0 * np.pi / n_phi)
    s_i, s_o = np.sin(theta_i), np.sin(theta_o)
    # Local directions (y polar): ω_o at azimuth 0, ω_i at azimuth Δφ
    wo_dir = np.stack([np.zeros_like(s_o), np.cos(theta_o), -s_o], axis=-1)
    rho = None
    for a, wo_a in enumerate(wo_dir):
        wi_dir = np.stack(
            [
                s_i[:, None] * np.sin(phi)[None, :],
                np.broadcast_to(np.cos(theta_i)[:, None], (theta_i.size, n_phi)),
                -s_i[:, None] * np.cos(phi)[None, :],
            ],
            axis=-1,
        )
        values = transfer_function(brdf, params, wi_dir, np.broadcast_to(wo_a, wi_dir.shape), frame)
        if rho is None:
            rho = np.zeros((values.shape[-1], F + 1, P + 1, M + 1))
        # R&H 2002, the isotropic BRDF coefficients: the Δφ moments, then the θ_i and θ_o sums
        moments = np.einsum("ijc,mj->mic", values, cos_m_phi) * w_i[None, :, None]
        for m in range(M + 1):
            # 2π ∫ λ_lm(θ_i) λ_pm(θ_o) · moment
            part = 2.0 * np.pi * (lam_i[m] @ moments[m]) * w_o[a]  # (F+1-m, C)
            rho[:, m:, m:, m] += part.T[:, :, None] * lam_o[m][None, None, :, a]
    return rho


def choose_orders(rho: np.ndarray, tol: float) -> tuple[int, int]:
    """The smallest orders (F, P) whose coefficient tails are below ``tol`` (relative, L2).

    R&H 2002, the isotropic BRDF coefficients.
    ``tail_F = sqrt(Σ_{l>F} |ρ_l|² / Σ |ρ|²)`` with
    ``|ρ_l|²`` summed over p, m (twice for m > 0, which stands for ±m) and bands; likewise for P.
    P is at least 2 and both at most what ``rho`` holds.

    Parameters
    ----------
    rho : ndarray, shape (C, F_max+1, P_max+1, M+1)
    tol : float
        In (0, 1).

    Returns
    -------
    F, P : int

    Raises
    ------
    SpecrefError
        ``tol`` outside (0, 1), or no order within ``rho`` reaches it.

    Examples
    --------
    >>> rho = np.zeros((1, 5, 4, 4)); rho[0, :, 0, 0] = [1.0, 0.5, 0.1, 0.001, 0.0]
    >>> choose_orders(rho, 0.01)
    (2, 2)
    """
    require(0.0 < tol < 1.0, f"SHRM: tol: must be in (0, 1), got {tol!r}")
    weight = np.where(np.arange(rho.shape[3]) > 0, 2.0, 1.0)
    energy = rho**2 * weight
    total = energy.sum()
    require(total > 0, "SHRM: the BRDF's transfer function is zero everywhere")
    orders = []
    for axis, name in ((1, "F"), (2, "P")):
        per = energy.sum(axis=tuple(a for a in range(4) if a != axis))
        tail = np.sqrt(np.maximum(total - np.cumsum(per), 0.0) / total)
        below = np.nonzero(tail <= tol)[0]
        require(
            below.size > 0,
            f"SHRM: no {name} up to {per.size - 1} reaches tol {tol:g} (tail {tail[-1]:.3g}); "
            "raise the tolerance or the maximum order",
        )
        orders.append(int(below[0]))
    return orders[0], max(orders[1], P_RANGE[0])


def shrm_orders(rho: np.ndarray, tol: float, F: int | None = None, P: int | None = None):
    """Orders (F, P) for a tolerance, or a check that requested orders meet it.

    R&H 2002, the isotropic BRDF coefficients (their tails, :func:`choose_orders`). P must lie in
    :data:`P_RANGE` (§5.5, Herbert et al.: "between 2 and 10") and neither order may be below what
    ``tol`` requires or above what ``rho`` holds.

    Parameters
    ----------
    rho : ndarray, shape (C, F_max+1, P_max+1, M+1)
    tol : float
    F, P : int, optional
        Requested orders; default the smallest that meet ``tol``.

    Returns
    -------
    F, P : int

    Raises
    ------
    SpecrefError
        A requested order outside what the tolerance allows.

    Examples
    --------
    >>> rho = np.zeros((1, 5, 4, 4)); rho[0, :, 0, 0] = [1.0, 0.5, 0.1, 0.001, 0.0]
    >>> shrm_orders(rho, 0.01, P=3)
    (2, 3)
    >>> shrm_orders(rho, 0.01, F=1)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: SHRM: F = 1 is outside what tol 0.01 allows: [2, 4]
    """
    F_min, P_min = choose_orders(rho, tol)
    F_max, P_max = rho.shape[1] - 1, min(rho.shape[2] - 1, P_RANGE[1])
    for name, value, low, high in (("F", F, F_min, F_max), ("P", P, P_min, P_max)):
        if value is not None:
            require(
                isinstance(value, int | np.integer) and low <= value <= high,
                f"SHRM: {name} = {value} is outside what tol {tol:g} allows: [{low}, {high}]",
            )
    require(P_min <= P_max, f"SHRM: tol {tol:g} needs P = {P_min} > {P_max} (§5.5 allows 2-10)")
    return (F_min if F is None else int(F)), (P_min if P is None else int(P))


def polar_rotate(coeffs, angles) -> np.ndarray:
    """Rotate SH coefficients about the polar axis (+y) by many angles: ``D(R_y(a)) c``.

    Ivanic & Ruedenberg's real Wigner-D for a rotation about the polar axis (the
    ``shrm.rotation`` blocks): ``c'_m = cos(ma) c_m + sin(ma) c_{−m}``,
    ``c'_{−m} = cos(ma) c_{−m} − sin(ma) c_m`` (m > 0).

    Parameters
    ----------
    coeffs : ndarray, shape (..., (L+1)²)
    angles : ndarray, shape (K,)
        Radians.

    Returns
    -------
    ndarray, shape (K, ..., (L+1)²)

    Examples
    --------
    >>> c = np.zeros(4); c[3] = 1.0
    >>> polar_rotate(c, np.array([np.pi / 2])).round(12) + 0.0
    array([[ 0., -1.,  0.,  0.]])
    """
    c = np.asarray(coeffs, dtype=np.float64)
    L = round(np.sqrt(c.shape[-1])) - 1
    l, m = sh_degrees_orders(L)
    partner = l * l + l - m
    a = np.asarray(angles, dtype=np.float64).reshape((-1,) + (1,) * c.ndim)
    cos_ma, sin_ma = np.cos(np.abs(m) * a), np.sin(np.abs(m) * a)
    sign = np.sign(m)  # +: c'_m gets + sin c_{-m}; −: c'_{-m} gets − sin c_m
    return cos_ma * c + sign * sin_ma * c[..., partner]


@functools.lru_cache(maxsize=8)
def _quarter_turn_blocks(order: int) -> tuple[np.ndarray, ...]:
    return tuple(sh_rotation_blocks(_Q, order))


def _block_apply(blocks, c, transpose=False):
    """Apply per-degree blocks to coefficients (..., (L+1)²)."""
    out = np.empty_like(c)
    for l, D in enumerate(blocks):
        s = slice(l * l, (l + 1) * (l + 1))
        out[..., s] = c[..., s] @ (D if transpose else D.T)
    return out


def _block_diag(blocks) -> np.ndarray:
    from scipy.linalg import block_diag

    return block_diag(*blocks)


def _world_view_rotation(B_local, theta, phi, P):
    """``D(R_n) B^loc`` for R_n = R_y(−φ) R_x(−θ) = R_y(−φ) Qᵀ R_y(−θ) Q, per row θ and column φ."""
    DQ = _block_diag(_quarter_turn_blocks(P))
    x = B_local @ DQ.T  # D(Q)
    for j in range(x.shape[0]):
        x[j] = polar_rotate(x[j], np.array([-theta[j]]))[0]  # Y(−θ_j)
    x = x @ DQ  # D(Qᵀ) = D(Q)ᵀ
    for k in range(x.shape[1]):
        x[:, k] = polar_rotate(x[:, k], np.array([-phi[k]]))[0]  # Y(−φ_k)
    return x


@dataclass(frozen=True, eq=False)
class SHRM:
    """A global SHRM: per cube-map texel, the coefficients B_pq of reflected radiance over views.

    Attributes
    ----------
    coeffs : ndarray, shape (6, S, S, C, (P+1)²)
        ``B_pq(n)`` in world axes (module docstring), per band or channel.
    frame : str
        ``"normal"`` or ``"reflection"``: what the texel direction indexes.
    F, P : int
        Lighting and view orders.
    """

    coeffs: np.ndarray
    frame: str
    F: int
    P: int

    @property
    def size(self) -> int:
        """Cube face size S."""
        return self.coeffs.shape[1]


def shrm_create(
    env_coeffs, rho: np.ndarray, frame: str = "reflection", size: int = 64, backend="ducc0"
) -> SHRM:
    """Create a SHRM in frequency space from lighting and BRDF coefficients.

    R&H 2002, the SHRM coefficients: ``B^loc_pq(n) = Σ_l ρ_{lp|q|} [D(R_nᵀ) L]_lq``, rotated to
    world axes,
    evaluated on a Fejér-1 grid (an FFT over φ per row), projected onto SH of degree F + P and
    synthesized at the cube-map texels (module docstring).

    Parameters
    ----------
    env_coeffs : ndarray, shape (C, (F'+1)²)
        Lighting coefficients (``shrm.sh.project_latlong``), F' >= F (truncated to F).
    rho : ndarray, shape (C, F+1, P+1, M+1)
        BRDF coefficients from :func:`brdf_sh_coefficients` (same bands C).
    frame : {"normal", "reflection"}
        The frame ``rho`` was computed in.
    size : int
        Cube face size S (default 64, §5.5, Herbert et al.).
    backend : {"ducc0", "numpy", "numba"}
        SH projection and synthesis path.

    Returns
    -------
    SHRM

    Examples
    --------
    >>> from reference.brdf import brdf_lambert
    >>> rho = brdf_sh_coefficients(brdf_lambert, {"rho_d": [1.0]}, 4, 2, "normal")
    >>> env = np.zeros((1, 25)); env[0, 0] = np.sqrt(4 * np.pi)        # L = 1 everywhere
    >>> s = shrm_create(env, rho, "normal", size=2)
    >>> float(shrm_extract(s, [0.0, 0.0, 1.0]).max()).__round__(6)     # white furnace: ρ_d = 1
    1.0
    """
    require_choice(frame, FRAMES, "SHRM frame")
    C, F1, P1, _ = rho.shape
    F, P = F1 - 1, P1 - 1
    L = np.atleast_2d(np.asarray(env_coeffs, dtype=np.float64))
    if C == 1 and L.shape[0] > 1:  # a grey BRDF under a coloured environment
        rho, C = np.broadcast_to(rho, (L.shape[0], *rho.shape[1:])), L.shape[0]
    require(L.shape[0] == C, f"SHRM: lighting has {L.shape[0]} channels but the BRDF has {C}")
    require(L.shape[1] >= F1 * F1, f"SHRM: lighting order is below F = {F}")
    L = L[:, : F1 * F1]
    K = F + P
    H = 2 * K + 2
    W = 2 * H
    theta = latlong_ring_angles(H)
    phi = 2.0 * np.pi * (np.arange(W) + 0.5) / W
    # D(R_nᵀ) L = D(Qᵀ) Y(θ) D(Q) Y(φ) L. The part per row, M_j = D(Qᵀ) Y(θ_j) D(Q), meets
    # Y(φ) L = Σ_m' cos(m'φ) L^c_m' + sin(m'φ) L^s_m' (polar_rotate): per row two sets of Fourier
    # terms are contracted with ρ, and the φ dependence is a sum over m' for every column.
    blocks = _quarter_turn_blocks(F)
    qmax = P
    A_cos = np.zeros((H, C, P1, 2 * qmax + 1, F1))
    A_sin = np.zeros((H, C, P1, 2 * qmax + 1, F1))
    for l in range(F1):
        DQ = blocks[l]
        ms = np.arange(-l, l + 1)
        qs = np.arange(-min(l, qmax), min(l, qmax) + 1)
        # Y(θ_j) D(Q) for every row j (polar_rotate on the rows of D(Q)), then the rows q of
        # M_j = D(Qᵀ) Y(θ_j) D(Q)
        cos_t = np.cos(np.abs(ms)[None, :] * theta[:, None])[..., None]
        sin_t = np.sin(np.abs(ms)[None, :] * theta[:, None])[..., None]
        YD = cos_t * DQ[None] + np.sign(ms)[None, :, None] * sin_t * DQ[None, ::-1]
        rows = np.einsum("aq,jab->jqb", DQ[:, qs + l], YD)  # (H, nq, 2l+1)
        c_l = L[:, l * l : (l + 1) * (l + 1)]  # (C, 2l+1), index m' + l
        mp = np.arange(1, l + 1)
        # Fourier terms of Y(φ)L: cos part m' = 0: M[q,0] c_0; m' > 0: M[q,m'] c_m' + M[q,-m'] c_-m'
        # and sin part m' > 0: M[q,m'] c_-m' - M[q,-m'] c_m'
        u = np.zeros((H, C, qs.size, l + 1))
        v = np.zeros((H, C, qs.size, l + 1))
        u[..., 0] = rows[:, None, :, l] * c_l[None, :, None, l]
        if l > 0:
            u[..., 1:] = (
                rows[:, None, :, l + mp] * c_l[None, :, None, l + mp]
                + rows[:, None, :, l - mp] * c_l[None, :, None, l - mp]
            )
            v[..., 1:] = (
                rows[:, None, :, l + mp] * c_l[None, :, None, l - mp]
                - rows[:, None, :, l - mp] * c_l[None, :, None, l + mp]
            )
        # R&H 2002, the SHRM coefficients: Σ_l ρ_{lp|q|} (D(R_nᵀ) L)_lq
        r = rho[:, l][:, :, np.abs(qs)]  # (C, P+1, nq)
        A_cos[:, :, :, qs + qmax, : l + 1] += r[None, ..., None] * u[:, :, None]
        A_sin[:, :, :, qs + qmax, : l + 1] += r[None, ..., None] * v[:, :, None]
    cos_phi = np.cos(np.arange(F1)[None, :] * phi[:, None])  # (W, F+1)
    sin_phi = np.sin(np.arange(F1)[None, :] * phi[:, None])
    B_loc = np.zeros((H, W, C, P1 * P1))
    for j in range(H):
        # Σ_m' cos(m'φ_k) A_cos + sin(m'φ_k) A_sin, for every column k
        values = np.einsum("cpqm,km->kcpq", A_cos[j], cos_phi) + np.einsum(
            "cpqm,km->kcpq", A_sin[j], sin_phi
        )
        for p in range(P1):
            qs = np.arange(-p, p + 1)
            B_loc[j, :, :, p * p : (p + 1) * (p + 1)] = values[:, :, p, qs + qmax]
    # Rotate the view expansion to world axes, D(R_n) B^loc
    B_world = _world_view_rotation(B_loc, theta, phi, P)
    # B_pq(n) is band-limited to F + P: project exactly (Fejér-1), synthesize at the texels
    from reference.cubemap import cubemap_texel_directions

    grid = B_world.reshape(H, W, C * P1 * P1)
    coeffs_n = project_latlong(grid, K, backend=backend, where="SHRM")
    values = sh_evaluate(coeffs_n, cubemap_texel_directions(size), backend=backend)
    return SHRM(values.reshape(6, size, size, C, P1 * P1), frame, F, P)


def shrm_extract(shrm: SHRM, view) -> np.ndarray:
    """A reflection map for one (distant) viewpoint: ``E_v(n) = Σ_pq B_pq(n) Y_pq(v)``.

    §5.6, Herbert et al.; R&H 2002, SHRM evaluation.

    Parameters
    ----------
    shrm : SHRM
    view : array_like, shape (3,)
        Unit direction from the surface towards the viewer.

    Returns
    -------
    ndarray, shape (6, S, S, C)
        Reflected radiance per texel and band.

    Examples
    --------
    >>> s = SHRM(np.ones((6, 1, 1, 1, 9)), "normal", 2, 2)
    >>> shrm_extract(s, [0.0, 1.0, 0.0]).shape
    (6, 1, 1, 1)
    """
    v = np.asarray(view, dtype=np.float64)
    v = v / np.linalg.norm(v)
    Y = sh_basis(shrm.P, v[None])[0]
    # §5.6, Herbert et al.: expand the series with Y_pq indexed by the viewpoint
    return shrm.coeffs @ Y


def _index_directions(frame: str, normal, view) -> np.ndarray:
    """The texel direction a pixel reads: its normal, or the reflection of the view about it."""
    if frame == "normal":
        return normal
    # R&H 2002, reparameterization: r = 2 (N·v) N − v
    return 2.0 * _dot(normal, view)[..., None] * normal - view


def render_shrm(gbuffer, shrm: SHRM, view, material_id: int = 0, E=None) -> np.ndarray:
    """Deferred rendering of one material through the G-buffer with a SHRM (distant viewer).

    §5.6, Herbert et al.: extract the reflection map for the viewpoint, then look it up per pixel
    at the normal (or reflection vector), with seamless bilinear filtering.

    Parameters
    ----------
    gbuffer : reference.gbuffer.GBuffer
        Visible surfaces.
    shrm : SHRM
    view : array_like, shape (3,)
        Direction towards the (distant) viewer.
    material_id : int
        The pixels to shade.
    E : ndarray, optional
        An already extracted map (:func:`shrm_extract`) for ``view``.

    Returns
    -------
    ndarray, shape (H, W, C)
        Radiance per band (0 where the material is not visible).

    Examples
    --------
    >>> from reference.gbuffer import empty_gbuffer
    >>> s = SHRM(np.ones((6, 1, 1, 1, 9)), "normal", 2, 2)
    >>> render_shrm(empty_gbuffer(2, 2), s, [0.0, 0.0, 1.0]).shape
    (2, 2, 1)
    """
    from reference.cubemap import cubemap_lookup_bilinear

    v = np.asarray(view, dtype=np.float64)
    v = v / np.linalg.norm(v)
    E = shrm_extract(shrm, v) if E is None else E
    H, W = gbuffer.shape
    out = np.zeros((H, W, E.shape[-1]))
    sel = gbuffer.mask & (gbuffer.material_id == material_id)
    if sel.any():
        n = gbuffer.normal[sel]
        out[sel] = cubemap_lookup_bilinear(E, _index_directions(shrm.frame, n, v))
    return out


def _env_quadrature(image):
    """Pixel directions and Fejér-1 × uniform-φ weights of a lat-long map (as project_latlong)."""
    from reference.envmap import latlong_pixel_directions

    H, W = image.shape[:2]
    d = latlong_pixel_directions(H, W).reshape(-1, 3)
    w = np.repeat(fejer1_weights(H), W) * (2.0 * np.pi / W)
    return d, w, np.asarray(image, dtype=np.float64).reshape(H * W, -1)


def _reflected_bruteforce(brdf, params, frame, index, views, env, chunk=4096):
    """∫ L(ω) ρ̃ dω by the sum over environment pixels, for pairs (index direction, view)."""
    d, w, Lpx = env
    out = np.zeros((index.shape[0], Lpx.shape[1]))
    for a in range(index.shape[0]):
        n, v = index[a], views[a]
        if frame == "normal":
            normal = n
            v = v if _dot(v, n) >= 0 else v - 2.0 * _dot(v, n) * n
        else:
            h = n + v
            normal = h / max(np.linalg.norm(h), 1e-300)
        for s in range(0, d.shape[0], chunk):
            wi = d[s : s + chunk]
            cosine = np.maximum(wi @ normal, 0.0)
            f = brdf(wi, np.broadcast_to(v, wi.shape), normal, **params)
            out[a] += (f * (Lpx[s : s + chunk] * (cosine * w[s : s + chunk])[:, None])).sum(0)
    return out


def shrm_create_angular(image, brdf, params: dict, P: int, frame: str = "reflection", size=8):
    """The oracle: SHRM texels by brute-force angular integration, projected onto ``Y_pq``.

    The reflection equation (R&H 2002) at every texel n and every view v of a Fejér-1 grid of
    ``2P + 2`` rows:
    ``B(n, v) = Σ_pixels L(ω) ρ̃ w`` (the environment's own quadrature weights), then
    ``B_pq(n) = ∫ B(n, v) Y_pq(v) dv`` (``shrm.sh.project_latlong``). Quadratic per texel.

    Parameters
    ----------
    image : ndarray, shape (H, 2H, C)
        Linear radiance of the environment.
    brdf, params
        The BRDF.
    P : int
        View order.
    frame : {"normal", "reflection"}
    size : int
        Cube face size (keep it small: the cost is texels × views × pixels).

    Returns
    -------
    SHRM
        With ``F = -1`` (no lighting truncation).

    Examples
    --------
    >>> from reference.brdf import brdf_lambert
    >>> s = shrm_create_angular(np.ones((4, 8, 1)), brdf_lambert, {"rho_d": [1.0]}, 2, "normal", 1)
    >>> float(shrm_extract(s, [0.0, 0.0, 1.0])[4, 0, 0, 0]).__round__(6)   # facing +z: ρ_d
    1.0
    """
    from reference.cubemap import cubemap_texel_directions
    from reference.envmap import latlong_pixel_directions

    require_choice(frame, FRAMES, "SHRM frame")
    env = _env_quadrature(image)
    Hv = 2 * P + 2
    views = latlong_pixel_directions(Hv, 2 * Hv).reshape(-1, 3)
    texels = cubemap_texel_directions(size).reshape(-1, 3)
    C = env[2].shape[1]
    out = np.empty((texels.shape[0], C, (P + 1) ** 2))
    for t, n in enumerate(texels):
        B = _reflected_bruteforce(brdf, params, frame, np.broadcast_to(n, views.shape), views, env)
        out[t] = project_latlong(B.reshape(Hv, 2 * Hv, C), P, where="SHRM oracle")
    return SHRM(out.reshape(6, size, size, C, (P + 1) ** 2), frame, -1, P)


def render_bruteforce(gbuffer, image, brdf, params: dict, view, material_id: int = 0):
    """The per-pixel oracle: every pixel integrates BRDF × environment over all map pixels.

    The reflection equation (R&H 2002), with a distant viewer ``v`` and the environment's
    Fejér-1 × uniform-φ quadrature.

    Parameters
    ----------
    gbuffer : reference.gbuffer.GBuffer
    image : ndarray, shape (H, 2H, C)
        Environment radiance.
    brdf, params
        The BRDF.
    view : array_like, shape (3,)
        Direction towards the viewer.
    material_id : int

    Returns
    -------
    ndarray, shape (H_img, W_img, C)

    Examples
    --------
    >>> from reference.brdf import brdf_lambert
    >>> from reference.gbuffer import empty_gbuffer
    >>> g = empty_gbuffer(1, 1)
    >>> g.mask[0, 0] = True; g.material_id[0, 0] = 0; g.normal[0, 0] = [0.0, 0.0, 1.0]
    >>> render_bruteforce(g, np.ones((8, 16, 1)), brdf_lambert, {"rho_d": [0.5]},
    ...                   [0.0, 0.0, 1.0]).round(4)
    array([[[0.5]]])
    """
    v = np.asarray(view, dtype=np.float64)
    v = v / np.linalg.norm(v)
    env = _env_quadrature(image)
    H, W = gbuffer.shape
    out = np.zeros((H, W, env[2].shape[1]))
    sel = gbuffer.mask & (gbuffer.material_id == material_id)
    normals = gbuffer.normal[sel]
    out[sel] = _reflected_bruteforce(
        brdf, params, "normal", normals, np.broadcast_to(v, normals.shape), env
    )
    return out

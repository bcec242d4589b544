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

Views below the horizon never reach a texel. The projection over all views continues the transfer
function evenly there (``ω_o`` mirrored across the tangent plane), so that no jump slows the
convergence in P; in the normal frame the default *hemisphere fit* (:mod:`shrm.brdf_sh`) instead
fits the view dependence to the seen views by regularized weighted least squares, which also
avoids the kink of the even continuation at the horizon (the grazing error of R&H 2002's
projection). Creation, extraction and shading are the same for both.

**BRDF coefficients.** Isotropy makes ``ρ̃`` depend on ``(θ_i, θ_o, Δφ)`` only, so its double SH
expansion ``ρ̃ = Σ ρ_{lm,pq} Y_lm(ω_i) Y_pq(ω_o)`` has ``ρ_{lm,pq} = δ_mq ρ_{lp|m|}`` with

    ρ_{lpm} = 2π ∫∫∫ ρ̃(θ_i, θ_o, Δφ) cos(mΔφ) λ_lm(cos θ_i) λ_pm(cos θ_o) dcos θ_i dcos θ_o dΔφ

(R&H 2002, the isotropic BRDF coefficients, in specref's real basis; ``λ_lm`` are the normalized
Legendre functions of ``shrm.sh``). :func:`shrm.brdf_sh.brdf_sh_coefficients` computes it by
composite Gauss–Legendre quadrature in ``cos θ_i`` and ``cos θ_o`` and the trapezoid rule in Δφ.
The orders F (lighting) and P (view) come from a tolerance on the coefficients' tails
(:func:`shrm.brdf_sh.choose_orders`).

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
from shrm.brdf_sh import (
    FRAMES,
)
from shrm.rotation import rotation_matrix, sh_rotation_blocks
from shrm.sh import (
    latlong_ring_angles,
    sh_basis,
    sh_degrees_orders,
    sh_evaluate,
)
from shrm.transform import project_latlong

__all__ = [
    "SHRM",
    "polar_rotate",
    "render_shrm",
    "shade_shrm",
    "shrm_create",
    "shrm_extract",
]

_Y = np.array([0.0, 1.0, 0.0])
# A quarter turn about z maps x to y: R_x(a) = Qᵀ R_y(a) Q.
_Q = rotation_matrix([0.0, 0.0, 1.0], np.pi / 2)


def _dot(a, b):
    return np.einsum("...i,...i->...", a, b)


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


def _polar_rotate_each(x, a, P, backend: str = "numpy"):
    """``Y(a) x`` with one angle per row or column (``a`` broadcast against ``x[..., :1]``).

    ``backend="numba"`` (or ``"ducc0"``) runs ``shrm._kernels._polar_rotate_each_kernel`` in one
    pass over ``x`` (rows × columns × channels × (P+1)², hundreds of MB for an SHRM).
    """
    l, m = sh_degrees_orders(P)
    partner = l * l + l - m
    a = np.asarray(a, dtype=np.float64)
    varying = [axis for axis, n in enumerate(a.shape) if n > 1]
    if backend != "numpy" and len(varying) == 1:
        return _polar_rotate_each_numba(x, a.reshape(-1), varying[0], m, partner)
    # cos(|m| a) x_m + sgn(m) sin(|m| a) x_-m, in place on two full-size arrays
    out = np.multiply(np.cos(np.abs(m) * a), x)
    swapped = x[..., partner]
    swapped *= np.sign(m) * np.sin(np.abs(m) * a)
    out += swapped
    return out


def _polar_rotate_each_numba(x, angles, axis, m, partner):
    # x as (outer, angle, inner, (P+1)²) around the axis the angles run along
    from shrm._kernels import _polar_rotate_each_kernel as kernel

    shape = x.shape
    outer = int(np.prod(shape[:axis], dtype=np.int64))
    x4 = np.ascontiguousarray(x).reshape(outer, shape[axis], -1, shape[-1])
    cos_ma = np.cos(np.abs(m)[None, :] * angles[:, None])
    sin_ma = np.sign(m)[None, :] * np.sin(np.abs(m)[None, :] * angles[:, None])
    out = np.empty_like(x4)
    kernel(x4, cos_ma, sin_ma, partner, out)
    return out.reshape(shape)


@dataclass(frozen=True, eq=False)
class SHRM:
    """A global SHRM: per cube-map texel, the coefficients B_pq of reflected radiance over views.

    Attributes
    ----------
    coeffs : ndarray, shape (6, S, S, R, (P+1)²)
        ``B_pq(n)`` in world axes (module docstring), per band (R = C) or, with ``mixing``, per
        basis channel.
    frame : str
        ``"normal"`` or ``"reflection"``: what the texel direction indexes.
    F, P : int
        Lighting and view orders.
    view_power : float
        The grazing view power k: ``coeffs`` hold ``cos^k θ_o B`` (the regular part of a BRDF that
        grows like ``cos^{−k} θ_o``, :func:`shrm_brdf_parts`); shading divides by ``(N·v)^k``.
    lambert : ndarray, shape (C,), optional
        The Lambertian albedo ρ_d split off the BRDF; its radiance ``ρ_d/π E(N)`` comes from
        ``irradiance``, not from ``coeffs``.
    irradiance : ndarray, shape (6, S, S, C), optional
        The irradiance cube map ``E(n) = ∫ L max(0, ω·n) dω`` (Eq. (7), Ramamoorthi & Hanrahan
        2001), when ``lambert`` is given.
    mixing : ndarray, shape (C, R), optional
        The bands as combinations of the R basis channels ``coeffs`` hold (:func:`shrm_create`'s
        channel basis): band c is ``Σ_r mixing[c, r] coeffs[..., r, :]``. None: R = C.
    """

    coeffs: np.ndarray
    frame: str
    F: int
    P: int
    view_power: float = 0.0
    lambert: np.ndarray | None = None
    irradiance: np.ndarray | None = None
    mixing: np.ndarray | None = None

    @property
    def size(self) -> int:
        """Cube face size S."""
        return self.coeffs.shape[1]


def shrm_create(
    env_coeffs,
    rho: np.ndarray,
    frame: str = "reflection",
    size: int = 64,
    backend="ducc0",
    view_power: float = 0.0,
    lambert=None,
) -> SHRM:
    """Create a SHRM in frequency space from lighting and BRDF coefficients.

    R&H 2002, the SHRM coefficients: ``B^loc_pq(n) = Σ_l ρ_{lp|q|} [D(R_nᵀ) L]_lq``, rotated to
    world axes, evaluated on a Fejér-1 grid (an FFT over φ per row), projected onto SH of degree
    F + P and synthesized at the cube-map texels (module docstring).

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
    view_power : float
        The grazing view power ``rho`` was computed with (:func:`brdf_sh_coefficients`).
    lambert : array_like, shape (C,) or scalar, optional
        A Lambertian albedo split off the BRDF (:func:`shrm_brdf_parts`): its irradiance map is
        made on the irradiance path of the SH engine, exact at low order (Eq. (7), Ramamoorthi &
        Hanrahan 2001, at the full order of ``env_coeffs``).

    Returns
    -------
    SHRM

    Examples
    --------
    >>> from reference.materials.brdf import brdf_lambert
    >>> from shrm.brdf_sh import brdf_sh_coefficients
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
    bands = L.shape[0]  # a grey BRDF (one channel) goes with any environment
    require(C in (1, bands), f"SHRM: lighting has {bands} channels but the BRDF has {C}")
    require(L.shape[1] >= F1 * F1, f"SHRM: lighting order is below F = {F}")
    L = L[:, : F1 * F1]
    # Create on a basis of the channels where the bands are few combinations of it (E103)
    rho, L, mixing = channel_basis(rho, L)
    C = L.shape[0]
    K = F + P
    H = 2 * K + 2
    W = 2 * H
    theta = latlong_ring_angles(H)
    phi = 2.0 * np.pi * (np.arange(W) + 0.5) / W
    # B_pq(n) on a Fejér-1 grid of 2(F+P)+2 rows: each texel's frame, then world axes
    A_cos, A_sin = _local_row_terms(L, rho, theta)
    B_world = _rotate_to_world(A_cos, A_sin, theta, phi, backend)  # (H, W, C, (P+1)²)
    # B_pq(n) is band-limited to F + P: project exactly (Fejér-1), synthesize at the texels
    from reference.geometry.cubemap import cubemap_texel_directions

    grid = B_world.reshape(H, W, C * P1 * P1)
    coeffs_n = project_latlong(grid, K, backend=backend, where="SHRM")
    texels = cubemap_texel_directions(size)
    values = _synthesize_many(coeffs_n, K, texels, backend)
    coeffs = values.reshape(6, size, size, C, P1 * P1)
    irradiance = None
    if lambert is not None:
        lambert = np.broadcast_to(np.asarray(lambert, dtype=np.float64), (bands,)).copy()
        irradiance = _irradiance_cube(env_coeffs, texels, backend)
    return SHRM(coeffs, frame, F, P, float(view_power), lambert, irradiance, mixing)


#: Singular values below this fraction of the largest are dropped by :func:`channel_basis`.
CHANNEL_RANK_RTOL = 1e-12


def _numerical_basis(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``x (C, n) ≈ mix (C, r) @ basis (r, n)`` with r the numerical rank (SVD)."""
    U, s, Vt = np.linalg.svd(x, full_matrices=False)
    r = max(1, int((s > CHANNEL_RANK_RTOL * s[0]).sum())) if s[0] > 0 else 1
    return U[:, :r], s[:r, None] * Vt[:r]


def channel_basis(rho, L) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """The BRDF's and the lighting's channels on a common basis, when it has fewer channels.

    Ours (E103): a SHRM's coefficients are bilinear in the BRDF and lighting coefficients of each
    band, ``B_c = B(ρ_c, L_c)``. When ``ρ_c = Σ_j A_cj ρ_j`` (s basis BRDFs: 1 for a grey BRDF)
    and ``L_c = Σ_k U_ck L_k`` (r basis lightings: 3 for a map upsampled linearly from RGB),
    ``B_c = Σ_jk A_cj U_ck B(ρ_j, L_k)``: the SHRM is created on the s·r pairs and the bands
    are mixed back at extraction. Used when s·r < C; the ranks are numerical
    (:data:`CHANNEL_RANK_RTOL`), so the bands agree with a per-band creation to rounding.

    Parameters
    ----------
    rho : ndarray, shape (C, F+1, P+1, M+1) or (1, ...)
        BRDF coefficients per band (one channel: grey).
    L : ndarray, shape (C, (F+1)²)
        Lighting coefficients per band.

    Returns
    -------
    rho, L : ndarray
        Per basis channel, shapes (R, F+1, P+1, M+1) and (R, (F+1)²); the inputs (``rho``
        broadcast to C channels) when no basis is smaller.
    mixing : ndarray, shape (C, R), or None

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> L = rng.normal(size=(3, 9)); rho = rng.normal(size=(1, 3, 2, 2))
    >>> L16 = np.linspace(0, 1, 16)[:, None] * L[0] + np.linspace(1, 0, 16)[:, None] * L[1]
    >>> rho_b, L_b, mix = channel_basis(rho, L16)
    >>> L_b.shape, mix.shape, bool(np.allclose(mix @ L_b, L16))
    ((2, 9), (16, 2), True)
    >>> channel_basis(rho, L)[2] is None                     # three independent bands
    True
    """
    C = L.shape[0]
    A, rho_j = _numerical_basis(rho.reshape(rho.shape[0], -1))
    U, L_k = _numerical_basis(L)
    s, r = rho_j.shape[0], L_k.shape[0]
    if s * r >= C:
        return np.broadcast_to(rho, (C, *rho.shape[1:])), L, None
    A = np.broadcast_to(A, (C, s))
    # The pairs (j, k): ρ_j with L_k, and the bands' weights A_cj U_ck
    rho_pairs = np.repeat(rho_j.reshape(s, *rho.shape[1:]), r, axis=0)
    L_pairs = np.tile(L_k, (s, 1))
    mixing = (A[:, :, None] * U[:, None, :]).reshape(C, s * r)
    return rho_pairs, L_pairs, mixing


#: Up to this degree, :func:`_synthesize_many` evaluates the basis once and multiplies.
BASIS_PRODUCT_MAX_ORDER = 64
#: Texels per block of the basis matrix in :func:`_synthesize_many` (bytes of float64).
BASIS_BLOCK_BYTES = 64 << 20


def _synthesize_many(coeffs, K: int, texels, backend: str) -> np.ndarray:
    """``f_c(ω) = Σ_lm c_lm Y_lm(ω)`` for thousands of functions c at the texels, (..., C).

    Eq. (2), Ramamoorthi & Hanrahan 2001, as a matrix product: the basis ``Y`` (texels ×
    (K+1)²) once per block of texels, times the coefficients of every function. An SHRM has
    C·(P+1)² functions (thousands); one synthesis call per function (``sh_evaluate``) spends its
    time in per-call work, while the product costs (K+1)² per texel and function, less up to
    :data:`BASIS_PRODUCT_MAX_ORDER` (docs/errata.md, SHRM creation).

    Examples
    --------
    >>> c = np.zeros((2, 4)); c[0, 0] = np.sqrt(4 * np.pi); c[1, 2] = 1.0
    >>> d = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
    >>> np.allclose(_synthesize_many(c, 1, d, "ducc0"), sh_evaluate(c, d, backend="numpy"))
    True
    """
    if K > BASIS_PRODUCT_MAX_ORDER:
        return sh_evaluate(coeffs, texels, backend=backend)
    flat = texels.reshape(-1, 3)
    out = np.empty((flat.shape[0], coeffs.shape[0]))
    step = max(1, BASIS_BLOCK_BYTES // (8 * (K + 1) ** 2))
    for start in range(0, flat.shape[0], step):
        Y = sh_basis(K, flat[start : start + step])  # (texels, (K+1)²)
        out[start : start + step] = Y @ coeffs.T
    return out.reshape(*texels.shape[:-1], coeffs.shape[0])


def _local_row_terms(L, rho, theta) -> tuple[np.ndarray, np.ndarray]:
    """The texels' local ``B^loc_pq`` per grid row θ_j, as cosine and sine Fourier terms in φ.

    Both terms have shape (H, C, P+1, 2P+1, F+1): row, channel, p, q + P, m'.
    """
    C, F1, P1, _ = rho.shape
    H = theta.size
    # D(R_nᵀ) L = D(Qᵀ) Y(θ) D(Q) Y(φ) L. The part per row, M_j = D(Qᵀ) Y(θ_j) D(Q), meets
    # Y(φ) L = Σ_m' cos(m'φ) L^c_m' + sin(m'φ) L^s_m' (polar_rotate): per row two sets of Fourier
    # terms are contracted with ρ, and the φ dependence is a sum over m' for every column.
    blocks = _quarter_turn_blocks(F1 - 1)
    qmax = P1 - 1
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
        q = slice(qs[0] + qmax, qs[-1] + qmax + 1)  # the q of this l, a view (no gather/scatter)
        A_cos[:, :, :, q, : l + 1] += r[None, ..., None] * u[:, :, None]
        A_sin[:, :, :, q, : l + 1] += r[None, ..., None] * v[:, :, None]
    return A_cos, A_sin


def _rotate_to_world(A_cos, A_sin, theta, phi, backend: str = "numpy") -> np.ndarray:
    """``B_pq(n) = [D(R_n) B^loc(n)]_pq`` in world axes on the Fejér-1 grid, (H, W, C, (P+1)²)."""
    F1 = A_cos.shape[-1]
    P = qmax = A_cos.shape[2] - 1
    cos_phi = np.cos(np.arange(F1)[None, :] * phi[:, None])  # (W, F+1)
    sin_phi = np.sin(np.arange(F1)[None, :] * phi[:, None])
    # The view coefficients (p, q) in specref's layout: A (H, C, F+1, (P+1)²)
    p_of, q_of = sh_degrees_orders(P)
    A = np.moveaxis(np.stack([A_cos, A_sin])[:, :, :, p_of, q_of + qmax], 3, -1)
    # Rotate the view expansion to world axes, D(R_n) B^loc with
    # R_n = R_y(−φ) R_x(−θ) = R_y(−φ) Qᵀ R_y(−θ) Q: the row part D(Qᵀ) Y(−θ_j) D(Q) acts on the
    # Fourier terms of each row, before the sum over m' for every column k
    DQ = _quarter_turn_blocks(P)
    A = _polar_rotate_each(_block_apply(DQ, A), -theta[None, :, None, None, None], P, backend)
    A = np.moveaxis(_block_apply(DQ, A, transpose=True), -1, -2)  # (2, H, C, (P+1)², F+1)
    # Σ_m' cos(m'φ_k) A_cos + sin(m'φ_k) A_sin, then Y(−φ_k) per column k
    B_world = np.moveaxis(A[0] @ cos_phi.T + A[1] @ sin_phi.T, -1, 1)  # (H, W, C, (P+1)²)
    B_world = _polar_rotate_each(B_world, -phi[None, :, None, None], P, backend)
    return B_world


def _irradiance_cube(env_coeffs, texels, backend) -> np.ndarray:
    """E(n) = ∫ L max(0, ω·n) dω at the texels, Eq. (7), Ramamoorthi & Hanrahan 2001."""
    from shrm.lobes import lambert_Lambda_closed_form
    from shrm.prefilter import prefilter_coefficients
    from shrm.sh import order_of

    L = np.atleast_2d(np.asarray(env_coeffs, dtype=np.float64))
    E_lm = prefilter_coefficients(L, lambert_Lambda_closed_form(order_of(L.shape[1])))
    return sh_evaluate(E_lm, texels, backend=backend)


def shrm_extract(shrm: SHRM, view) -> np.ndarray:
    """A reflection map for one (distant) viewpoint: ``E_v(n) = Σ_pq B_pq(n) Y_pq(v)``.

    §5.6, Herbert et al.; R&H 2002, SHRM evaluation. The map holds what the SHRM stores: the
    reflected radiance of the BRDF without a split-off Lambertian part, times ``cos^k θ_o`` for a
    grazing view power k; :func:`shade_shrm` completes it per pixel.

    Parameters
    ----------
    shrm : SHRM
    view : array_like, shape (3,)
        Unit direction from the surface towards the viewer.

    Returns
    -------
    ndarray, shape (6, S, S, C)
        Per texel and band.

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
    E = shrm.coeffs @ Y
    # E103: the bands from the basis channels
    return E if shrm.mixing is None else E @ shrm.mixing.T


def _index_directions(frame: str, normal, view) -> np.ndarray:
    """The texel direction a pixel reads: its normal, or the reflection of the view about it."""
    if frame == "normal":
        return normal
    # R&H 2002, reparameterization: r = 2 (N·v) N − v
    return 2.0 * _dot(normal, view)[..., None] * normal - view


def shade_shrm(shrm: SHRM, E, normal, view) -> np.ndarray:
    """Reflected radiance at surface points from an extracted map (§5.6, Herbert et al.).

    R&H 2002, SHRM evaluation, completed per point:
    ``B = (N·v)^{−k} E_v(index) + ρ_d/π E_irr(N)``, where ``index`` is the normal or the
    reflection vector (seamless bilinear lookups), k the grazing view power and the second term
    the split-off Lambertian part. Points facing away (N·v <= 0) get no view-singular part.

    Parameters
    ----------
    shrm : SHRM
    E : ndarray, shape (6, S, S, C)
        :func:`shrm_extract` for ``view``.
    normal : ndarray, shape (N, 3)
        Unit surface normals.
    view : array_like, shape (3,)
        Unit direction towards the distant viewer.

    Returns
    -------
    ndarray, shape (N, C)

    Examples
    --------
    >>> s = SHRM(np.ones((6, 1, 1, 1, 1)), "normal", 0, 0, 1.0, np.array([np.pi]),
    ...          np.full((6, 1, 1, 1), 2.0))
    >>> shade_shrm(s, np.full((6, 1, 1, 1), 0.5), np.array([[0.0, 0.0, 1.0]]), [0.6, 0.0, 0.8])
    array([[2.625]])
    """
    from reference.geometry.cubemap import cubemap_lookup_bilinear

    v = np.asarray(view, dtype=np.float64)
    out = cubemap_lookup_bilinear(E, _index_directions(shrm.frame, normal, v))
    if shrm.view_power:
        # cos^k θ_o was factored out at creation: divide it back per pixel
        cos_o = _dot(normal, v)[..., None]
        out = np.where(cos_o > 0.0, out / np.maximum(cos_o, 1e-300) ** shrm.view_power, 0.0)
    if shrm.lambert is not None:
        # The Lambertian part, ρ_d/π E(N) (Eq. (7), Ramamoorthi & Hanrahan 2001)
        out = out + shrm.lambert / np.pi * cubemap_lookup_bilinear(shrm.irradiance, normal)
    return out


def render_shrm(gbuffer, shrm: SHRM, view, material_id: int = 0, E=None) -> np.ndarray:
    """Deferred rendering of one material through the G-buffer with a SHRM (distant viewer).

    §5.6, Herbert et al.: extract the reflection map for the viewpoint, then shade every pixel
    from it (:func:`shade_shrm`).

    Parameters
    ----------
    gbuffer : reference.geometry.gbuffer.GBuffer
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
    >>> from reference.geometry.gbuffer import empty_gbuffer
    >>> s = SHRM(np.ones((6, 1, 1, 1, 9)), "normal", 2, 2)
    >>> render_shrm(empty_gbuffer(2, 2), s, [0.0, 0.0, 1.0]).shape
    (2, 2, 1)
    """
    v = np.asarray(view, dtype=np.float64)
    v = v / np.linalg.norm(v)
    E = shrm_extract(shrm, v) if E is None else E
    H, W = gbuffer.shape
    out = np.zeros((H, W, E.shape[-1]))
    sel = gbuffer.mask & (gbuffer.material_id == material_id)
    if sel.any():
        out[sel] = shade_shrm(shrm, E, gbuffer.normal[sel], v)
    return out

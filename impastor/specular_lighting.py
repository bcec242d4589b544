"""Specular reflection of a plane light by point lights, FIS and brute force.

ImpastoR's specular pipeline (§3.5.2 and §3.5.4, Ferwerda): median-cut point lights, filtered
importance sampling and a brute-force reference. The per-pixel hybrid of the first two, and the
registry of all four methods, :data:`impastor.specular_hybrid.SPECULAR_METHODS`, are in
``impastor.specular_hybrid``.

Every method computes the *specular integral* of the Ward–Dür lobe (Eq. (4), Ferwerda, with
``ρ_s = 1``) against the light image,

    I_s(p, ω_o) = ∫ f_s(ω_i, ω_o) L(ω_i) cos θ_i dω_i,

per channel of the light image; the rendered specular radiance of channel j is
``ρ_s,j S_j I_s`` (the light's normalised channel value, as in Eq. (3), Ferwerda).

- ``point_lights``: the lobe evaluated at the N median-cut (or variance-minimization) lights, each
  weighted as in Eq. (2), Ferwerda. Accurate for wide lobes; a narrow lobe falls between lights.
- ``fis``: filtered importance sampling (Colbert, Premože & François 2010; GPU Gems 3 ch. 20). K
  Hammersley samples of Ward's half-vector distribution; each direction meets the light plane by
  Eqs. (5)-(8), Ferwerda, and reads a mip-mapped light image at the level
  ``max(½ log2(Ω_s/Ω_p) + bias, 0)`` with ``Ω_s = 1/(K p)`` the sample's solid angle and ``Ω_p``
  a texel's. Accurate for narrow lobes; a wide lobe spills past the light's edges.
- ``brute_force``: the converged reference: the lobe summed over every light pixel, each split
  into ``supersample²`` sub-pixels (the light image is piecewise constant).

Each method has a NumPy reference here and a numba twin in ``_specular_lighting_kernels.py``
(``backend="numpy" | "numba"``).

References
----------
- J. A. Ferwerda, "ImpastoR: A realistic surface display system", Vision Research 109, 2015.
- M. Colbert, S. Premože, G. François, "Importance sampling for production rendering", SIGGRAPH
  2010 course notes; M. Colbert, J. Křivánek, "GPU-based importance sampling", GPU Gems 3, ch. 20.
- J. H. Halton, "On the efficiency of certain quasi-random sequences...", 1960 (Hammersley points).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from impastor._kernels import (
    specular_brute_force_kernel,
    specular_fis_kernel,
    specular_point_lights_kernel,
)
from impastor.arealights import PlaneLight, light_plane_uv
from impastor.point_lights import PointLights
from reference.errors import require, require_choice, require_nonnegative, require_positive_int
from reference.geometry.sampling import hammersley
from reference.jit import kernel_input
from reference.materials.brdf import (
    brdf_ward_duer_specular,
    frame_from_normal,
    pdf_ward_duer_lobe,
    sample_ward_duer_lobe,
)

__all__ = [
    "BACKENDS",
    "mip_lookup",
    "mip_pyramid",
    "specular_brute_force",
    "specular_fis",
    "specular_mis",
    "specular_point_lights",
]

BACKENDS = ("numpy", "numba")


def _flat(points, normals, views, alpha):
    """Validate and flatten per-pixel inputs to ``(P, 3)`` and ``(P,)``; also the leading shape."""
    p = np.asarray(points, dtype=np.float64)
    shape = p.shape[:-1]
    n = np.broadcast_to(np.asarray(normals, dtype=np.float64), p.shape)
    v = np.broadcast_to(np.asarray(views, dtype=np.float64), p.shape)
    alpha = require_nonnegative(alpha, "specular: alpha")
    require(bool((alpha > 0).all()), f"specular: alpha: must be > 0, got {float(alpha.min()):g}")
    a = np.broadcast_to(alpha, shape)
    # kernel inputs: one compiled signature whether the caller's arrays were broadcast or not
    as_c = lambda x, k: kernel_input(x.reshape(-1, k) if k else x.reshape(-1))  # noqa: E731
    return as_c(p, 3), as_c(n, 3), as_c(v, 3), as_c(a, 0), shape


def mip_pyramid(image) -> list[np.ndarray]:
    """Mip levels of a 2-D image by 2×2 box filtering, down to 1×1.

    An odd side is padded by repeating its last row or column before averaging.

    Examples
    --------
    >>> [level.shape for level in mip_pyramid(np.ones((4, 8)))]
    [(4, 8), (2, 4), (1, 2), (1, 1)]
    """
    level = np.asarray(image, dtype=np.float64)
    levels = [level]
    while level.shape != (1, 1):
        if level.shape[0] % 2 and level.shape[0] > 1:
            level = np.concatenate([level, level[-1:]], axis=0)
        if level.shape[1] % 2 and level.shape[1] > 1:
            level = np.concatenate([level, level[:, -1:]], axis=1)
        H, W = level.shape
        fy, fx = (2 if H > 1 else 1), (2 if W > 1 else 1)
        level = level.reshape(H // fy, fy, W // fx, fx).mean(axis=(1, 3))
        levels.append(level)
    return levels


def _bilinear(level, a, b):
    H, W = level.shape
    x = np.clip(a * W - 0.5, 0.0, W - 1.0)
    y = np.clip(b * H - 0.5, 0.0, H - 1.0)
    x0 = np.minimum(np.floor(x).astype(np.int64), W - 1)
    y0 = np.minimum(np.floor(y).astype(np.int64), H - 1)
    x1, y1 = np.minimum(x0 + 1, W - 1), np.minimum(y0 + 1, H - 1)
    fx, fy = x - x0, y - y0
    top = level[y0, x0] * (1 - fx) + level[y0, x1] * fx
    bottom = level[y1, x0] * (1 - fx) + level[y1, x1] * fx
    return top * (1 - fy) + bottom * fy


def mip_lookup(levels, a, b, level) -> np.ndarray:
    """Trilinear lookup: bilinear within the two nearest levels, linear between them.

    Examples
    --------
    >>> levels = mip_pyramid(np.arange(16.0).reshape(4, 4))
    >>> float(mip_lookup(levels, 0.5, 0.5, 0.0)), float(mip_lookup(levels, 0.5, 0.5, 2.0))
    (7.5, 7.5)
    """
    level = np.clip(np.asarray(level, dtype=np.float64), 0.0, len(levels) - 1.0)
    l0 = np.floor(level).astype(np.int64)
    l1 = np.minimum(l0 + 1, len(levels) - 1)
    t = level - l0
    a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
    out = np.zeros(np.broadcast_shapes(a.shape, level.shape))
    a, b = np.broadcast_to(a, out.shape), np.broadcast_to(b, out.shape)
    l0, l1, t = (np.broadcast_to(x, out.shape) for x in (l0, l1, t))
    for index in np.unique(np.concatenate([l0.ravel(), l1.ravel()])):
        m0, m1 = l0 == index, l1 == index
        if m0.any():
            out[m0] += (1 - t[m0]) * _bilinear(levels[index], a[m0], b[m0])
        if m1.any():
            out[m1] += t[m1] * _bilinear(levels[index], a[m1], b[m1])
    return out


def _channels(light_image):
    return [np.ascontiguousarray(light_image[..., c]) for c in range(light_image.shape[-1])]


# --- point lights --------------------------------------------------------------------------------


def specular_point_lights(
    points, normals, views, alpha, lights: PointLights, visibility=None, backend: str = "numpy"
) -> np.ndarray:
    """Specular integral from point lights (median cut or variance minimization).

    Eq. (2), Ferwerda, with the Ward–Dür lobe of Eq. (4), Ferwerda, as the BRDF:
    ``I_s = Σ_n f_s(I_n, V) L_n (N·I_n)(−N_light·I_n) (A/P) / d_n²``.

    Parameters
    ----------
    points, normals, views : array_like, shape (..., 3)
        Surface positions (m), unit shading normals, unit vectors towards the eye.
    alpha : array_like, shape (...,)
        Roughness > 0.
    lights : PointLights
        From ``point_lights_from_plane`` (directional lights are not supported here).
    visibility : array_like, shape (..., N), optional
        Shadowing per light (1 lit, 0 shadowed).
    backend : {"numpy", "numba"}

    Returns
    -------
    ndarray, shape (..., C)

    Examples
    --------
    >>> from impastor.arealights import PlaneLight
    >>> from impastor.point_lights import point_lights_from_plane
    >>> plane = PlaneLight(np.full((1, 1), 100.0), (-0.05, 1, -0.05), (1, 0, 0), (0, 0, 1), 0.1,
    ...                    0.1)
    >>> lights = point_lights_from_plane(plane, "median_cut", 1)
    >>> up = np.array([0.0, 1.0, 0.0])
    >>> specular_point_lights(np.zeros(3), up, up, 0.1, lights).round(4)
    array([7.9577])
    """
    require_choice(backend, BACKENDS, "backend")
    require(not lights.directional, "specular_point_lights: directional lights are not supported")
    P, N, V, a, shape = _flat(points, normals, views, alpha)
    vis = np.ones((P.shape[0], lights.L.shape[0]))
    if visibility is not None:
        vis = np.ascontiguousarray(
            np.broadcast_to(np.asarray(visibility, float), (*shape, lights.L.shape[0])).reshape(
                P.shape[0], -1
            )
        )
    out = np.zeros((P.shape[0], lights.L.shape[1]))
    if backend == "numba":
        for c in range(lights.L.shape[1]):
            column = np.zeros(P.shape[0])
            specular_point_lights_kernel(
                P, N, V, a, lights.position, np.ascontiguousarray(lights.L[:, c]),
                lights.n_light, lights.pixel_area, vis, column,
            )  # fmt: skip
            out[:, c] = column
        return out.reshape((*shape, -1))
    to_light = lights.position[None, :, :] - P[:, None, :]  # (P, N, 3)
    d2 = np.einsum("pni,pni->pn", to_light, to_light)
    I_n = to_light / np.sqrt(d2)[..., None]
    cos_s = np.einsum("pni,pi->pn", I_n, N)
    cos_l = -(I_n @ lights.n_light)
    lit = (cos_s > 0) & (cos_l > 0)
    f = brdf_ward_duer_specular(I_n, V[:, None, :], N[:, None, :], a[:, None])
    # Eq. (2), Ferwerda, weighted by the lobe: f L_n (N·I_n)(−N_l·I_n) A/P / d²
    weight = np.where(lit, f * cos_s * cos_l * lights.pixel_area / d2, 0.0) * vis
    return (weight @ lights.L).reshape((*shape, -1))


# --- filtered importance sampling ----------------------------------------------------------------


def specular_fis(
    points,
    normals,
    views,
    alpha,
    light: PlaneLight,
    n_samples: int = 32,
    bias: float = 1.0,
    backend: str = "numpy",
    shift=(0.0, 0.0),
) -> np.ndarray:
    """Specular integral by filtered importance sampling of the Ward–Dür lobe.

    Eq. (4), Ferwerda (the lobe and its sampler), Eqs. (5)-(8), Ferwerda (the light lookup), and
    Colbert et al. 2010's mip level ``max(½ log2(Ω_s/Ω_p) + bias, 0)``.

    Parameters
    ----------
    points, normals, views : array_like, shape (..., 3)
    alpha : array_like, shape (...,)
        Roughness > 0.
    light : PlaneLight
    n_samples : int
        K, the samples per pixel (the same Hammersley set at every pixel, as on the GPU).
    bias : float
        Added to the mip level (GPU Gems 3 ch. 20 uses 1: a slightly blurrier, smoother result).
    backend : {"numpy", "numba"}
    shift : tuple of float
        A Cranley–Patterson rotation of the Hammersley set, ``u ← (u + shift) mod 1``: (0, 0) is
        the plain set; the hybrid (``impastor.specular_hybrid``) draws a second, independent
        estimate with another shift.

    Returns
    -------
    ndarray, shape (..., C)

    Examples
    --------
    >>> from impastor.arealights import PlaneLight
    >>> plane = PlaneLight(np.full((8, 8), 100.0), (-1, 1, -1), (1, 0, 0), (0, 0, 1), 2.0, 2.0)
    >>> up = np.array([0.0, 1.0, 0.0])
    >>> specular_fis(np.zeros(3), up, up, 0.05, plane, 16).round(2)
    array([99.51])
    """
    require_choice(backend, BACKENDS, "backend")
    P, N, V, a, shape = _flat(points, normals, views, alpha)
    # Cranley & Patterson 1976: a rotated set keeps the stratification, moves every sample
    u = np.mod(hammersley(n_samples) + np.asarray(shift, dtype=np.float64), 1.0)
    out = np.zeros((P.shape[0], light.image.shape[-1]))
    channel = _fis_channel_kernel if backend == "numba" else _fis_channel
    for c, image in enumerate(_channels(light.image)):
        out[:, c] = channel(_Pixels(P, N, V, a), u, mip_pyramid(image), light, bias)
    return out.reshape((*shape, -1))


class _Pixels(NamedTuple):
    """Flattened shading points, normals, views and roughness (:func:`_flat`)."""

    P: np.ndarray
    N: np.ndarray
    V: np.ndarray
    a: np.ndarray


def _fis_channel(px: _Pixels, u, levels, light: PlaneLight, bias: float) -> np.ndarray:
    """One channel of :func:`specular_fis` in NumPy: K lobe samples, each a filtered lookup."""
    P, N, V, a = px
    K = u.shape[0]
    t, b = frame_from_normal(N)
    acc = np.zeros(P.shape[0])
    for k in range(K):
        # Ward 1992 half-vector sample, reflected about the view: ω_i = 2(V·h)h − V
        tan2_h = -(a**2) * np.log1p(-min(u[k, 0], 1.0 - 1e-16))
        cos_h = 1.0 / np.sqrt(1.0 + tan2_h)
        sin_h = np.sqrt(np.maximum(0.0, 1.0 - cos_h**2))
        phi = 2.0 * np.pi * u[k, 1]
        h = (sin_h * np.cos(phi))[:, None] * t + (sin_h * np.sin(phi))[:, None] * b
        h += cos_h[:, None] * N
        v_h = np.einsum("pi,pi->p", V, h)
        wi = 2.0 * v_h[:, None] * h - V
        cos_i = np.einsum("pi,pi->p", wi, N)
        pdf = pdf_ward_duer_lobe(V, wi, N, a)
        # The light lookup (light_plane_uv): where ω_i meets the light, in unit pixel coords
        a_uv, b_uv, d = light_plane_uv(light, P, wi)
        hit = (cos_i > 0) & (v_h > 0) & np.isfinite(d)
        hit &= (a_uv >= 0) & (a_uv < 1) & (b_uv >= 0) & (b_uv < 1)
        cos_l = -(wi @ light.n_light)
        safe_d = np.where(hit, d, 1.0)
        safe_pdf = np.where(hit, pdf, 1.0)
        # Colbert et al. 2010: Ω_s = 1/(K p), Ω_p = (A/P) cos θ_l / d², level ½ log2(Ω_s/Ω_p)
        omega_s = 1.0 / (K * safe_pdf)
        omega_p = light.pixel_area * np.where(hit, cos_l, 1.0) / safe_d**2
        level = np.maximum(0.5 * np.log2(omega_s / omega_p) + bias, 0.0)
        L = mip_lookup(levels, np.where(hit, a_uv, 0.5), np.where(hit, b_uv, 0.5), level)
        f = brdf_ward_duer_specular(wi, V, N, a)
        acc += np.where(hit, f * L * cos_i / safe_pdf, 0.0)
    return acc / K


def _fis_channel_kernel(px: _Pixels, u, levels, light: PlaneLight, bias: float) -> np.ndarray:
    """One channel of :func:`specular_fis` by its numba twin, the mip pyramid in one array."""
    P, N, V, a = px
    A, B = np.asarray(light.A), np.asarray(light.B)
    flat = np.concatenate([level.ravel() for level in levels])
    sizes = np.array([level.size for level in levels])
    offsets = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
    heights = np.array([level.shape[0] for level in levels], dtype=np.int64)
    widths = np.array([level.shape[1] for level in levels], dtype=np.int64)
    column = np.zeros(P.shape[0])
    specular_fis_kernel(
        P, N, V, a, u, flat, offsets, heights, widths, np.asarray(light.origin), A, B,
        light.l_A, light.l_B, light.pixel_area, float(bias), column,
    )  # fmt: skip
    return column


# --- multiple importance sampling (the hybrid's arbiter) ------------------------------------------


def specular_mis(
    points,
    normals,
    views,
    alpha,
    light: PlaneLight,
    n_samples: int = 128,
    seed: int = 0,
) -> tuple[np.ndarray, np.ndarray]:
    """Unbiased Monte Carlo estimate of the specular integral, and its standard error.

    Eq. (4), Ferwerda, over the light plane as :func:`specular_brute_force` integrates it (each
    light pixel constant), estimated by multiple importance sampling with the balance heuristic
    (Veach & Guibas 1995): ``n_samples`` points on the light drawn in proportion to the pixels'
    power (channel mean) and uniformly inside a pixel, and ``n_samples`` directions from Ward's lobe
    sampler (:func:`reference.materials.brdf.sample_ward_duer_lobe`). With ``M`` samples of each
    technique, ``I = (1/M) Σ f L cos θ_s / (p_light + p_lobe)`` over all ``2M`` samples, both
    densities per unit solid angle. Not one of ImpastoR's methods: the hybrid's fail-safe
    (``impastor.specular_hybrid``) measures the other methods against it (erratum E17). NumPy only:
    the hybrid evaluates it on a bounded number of pixels.

    Parameters
    ----------
    points, normals, views : array_like, shape (..., 3)
    alpha : array_like, shape (...,)
        Roughness > 0.
    light : PlaneLight
    n_samples : int
        M, the samples of each technique per pixel.
    seed : int
        Seeds NumPy's generator: the estimate is deterministic.

    Returns
    -------
    estimate : ndarray, shape (..., C)
    standard_error : ndarray, shape (...,)
        Of the channel mean, from the two techniques' sample variances.

    Examples
    --------
    >>> from impastor.arealights import PlaneLight
    >>> plane = PlaneLight(np.full((8, 8), 100.0), (-1, 1, -1), (1, 0, 0), (0, 0, 1), 2.0, 2.0)
    >>> up = np.array([0.0, 1.0, 0.0])
    >>> estimate, error = specular_mis(np.zeros(3), up, up, 0.05, plane, 256)
    >>> bool(abs(estimate[0] - specular_brute_force(np.zeros(3), up, up, 0.05, plane, 4)[0])
    ...      < 4 * error)
    True
    """
    P, N, V, a, shape = _flat(points, normals, views, alpha)
    M = require_positive_int(n_samples, "specular_mis: n_samples", 1 << 16)
    require(M >= 2, f"specular_mis: n_samples: must be >= 2 (a variance needs two), got {M}")
    rng = np.random.default_rng(seed)
    H, W = light.shape
    L_texel = light.image.reshape(H * W, -1)
    power = L_texel.mean(axis=-1)
    total = power.sum()
    require(total > 0, "specular_mis: the light has no power")
    mis = _MIS(light, P[:, None], V[:, None], N[:, None], a[:, None], power, total)
    g_light, texel = _mis_light_samples(mis, rng, M)
    g_lobe, lobe_texel = _mis_lobe_samples(mis, rng, M)
    estimate = np.einsum("pm,pmc->pc", g_light, L_texel[texel])
    estimate += np.einsum("pm,pmc->pc", g_lobe, L_texel[lobe_texel])
    # The standard error of the channel mean: the two techniques' sample variances, over M
    variance = g_light * power[texel]
    variance = variance.var(axis=1, ddof=1) + (g_lobe * power[lobe_texel]).var(axis=1, ddof=1)
    return (estimate / M).reshape((*shape, -1)), np.sqrt(variance / M).reshape(shape)


class _MIS(NamedTuple):
    """What both techniques of :func:`specular_mis` share: the light, the pixels, the power."""

    light: PlaneLight
    Pm: np.ndarray  # (n_P, 1, 3): one axis for the samples
    Vm: np.ndarray
    Nm: np.ndarray
    am: np.ndarray  # (n_P, 1)
    power: np.ndarray  # (H·W,): each light pixel's channel mean
    total: float


def _balance_weights(mis: _MIS, wi, d, texel, valid) -> np.ndarray:
    """``f cos θ_s / (p_light + p_lobe)`` per sample, 0 where the sample is not valid."""
    light, Vm, Nm, am = mis.light, mis.Vm, mis.Nm, mis.am
    # Balance heuristic: f L cos θ_s / (p_light + p_lobe), both per unit solid angle
    cos_l = -(wi @ light.n_light)
    cos_s = np.einsum("pmi,pmi->pm", wi, np.broadcast_to(Nm, wi.shape))
    p_light = mis.power[texel] / (mis.total * light.pixel_area) * d**2 / np.maximum(cos_l, 1e-300)
    p_lobe = pdf_ward_duer_lobe(Vm, wi, Nm, am)
    f = brdf_ward_duer_specular(wi, Vm, Nm, am)
    ok = valid & (cos_l > 0) & (cos_s > 0) & (p_light + p_lobe > 0)
    return np.where(ok, f * cos_s / np.where(ok, p_light + p_lobe, 1.0), 0.0)


def _mis_light_samples(mis: _MIS, rng, M: int) -> tuple[np.ndarray, np.ndarray]:
    """Technique 1 of :func:`specular_mis`: its weights and light pixels, (n_P, M) each."""
    light, Pm, power, total = mis.light, mis.Pm, mis.power, mis.total
    n_P = Pm.shape[0]
    H, W = light.shape
    # Technique 1: a light pixel in proportion to its power, a point uniform inside it
    u = rng.random((n_P, M, 3))
    cdf = np.cumsum(power) / total
    texel = np.minimum(np.searchsorted(cdf, u[..., 0], side="right"), H * W - 1)
    x = light.pixel_positions(texel // W + u[..., 1], texel % W + u[..., 2])
    d = np.linalg.norm(x - Pm, axis=-1)
    wi = (x - Pm) / d[..., None]
    return _balance_weights(mis, wi, d, texel, np.ones(d.shape, dtype=bool)), texel


def _mis_lobe_samples(mis: _MIS, rng, M: int) -> tuple[np.ndarray, np.ndarray]:
    """Technique 2 of :func:`specular_mis`: its weights and the light pixels met, (n_P, M) each."""
    light, Pm, Vm, Nm, am = mis.light, mis.Pm, mis.Vm, mis.Nm, mis.am
    n_P = Pm.shape[0]
    H, W = light.shape
    # Technique 2: Ward's lobe, the light pixel it meets (light_plane_uv: Eq. (8), Ferwerda)
    u = rng.random((n_P, M, 2))
    wi = sample_ward_duer_lobe(*(np.broadcast_to(x, (n_P, M, 3)) for x in (Vm, Nm)), am, u)
    a_uv, b_uv, d = light_plane_uv(light, np.broadcast_to(Pm, (n_P, M, 3)), wi)
    hit = np.isfinite(d) & (a_uv >= 0) & (a_uv < 1) & (b_uv >= 0) & (b_uv < 1)
    col = np.clip(np.floor(np.where(hit, a_uv, 0.0) * W), 0, W - 1).astype(np.int64)
    row = np.clip(np.floor(np.where(hit, b_uv, 0.0) * H), 0, H - 1).astype(np.int64)
    g_lobe = _balance_weights(mis, wi, np.where(hit, d, 1.0), row * W + col, hit)
    return g_lobe, row * W + col


# --- brute force ---------------------------------------------------------------------------------


def specular_brute_force(
    points, normals, views, alpha, light: PlaneLight, supersample: int = 4, backend: str = "numba"
) -> np.ndarray:
    """Specular integral summed over every light pixel, each split into sub-pixels: the reference.

    Eq. (4), Ferwerda, integrated against the piecewise-constant light image with the geometry of
    Eq. (2), Ferwerda, at every sub-pixel centre.

    Parameters
    ----------
    points, normals, views : array_like, shape (..., 3)
    alpha : array_like, shape (...,)
    light : PlaneLight
    supersample : int
        Sub-pixels per light pixel and axis; convergence is checked by doubling it.
    backend : {"numba", "numpy"}
        The NumPy twin loops over surface points (slow; for tests).

    Returns
    -------
    ndarray, shape (..., C)

    Examples
    --------
    >>> from impastor.arealights import PlaneLight
    >>> plane = PlaneLight(np.full((4, 4), 100.0), (-1, 1, -1), (1, 0, 0), (0, 0, 1), 2.0, 2.0)
    >>> up = np.array([0.0, 1.0, 0.0])
    >>> specular_brute_force(np.zeros(3), up, up, 0.05, plane, 8, backend="numpy").round(2)
    array([99.5])
    """
    require_choice(backend, BACKENDS, "backend")
    supersample = require_positive_int(supersample, "brute force: supersample", 256)
    P, N, V, a, shape = _flat(points, normals, views, alpha)
    out = np.zeros((P.shape[0], light.image.shape[-1]))
    o, A, B = (np.asarray(x) for x in (light.origin, light.A, light.B))
    H, W = light.shape
    s = supersample
    for c, image in enumerate(_channels(light.image)):
        if backend == "numba":
            column = np.zeros(P.shape[0])
            specular_brute_force_kernel(
                P, N, V, a, image, o, A, B, light.l_A, light.l_B, light.n_light, s, column
            )
            out[:, c] = column
            continue
        rows = (np.arange(H * s) + 0.5) / s
        cols = (np.arange(W * s) + 0.5) / s
        R, C = np.meshgrid(rows, cols, indexing="ij")
        X = light.pixel_positions(R, C).reshape(-1, 3)
        L = np.repeat(np.repeat(image, s, axis=0), s, axis=1).ravel()
        sub_area = light.pixel_area / (s * s)
        for p in range(P.shape[0]):
            to_light = X - P[p]
            d2 = np.einsum("xi,xi->x", to_light, to_light)
            I_n = to_light / np.sqrt(d2)[:, None]
            cos_s, cos_l = I_n @ N[p], -(I_n @ light.n_light)
            f = brdf_ward_duer_specular(I_n, V[p], N[p], a[p])
            lit = (cos_s > 0) & (cos_l > 0)
            out[p, c] = np.sum(np.where(lit, f * L * cos_s * cos_l * sub_area / d2, 0.0))
    return out.reshape((*shape, -1))

"""The per-pixel hybrid of point lights and FIS (§3.5.2, Ferwerda), and the specular registry.

ImpastoR renders specular reflection per pixel with either median-cut point lights or filtered
importance sampling, chosen by a "custom error minimization metric" that the paper does not give
(§3.5.2, Ferwerda). specref's metric, :func:`hybrid_error_estimates`, estimates each method's
error at each pixel from the estimates themselves: the point lights' second-moment error from
sigma-point lights (:func:`sigma_point_lights`), FIS's by Richardson's rule from an independent
second FIS estimate with half the samples (a rotated Hammersley set), and whatever part of the
two methods' disagreement these leave unexplained is charged to the method whose error estimate
is outside its range of validity. :func:`specular_hybrid` combines the two estimates
(``impastor.specular_lighting``) with inverse-variance weights where the error estimates are
alike, and chooses the one with the smaller error where they are not (erratum E17).

:data:`SPECULAR_METHODS` registers all four specular methods (point lights, FIS, the hybrid and
the brute-force reference); it lives here, beside the hybrid that uses the others.

References
----------
- J. A. Ferwerda, "ImpastoR: A realistic surface display system", Vision Research 109, 2015.
- S. J. Julier, J. K. Uhlmann, "Unscented filtering and nonlinear estimation", Proc. IEEE 92(3),
  2004 (sigma points that match a distribution's mean and variance).
- L. F. Richardson, "The deferred approach to the limit", Phil. Trans. R. Soc. A 226, 1927.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from impastor._kernels import (
    specular_brute_force_kernel,
    specular_fis_kernel,
    specular_point_lights_kernel,
)
from impastor.arealights import PlaneLight, booth_light_image, light_plane_uv
from impastor.point_lights import PointLights, _box, point_lights_from_plane, summed_area_table
from impastor.specular_lighting import (
    _flat,
    specular_brute_force,
    specular_fis,
    specular_mis,
    specular_point_lights,
)
from reference.errors import require, require_positive_int
from reference.materials.brdf import brdf_ward_duer_specular
from reference.registry import Method, Registry

__all__ = [
    "CHOOSE_RATIO",
    "FAILSAFE_MARGIN",
    "FAILSAFE_PIXELS",
    "FAILSAFE_REFINE_PIXELS",
    "FAILSAFE_REFINE_SAMPLES",
    "FAILSAFE_ROUNDS",
    "FAILSAFE_SAMPLES",
    "FAILSAFE_SEED",
    "GROUP_METHODS",
    "SECOND_SET_SHIFT",
    "SPECULAR_METHODS",
    "alpha_groups",
    "check_group_methods",
    "hybrid_error_estimates",
    "sigma_point_lights",
    "specular_by_alpha_group",
    "specular_hybrid",
    "specular_hybrid_parts",
]


# --- the hybrid ----------------------------------------------------------------------------------


def sigma_point_lights(light: PlaneLight, lights: PointLights) -> PointLights:
    """Four lights per median-cut region at ``c ± σ_x e_x`` and ``c ± σ_y e_y``, a quarter each.

    Each region's point light ``c`` (its energy centroid) is replaced by four points on the
    light plane at ± the region's energy-weighted standard deviations ``σ_x, σ_y`` along the
    image's axes: a central-difference stencil of step σ (a sigma-point set, Julier & Uhlmann
    2004, with half the region's variance). For a lobe ``g`` smooth over the region, with ``Φ``
    the region's power, ``Σ_sigma − Σ_point ≈ ¼ Φ (σ_x² g_xx + σ_y² g_yy)``, half the
    second-moment error of the one-point rule, ``−½ Φ (σ_x² g_xx + σ_y² g_yy)``, with its sign
    reversed. The hybrid uses them to estimate the point lights' error; ``spread`` is zero (each
    is a point). (The unscented set, at ``±√2 σ``, carries the full variance; its larger step
    made a worse estimate on one of the six configurations in ``docs/impastor.md``.)

    Parameters
    ----------
    light : PlaneLight
        The light the point lights were made from.
    lights : PointLights
        From ``point_lights_from_plane``.

    Returns
    -------
    PointLights
        ``4 N`` lights; light ``4 n + j`` belongs to region ``n``. Power and each region's
        centroid are conserved, and half its spread.

    Examples
    --------
    >>> from impastor.point_lights import point_lights_from_plane
    >>> plane = PlaneLight(booth_light_image("fluorescent", 32, 16), (-0.6, 0.6, -1.0), (1, 0, 0),
    ...                    (0, 0, 1), 1.2, 0.8)
    >>> lights = point_lights_from_plane(plane, "median_cut", 8)
    >>> sigma = sigma_point_lights(plane, lights)
    >>> x = sigma.position.reshape(8, 4, 3)
    >>> bool(np.allclose(x.mean(axis=1), lights.position))           # centroids
    True
    >>> spread = ((x - lights.position[:, None]) ** 2).sum(axis=-1).mean(axis=1)
    >>> bool(np.allclose(spread, lights.spread / 2))                   # half the spreads
    True
    """
    require(not lights.directional, "sigma_point_lights: directional lights are not supported")
    H, W = light.shape
    energy = light.image.mean(axis=-1)
    rows, cols = np.meshgrid(np.arange(H) + 0.5, np.arange(W) + 0.5, indexing="ij")
    x_m, y_m = cols * (light.l_A / W), rows * (light.l_B / H)
    tables = [summed_area_table(v) for v in (energy, energy * x_m**2, energy * y_m**2)]
    A, B = np.asarray(light.A, float), np.asarray(light.B, float)
    e_A, e_B = A / np.linalg.norm(A), B / np.linalg.norm(B)
    positions, L = [], []
    for region, c, L_n in zip(lights.regions, lights.position, lights.L, strict=True):
        e, xx, yy = (_box(T, *region) for T in tables)
        # The centroid in plane metres, then the per-axis variances about it.
        x_c, y_c = (c - np.asarray(light.origin)) @ e_A, (c - np.asarray(light.origin)) @ e_B
        s_x = np.sqrt(max(xx / e - x_c**2, 0.0)) if e > 0 else 0.0
        s_y = np.sqrt(max(yy / e - y_c**2, 0.0)) if e > 0 else 0.0
        # Central differences of step σ along each axis (sigma points with half the variance).
        for offset in (s_x * e_A, -s_x * e_A, s_y * e_B, -s_y * e_B):
            positions.append(c + offset)
            L.append(L_n / 4.0)
    return PointLights(
        np.array(positions),
        np.array(L),
        [r for r in lights.regions for _ in range(4)],
        False,
        lights.n_light,
        lights.pixel_area,
        np.zeros(len(positions)),
        lights.method,
    )


def _lobe_over_region(P, N, V, a, light: PlaneLight, lights: PointLights):
    """Per pixel: whether the lobe is narrower than the regions that light it.

    ``x_n = σ²/s_n²`` compares the lobe's angular variance ``σ² = 2α²`` (Ward's
    ``exp(−tan²θ_h/α²)`` with ``θ_i ≈ 2θ_h``, both axes) with the energy spread ``s_n²`` of
    region n (``PointLights.spread`` × cos θ_l / d², sr). The lobe is *narrow* where the regions
    with ``x_n < 1`` carry most of the point lights' estimate (their shares ``c_n`` of
    Eq. (2), Ferwerda); where the point lights see nothing, where the region that the mirror
    direction meets has ``x < 1``. Returns the boolean mask and ``x`` of that mirror region.
    """
    H, W = light.shape
    to_light = lights.position[None] - P[:, None]
    d2 = np.einsum("pni,pni->pn", to_light, to_light)
    I_n = to_light / np.sqrt(d2)[..., None]
    cos_l = np.maximum(-(I_n @ light.n_light), 0.0)
    cos_s = np.maximum(np.einsum("pni,pi->pn", I_n, N), 0.0)
    spread = lights.spread * cos_l / d2  # sr
    x_n = 2.0 * a[:, None] ** 2 / np.maximum(spread, 1e-300)
    # Eq. (2), Ferwerda: each light's share of the point lights' estimate
    f = brdf_ward_duer_specular(I_n, V[:, None, :], N[:, None, :], a[:, None])
    c_n = f * cos_s * cos_l / d2 * lights.L.mean(axis=-1)
    total = c_n.sum(axis=1)
    share = np.where(x_n < 1.0, c_n, 0.0).sum(axis=1) / np.where(total > 0, total, 1.0)
    cos_o = np.clip(np.einsum("pi,pi->p", N, V), 1e-6, 1.0)
    mirror = 2.0 * cos_o[:, None] * N - V
    a_uv, b_uv, d = light_plane_uv(light, P, mirror)
    on = np.isfinite(d) & (a_uv >= 0) & (a_uv < 1) & (b_uv >= 0) & (b_uv < 1)
    col = np.clip(np.floor(np.where(on, a_uv, 0) * W), 0, W - 1).astype(int)
    row = np.clip(np.floor(np.where(on, b_uv, 0) * H), 0, H - 1).astype(int)
    owner = np.full((H, W), -1)
    for k, (y0, y1, x0, x1) in enumerate(lights.regions):
        owner[y0:y1, x0:x1] = k
    s2 = np.where(on, spread[np.arange(P.shape[0]), owner[row, col]], spread.mean(axis=1))
    x_mirror = 2.0 * a**2 / np.maximum(s2, 1e-300)
    seen = total > 1e-12 * max(float(total.max(initial=0.0)), 1e-300)
    return np.where(seen, share > 0.5, x_mirror < 1.0), x_mirror


#: The Cranley–Patterson rotation of FIS's second sample set (the fractional parts of the golden
#: ratio and of √2): any shift that moves every sample off the first set's strata would do.
SECOND_SET_SHIFT = (0.6180339887498949, 0.41421356237309515)
#: Where the estimated errors differ by more than this factor, or cannot explain the methods'
#: disagreement, the hybrid takes the method with the smaller error instead of blending.
CHOOSE_RATIO = 3.0


#: The fail-safe's unbiased estimate (:func:`impastor.specular_lighting.specular_mis`): samples of
#: each technique per pixel, pixels per group of similar α at most (an even stride through the
#: group), and the generator's seed.
FAILSAFE_SAMPLES = 128
FAILSAFE_PIXELS = 256
FAILSAFE_SEED = 22
#: Refinement: while the choice is within this many standard deviations of the runner-up, up to
#: this many rounds add this many samples to this many pixels (those that add most to its variance).
FAILSAFE_MARGIN = 2.0
FAILSAFE_ROUNDS = 3
FAILSAFE_REFINE_PIXELS = 8
FAILSAFE_REFINE_SAMPLES = 2048


def _closest(candidates, U, se) -> tuple[int, int, float]:
    """The candidate with the smallest ``Σ (X − U)²``, the runner-up, and the margin in σ."""
    sums = [float(np.sum((X - U) ** 2)) for X in candidates]
    best, runner_up, margin = int(np.argmin(sums)), -1, np.inf
    for k, X in enumerate(candidates):
        if k != best:
            B = candidates[best]
            # Σ(X − U)² − Σ(B − U)² = Σ (X − B)(X + B − 2U): its variance is 4 Σ (X − B)² var U
            sigma = 2.0 * np.sqrt(np.sum((X - B) ** 2 * se**2))
            z = (sums[k] - sums[best]) / sigma if sigma > 0 else np.inf
            if z < margin:
                runner_up, margin = k, z
    return best, runner_up, margin


def _failsafe(P, N, V, a, light, lights, vis, backend, I_pl, I_fis, w_pl):
    """Per group of pixels with α within a half octave: which of the three to keep.

    Returns ``choice`` per pixel: 0 the hybrid, 1 the point lights, 2 FIS. Each is measured
    against an unbiased estimate ``U`` (:func:`specular_mis`) on a stride of the group's pixels:
    ``Σ (X − U)²`` is an unbiased estimate of ``Σ (X − I)² + Σ var U``, with the same second term
    for every X, so the smallest sum marks the smallest squared error. The few bright pixels that
    carry the sums' noise get more samples until the choice is clear (erratum E17).
    """
    choice = np.zeros(P.shape[0], dtype=np.int64)
    group = alpha_groups(a)
    for g in np.unique(group):
        members = np.flatnonzero(group == g)
        sub = members[:: -(-members.size // FAILSAFE_PIXELS)]
        seed = 1000 * (int(g) + 1000) + FAILSAFE_SEED  # non-negative for any α in use
        U, se = specular_mis(P[sub], N[sub], V[sub], a[sub], light, FAILSAFE_SAMPLES, seed)
        U, m = U.mean(axis=-1), np.full(sub.size, float(FAILSAFE_SAMPLES))
        pl = I_pl[sub].mean(axis=-1)
        if vis is not None:
            # U sees no shadows: compare the point lights' integration without them too
            pl = specular_point_lights(
                P[sub], N[sub], V[sub], a[sub], lights, None, backend=backend
            ).mean(axis=-1)
        fis = I_fis[sub].mean(axis=-1)
        candidates = (w_pl[sub] * pl + (1.0 - w_pl[sub]) * fis, pl, fis)
        best, runner_up, margin = _closest(candidates, U, se)
        for round_ in range(1, FAILSAFE_ROUNDS + 1):
            if margin > FAILSAFE_MARGIN:
                break
            # the pixels that carry most of the variance of the choice against the runner-up
            spread = (candidates[best] - candidates[runner_up]) ** 2 * se**2
            top = np.argsort(-spread, kind="stable")[:FAILSAFE_REFINE_PIXELS]
            more, more_se = specular_mis(
                P[sub][top], N[sub][top], V[sub][top], a[sub][top], light,
                FAILSAFE_REFINE_SAMPLES, seed + round_,
            )  # fmt: skip
            # pool the two unbiased estimates by their sample counts
            m_0, m_1 = m[top], float(FAILSAFE_REFINE_SAMPLES)
            U[top] = (m_0 * U[top] + m_1 * more.mean(axis=-1)) / (m_0 + m_1)
            se[top] = np.hypot(m_0 * se[top], m_1 * more_se) / (m_0 + m_1)
            m[top] = m_0 + m_1
            best, runner_up, margin = _closest(candidates, U, se)
        choice[members] = best
    return choice


def _hybrid_parts(P, N, V, a, light, lights, K, vis, backend):
    """Both estimates ``(P, C)``, their estimated absolute errors ``(P,)`` and the choice mask."""
    sigma = sigma_point_lights(light, lights)
    vis_sigma = None if vis is None else np.repeat(vis, 4, axis=1)
    I_pl = specular_point_lights(P, N, V, a, lights, vis, backend=backend)
    I_sigma = specular_point_lights(P, N, V, a, sigma, vis_sigma, backend=backend)
    I_fis = specular_fis(P, N, V, a, light, K, backend=backend)
    # An independent FIS estimate: K/2 samples of a rotated Hammersley set, its mip level not
    # biased upwards (less blur), so that the difference also sees the blur of the K estimate.
    I_half = specular_fis(P, N, V, a, light, K // 2, 0.0, backend, SECOND_SET_SHIFT)
    pl, sig, fis, half = (x.mean(axis=-1) for x in (I_pl, I_sigma, I_fis, I_half))
    # The Taylor expansion behind the sigma points holds where the lobe is wider than the region.
    narrow, x_pl = _lobe_over_region(P, N, V, a, light, lights)
    # Point lights: twice the sigma points' correction is their second-moment error; where the
    # lobe is narrower than the region, at least the one-point rule's error at the lobe's peak,
    # min(1, s²/(2σ²)) of the integral (FIS's estimate of it).
    peak = np.minimum(1.0, 1.0 / (2.0 * x_pl))
    e_pl = np.maximum(2.0 * np.abs(sig - pl), np.where(narrow, peak * np.abs(fis), 0.0))
    # FIS: error ∝ 1/K (stratified samples and the mip filter's blur, both ∝ 1/K), so
    # Richardson's rule with the independent K/2 set gives e_K ≈ |I_K − I_{K/2}|; the sets share
    # no sample, so a peak that one set misses and the other meets shows up in the difference.
    e_fis = np.abs(fis - half)
    # |I_pl − I_fis| ≤ e_pl + e_fis; the excess goes to the method outside its model's validity.
    excess = np.maximum(np.abs(pl - fis) - e_pl - e_fis, 0.0)
    e_pl = np.where(narrow, e_pl + excess, e_pl)
    e_fis = np.where(narrow, e_fis, e_fis + excess)
    # Fail-safe: blend only where the estimates are alike and explain the disagreement (the
    # unexplained part under a quarter of the two estimates' sum before it was added).
    ratio = np.maximum(e_pl, e_fis) / np.maximum(np.minimum(e_pl, e_fis), 1e-300)
    choose = (excess > 0.25 * (e_pl + e_fis - excess)) | (ratio > CHOOSE_RATIO)
    return I_pl, I_fis, e_pl, e_fis, choose


def hybrid_error_estimates(
    points,
    normals,
    views,
    alpha,
    light: PlaneLight,
    lights: PointLights,
    n_samples: int = 32,
    visibility=None,
    backend: str = "numpy",
):
    """Estimated relative errors of point lights and FIS at each pixel (specref's hybrid metric).

    The paper's "custom error minimization metric" is not given (§3.5.2, Ferwerda). specref
    estimates each method's error at each pixel from the estimates themselves:

    - **Point lights** put each region's energy at its centroid, which is exact to first order
      in the lobe's variation over the region. The second-moment error of the one-point rule,
      ``−½ Φ (σ_x² g_xx + σ_y² g_yy)``, is twice the difference between the point lights'
      estimate and the :func:`sigma_point_lights` one (Eq. (2), Ferwerda, with both).
      That expansion holds where the lobe is wider than the regions that carry the estimate,
      ``x = σ²/s² ≥ 1`` (``σ² = 2α²`` the lobe's angular variance, ``s²`` a region's angular
      spread); where it is narrower, the estimate is at least the one-point rule's error at the
      lobe's peak, ``min(1, s²/(2σ²))`` of the integral.
    - **FIS**: its error falls as 1/K (the K Hammersley samples are stratified, and the mip
      level's blur covers ``Ω_s = 1/(K p)``), so Richardson's rule with a second, independent
      FIS estimate of K/2 samples (a Cranley–Patterson-rotated set, :data:`SECOND_SET_SHIFT`,
      its mip level unbiased) gives ``e_K ≈ |I_K − I_{K/2}|``.
    - **Consistency**: the two errors must explain the methods' disagreement,
      ``|I_pl − I_fis| ≤ e_pl + e_fis``. What they leave unexplained is added to the point
      lights' error where ``x < 1`` (the point lights' estimate is outside its validity) and to
      FIS's elsewhere.

    No constant is fitted to a scene: 2 and ½ come from the expansions, 1/K from the sampler,
    and ``x = 1`` is where the lobe and the region have the same width. :func:`specular_hybrid`
    combines the two estimates with inverse-variance weights, or chooses one (the fail-safe).

    Parameters
    ----------
    points, normals, views : array_like, shape (..., 3)
    alpha : array_like, shape (...,)
    light : PlaneLight
    lights : PointLights
        The point lights the hybrid uses (their regions and spreads).
    n_samples : int
        K of FIS (>= 2: the error estimate uses K/2).
    visibility : array_like, shape (..., N), optional
        Shadowing per point light.
    backend : {"numpy", "numba"}

    Returns
    -------
    e_point_lights, e_fis : ndarray, shape (...,)
        Relative to the FIS estimate (channel mean).

    Examples
    --------
    >>> from impastor.point_lights import point_lights_from_plane
    >>> plane = PlaneLight(booth_light_image("fluorescent", 32, 16), (-0.6, 0.6, -1.0), (1, 0, 0),
    ...                    (0, 0, 1), 1.2, 0.8)
    >>> lights = point_lights_from_plane(plane, "median_cut", 32)
    >>> view = np.array([0.0, 0.6, 0.8])
    >>> e_pl, e_fis = hybrid_error_estimates(np.zeros((2, 3)), [0, 1, 0], view, [0.01, 0.4],
    ...                                      plane, lights, 32)
    >>> bool(e_fis[0] < e_pl[0]), bool(e_fis[1] > e_pl[1])
    (True, True)
    """
    shape, _, I_fis, e_pl, e_fis, _, _ = _evaluate(
        points, normals, views, alpha, light, lights, n_samples, visibility, backend
    )
    scale = np.maximum(np.abs(I_fis.mean(axis=-1)), 1e-300)
    return (e_pl / scale).reshape(shape), (e_fis / scale).reshape(shape)


def _evaluate(points, normals, views, alpha, light, lights, n_samples, visibility, backend):
    # the inputs of the public hybrid functions, checked and flattened, through _hybrid_parts
    P, N, V, a, shape = _flat(points, normals, views, alpha)
    K = require_positive_int(n_samples, "hybrid: n_samples", 1 << 20)
    require(K >= 2, f"hybrid: n_samples: must be >= 2 (the error estimate uses K/2), got {K}")
    vis = _visibility(visibility, shape, P.shape[0], len(lights.regions))
    return (shape, *_hybrid_parts(P, N, V, a, light, lights, K, vis, backend), (P, N, V, a, vis))


def _visibility(visibility, shape, n_points, n_lights):
    if visibility is None:
        return None
    vis = np.broadcast_to(np.asarray(visibility, float), (*shape, n_lights))
    return np.ascontiguousarray(vis.reshape(n_points, -1))


def specular_hybrid_parts(
    points,
    normals,
    views,
    alpha,
    light: PlaneLight,
    lights: PointLights,
    n_samples: int = 32,
    visibility=None,
    backend: str = "numpy",
    failsafe: bool = True,
) -> dict:
    """The hybrid and what it is made of: both estimates, their errors and the weights.

    :func:`specular_hybrid` returns ``["hybrid"]``; the report's error-against-α study reads the
    rest from the same evaluation instead of shading each method again.

    Parameters
    ----------
    points, normals, views, alpha, light, lights, n_samples, visibility, backend, failsafe
        As in :func:`specular_hybrid`.

    Returns
    -------
    dict
        ``hybrid``, ``point_lights``, ``fis``: shape (..., C); ``e_point_lights``, ``e_fis``
        (absolute, channel mean), ``w_point_lights`` (the point lights' weight, after the
        fail-safe) and ``failsafe`` (0: the per-pixel hybrid kept, 1: the point lights, 2: FIS):
        shape (...,).

    Examples
    --------
    >>> from impastor.point_lights import point_lights_from_plane
    >>> plane = PlaneLight(np.full((8, 8), 100.0), (-1, 1, -1), (1, 0, 0), (0, 0, 1), 2.0, 2.0)
    >>> lights = point_lights_from_plane(plane, "median_cut", 4)
    >>> up = np.array([0.0, 1.0, 0.0])
    >>> parts = specular_hybrid_parts(np.zeros(3), up, up, 0.05, plane, lights, 16)
    >>> sorted(parts)
    ['e_fis', 'e_point_lights', 'failsafe', 'fis', 'hybrid', 'point_lights', 'w_point_lights']
    >>> bool(0.0 <= parts["w_point_lights"] <= 1.0), int(parts["failsafe"])
    (True, 0)
    """
    shape, I_pl, I_fis, e_pl, e_fis, choose, flat = _evaluate(
        points, normals, views, alpha, light, lights, n_samples, visibility, backend
    )
    total = e_pl**2 + e_fis**2
    # Inverse-variance weights; where both errors vanish the two estimates agree: take FIS.
    w_pl = np.where(total > 0, e_fis**2 / np.where(total > 0, total, 1.0), 0.0)
    # The fail-safe: a choice, not a blend, where the estimates disagree.
    w_pl = np.where(choose, (e_pl < e_fis).astype(np.float64), w_pl)
    # The fail-safe: the hybrid, the point lights or FIS, whichever an unbiased estimate favours
    P, N, V, a, vis = flat  # the inputs as _evaluate checked and flattened them
    kept = np.zeros(P.shape[0], dtype=np.int64)
    if failsafe:
        kept = _failsafe(P, N, V, a, light, lights, vis, backend, I_pl, I_fis, w_pl)
    w_pl = np.select([kept == 1, kept == 2], [1.0, 0.0], w_pl)
    I_hybrid = w_pl[:, None] * I_pl + (1.0 - w_pl[:, None]) * I_fis
    return {
        "hybrid": I_hybrid.reshape((*shape, -1)),
        "point_lights": I_pl.reshape((*shape, -1)),
        "fis": I_fis.reshape((*shape, -1)),
        "e_point_lights": e_pl.reshape(shape),
        "e_fis": e_fis.reshape(shape),
        "w_point_lights": w_pl.reshape(shape),
        "failsafe": kept.reshape(shape),
    }


def specular_hybrid(
    points,
    normals,
    views,
    alpha,
    light: PlaneLight,
    lights: PointLights,
    n_samples: int = 32,
    visibility=None,
    backend: str = "numpy",
    failsafe: bool = True,
) -> np.ndarray:
    """Per-pixel hybrid of point lights and FIS (§3.5.2, Ferwerda).

    Eq. (4), Ferwerda, estimated at each pixel by both methods and combined with the weights that
    minimise the variance of the combination, given the errors :func:`hybrid_error_estimates`
    estimates: ``I = (e_fis² I_pl + e_pl² I_fis) / (e_pl² + e_fis²)``. Where one error is far
    below the other this is a switch; near the crossover it averages the two. Fail-safe: where
    the errors differ by more than :data:`CHOOSE_RATIO` or cannot explain the disagreement
    between the two estimates, it takes the one with the smaller error. Besides the two
    methods it evaluates the sigma-point lights (4N) and FIS with K/2 samples for the estimates
    (:func:`specular_hybrid_parts` returns them too).

    Parameters
    ----------
    points, normals, views, alpha, light, lights, n_samples, visibility, backend
        As in :func:`specular_point_lights` and :func:`specular_fis`; ``n_samples >= 2``.
    failsafe : bool
        Check the choice per group of similar α against an unbiased estimate (default); False
        keeps the per-pixel hybrid as its error estimates have it, for a scene whose tolerance
        does not need the check (:mod:`impastor.settings`).

    Returns
    -------
    ndarray, shape (..., C)

    Examples
    --------
    >>> from impastor.point_lights import point_lights_from_plane
    >>> plane = PlaneLight(np.full((8, 8), 100.0), (-1, 1, -1), (1, 0, 0), (0, 0, 1), 2.0, 2.0)
    >>> lights = point_lights_from_plane(plane, "median_cut", 4)
    >>> up = np.array([0.0, 1.0, 0.0])
    >>> specular_hybrid(np.zeros(3), up, up, 0.05, plane, lights, 16).round(2)
    array([99.51])
    """
    return specular_hybrid_parts(
        points, normals, views, alpha, light, lights, n_samples, visibility, backend, failsafe
    )["hybrid"]


#: What a group of similar α may take instead of the per-pixel hybrid, cheapest first: the point
#: lights alone (N evaluations per pixel), FIS alone (K), or the hybrid itself (5 N + 3 K / 2).
GROUP_METHODS = ("point_lights", "fis", "hybrid")


def alpha_groups(alpha) -> np.ndarray:
    """Half-octave groups of roughness, ``⌊2 log2 α⌋``: the fail-safe's groups, and the settings'.

    Examples
    --------
    >>> alpha_groups([0.01, 0.1, 0.12, 0.5]).tolist()
    [-14, -7, -7, -2]
    """
    return np.floor(2.0 * np.log2(np.asarray(alpha, dtype=np.float64))).astype(np.int64)


def check_group_methods(methods) -> dict:
    """``methods`` as ``{int group: method}`` after checking it (one-line error).

    Examples
    --------
    >>> check_group_methods({-4: "fis", np.int64(-3): "point_lights"})
    {-4: 'fis', -3: 'point_lights'}
    >>> check_group_methods({"rough": "fis"})
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: specular by α group: group 'rough': must be an integer (2 log2 α,
    floored)
    """
    checked = {}
    for group, method in dict(methods or {}).items():
        require(
            isinstance(group, int | np.integer) and not isinstance(group, bool),
            f"specular by α group: group {group!r}: must be an integer (2 log2 α, floored)",
        )
        require(
            method in GROUP_METHODS,
            f"specular by α group: group {group}: method must be one of "
            f"{', '.join(GROUP_METHODS)}, got {method!r}",
        )
        checked[int(group)] = str(method)
    return checked


def specular_by_alpha_group(
    points,
    normals,
    views,
    alpha,
    light: PlaneLight,
    lights: PointLights,
    n_samples: int = 32,
    visibility=None,
    backend: str = "numpy",
    failsafe: bool = True,
    methods=None,
) -> np.ndarray:
    """Eq. (4), Ferwerda, by one method per group of similar α: point lights, FIS or the hybrid.

    Where the hybrid (:func:`specular_hybrid`) keeps the point lights at nearly every pixel of a
    group, or FIS at nearly every one, that method alone gives the group the same light for a
    fraction of the cost: the hybrid evaluates both, the sigma-point lights (4 N) and a second FIS
    set (K/2) at every pixel. ``methods`` says which groups (:func:`alpha_groups`) take which
    method of :data:`GROUP_METHODS`; a group it does not name takes the hybrid. The painting's
    settings choose it from a tolerance (``impastor.settings``, erratum E96; specref's, not the
    paper's).

    Parameters
    ----------
    points, normals, views, alpha, light, lights, n_samples, visibility, backend, failsafe
        As in :func:`specular_hybrid` (``failsafe`` for the groups on the hybrid).
    methods : mapping of int to str, optional
        Group to method; None: the hybrid everywhere.

    Returns
    -------
    ndarray, shape (..., C)
        Each pixel as its group's method has it; a group's pixels as that method alone would
        shade them (the hybrid's fail-safe works per group, so it sees the same pixels).

    Examples
    --------
    >>> from impastor.point_lights import point_lights_from_plane
    >>> plane = PlaneLight(np.full((8, 8), 100.0), (-1, 1, -1), (1, 0, 0), (0, 0, 1), 2.0, 2.0)
    >>> lights = point_lights_from_plane(plane, "median_cut", 4)
    >>> up = np.array([0.0, 1.0, 0.0])
    >>> P, N, a = np.zeros((2, 3)), np.tile(up, (2, 1)), np.array([0.05, 0.3])
    >>> alpha_groups(a).tolist()
    [-9, -4]
    >>> I = specular_by_alpha_group(P, N, N, a, plane, lights, 16, methods={-4: "point_lights"})
    >>> bool(np.allclose(I[1], specular_point_lights(P[1], up, up, 0.3, lights)))
    True
    """
    methods = check_group_methods(methods)
    P, N, V, a, shape = _flat(points, normals, views, alpha)
    vis = _visibility(visibility, shape, P.shape[0], len(lights.regions))
    unique, inverse = np.unique(alpha_groups(a), return_inverse=True)
    pixel_method = np.array([methods.get(int(g), "hybrid") for g in unique])[inverse]
    out = np.zeros((P.shape[0], light.image.shape[-1] if light.image.ndim == 3 else 1))
    for method in GROUP_METHODS:
        take = np.flatnonzero(pixel_method == method)
        if take.size == 0:
            continue
        p, n, v, a_t = P[take], N[take], V[take], a[take]
        sub_vis = None if vis is None else vis[take]
        if method == "point_lights":  # Eq. (2), Ferwerda, with the lobe
            out[take] = specular_point_lights(p, n, v, a_t, lights, sub_vis, backend=backend)
        elif method == "fis":
            out[take] = specular_fis(p, n, v, a_t, light, n_samples, backend=backend)
        else:
            out[take] = specular_hybrid(
                p, n, v, a_t, light, lights, n_samples, sub_vis, backend, failsafe
            )
    return out.reshape((*shape, -1))


def _example_scene(rng):
    plane = PlaneLight(
        booth_light_image("fluorescent", 16, 8), (-0.6, 0.6, -1.0), (1, 0, 0), (0, 0, 1), 1.2, 0.8
    )
    n = 5
    points = np.stack([rng.uniform(-0.1, 0.1, n), np.zeros(n), rng.uniform(-0.1, 0.1, n)], axis=-1)
    normals = np.tile([0.0, 1.0, 0.0], (n, 1))
    eye = np.array([0.0, 0.5, 0.6])
    views = eye - points
    views /= np.linalg.norm(views, axis=-1, keepdims=True)
    alpha = rng.uniform(0.02, 0.4, n)
    lights = point_lights_from_plane(plane, "median_cut", 8)
    return points, normals, views, alpha, plane, lights


# How each method runs on the inputs of ``_example_scene``: ``n_samples`` FIS samples per point
# (fis, hybrid), ``supersample²`` sub-pixels per light pixel (brute_force); a method ignores the
# setting it has no use for. Tests use the defaults; the benchmarks ask for more samples.


def _call_point_lights(x, backend, n_samples=16, supersample=2):
    return specular_point_lights(*x[:4], x[5], backend=backend)


def _call_fis(x, backend, n_samples=16, supersample=2):
    return specular_fis(*x[:5], n_samples, backend=backend)


def _call_hybrid(x, backend, n_samples=16, supersample=2):
    return specular_hybrid(*x[:6], n_samples, backend=backend)


def _call_brute_force(x, backend, n_samples=16, supersample=2):
    return specular_brute_force(*x[:5], supersample, backend=backend)


@dataclass(frozen=True, kw_only=True)
class SpecularMethod(Method):
    """A specular lighting method of the Ward–Dür lobe.

    ``reference`` is the NumPy function (``backend`` selects the numba twin named by ``kernel``);
    ``example_inputs(rng)`` returns ``(points, normals, views, alpha, plane, lights)``.

    Parameters
    ----------
    run : callable
        ``run(inputs, backend, n_samples=16, supersample=2)``: the method on the inputs of
        ``example_inputs``, each method taking the ones it uses (the methods differ in what they
        read: the point lights, the plane, a sample count or a sub-pixel count).
    """

    run: Callable[..., np.ndarray]


#: Specular lighting methods by key.
SPECULAR_METHODS = Registry("specular lighting", SpecularMethod)
SPECULAR_METHODS.register(
    SpecularMethod(
        "point_lights",
        specular_point_lights,
        specular_point_lights_kernel,
        "Eq. (2), Ferwerda",
        _example_scene,
        run=_call_point_lights,
    )
)
SPECULAR_METHODS.register(
    SpecularMethod(
        "fis",
        specular_fis,
        specular_fis_kernel,
        "Eq. (4), Ferwerda (FIS with the lookup of Eqs. (5)-(8), Ferwerda)",
        _example_scene,
        run=_call_fis,
    )
)
SPECULAR_METHODS.register(
    SpecularMethod(
        "hybrid",
        specular_hybrid,
        None,
        "Eq. (4), Ferwerda",
        _example_scene,
        run=_call_hybrid,
    )
)
SPECULAR_METHODS.register(
    SpecularMethod(
        "brute_force",
        specular_brute_force,
        specular_brute_force_kernel,
        "Eq. (4), Ferwerda",
        _example_scene,
        run=_call_brute_force,
    )
)

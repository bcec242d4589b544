"""The per-pixel hybrid of point lights and FIS (§3.5.2, Ferwerda), and the specular registry.

ImpastoR renders specular reflection per pixel with either median-cut point lights or filtered
importance sampling, chosen by a "custom error minimization metric" that the paper does not give
(§3.5.2, Ferwerda). specref's metric, :func:`hybrid_error_estimates`, predicts each method's
relative error from the lobe's width, the light's layout and the sample count;
:func:`specular_hybrid` combines the two estimates (``reference.specular_lighting``) with
inverse-variance weights.

:data:`SPECULAR_METHODS` registers all four specular methods (point lights, FIS, the hybrid and
the brute-force reference); it lives here, beside the hybrid that uses the others.

References
----------
- J. A. Ferwerda, "ImpastoR: A realistic surface display system", Vision Research 109, 2015.
"""

from __future__ import annotations

import numpy as np

from reference._specular_lighting_kernels import (
    specular_brute_force_kernel,
    specular_fis_kernel,
    specular_point_lights_kernel,
)
from reference.arealights import PlaneLight, booth_light_image, light_plane_uv
from reference.errors import require_positive_int
from reference.point_lights import PointLights, point_lights_from_plane
from reference.registry import Method, Registry
from reference.specular_lighting import (
    _flat,
    mip_lookup,
    mip_pyramid,
    specular_brute_force,
    specular_fis,
    specular_point_lights,
)

__all__ = ["SPECULAR_METHODS", "hybrid_error_estimates", "specular_hybrid"]


# --- the hybrid ----------------------------------------------------------------------------------


def _lobe_scales(P, N, V, a, light: PlaneLight, lights: PointLights):
    """Per pixel: ``x_pl = σ²/s²`` and ``x_fis = Ω_lobe/Ω_texel`` (see hybrid_error_estimates)."""
    H, W = light.shape
    to_light = lights.position[None] - P[:, None]
    d2 = np.einsum("pni,pni->pn", to_light, to_light)
    cos_l = np.maximum(-(to_light @ light.n_light) / np.sqrt(d2), 0.0)
    spread = lights.spread * cos_l / d2  # sr
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
    sigma2 = 2.0 * a**2
    x_pl = sigma2 / np.maximum(s2, 1e-300)
    safe_d = np.where(on, d, 1.0)
    omega_texel = light.pixel_area * np.where(on, -(mirror @ light.n_light), 1.0) / safe_d**2
    omega_lobe = 4.0 * np.pi * a**2 * cos_o
    x_fis = omega_lobe / omega_texel
    return x_pl, x_fis, on, mirror, a_uv, b_uv, d, cos_o


def hybrid_error_estimates(points, normals, views, alpha, light: PlaneLight, lights, n_samples):
    """Predicted relative errors of point lights and FIS at each pixel (specref's hybrid metric).

    The paper's "custom error minimization metric" is not given (§3.5.2, Ferwerda). specref
    predicts each method's error from the lobe's width, the light's layout and the sample count:

    - **Point lights** put each region's energy at its centroid. For a lobe of angular variance
      ``σ² = 2α²`` (Ward's ``exp(−tan²θ_h/α²)`` with ``θ_i ≈ 2θ_h``; both axes) the one-point rule
      errs by its second-moment term, ``(s²/4)|∇²g|/g = s²/(2σ²)`` at the lobe's peak, with ``s²``
      the energy spread (``PointLights.spread`` × cos θ_l / d², sr) of the median-cut region that
      the mirror direction meets (the mean region's where it misses the light):
      ``e_pl = min(1, s² / (4α²))``.
    - **FIS** draws K samples in proportion to the lobe, so its weights are nearly constant and
      its error is that of K samples of the light itself, ``CV / sqrt(K)``, with CV the light's
      coefficient of variation over the lobe's footprint, read from mip pyramids of L and L² at
      the level whose texel covers ``Ω_lobe = 4π α² cos θ_o`` (one over the lobe pdf's peak)
      around the mirror direction. The part of the lobe that misses the light adds the binomial
      noise ``sqrt((1 − q)/(K q))``, ``q = min(1, Ω_light / (4 Ω_lobe))``.

    Every constant comes from these models; none is fitted to a scene. :func:`specular_hybrid`
    combines the two estimates with inverse-variance weights.

    Parameters
    ----------
    points, normals, views : array_like, shape (..., 3)
    alpha : array_like, shape (...,)
    light : PlaneLight
    lights : PointLights
        The point lights the hybrid uses (their regions and spreads).
    n_samples : int
        K of FIS.

    Returns
    -------
    e_point_lights, e_fis : ndarray, shape (...,)

    Examples
    --------
    >>> from reference.arealights import PlaneLight, booth_light_image
    >>> from reference.point_lights import point_lights_from_plane
    >>> plane = PlaneLight(booth_light_image("fluorescent", 32, 16), (-0.6, 0.6, -1.0), (1, 0, 0),
    ...                    (0, 0, 1), 1.2, 0.8)
    >>> lights = point_lights_from_plane(plane, "median_cut", 32)
    >>> view = np.array([0.0, 0.6, 0.8])
    >>> e_pl, e_fis = hybrid_error_estimates(np.zeros((2, 3)), [0, 1, 0], view, [0.01, 0.4],
    ...                                      plane, lights, 32)
    >>> bool(e_fis[0] < e_pl[0]), bool(e_fis[1] > e_pl[1])
    (True, True)
    """
    P, N, V, a, shape = _flat(points, normals, views, alpha)
    K = require_positive_int(n_samples, "hybrid: n_samples", 1 << 20)
    x_pl, _, on, mirror, a_uv, b_uv, d, cos_o = _lobe_scales(P, N, V, a, light, lights)
    # Point lights: the one-point rule's second-moment error at the lobe's peak, s²/(2σ²).
    e_point_lights = np.minimum(1.0, 1.0 / (2.0 * x_pl))
    # FIS: K lobe-proportional samples of the light: CV/√K over the lobe's footprint.
    omega_lobe = 4.0 * np.pi * a**2 * cos_o
    luminance = light.image.mean(axis=-1)
    mean_levels, square_levels = mip_pyramid(luminance), mip_pyramid(luminance**2)
    safe_d = np.where(on, d, 1.0)
    omega_texel = light.pixel_area * np.where(on, -(mirror @ light.n_light), 1.0) / safe_d**2
    level = np.maximum(0.5 * np.log2(omega_lobe / omega_texel), 0.0)
    a_on, b_on = np.where(on, a_uv, 0.5), np.where(on, b_uv, 0.5)
    mean = mip_lookup(mean_levels, a_on, b_on, level)
    square = mip_lookup(square_levels, a_on, b_on, level)
    safe_mean = np.where(mean > 0, mean, 1.0)
    cv = np.where(on & (mean > 0), np.sqrt(np.maximum(square - mean**2, 0.0)) / safe_mean, 1.0)
    # The part of the lobe that misses the light: binomial noise of the hits.
    area = np.array([(y1 - y0) * (x1 - x0) for y0, y1, x0, x1 in lights.regions])
    to_light = lights.position[None] - P[:, None]
    d2 = np.einsum("pni,pni->pn", to_light, to_light)
    cos_l = np.maximum(-(to_light @ light.n_light) / np.sqrt(d2), 0.0)
    omega_light = (area * light.pixel_area * cos_l / d2).sum(axis=1)
    q = np.clip(omega_light / (4.0 * omega_lobe), 1e-12, 1.0)
    e_fis = cv / np.sqrt(K) + np.sqrt((1.0 - q) / (K * q))
    return e_point_lights.reshape(shape), e_fis.reshape(shape)


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
) -> np.ndarray:
    """Per-pixel hybrid of point lights and FIS (§3.5.2, Ferwerda).

    Eq. (4), Ferwerda, estimated at each pixel by both methods and combined with the weights that
    minimise the variance of the combination, given the errors :func:`hybrid_error_estimates`
    predicts: ``I = (e_fis² I_pl + e_pl² I_fis) / (e_pl² + e_fis²)``. Where one prediction is far
    below the other this is a switch; near the crossover it averages the two.

    Parameters
    ----------
    points, normals, views, alpha, light, lights, n_samples, visibility, backend
        As in :func:`specular_point_lights` and :func:`specular_fis`.

    Returns
    -------
    ndarray, shape (..., C)

    Examples
    --------
    >>> from reference.arealights import PlaneLight
    >>> from reference.point_lights import point_lights_from_plane
    >>> plane = PlaneLight(np.full((8, 8), 100.0), (-1, 1, -1), (1, 0, 0), (0, 0, 1), 2.0, 2.0)
    >>> lights = point_lights_from_plane(plane, "median_cut", 4)
    >>> up = np.array([0.0, 1.0, 0.0])
    >>> specular_hybrid(np.zeros(3), up, up, 0.05, plane, lights, 16).round(2)
    array([99.51])
    """
    P, N, V, a, shape = _flat(points, normals, views, alpha)
    e_pl, e_fis = hybrid_error_estimates(P, N, V, a, light, lights, n_samples)
    vis = None
    if visibility is not None:
        vis = np.broadcast_to(np.asarray(visibility, float), (*shape, len(lights.regions)))
        vis = vis.reshape(P.shape[0], -1)
    w_pl = (e_fis**2 / np.maximum(e_pl**2 + e_fis**2, 1e-300))[:, None]
    out = np.zeros((P.shape[0], light.image.shape[-1]))
    # Evaluate each method only where its weight matters (> 1e-6).
    need_pl, need_fis = w_pl[:, 0] > 1e-6, w_pl[:, 0] < 1.0 - 1e-6
    if need_pl.any():
        k = need_pl
        out[k] += w_pl[k] * specular_point_lights(
            P[k], N[k], V[k], a[k], lights, None if vis is None else vis[k], backend=backend
        )
    if need_fis.any():
        k = need_fis
        out[k] += (1.0 - w_pl[k]) * specular_fis(
            P[k], N[k], V[k], a[k], light, n_samples, backend=backend
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


#: Specular lighting methods; ``reference`` is the NumPy function (``backend`` selects the numba
#: twin named by ``kernel``); ``example_inputs(rng)`` returns ``(points, normals, views, alpha,
#: plane, lights)``; ``extra["call"](method_fn, inputs, backend)`` runs it on those inputs.
SPECULAR_METHODS = Registry("specular lighting")
SPECULAR_METHODS.register(
    Method(
        "point_lights",
        specular_point_lights,
        specular_point_lights_kernel,
        "Eq. (2), Ferwerda",
        _example_scene,
        extra={"call": lambda x, backend: specular_point_lights(*x[:4], x[5], backend=backend)},
    )
)
SPECULAR_METHODS.register(
    Method(
        "fis",
        specular_fis,
        specular_fis_kernel,
        "Eq. (4), Ferwerda (FIS with the lookup of Eqs. (5)-(8))",
        _example_scene,
        extra={"call": lambda x, backend: specular_fis(*x[:5], 16, backend=backend)},
    )
)
SPECULAR_METHODS.register(
    Method(
        "hybrid",
        specular_hybrid,
        None,
        "Eq. (4), Ferwerda",
        _example_scene,
        extra={"call": lambda x, backend: specular_hybrid(*x[:6], 16, backend=backend)},
    )
)
SPECULAR_METHODS.register(
    Method(
        "brute_force",
        specular_brute_force,
        specular_brute_force_kernel,
        "Eq. (4), Ferwerda",
        _example_scene,
        extra={"call": lambda x, backend: specular_brute_force(*x[:5], 2, backend=backend)},
    )
)

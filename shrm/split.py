"""SH for the low frequencies, angular space for the rest: Herbert et al.'s §9 future work.

§9, Herbert et al.: "couple SH-based BRDF rendering with a straightforward angular-space method
for the highest-frequency portion". An environment ``L`` is split texel by texel at a luminance
threshold τ (erratum E91):

    L_low(ω) = L(ω) · min(1, τ / Y(ω)),        L_res(ω) = L(ω) − L_low(ω),

where ``Y(ω)`` is the texel's luminance. Both parts are non-negative, each texel keeps its
chromaticity, and ``L_low <= τ`` (in Y) everywhere: the bright, compact sources (the sun, studio
lamps) go to the residual, whose texels are few. The reflected radiance is the sum of

- the SHRM of ``L_low`` (§5.5-5.6, Herbert et al.; :mod:`shrm.shrm`), clamped at zero per band;
- the residual integrated in angular space per pixel, ``Σ_k f(ω_k, v, n) max(n·ω_k, 0) L_res,k w_k``
  over the residual texels with the environment's own quadrature weights (:func:`angular_sum`),
  with each pixel's own view.

**The bound.** The SHRM of order F sees ``L_low`` through its SH coefficients of degree l <= F
only, so its lighting truncation error at a pixel of normal n and view v is
``Σ_{l>F} Σ_m L_lm k_lm(n, v)`` with ``k(ω) = f(ω, v, n) max(n·ω, 0)`` the pixel's kernel. By
Cauchy–Schwarz per degree it is at most ``B = Σ_{l>F} ‖L_l‖ κ_l`` with ``‖L_l‖`` the power of
degree l of ``L_low`` and ``κ_l`` the largest power of degree l of the kernel over views
(:func:`kernel_spectrum`; the kernel's rotations about n leave ``‖k_l‖`` unchanged). ``B``
falls with τ, and ``τ = 0`` (everything residual) is the brute force. Clamping the SH part at
zero never moves it further from the truth, which is non-negative, so the clamp keeps the bound
and no pixel is ever negative. ``B`` does not cover the view order P (chosen from the BRDF's view
tail) nor the cube-map interpolation: :func:`split_renderer` spot-checks the renderer against
brute force at a few points, the most grazing among them, and states that error too. Where the
view is grazing (``n·v <`` :data:`NV_ANGULAR`) the reflection frame's view order runs out, and
there the low part is summed in angular space as well, over its texels merged into blocks
(:func:`merge_texels`, erratum E94).

References
----------
- F. Herbert, J. Kirkenaer, O. Unter Ecker, "Achieving a Multi-spectral Virtual Reality", 2004.
- R. Ramamoorthi, P. Hanrahan, "Frequency Space Environment Map Rendering", SIGGRAPH 2002.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.errors import require, require_choice
from shrm._kernels import _pair_sum_kernel

__all__ = [
    "EnvironmentSplit",
    "SplitRenderer",
    "SplitSettings",
    "angular_sum",
    "choose_split_settings",
    "degree_power",
    "environment_spectrum",
    "kernel_spectrum",
    "merge_texels",
    "split_create",
    "split_environment",
    "split_renderer",
    "split_shade",
    "truncation_bound",
]

#: BRDF × texel pairs per block of :func:`angular_sum` (memory, not accuracy).
PAIRS_PER_BLOCK = 1 << 18


def angular_sum(env, brdf, params: dict, normals, views, backend: str = "numba") -> np.ndarray:
    """``Σ_k f(ω_k, v, n) max(n·ω_k, 0) L_k w_k`` per point: reflection in angular space.

    The reflection equation (R&H 2002) summed over the texels of ``env`` with their quadrature
    weights; every point has its own normal and view. With all texels of a map this is the
    brute-force oracle; with the residual texels of :func:`split_environment`, the angular half
    of the split.

    Parameters
    ----------
    env : tuple
        ``(directions (K, 3), weights (K,) in sr, radiance (K, C))``
        (:func:`shrm.shrm_oracles.env_quadrature` or a subset of it).
    brdf : callable
        ``brdf(wi, wo, normal, **params) -> (..., C)`` (``BRDF_METHODS`` convention).
    params : dict
    normals, views : ndarray, shape (N, 3)
        Unit normals and unit directions towards the viewer.
    backend : {"numba", "numpy"}
        Who sums a spectral BRDF's pairs: ``shrm._kernels._pair_sum_kernel``, or NumPy's
        gather and ``reduceat`` (the readable form; they agree to 1e-12).

    Returns
    -------
    ndarray, shape (N, C)

    Examples
    --------
    >>> from reference.materials.brdf import brdf_lambert
    >>> from shrm.shrm_oracles import env_quadrature
    >>> n = np.array([[0.0, 1.0, 0.0]])
    >>> angular_sum(env_quadrature(np.ones((32, 64, 1))), brdf_lambert, {"rho_d": [1.0]}, n,
    ...             n).round(3)                # a white furnace: the albedo
    array([[1.]])
    """
    require_choice(backend, ("numba", "numpy"), "backend")
    d, w, L = env
    normals = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    views = np.broadcast_to(np.asarray(views, dtype=np.float64), normals.shape)
    C = np.asarray(L).shape[1]
    out = np.zeros((normals.shape[0], C))
    if d.shape[0] == 0 or normals.shape[0] == 0:
        return out
    Lw = L * w[:, None]
    params = _grey_once(params, C)
    step_k = max(1, min(d.shape[0], PAIRS_PER_BLOCK // max(1, C)))
    step_p = max(1, PAIRS_PER_BLOCK // step_k)
    for p in range(0, normals.shape[0], step_p):
        n, v = normals[p : p + step_p], views[p : p + step_p]
        for k in range(0, d.shape[0], step_k):
            cosine = n @ d[k : k + step_k].T
            # only the pairs above the horizon add anything (cos θ_i ≤ 0 there): about half
            i, j = np.nonzero(cosine > 0.0)  # row-major: each point's pairs together
            if i.size == 0:
                continue
            f = brdf(d[k + j], v[i], n[i], **params)
            if f.shape[-1] == 1:  # a grey BRDF: the sum below is a matrix product
                A = np.zeros_like(cosine)
                A[i, j] = f[:, 0] * cosine[i, j]
                # The reflection equation (R&H 2002): Σ_k (f cos θ_i) L_k w_k
                out[p : p + step_p] += A @ Lw[k : k + step_k]
                continue
            if backend == "numba":  # the same sum, pair by pair, without the temporaries
                _pair_sum_kernel(f, cosine[i, j], Lw, k + j, p + i, out)
                continue
            # The reflection equation (R&H 2002): Σ_k f cos θ_i L_k w_k
            terms = f * (cosine[i, j][:, None] * Lw[k + j])
            first = np.flatnonzero(np.r_[True, i[1:] != i[:-1]])
            out[p + i[first]] += np.add.reduceat(terms, first, axis=0)
    return out


def _grey_once(params: dict, C: int) -> dict:
    """``params`` with each per-band parameter that is equal in all ``C`` bands given once.

    A BRDF whose parameters are then all single values is evaluated once per pair of directions,
    not once per band (the same values), and :func:`angular_sum` sums it as a matrix product.
    """
    return {
        key: value[:1]
        if isinstance(value, np.ndarray) and value.shape == (C,) and np.ptp(value) == 0
        else value
        for key, value in params.items()
    }


@dataclass(frozen=True)
class EnvironmentSplit:
    """An environment split at luminance τ: a band-limited part and the residual texels.

    Attributes
    ----------
    low : ndarray, shape (H, W, C)
        ``L · min(1, τ/Y)``, for the SHRM.
    index : ndarray, shape (K,)
        Flat indices (row-major) of the residual texels.
    residual : ndarray, shape (K, C)
        ``L − L_low`` at those texels.
    tau : float
        The threshold, in luminance (``Y`` of the radiance with the scene's band weights).
    """

    low: np.ndarray
    index: np.ndarray
    residual: np.ndarray
    tau: float


def split_environment(radiance, y_weights, tau: float) -> EnvironmentSplit:
    """Split a spectral environment at luminance τ into ``L_low`` and residual texels (E91).

    §9, Herbert et al. (the split of the module docstring): ``L_low = L min(1, τ/Y)``.

    Parameters
    ----------
    radiance : ndarray, shape (H, W, C)
        Spectral radiance, >= 0.
    y_weights : ndarray, shape (C,)
        Band weights of Y (``ctx.weights(None)[:, 1]``).
    tau : float
        Threshold >= 0; ``inf`` keeps everything in ``low``, 0 puts every lit texel in the residual.

    Returns
    -------
    EnvironmentSplit

    Examples
    --------
    >>> s = split_environment(np.array([[[1.0], [4.0]]]), np.array([1.0]), 2.0)
    >>> s.low[..., 0].tolist(), s.index.tolist(), s.residual.tolist()
    ([[1.0, 2.0]], [1], [[2.0]])
    """
    require(tau >= 0, f"SHRM split: tau: must be >= 0, got {tau!r}")
    radiance = np.asarray(radiance, dtype=np.float64)
    Y = radiance @ np.asarray(y_weights, dtype=np.float64)
    above = tau < Y
    scale = np.ones_like(Y)
    # §9, Herbert et al.: L_low = L min(1, τ/Y); the rest of each bright texel is the residual
    scale[above] = tau / Y[above]
    low = radiance * scale[..., None]
    index = np.flatnonzero(above)
    flat = radiance.reshape(-1, radiance.shape[-1])
    residual = flat[index] - low.reshape(flat.shape)[index]
    return EnvironmentSplit(low, index, residual, float(tau))


def degree_power(coeffs) -> np.ndarray:
    """``‖c_l‖ = sqrt(Σ_m c_lm²)`` per degree: ``(C, (L+1)²) -> (C, L+1)``.

    Examples
    --------
    >>> degree_power(np.array([[1.0, 3.0, 0.0, 4.0]]))
    array([[1., 5.]])
    """
    c = np.asarray(coeffs, dtype=np.float64)
    L = round(np.sqrt(c.shape[-1])) - 1
    l_of = np.repeat(np.arange(L + 1), 2 * np.arange(L + 1) + 1)
    power = np.zeros((*c.shape[:-1], L + 1))
    np.add.at(power.T, l_of, (c**2).T)
    return np.sqrt(power)


def _spectrum_and_tail(image, order: int):
    """Degree powers to ``order`` and the Parseval tail beyond it, per channel."""
    from shrm.shrm_oracles import env_quadrature
    from shrm.transform import project_latlong

    order = min(order, image.shape[1] // 2 - 1)
    c = project_latlong(image, order, backend="ducc0")
    power = degree_power(c)
    _, w, values = env_quadrature(image)
    total = (values**2 * w[:, None]).sum(0)
    # Parseval: ‖f‖² = Σ_l ‖f_l‖², so the degrees beyond the order hold the rest
    tail = np.sqrt(np.maximum(total - (power**2).sum(-1), 0.0))
    return power, tail


def environment_spectrum(image, order: int) -> tuple[np.ndarray, np.ndarray]:
    """The environment's power per SH degree, ``‖L_l‖`` for l <= order, and its tail beyond.

    R&H 2002 (SH projection, Fejér-1 quadrature of :func:`shrm.transform.project_latlong`).

    Parameters
    ----------
    image : ndarray, shape (H, 2H, C)
    order : int
        Highest degree (at most ``H − 1``).

    Returns
    -------
    power : ndarray, shape (C, order+1)
    tail : ndarray, shape (C,)
        ``sqrt(Σ_{l>order} ‖L_l‖²)`` by Parseval.

    Examples
    --------
    >>> p, t = environment_spectrum(np.ones((16, 32, 1)), 4)
    >>> p.round(4).tolist(), t.round(4).tolist()   # a constant: all power in l = 0, sqrt(4π)
    ([[3.5449, 0.0, 0.0, 0.0, 0.0]], [0.0])
    """
    return _spectrum_and_tail(image, order)


def kernel_spectrum(brdf, params: dict, order: int, rows: int = 256, views: int = 7):
    """The largest power per SH degree of a pixel's kernel ``f(ω, v, n) max(n·ω, 0)`` over views.

    R&H 2002: the kernel with n = +y and views at ``views`` polar angles from 0 to 85°,
    projected on a ``rows × 2 rows`` lat-long grid; a rotation about n leaves each degree's
    power unchanged, so these views cover every view.

    Parameters
    ----------
    brdf, params
        The BRDF (``BRDF_METHODS`` convention).
    order : int
        Highest degree, < rows.
    rows : int
        Lat-long rows of the projection grid.
    views : int
        View angles.

    Returns
    -------
    power : ndarray, shape (C, order+1)
        ``max_v ‖k_l(v)‖``.
    tail : ndarray, shape (C,)
        ``max_v`` of the Parseval tail beyond ``order``.

    Examples
    --------
    >>> from reference.materials.brdf import brdf_lambert
    >>> p, t = kernel_spectrum(brdf_lambert, {"rho_d": [np.pi]}, 2, rows=128, views=2)
    >>> p.round(3).tolist()        # max(cos θ, 0): sqrt(π)/2, sqrt(π/3), sqrt(5π)/8
    [[0.886, 1.023, 0.495]]
    """
    from reference.geometry.envmap import latlong_pixel_directions

    require(order < rows, f"kernel spectrum: order {order} needs more than {rows} rows")
    omega = latlong_pixel_directions(rows, 2 * rows)
    n = np.array([0.0, 1.0, 0.0])
    power, tail = None, None
    for theta_o in np.radians(np.linspace(0.0, 85.0, views)):
        v = np.array([np.sin(theta_o), np.cos(theta_o), 0.0])
        wo, nn = np.broadcast_to(v, omega.shape), np.broadcast_to(n, omega.shape)
        k = brdf(omega, wo, nn, **params) * np.maximum(omega[..., 1], 0.0)[..., None]
        p, t = _spectrum_and_tail(k, order)
        power = p if power is None else np.maximum(power, p)
        tail = t if tail is None else np.maximum(tail, t)
    return power, tail


def truncation_bound(env_power, env_tail, kernel_power, kernel_tail, F: int) -> np.ndarray:
    """``B = Σ_{l>F} ‖L_l‖ κ_l`` (plus the tails' product): the lighting truncation bound per band.

    The module docstring's Cauchy–Schwarz bound on the SHRM's lighting truncation at order F.

    Parameters
    ----------
    env_power, kernel_power : ndarray, shape (C, L+1)
        :func:`environment_spectrum` and :func:`kernel_spectrum` to the same order (or C = 1
        broadcast).
    env_tail, kernel_tail : ndarray, shape (C,)
    F : int

    Returns
    -------
    ndarray, shape (C,)

    Examples
    --------
    >>> truncation_bound(np.array([[1.0, 0.5, 0.2]]), np.array([0.1]),
    ...                  np.array([[1.0, 0.4, 0.3]]), np.array([0.2]), 1).round(3)
    array([0.08])
    """
    high = (np.asarray(env_power)[..., F + 1 :] * np.asarray(kernel_power)[..., F + 1 :]).sum(-1)
    return high + np.asarray(env_tail) * np.asarray(kernel_tail)


#: Residual fractions of the texels tried by :func:`choose_split_settings`, smallest first.
RESIDUAL_FRACTIONS = (0.0, 1e-4, 2e-4, 5e-4, 1e-3, 2e-3, 5e-3, 1e-2, 2e-2)
#: Highest kernel degree measured, the largest F, the largest view order (§5.5 uses 2-10; 18
#: here: at 10 grazing pixels miss 1 % of the peak, E92) and the order the view tail is measured to.
KERNEL_ORDER, F_MAX, P_MAX, P_FIT = 128, 32, 18, 20
#: Relative L2 tails of the kernel (lighting) and of the BRDF coefficients (view) (E92).
F_TAIL, P_TAIL = 0.02, 0.01
#: Pixels sampled for the lower bound of the image's peak.
PEAK_SAMPLES = 128
#: Points of the spot check against brute force (half the most grazing, half spread) (E92).
CHECK_POINTS = 8
#: Points seen more grazing than this (n·v) are shaded wholly in angular space (E94): the
#: reflection frame's view order runs out there (GGX α 0.3 under venice, 128² sphere: 2.1 % of
#: the peak at n·v 0.1, 0.66 % at 0.2-0.25, none above 1 % beyond).
NV_ANGULAR = 0.25
#: The low part is summed there on texels merged into blocks of at most this many rows.
ANGULAR_LOW_ROWS = 128


@dataclass(frozen=True)
class SplitSettings:
    """What :func:`choose_split_settings` picked, and what it promises (render metadata).

    Attributes
    ----------
    F, P, size, frame
        SHRM lighting and view orders, cube face size, index frame.
    env_rows : int
        Rows of the environment the SHRM projects and the residual sums (the full map).
    tau : float
        The split's luminance threshold.
    residual_texels : int
    residual_fraction : float
    bound_Y : float
        The lighting truncation bound B in Y (module docstring), per pixel.
    peak_lower_bound : float
        A lower bound of the image's peak Y (the residual of the brightest texels at sampled
        pixels: part of the true integral).
    tol : float
        The per-pixel tolerance, relative to the peak.
    meets_tolerance : bool
        ``bound_Y <= tol · peak_lower_bound`` and ``check_error <= tol``; when False the render
        says so (E92).
    view_tail : float
        The BRDF coefficients' relative L2 tail beyond P, measured to :data:`P_FIT` (not in the
        bound).
    check_points : int
        Points of the spot check (0: not run).
    check_error : float
        The largest |ΔY| of the split against brute force at those points, relative to
        ``peak_lower_bound`` (covers P and the cube interpolation, which ``bound_Y`` does not).
        ``meets_tolerance`` also needs it to be at most ``tol``.
    """

    F: int
    P: int
    size: int
    frame: str
    env_rows: int
    tau: float
    residual_texels: int
    residual_fraction: float
    bound_Y: float
    peak_lower_bound: float
    tol: float
    meets_tolerance: bool
    view_tail: float
    check_points: int = 0
    check_error: float = 0.0

    def metadata(self) -> dict:
        """The settings as plain data for render metadata (``RenderResult.records["shrm"]``)."""
        from dataclasses import asdict

        return {k: (float(v) if isinstance(v, np.floating) else v) for k, v in asdict(self).items()}


def _lighting_order(kernel_power) -> int:
    """The smallest F whose kernel tail (largest band, relative L2) is below :data:`F_TAIL`."""
    k = np.max(kernel_power, axis=0) ** 2
    tail = np.sqrt(np.maximum(k.sum() - np.cumsum(k), 0.0) / max(k.sum(), 1e-300))
    below = np.flatnonzero(tail <= F_TAIL)
    return int(min(F_MAX, below[0] if below.size else F_MAX))


def _view_order(brdf, expand, F: int, frame: str, view_power: float):
    """The smallest P <= :data:`P_MAX` whose view tail (to :data:`P_FIT`) is <= :data:`P_TAIL`."""
    from shrm.brdf_sh import brdf_sh_coefficients

    rho = brdf_sh_coefficients(brdf, expand, F, P_FIT, frame, view_power=view_power)
    weight = np.where(np.arange(rho.shape[3]) > 0, 2.0, 1.0)
    per_p = (rho**2 * weight).sum(axis=(0, 1, 3))
    tail = np.sqrt(np.maximum(per_p.sum() - np.cumsum(per_p), 0.0) / max(per_p.sum(), 1e-300))
    below = np.flatnonzero(tail[2 : P_MAX + 1] <= P_TAIL)
    P = int(2 + below[0]) if below.size else P_MAX
    return P, float(tail[P]), rho


def _peak_lower_bound(env, brdf, params, Y_flat, y_weights, normals, views) -> float:
    """Max over sampled points of the brightest texels' part of the integral, in Y."""
    d, w, L = env
    top = np.argsort(Y_flat)[::-1][: max(1, int(RESIDUAL_FRACTIONS[-1] * Y_flat.size))]
    pick = np.linspace(0, normals.shape[0] - 1, min(PEAK_SAMPLES, normals.shape[0])).astype(int)
    part = angular_sum((d[top], w[top], L[top]), brdf, params, normals[pick], views[pick])
    return float((part @ y_weights).max(initial=0.0))


def choose_split_settings(
    radiance,
    brdf_name: str,
    params: dict,
    y_weights,
    normals,
    views,
    tol: float = 0.005,
    frame: str = "reflection",
) -> SplitSettings:
    """Split and SHRM settings for a per-pixel tolerance (:func:`split_renderer`'s choice).

    §9, Herbert et al.; the choice is described in :func:`split_renderer`.

    Examples
    --------
    >>> env = np.ones((16, 32, 2)); env[3, 5] = 500.0          # a sky and a sun
    >>> n = np.array([[0.0, 1.0, 0.0]])
    >>> s = choose_split_settings(env, "ggx", {"rho_d": 0.0, "F_0": 1.0, "alpha": 0.3},
    ...                           np.array([0.5, 0.5]), n, n)
    >>> s.residual_texels, s.meets_tolerance
    (1, True)
    """
    return _choose(radiance, brdf_name, params, y_weights, normals, views, tol, frame)[0]


def _choose(radiance, brdf_name, params, y_weights, normals, views, tol, frame):
    """The settings of :func:`split_renderer`, the BRDF coefficients and the map's quadrature.

    The coefficients are those of the reflection frame (None otherwise); the quadrature
    (``env_quadrature``) serves the spot check.
    """
    from shrm.brdf_sh import shrm_brdf_parts
    from shrm.shrm_oracles import env_quadrature

    require(0.0 < tol < 1.0, f"SHRM: tol: must be in (0, 1), got {tol!r}")
    brdf, expand, _, view_power = shrm_brdf_parts(brdf_name, params)
    H = radiance.shape[0]
    order = min(KERNEL_ORDER, H - 1)
    k_power, k_tail = kernel_spectrum(brdf, params, order, rows=max(2 * order + 2, 64))
    F = min(_lighting_order(k_power), H // 2 - 1)
    P, view_tail, rho = _view_order(brdf, expand, F, frame, view_power)
    size = int(np.clip(2 ** int(np.ceil(np.log2(max(2 * F, 1)))), 16, 64))
    env = env_quadrature(radiance)
    y_weights = np.asarray(y_weights, dtype=np.float64)
    Y_flat = env[2] @ y_weights
    peak = _peak_lower_bound(env, brdf, params, Y_flat, y_weights, normals, views)
    ordered = np.sort(Y_flat)[::-1]
    for q in RESIDUAL_FRACTIONS:
        k = int(q * Y_flat.size)
        tau = float(ordered[k]) if k < ordered.size else 0.0
        split = split_environment(radiance, y_weights, tau)
        e_power, e_tail = environment_spectrum(split.low, order)
        # The bound per band, summed with the Y weights (module docstring)
        bound = float(truncation_bound(e_power, e_tail, k_power, k_tail, F) @ y_weights)
        if bound <= tol * peak:
            break
    settings = SplitSettings(
        F,
        P,
        size,
        frame,
        H,
        tau,
        int(split.index.size),
        float(split.index.size / Y_flat.size),
        bound,
        peak,
        float(tol),
        bool(bound <= tol * peak),
        view_tail,
    )
    # The sphere fit of order P is the truncation of the one of order P_FIT (reflection frame)
    reusable = frame == "reflection"
    return settings, (rho[:, :, : P + 1, : min(F, P) + 1] if reusable else None), env


@dataclass(frozen=True)
class SplitRenderer:
    """A split environment ready to shade: the SHRM of ``L_low`` and the residual texels.

    Attributes
    ----------
    settings : SplitSettings
    shrm : shrm.shrm.SHRM
        Of the band-limited part.
    residual : tuple
        ``(directions (K, 3), weights (K,), radiance (K, C))`` of the residual texels.
    brdf : callable
    params : dict
        The whole BRDF (its Lambertian part included) for the angular half.
    low_texels : tuple or None
        ``(directions, weights, radiance)`` of ``L_low`` merged into blocks
        (:func:`merge_texels`), for the points more grazing than :data:`NV_ANGULAR`.
    """

    settings: SplitSettings
    shrm: object
    residual: tuple
    brdf: object
    params: dict
    low_texels: tuple | None = None


def merge_texels(image, rows: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A lat-long map's quadrature with its texels merged into blocks, power kept.

    Each block of ``f × f`` texels (``f = H // rows``, at least 1) becomes one texel of weight
    ``Σ w``, radiance ``Σ w L / Σ w`` and direction the normalized ``Σ w ω``: the integral of a
    function constant over each block is unchanged (E94; ours).

    Parameters
    ----------
    image : ndarray, shape (H, 2H, C)
    rows : int
        Rows of blocks wanted.

    Returns
    -------
    directions (K, 3), weights (K,), radiance (K, C)

    Examples
    --------
    >>> from shrm.shrm_oracles import env_quadrature
    >>> img = np.arange(8 * 16 * 2, dtype=float).reshape(8, 16, 2)
    >>> d, w, L = merge_texels(img, 2)
    >>> d.shape, L.shape
    ((8, 3), (8, 2))
    >>> _, w0, L0 = env_quadrature(img)
    >>> bool(np.allclose(w @ L, w0 @ L0)), bool(np.allclose((d**2).sum(-1), 1.0))
    (True, True)
    """
    from shrm.shrm_oracles import env_quadrature

    H, W = image.shape[:2]
    f = max(1, H // max(int(rows), 1))
    d, w, L = env_quadrature(image[: f * (H // f), : f * (W // f)])
    h, g = H // f, W // f

    def blocks(x):  # (h·f · g·f, k) → (h·g, k) summed over each f × f block
        return x.reshape(h, f, g, f, -1).sum(axis=(1, 3)).reshape(h * g, -1)

    w_c = blocks(w[:, None])[:, 0]
    d_c = blocks(w[:, None] * d)
    d_c /= np.linalg.norm(d_c, axis=1, keepdims=True)
    return d_c, w_c, blocks(w[:, None] * L) / w_c[:, None]


def split_create(
    radiance, brdf_name: str, params: dict, y_weights, settings: SplitSettings, rho=None
):
    """Split the environment at ``settings.tau`` and create the SHRM of its low part.

    §9, Herbert et al. (module docstring); §5.5, Herbert et al. (SHRM creation from the low
    part's coefficients, :func:`shrm.shrm.shrm_create`).

    Parameters
    ----------
    radiance : ndarray, shape (H, 2H, C)
    brdf_name, params
        The BRDF.
    y_weights : ndarray, shape (C,)
    settings : SplitSettings
    rho : ndarray, optional
        The BRDF's coefficients at ``settings.F, settings.P`` (computed when None).

    Returns
    -------
    SplitRenderer

    Examples
    --------
    >>> s = SplitSettings(2, 2, 4, "reflection", 8, 1.0, 0, 0.0, 0.0, 1.0, 0.01, True, 0.0)
    >>> r = split_create(np.ones((8, 16, 1)), "ggx", {"rho_d": 0.0, "F_0": 1.0, "alpha": 0.5},
    ...                  np.ones(1), s)
    >>> r.shrm.coeffs.shape, r.residual[0].shape
    ((6, 4, 4, 1, 9), (0, 3))
    """
    from shrm.brdf_sh import brdf_sh_coefficients, shrm_brdf_parts
    from shrm.shrm import shrm_create
    from shrm.shrm_oracles import env_quadrature
    from shrm.transform import project_latlong

    s = settings
    split = split_environment(radiance, y_weights, s.tau)
    brdf, expand, lam, k = shrm_brdf_parts(brdf_name, params)
    L = project_latlong(split.low, s.F, backend="ducc0")
    if rho is None:
        rho = brdf_sh_coefficients(brdf, expand, s.F, s.P, s.frame, view_power=k)
    # §5.5, Herbert et al.: the SHRM of the band-limited part
    shrm = shrm_create(L, rho, s.frame, s.size, "ducc0", k, lam)
    d, w, _ = env_quadrature(radiance[..., :1])
    residual = (d[split.index], w[split.index], split.residual)
    low_texels = merge_texels(split.low, ANGULAR_LOW_ROWS)
    return SplitRenderer(s, shrm, residual, brdf, dict(params), low_texels)


def split_shade(
    renderer: SplitRenderer, normals, views, distant_view=None
) -> tuple[np.ndarray, int]:
    """Reflected radiance: the SHRM of the low part (clamped at 0) plus the residual in angles.

    §9, Herbert et al.; §5.6, Herbert et al. for the SHRM half, which reads one distant view
    (the mean of ``views``); the angular half uses each point's view. Points seen more grazing
    than :data:`NV_ANGULAR` sum the low part in angular space as well, over its merged texels
    (``renderer.low_texels``, E94), where the SHRM's view order runs out.

    Parameters
    ----------
    renderer : SplitRenderer
    normals, views : ndarray, shape (N, 3)
        Unit normals and directions towards the viewer.
    distant_view : ndarray, shape (3,), optional
        The SHRM half's view (default: the mean of ``views``).

    Returns
    -------
    radiance : ndarray, shape (N, C)
        >= 0.
    clamped : int
        Values of the SH half that were negative and set to 0 (module docstring: the clamp never
        moves a value away from the truth).

    Examples
    --------
    >>> s = SplitSettings(2, 2, 4, "reflection", 8, 1.0, 0, 0.0, 0.0, 1.0, 0.01, True, 0.0)
    >>> r = split_create(np.ones((8, 16, 1)), "ggx", {"rho_d": 0.0, "F_0": 1.0, "alpha": 0.5},
    ...                  np.ones(1), s)
    >>> n = np.array([[0.0, 0.0, 1.0]])
    >>> out, clamped = split_shade(r, n, n)
    >>> out.shape, clamped
    ((1, 1), 0)
    """
    from shrm.shrm import shade_shrm, shrm_extract

    normals = np.asarray(normals, dtype=np.float64)
    views = np.asarray(views, dtype=np.float64)
    v = views.mean(axis=0) if distant_view is None else np.asarray(distant_view, np.float64)
    v = v / np.linalg.norm(v)
    grazing = np.einsum("ij,ij->i", normals, views) < NV_ANGULAR
    if renderer.low_texels is None:
        grazing[:] = False
    low = np.zeros((len(normals), renderer.residual[2].shape[1]))
    if not grazing.all():
        # §5.6, Herbert et al.: extract for the viewpoint, then shade per point
        E = shrm_extract(renderer.shrm, v)
        low[~grazing] = shade_shrm(renderer.shrm, E, normals[~grazing], v)
    if grazing.any():
        # E94: grazing points sum the low part in angular space too (merged texels)
        low[grazing] = angular_sum(
            renderer.low_texels, renderer.brdf, renderer.params, normals[grazing], views[grazing]
        )
    clamped = int((low < 0).sum())
    high = angular_sum(renderer.residual, renderer.brdf, renderer.params, normals, views)
    return np.maximum(low, 0.0) + high, clamped


def split_renderer(
    radiance,
    brdf_name: str,
    params: dict,
    y_weights,
    normals,
    views,
    tol: float = 0.005,
    frame: str = "reflection",
) -> SplitRenderer:
    """Split and SHRM settings for a per-pixel tolerance, from the spectra of power (E92).

    §9, Herbert et al. (the split), with the bound of the module docstring: F from the kernel's
    power spectrum (:data:`F_TAIL`), P from the BRDF's view tail (:data:`P_TAIL`), the cube
    face ``2F`` (16-64), then the largest τ (the fewest residual texels among
    :data:`RESIDUAL_FRACTIONS`) whose bound B is at most ``tol`` times a lower bound of the
    image's peak. When even the largest residual fraction cannot meet it, that fraction is used
    and ``meets_tolerance`` is False. B does not cover P nor the cube interpolation, so the
    renderer is then spot-checked against brute force at :data:`CHECK_POINTS` points (the most
    grazing among them) and ``meets_tolerance`` also needs that error within ``tol``
    (``settings.check_error``).

    Parameters
    ----------
    radiance : ndarray, shape (H, 2H, C)
        The environment's spectral radiance.
    brdf_name : str
        A key of ``BRDF_METHODS`` (isotropic).
    params : dict
        Its parameters on the grid.
    y_weights : ndarray, shape (C,)
        Band weights of Y.
    normals, views : ndarray, shape (N, 3)
        The points to be shaded (for the peak's lower bound).
    tol : float
        Per-pixel tolerance relative to the peak, in (0, 1).
    frame : {"normal", "reflection"}

    Returns
    -------
    SplitRenderer

    Examples
    --------
    >>> env = np.ones((16, 32, 2)); env[3, 5] = 500.0          # a sky and a sun
    >>> n = np.array([[0.0, 1.0, 0.0]])
    >>> r = split_renderer(env, "ggx", {"rho_d": 0.0, "F_0": 1.0, "alpha": 0.3},
    ...                    np.array([0.5, 0.5]), n, n)
    >>> r.settings.residual_texels, float(split_shade(r, n, n)[0].min()) > 0
    (1, True)
    """
    settings, rho, env = _choose(radiance, brdf_name, params, y_weights, normals, views, tol, frame)
    renderer = split_create(radiance, brdf_name, params, y_weights, settings, rho)
    return _spot_check(renderer, env, y_weights, normals, views)


def _spot_check(renderer: SplitRenderer, env, y_weights, normals, views) -> SplitRenderer:
    """The renderer with its settings' spot check against brute force filled in (E92).

    :data:`CHECK_POINTS` points: half the most grazing of those the SHRM shades (where the view
    order P falls short first), half spread over the points. The split is shaded there as the
    render will shade it (the SHRM half at the mean of all views) and compared in Y with
    :func:`angular_sum` over every texel (``env``: the map's quadrature), relative to the larger
    of two lower bounds of the peak.
    """
    from dataclasses import replace

    normals = np.asarray(normals, dtype=np.float64)
    views = np.asarray(views, dtype=np.float64)
    nv = np.einsum("ij,ij->i", normals, views)
    # the most grazing points the SHRM shades (below NV_ANGULAR all is angular, E94)
    shrm_points = np.flatnonzero(nv >= NV_ANGULAR)
    grazing = shrm_points[np.argsort(nv[shrm_points])[: CHECK_POINTS // 2]]
    rest = np.setdiff1d(np.arange(len(nv)), grazing)
    k = min(CHECK_POINTS - grazing.size, rest.size)
    pick = np.concatenate([grazing, rest[np.linspace(0, rest.size - 1, k).astype(int)]])
    y = np.asarray(y_weights, dtype=np.float64)
    out = split_shade(renderer, normals[pick], views[pick], distant_view=views.mean(axis=0))[0]
    truth = angular_sum(env, renderer.brdf, renderer.params, normals[pick], views[pick])
    s = renderer.settings
    peak = max(s.peak_lower_bound, float((truth @ y).max(initial=0.0)), 1e-300)
    error = float(np.abs((out - truth) @ y).max(initial=0.0) / peak)
    settings = replace(
        s,
        check_points=int(pick.size),
        check_error=error,
        meets_tolerance=bool(s.meets_tolerance and error <= s.tol),
    )
    return replace(renderer, settings=settings)

"""The SH order an environment needs for a per-pixel accuracy (Herbert et al. §5.4; ours).

A prefiltered map ``E(n) = Σ_l Λ_l Σ_m L_lm Y_lm(n)`` (Eq. (7), Ramamoorthi & Hanrahan 2001)
truncated at order L is off by the tail ``e_L(n) = Σ_{l>L} Λ_l Σ_m L_lm Y_lm(n)``. Its size
depends on the kernel's tail *and* on the environment: by Parseval its mean square over the sphere
is ``Σ_{l>L} Λ_l² C_l / 4π`` with ``C_l = Σ_m L_lm²`` the map's power in degree l, and a map whose
energy sits in a few bright texels keeps its power to high degrees. The kernel's tail alone
(:func:`shrm.lobes.adaptive_order`) ignores that and picks order 14 for the irradiance under
``studio_small_03_1k.hdr``, 29 % off at some pixels (erratum E75).

:func:`accuracy_order` measures the truncation error itself, in frequency space, on the luminance
Y of the map: it projects Y to the map's band limit ``L_max = min(W/2 − 1, 511)``, scales by Λ_l,
and for a candidate L compares the order-L synthesis with the order-``L_max`` one on a lat-long grid
of directions. The figure of merit is the one users read (docs/sh.md, "Accuracy"): the relative
error of Y over the directions whose irradiance is at least :data:`LIT_FRACTION` of the peak,
averaged over solid angle (≤ ``tol``) and at its maximum (≤ :data:`MAX_FACTOR` · ``tol``). The
order is the smallest that meets :data:`SAFETY` times both, so the cube-map lookup and the
map's content beyond ``L_max`` (which the estimate cannot see) fit in the rest (erratum E75). A
smooth sky keeps a low order; a sun disc gets a high one.

References
----------
- F. Herbert, J. Kirkenaer, O. Unter Ecker, "Achieving a Multi-spectral Virtual Reality", 2004.
- R. Ramamoorthi, P. Hanrahan, "An Efficient Representation for Irradiance Environment Maps",
  SIGGRAPH 2001.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from reference.errors import require
from reference.scene.metadata import DEFAULT_ACCURACY, LIT_FRACTION, MAX_FACTOR, check_accuracy
from shrm.lobes import parse_kernel
from shrm.sh import SH_MAX_ORDER, n_coefficients
from shrm.transform import project_latlong, synthesize_latlong

__all__ = [
    "BRIGHT_CONTRAST",
    "BRIGHT_MAX",
    "BRIGHT_SHARE",
    "SAFETY",
    "BrightTexels",
    "OrderChoice",
    "accuracy_order",
    "bright_texels",
    "degree_power",
    "sparse_convolution",
    "truncation_error",
]

#: The order must meet this fraction of both tolerances in the estimate (erratum E75).
SAFETY = 0.5
#: Highest degree the estimate resolves (and the highest order chosen).
ESTIMATE_MAX_ORDER = 511
#: A texel is lit exactly (not through SH) when it carries at least this share of the map's power.
BRIGHT_SHARE = 1e-3
#: At most this many texels are lit exactly, the brightest first.
BRIGHT_MAX = 64
#: ... and only texels at least this many times brighter than the map's median luminance.
BRIGHT_CONTRAST = 100.0


@dataclass(frozen=True)
class BrightTexels:
    """The brightest texels of a map, lit exactly, and the scale that leaves the SH residual.

    The residual map is ``radiance · scale`` (each selected texel clipped to the luminance of the
    brightest texel not selected); the exact part is ``radiance · (1 − scale)`` at ``index``.

    Attributes
    ----------
    index : ndarray of int, shape (K,)
        Flat texel indices (row-major).
    directions : ndarray, shape (K, 3)
        Their pixel-centre directions.
    weights : ndarray, shape (K,)
        Their Fejér-1 quadrature weights (sr), as in :func:`shrm.prefilter.prefilter_bruteforce`.
    scale : ndarray, shape (H, W)
        1 except at the selected texels.
    """

    index: np.ndarray
    directions: np.ndarray
    weights: np.ndarray
    scale: np.ndarray

    def exact_part(self, radiance) -> np.ndarray:
        """``radiance · (1 − scale)`` at the selected texels, ``(K, C)`` from ``(H, W, C)``."""
        flat = np.asarray(radiance).reshape(-1, np.shape(radiance)[-1])
        return flat[self.index] * (1.0 - self.scale.reshape(-1)[self.index])[:, None]


def bright_texels(luminance) -> BrightTexels:
    """The texels that carry :data:`BRIGHT_SHARE` of the power each and outshine the median 100×.

    At most :data:`BRIGHT_MAX`, the most powerful first.

    Ours (erratum E75): a light in a few texels keeps its power to every SH degree, so no order a
    1k map can hold reaches 2 % at the edge of its shadow; lit exactly, it costs K dot products
    per pixel and leaves a residual that a low order represents.

    Parameters
    ----------
    luminance : ndarray, shape (H, 2H)

    Returns
    -------
    BrightTexels

    Examples
    --------
    >>> Y = np.ones((8, 16)); Y[3, 5] = 1e5
    >>> b = bright_texels(Y)
    >>> b.index.tolist(), float(b.scale[3, 5])
    ([53], 1e-05)
    """
    from reference.geometry.envmap import latlong_pixel_directions
    from shrm.sh import fejer1_weights

    Y = np.asarray(luminance, dtype=np.float64)
    H, W = Y.shape
    w = np.repeat(fejer1_weights(H) * (2.0 * np.pi / W), W)
    power = np.maximum(Y.reshape(-1), 0.0) * w
    order = np.argsort(power)[::-1]
    top = order[:BRIGHT_MAX]
    keep = (power[top] >= BRIGHT_SHARE * power.sum()) & (
        Y.reshape(-1)[top] >= BRIGHT_CONTRAST * max(float(np.median(Y)), 0.0)
    )
    chosen = top[keep]
    scale = np.ones(H * W)
    if chosen.size:
        rest = np.delete(Y.reshape(-1), chosen)
        threshold = max(float(rest.max()), 0.0) if rest.size else 0.0
        scale[chosen] = np.minimum(1.0, threshold / Y.reshape(-1)[chosen])
    directions = latlong_pixel_directions(H, W).reshape(-1, 3)[chosen]
    return BrightTexels(chosen, directions, w[chosen], scale.reshape(H, W))


def sparse_convolution(values, directions, weights, kernel, normals) -> np.ndarray:
    """``Σ_k K(ω_k · n) w_k L_k`` over a few texels: the angular convolution of the oracle.

    Eq. (7), Ramamoorthi & Hanrahan 2001 in the angular domain, the sum of
    :func:`shrm.prefilter.prefilter_bruteforce` restricted to the texels given.

    Parameters
    ----------
    values : ndarray, shape (K, C)
    directions : ndarray, shape (K, 3)
    weights : ndarray, shape (K,)
        Quadrature weights, sr.
    kernel : str or RadialKernel
    normals : ndarray, shape (N, 3)

    Returns
    -------
    ndarray, shape (N, C)

    Examples
    --------
    >>> sparse_convolution(np.ones((1, 1)), np.array([[0.0, 1.0, 0.0]]), np.array([0.5]),
    ...                    "lambert", np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]))
    array([[0.5],
           [0. ]])
    """
    k = parse_kernel(kernel)
    normals = np.asarray(normals, dtype=np.float64)
    values = np.asarray(values, dtype=np.float64)
    out = np.empty((normals.shape[0], values.shape[1]))
    for start in range(0, normals.shape[0], 1 << 15):  # bounded temporaries
        t = np.clip(normals[start : start + (1 << 15)] @ np.asarray(directions).T, -1.0, 1.0)
        if k.power is not None:
            s, scale = k.power
            K = np.where(t > 0.0, scale * np.maximum(t, 0.0) ** s, 0.0)
        else:
            K = k.profile(np.arccos(t))
        # Eq. (7), Ramamoorthi & Hanrahan 2001, angular domain: Σ_k L_k K(ω_k · n) w_k
        out[start : start + (1 << 15)] = (K * np.asarray(weights)) @ values
    return out


@dataclass(frozen=True)
class OrderChoice:
    """The order chosen for a kernel and an environment, with the bound it promises.

    Attributes
    ----------
    kernel : str
        The lobe (``"lambert"``, ``"phong:32"``).
    order : int
        L used by the frequency path.
    tol_mean, tol_max : float
        The promised bounds: mean and maximum relative error of Y over lit pixels.
    estimate_mean, estimate_max : float
        The truncation error of Y that :func:`truncation_error` measured at ``order``.
    band_limit : int
        The highest degree the estimate saw (``min(W/2 − 1, 511)``).
    exact_texels : int
        How many bright texels are lit exactly beside the SH residual (:func:`bright_texels`).
    met : bool
        Whether the estimate met ``SAFETY`` × both bounds (False only when the band limit was
        reached first; then the estimate, not the tolerance, is the honest bound).
    """

    kernel: str
    order: int
    tol_mean: float
    tol_max: float
    estimate_mean: float
    estimate_max: float
    band_limit: int
    met: bool
    exact_texels: int = 0

    def as_dict(self) -> dict:
        """Plain JSON-able dict (the render metadata's entry).

        Examples
        --------
        >>> OrderChoice("lambert", 4, 5e-3, 2e-2, 1e-3, 4e-3, 63, True, 0).as_dict()["order"]
        4
        """
        return asdict(self)


def degree_power(coeffs) -> np.ndarray:
    """Power per degree ``C_l = Σ_m c_lm²`` of one set of real SH coefficients.

    Parseval: ``∫ f² dω = Σ_l C_l``.

    Parameters
    ----------
    coeffs : ndarray, shape ((L+1)²,)

    Returns
    -------
    ndarray, shape (L+1,)

    Examples
    --------
    >>> degree_power(np.array([2.0, 1.0, 0.0, 1.0]))
    array([4., 2.])
    """
    c = np.asarray(coeffs, dtype=np.float64)
    L = round(np.sqrt(c.size)) - 1
    require(c.size == n_coefficients(L), f"degree_power: {c.size} is not (L+1)² coefficients")
    l = np.repeat(np.arange(L + 1), 2 * np.arange(L + 1) + 1)
    return np.bincount(l, weights=c**2, minlength=L + 1)


def _truncate(coeffs: np.ndarray, L: int) -> np.ndarray:
    return coeffs[: n_coefficients(L)]


def truncation_error(
    filtered, order: int, reference_map=None, exact_map=None
) -> tuple[float, float]:
    """Mean and maximum relative error of the order-L truncation of a prefiltered map.

    Over the directions of a lat-long grid (``L_max + 1`` rows) where the full map is at least
    :data:`LIT_FRACTION` of its peak; the mean weights each direction by its solid angle.

    Parameters
    ----------
    filtered : ndarray, shape ((L_max+1)²,)
        Prefiltered coefficients ``Λ_l L_lm`` of the luminance to the band limit.
    order : int
        The candidate order L ≤ L_max.
    reference_map : ndarray, optional
        The order-``L_max`` synthesis, if already computed.
    exact_map : ndarray, optional
        A part computed exactly (the bright texels) on the same grid, added to both.

    Returns
    -------
    (mean, max) : tuple of float

    Examples
    --------
    >>> c = np.zeros(9); c[0] = 3.0; c[6] = 0.3           # a constant plus a little Y_20
    >>> [round(v, 3) for v in truncation_error(c, 1)]
    [0.124, 0.126]
    """
    filtered = np.asarray(filtered, dtype=np.float64)
    L_max = round(np.sqrt(filtered.size)) - 1
    if reference_map is None:
        reference_map = synthesize_latlong(filtered, L_max + 1, backend="ducc0")
    H = reference_map.shape[0]
    approx = synthesize_latlong(_truncate(filtered, order), H, backend="ducc0")
    if exact_map is not None:
        approx = approx + exact_map
        reference_map = reference_map + exact_map
    lit = reference_map >= LIT_FRACTION * reference_map.max()
    relative = np.abs(approx - reference_map)[lit] / reference_map[lit]
    theta = (np.arange(H) + 0.5) * np.pi / H
    weight = np.broadcast_to(np.sin(theta)[:, None], reference_map.shape)[lit]
    return float(np.sum(relative * weight) / np.sum(weight)), float(relative.max())


def accuracy_order(
    luminance, kernel, tol: float = DEFAULT_ACCURACY, where: str = "environment", bright=None
):
    """The smallest order whose truncation error of Y meets ``SAFETY`` × the tolerance.

    Eq. (7), Ramamoorthi & Hanrahan 2001 (``E_lm = Λ_l L_lm``) on the luminance map; the error is
    :func:`truncation_error` (module docstring). The candidate orders are searched by bisection
    between 1 and the band limit.

    Parameters
    ----------
    luminance : ndarray, shape (H, 2H)
        Luminance Y of the environment's radiance (any scale).
    kernel : str or RadialKernel
        The lobe (``"lambert"``, ``"phong:32"``).
    tol : float
        Mean relative error of Y over lit directions; the maximum is :data:`MAX_FACTOR` × tol.
    where : str
        Name for messages.
    bright : BrightTexels, optional
        Texels lit exactly: the order is chosen for the residual map, the error measured on the
        sum (:func:`bright_texels`).

    Returns
    -------
    OrderChoice

    Examples
    --------
    >>> sky = np.ones((32, 64))                           # a constant sky needs order 0
    >>> accuracy_order(sky, "lambert").order
    0
    """
    tol = check_accuracy(tol)
    luminance = np.asarray(luminance, dtype=np.float64)
    require(luminance.ndim == 2, f"{where}: luminance must be (H, W), got {luminance.shape}")
    k = parse_kernel(kernel)
    L_max = min(luminance.shape[1] // 2 - 1, ESTIMATE_MAX_ORDER, SH_MAX_ORDER)
    exact_map, residual = None, luminance
    if bright is not None and bright.index.size:
        from reference.geometry.envmap import latlong_pixel_directions

        residual = luminance * bright.scale
        grid = latlong_pixel_directions(L_max + 1, 2 * L_max + 2).reshape(-1, 3)
        values = bright.exact_part(luminance[..., None])
        exact_map = sparse_convolution(values, bright.directions, bright.weights, k, grid)
        exact_map = exact_map.reshape(L_max + 1, 2 * L_max + 2)
    coeffs = project_latlong(residual[..., None], L_max, backend="ducc0", where=where)[0]
    # Eq. (7), Ramamoorthi & Hanrahan 2001: E_lm = Λ_l L_lm
    l = np.repeat(np.arange(L_max + 1), 2 * np.arange(L_max + 1) + 1)
    filtered = k.Lambda(L_max)[l] * coeffs
    full = synthesize_latlong(filtered, L_max + 1, backend="ducc0")
    tol_max = MAX_FACTOR * tol

    def meets(L):
        mean, worst = truncation_error(filtered, L, full, exact_map)
        return mean <= SAFETY * tol and worst <= SAFETY * tol_max, (mean, worst)

    lo, hi = -1, L_max  # meets(L_max) holds trivially (zero error)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if meets(mid)[0]:
            hi = mid
        else:
            lo = mid
    _, (mean, worst) = meets(hi)
    # At the band limit the estimate sees no tail, so it cannot promise the tolerance.
    K = 0 if bright is None else int(bright.index.size)
    return OrderChoice(k.name, int(hi), tol, tol_max, mean, worst, L_max, hi < L_max, K)

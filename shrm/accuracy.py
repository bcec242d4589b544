"""The SH order an environment needs for a per-pixel accuracy (Herbert et al. §5.4; ours).

A prefiltered map ``E(n) = Σ_l Λ_l Σ_m L_lm Y_lm(n)`` (Eq. (7), Ramamoorthi & Hanrahan 2001)
truncated at order L is off by the tail ``e_L(n) = Σ_{l>L} Λ_l Σ_m L_lm Y_lm(n)``. Its size
depends on the kernel's tail *and* on the environment: by Parseval its mean square over the sphere
is ``Σ_{l>L} Λ_l² C_l / 4π`` with ``C_l = Σ_m L_lm²`` the map's power in degree l, and a map whose
energy sits in a few bright texels keeps its power to high degrees. The kernel's tail alone
(:func:`shrm.lobes.adaptive_order`) ignores that and picks order 14 for the irradiance under
``studio_small_03_1k.hdr``, 29 % off at some pixels (issue 17).

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
from reference.render_metadata import DEFAULT_ACCURACY, LIT_FRACTION, MAX_FACTOR, check_accuracy
from shrm.lobes import parse_kernel
from shrm.sh import SH_MAX_ORDER, n_coefficients
from shrm.transform import project_latlong, synthesize_latlong

__all__ = [
    "SAFETY",
    "OrderChoice",
    "accuracy_order",
    "degree_power",
    "truncation_error",
]

#: The order must meet this fraction of both tolerances in the estimate (erratum E75).
SAFETY = 0.5
#: Highest degree the estimate resolves (and the highest order chosen).
ESTIMATE_MAX_ORDER = 511


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

    def as_dict(self) -> dict:
        """Plain JSON-able dict (the render metadata's entry).

        Examples
        --------
        >>> OrderChoice("lambert", 4, 5e-3, 2e-2, 1e-3, 4e-3, 63, True).as_dict()["order"]
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


def truncation_error(filtered, order: int, reference_map=None) -> tuple[float, float]:
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

    Returns
    -------
    (mean, max) : tuple of float

    Examples
    --------
    >>> c = np.zeros(9); c[0] = 3.0; c[6] = 0.3           # a constant plus a little Y_20
    >>> [round(v, 3) for v in truncation_error(c, 1)]
    [0.07, 0.2]
    """
    filtered = np.asarray(filtered, dtype=np.float64)
    L_max = round(np.sqrt(filtered.size)) - 1
    if reference_map is None:
        reference_map = synthesize_latlong(filtered, L_max + 1, backend="ducc0")
    H = reference_map.shape[0]
    approx = synthesize_latlong(_truncate(filtered, order), H, backend="ducc0")
    lit = reference_map >= LIT_FRACTION * reference_map.max()
    relative = np.abs(approx - reference_map)[lit] / reference_map[lit]
    theta = (np.arange(H) + 0.5) * np.pi / H
    weight = np.broadcast_to(np.sin(theta)[:, None], reference_map.shape)[lit]
    return float(np.sum(relative * weight) / np.sum(weight)), float(relative.max())


def accuracy_order(luminance, kernel, tol: float = DEFAULT_ACCURACY, where: str = "environment"):
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
    coeffs = project_latlong(luminance[..., None], L_max, backend="ducc0", where=where)[0]
    # Eq. (7), Ramamoorthi & Hanrahan 2001: E_lm = Λ_l L_lm
    l = np.repeat(np.arange(L_max + 1), 2 * np.arange(L_max + 1) + 1)
    filtered = k.Lambda(L_max)[l] * coeffs
    full = synthesize_latlong(filtered, L_max + 1, backend="ducc0")
    tol_max = MAX_FACTOR * tol

    def meets(L):
        mean, worst = truncation_error(filtered, L, full)
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
    return OrderChoice(k.name, int(hi), tol, tol_max, mean, worst, L_max, hi < L_max)

"""Frequency-space prefiltering with radially symmetric kernels (§5.4, Herbert et al.).

Prefiltering convolves the environment L with a kernel K that depends only on the angle between the
lookup direction n and the incident direction ω:

    E(n) = ∫ L(ω) K(ω · n) dω.

By the Funk–Hecke theorem this scales each SH degree: ``E_lm = Λ_l L_lm`` (Eq. (7), Ramamoorthi &
Hanrahan 2001, where ``Λ_l = sqrt(4π/(2l+1)) A_l``), with the exact Legendre projection of the lobe

    Λ_l = 2π ∫_{-1}^{1} K(t) P_l(t) dt,

computed here by Gauss–Legendre quadrature, not by the Gaussian approximation ``exp(-l²/2s)`` of a
Phong lobe (prefiltering the red channel of ``venice_sunset_1k.hdr`` at L = 100 with it is off by
about 10 % at the worst texel for s = 32 and 256; the report measures it). The
angular-domain convolution is quadratic per texel; the frequency-space one is a product per
coefficient (§5.4, Herbert et al.).

The lobes, their Legendre coefficients Λ_l and the adaptive order (the smallest L whose truncated
tail is below ``tol``, so a Lambert map does not pay for order 100) are in :mod:`shrm.lobes`.

The oracle is the brute-force angular convolution, :func:`prefilter_bruteforce`: per output
direction, ``Σ_p L_p K(ω_p · n) w_p`` over all map pixels with the same Fejér-1 weights as the
projection, so the two differ only by the truncation of K's Legendre series (exactly, by the
addition theorem).

References
----------
- F. Herbert, J. Kirkenaer, O. Unter Ecker, "Achieving a Multi-spectral Virtual Reality", 2004.
- R. Ramamoorthi, P. Hanrahan, "An Efficient Representation for Irradiance Environment Maps",
  SIGGRAPH 2001.
- R. Ramamoorthi, P. Hanrahan, "Frequency Space Environment Map Rendering", SIGGRAPH 2002.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.errors import require, require_choice
from reference.jit import kernel_input
from reference.registry import Method, Registry
from shrm.lobes import (
    DEFAULT_TOL,
    adaptive_order,
    parse_kernel,
    truncation_tail,
)
from shrm.sh import (
    SH_MAX_ORDER,
    check_order,
    fejer1_weights,
    order_of,
    sh_degrees_orders,
    sh_evaluate,
)
from shrm.transform import project_latlong, synthesize_latlong

__all__ = [
    "BRUTEFORCE_METHODS",
    "MAX_PREFILTER_FACE",
    "PrefilterResult",
    "prefilter_bruteforce",
    "prefilter_coefficients",
    "prefilter_environment",
]


def prefilter_coefficients(coeffs, Lambda) -> np.ndarray:
    """Frequency-space convolution: ``E_lm = Λ_l L_lm``, Eq. (7), Ramamoorthi & Hanrahan 2001.

    Parameters
    ----------
    coeffs : array_like, shape (C, (L+1)²)
    Lambda : array_like, shape (L'+1,) or (C, L'+1), L' >= L
        One factor per degree, or one row per channel (a per-band Phong exponent).

    Returns
    -------
    ndarray, shape (C, (L+1)²)

    Examples
    --------
    >>> prefilter_coefficients(np.ones((1, 4)), np.array([1.0, 0.5]))
    array([[1. , 0.5, 0.5, 0.5]])
    """
    c = np.atleast_2d(np.asarray(coeffs, dtype=np.float64))
    L = order_of(c.shape[1])
    Lam = np.asarray(Lambda, dtype=np.float64)
    require(Lam.shape[-1] > L, f"prefilter: Λ has {Lam.shape[-1]} degrees, need {L + 1}")
    l, _ = sh_degrees_orders(L)
    # Eq. (7), Ramamoorthi & Hanrahan 2001: E_lm = Λ_l L_lm
    return c * Lam[..., l]


@dataclass(frozen=True)
class PrefilterResult:
    """A prefiltered environment: the values and how they were made.

    Attributes
    ----------
    values : ndarray
        ``(6, S, S, C)`` for a cube map, ``(H, 2H, C)`` for lat-long.
    format : str
        ``"cube"`` or ``"latlong"``.
    order : int
        The SH order used.
    kernel : str
        The kernel spec.
    Lambda : ndarray, shape (order+1,)
        The degree factors.
    tail : float
        :func:`truncation_tail` at ``order``.
    """

    values: np.ndarray
    format: str
    order: int
    kernel: str
    Lambda: np.ndarray
    tail: float


#: The largest cube face of a prefiltered map, texels (:func:`prefilter_environment`).
MAX_PREFILTER_FACE = 2048


def prefilter_environment(
    image,
    kernel,
    order: int | None = None,
    tol: float = DEFAULT_TOL,
    output: str = "cube",
    size: int = 64,
    height: int | None = None,
    backend: str = "ducc0",
    where: str = "environment map",
) -> PrefilterResult:
    """Prefilter a lat-long environment in frequency space and sample it as a cube or lat-long map.

    §5.4, Herbert et al.: project (Fejér-1, order L), scale by Λ_l (Eq. (7), Ramamoorthi &
    Hanrahan 2001), synthesize at the output texels.

    Parameters
    ----------
    image : array_like, shape (H, W, C)
        Linear radiance, finite and >= 0, W = 2H.
    kernel : str or RadialKernel
        ``lambert``, ``phong:S`` or ``table:FILE``.
    order : int, optional
        Fixed order; default :func:`adaptive_order` at ``tol``.
    tol : float
        Tolerance of the adaptive order.
    output : {"cube", "latlong"}
    size : int
        Cube face size.
    height : int, optional
        Lat-long output height (default 2L + 2, at least 16).
    backend : {"ducc0", "numba", "numpy"}
        Projection and synthesis path.
    where : str
        Name for messages.

    Returns
    -------
    PrefilterResult

    Examples
    --------
    >>> r = prefilter_environment(np.ones((32, 64, 1)), "lambert", output="latlong")
    >>> r.order, r.values.shape, round(float(r.values.mean()), 6)    # E = π under L = 1
    (14, (30, 60, 1), 3.141593)
    """
    from reference.geometry.cubemap import cubemap_texel_directions

    image = np.asarray(image, dtype=np.float64)
    require(
        image.ndim == 3 and np.isfinite(image).all(),
        f"{where}: expected a finite (H, W, C) map, got shape {image.shape}",
    )
    require((image >= 0).all(), f"{where}: radiance must be >= 0, found {image.min():g}")
    require_choice(output, ("cube", "latlong"), "prefilter output format")
    # a prefiltered map holds no detail beyond its order (at most a few hundred): a larger face
    # only costs memory (4096² faces ran out of 8 GB)
    require(
        isinstance(size, int) and 1 <= size <= MAX_PREFILTER_FACE,
        f"{where}: --size: a cube face of 1 to {MAX_PREFILTER_FACE} texels, got {size!r}",
    )
    k = parse_kernel(kernel)
    L = adaptive_order(k, tol) if order is None else check_order(order, f"{where}: order")
    L = min(L, image.shape[1] // 2 - 1, SH_MAX_ORDER)
    coeffs = prefilter_coefficients(
        project_latlong(image, L, backend=backend, where=where), k.Lambda(L)
    )
    if output == "cube":
        d = cubemap_texel_directions(size)
        values = sh_evaluate(coeffs, d, backend=backend)
    else:
        H = max(2 * L + 2, 16) if height is None else int(height)
        values = synthesize_latlong(coeffs, max(H, L + 1), backend=backend)
    return PrefilterResult(values, output, L, k.name, k.Lambda(L), truncation_tail(k, L))


def prefilter_bruteforce(image, kernel, directions, backend: str = "numba") -> np.ndarray:
    """The angular-domain oracle: ``E(n) = Σ_p L_p K(ω_p · n) w_p`` over every map pixel.

    Eq. (7), Ramamoorthi & Hanrahan 2001 in the angular domain (quadratic per texel, §5.4,
    Herbert et al.), with the Fejér-1 weights of the projection ``w_p = w_j 2π/W``.

    Parameters
    ----------
    image : array_like, shape (H, W, C)
        Lat-long radiance.
    kernel : str or RadialKernel
    directions : array_like, shape (..., 3)
        Unit lookup directions (cube texels, normals).
    backend : {"numba", "numpy"}

    Returns
    -------
    ndarray, shape (..., C)

    Examples
    --------
    >>> E = prefilter_bruteforce(np.ones((64, 128, 1)), "lambert", [[0.0, 1.0, 0.0]])
    >>> E.round(3)                                  # π under uniform unit radiance
    array([[3.142]])
    """
    from reference.geometry.envmap import latlong_pixel_directions

    image = np.asarray(image, dtype=np.float64)
    require(image.ndim == 3, f"prefilter_bruteforce: expected (H, W, C), got {image.shape}")
    require_choice(backend, ("numba", "numpy"), "brute-force backend")
    k = parse_kernel(kernel)
    H, W, C = image.shape
    omega = latlong_pixel_directions(H, W).reshape(-1, 3)
    w = np.repeat(fejer1_weights(H) * (2.0 * np.pi / W), W)
    radiance = image.reshape(-1, C)
    n = np.asarray(directions, dtype=np.float64)
    shape = n.shape[:-1]
    n = np.ascontiguousarray(n.reshape(-1, 3))
    out = np.zeros((n.shape[0], C))
    if backend == "numba":
        from shrm import _kernels

        if k.power is not None:
            radiance = kernel_input(radiance)
            _kernels.prefilter_bruteforce_power_kernel(
                kernel_input(n), kernel_input(omega), kernel_input(w), radiance, *k.power, out
            )
        else:
            angles, values = k.table
            _kernels.prefilter_bruteforce_table_kernel(n, omega, w, radiance, angles, values, out)
    else:
        chunk = max(1, 2_000_000 // omega.shape[0])
        for start in range(0, n.shape[0], chunk):
            t = np.clip(n[start : start + chunk] @ omega.T, -1.0, 1.0)
            # Eq. (7), Ramamoorthi & Hanrahan 2001, angular domain: Σ_p L_p K(ω_p · n) w_p
            if k.power is not None:
                s, scale = k.power
                K = np.where(t > 0.0, scale * np.maximum(t, 0.0) ** s, 0.0)
            else:
                K = k.profile(np.arccos(t))
            out[start : start + chunk] = (K * w) @ radiance
    return out.reshape(*shape, C)


def _example_bruteforce_inputs(kernel_spec):
    def make(rng):
        d = rng.normal(size=(5, 3))
        return rng.random((8, 16, 2)), kernel_spec, d / np.linalg.norm(d, axis=-1, keepdims=True)

    return make


def _register_bruteforce():
    from shrm import _kernels

    BRUTEFORCE_METHODS.register(
        Method(
            "power",
            prefilter_bruteforce,
            _kernels.prefilter_bruteforce_power_kernel,
            "Eq. (7), Ramamoorthi & Hanrahan 2001",
            _example_bruteforce_inputs("phong:7.5"),
        )
    )
    BRUTEFORCE_METHODS.register(
        Method(
            "table",
            prefilter_bruteforce,
            _kernels.prefilter_bruteforce_table_kernel,
            "Eq. (7), Ramamoorthi & Hanrahan 2001",
            None,
        )
    )


#: The brute-force oracle: NumPy reference and numba kernels (power lobes, tabulated lobes).
BRUTEFORCE_METHODS = Registry("brute-force prefilter")
_register_bruteforce()

"""Windows against ringing in truncated SH expansions (§7.3, Herbert et al.).

Truncating an SH series at order L rings around sharp features (a sun), like a truncated Fourier
series: the reconstruction undershoots below zero, which is unphysical radiance. Herbert et al.
"countered ringing tendencies in projections by sampling the angular-space source with a Gaussian
kernel". A window multiplies each degree by a weight h_l before synthesis,

    f_L(ω) = Σ_{l <= L} h_l Σ_m c_lm Y_lm(ω)

(Eq. (2), Ramamoorthi & Hanrahan 2001, windowed). By the Funk–Hecke theorem this is a convolution
of f with a radially symmetric kernel, so a Gaussian window is exactly Herbert's Gaussian
pre-sampling. Windows, by spec string (``--window``):

- ``none``: h_l = 1;
- ``hanning``: h_l = ½ (1 + cos(π l / (L + 1)));
- ``lanczos``: h_l = sinc(l / (L + 1)) = sin(π l/(L+1)) / (π l/(L+1));
- ``gaussian[:SIGMA]``: h_l = exp(-l (l + 1) σ² / 2), σ in radians, default σ = π/L (the default
  window: it leaves no negative pixel on ``venice_sunset_1k.hdr`` at L = 100).

:func:`ringing_statistics` gives the figures the report charts: the undershoot (minimum / peak) and
the share of negative pixels.

References
----------
- F. Herbert, J. Kirkenaer, O. Unter Ecker, "Achieving a Multi-spectral Virtual Reality", 2004.
- P.-P. Sloan, "Stupid Spherical Harmonics (SH) Tricks", GDC 2008 (windowing against ringing).
- K. M. Górski et al., "HEALPix", ApJ 622, 2005 (the Gaussian beam window exp(-l(l+1)σ²/2)).
"""

from __future__ import annotations

import numpy as np

from reference.errors import SpecrefError, require
from reference.registry import Method, ParametricMethod, Registry

__all__ = [
    "DEFAULT_WINDOW",
    "WINDOWS",
    "apply_window",
    "parse_window",
    "ringing_statistics",
    "window_gaussian",
    "window_hanning",
    "window_lanczos",
    "window_none",
    "window_weights",
]

#: The window used when none is named.
DEFAULT_WINDOW = "gaussian"


def window_none(order: int) -> np.ndarray:
    """No window: h_l = 1 (the plain truncation, Eq. (2), Ramamoorthi & Hanrahan 2001).

    Examples
    --------
    >>> window_none(2)
    array([1., 1., 1.])
    """
    return np.ones(int(order) + 1)


def window_hanning(order: int) -> np.ndarray:
    """Hann window over degree: h_l = ½(1 + cos(π l/(L+1))).

    Applied to Eq. (2), Ramamoorthi & Hanrahan 2001 (module docstring).

    Examples
    --------
    >>> window_hanning(3)
    array([1.        , 0.85355339, 0.5       , 0.14644661])
    """
    l = np.arange(int(order) + 1)
    return 0.5 * (1.0 + np.cos(np.pi * l / (order + 1)))


def window_lanczos(order: int) -> np.ndarray:
    """Lanczos sigma factors: h_l = sinc(l/(L+1)).

    Applied to Eq. (2), Ramamoorthi & Hanrahan 2001 (module docstring).

    Examples
    --------
    >>> window_lanczos(2).round(6)
    array([1.      , 0.826993, 0.413497])
    """
    l = np.arange(int(order) + 1)
    return np.sinc(l / (order + 1))


def window_gaussian(order: int, sigma: float | None = None) -> np.ndarray:
    """Gaussian window of angular width σ: h_l = exp(-l(l+1)σ²/2).

    Applied to Eq. (2), Ramamoorthi & Hanrahan 2001 (module docstring).

    The spherical heat kernel: convolution with a Gaussian of standard deviation σ (radians) on
    the sphere, Herbert et al.'s Gaussian pre-sampling (§7.3).

    Parameters
    ----------
    order : int
        L.
    sigma : float, optional
        σ in radians, > 0; default π/L (and no window at L = 0).

    Examples
    --------
    >>> window_gaussian(2, 0.5).round(6)
    array([1.      , 0.778801, 0.472367])
    """
    L = int(order)
    if sigma is None:
        sigma = np.pi / L if L > 0 else 0.0
    l = np.arange(L + 1)
    return np.exp(-0.5 * l * (l + 1) * sigma * sigma)


#: Windows by spec name; ``reference(order, *params) -> h (L+1,)``.
WINDOWS = Registry("window")
WINDOWS.register(Method("none", window_none, None, "Eq. (2), Ramamoorthi & Hanrahan 2001"))
WINDOWS.register(Method("hanning", window_hanning, None, "§7.3, Herbert et al."))
WINDOWS.register(Method("lanczos", window_lanczos, None, "§7.3, Herbert et al."))
WINDOWS.register(
    ParametricMethod("gaussian", window_gaussian, None, "§7.3, Herbert et al.", param="sigma")
)


def parse_window(spec: str) -> tuple[str, tuple]:
    """Split a window spec ``NAME[:PARAM]`` into the registered name and its parameters.

    Raises
    ------
    SpecrefError
        Unknown window, a parameter where none is allowed, or a bad σ.

    Examples
    --------
    >>> parse_window("gaussian:0.05")
    ('gaussian', (0.05,))
    >>> parse_window("hamming")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: unknown window 'hamming'; allowed: gaussian, hanning, lanczos,
    none
    """
    name, _, param = str(spec).partition(":")
    entry = WINDOWS.lookup(name)
    if not param:
        return name, ()
    require(
        isinstance(entry, ParametricMethod), f"window {name!r} takes no parameter, got {spec!r}"
    )
    try:
        value = float(param)
    except ValueError:
        raise SpecrefError(
            f"window {spec!r}: σ must be a number in radians, got {param!r}"
        ) from None
    require(np.isfinite(value) and value > 0, f"window {spec!r}: σ must be > 0 radians")
    return name, (value,)


def window_weights(window, order: int) -> np.ndarray:
    """The weights h_l, l = 0..L, of a window spec (or None for no window).

    Examples
    --------
    >>> window_weights("hanning", 1)
    array([1. , 0.5])
    """
    if window is None:
        window = "none"
    name, params = parse_window(window)
    return WINDOWS.lookup(name).reference(int(order), *params)


def apply_window(coeffs, window) -> np.ndarray:
    """Multiply SH coefficients ``(..., (L+1)²)`` by the window's h_l, degree by degree.

    Eq. (2), Ramamoorthi & Hanrahan 2001, windowed (module docstring).

    Examples
    --------
    >>> apply_window(np.ones(4), "hanning")
    array([1. , 0.5, 0.5, 0.5])
    """
    from shrm.sh import order_of, sh_degrees_orders

    coeffs = np.asarray(coeffs, dtype=np.float64)
    L = order_of(coeffs.shape[-1])
    l, _ = sh_degrees_orders(L)
    return coeffs * window_weights(window, L)[l]


def ringing_statistics(values) -> dict:
    """Undershoot and negative share of a reconstruction: how badly a window rings.

    Parameters
    ----------
    values : array_like, shape (H, W) or (H, W, C)
        The reconstructed map (for several channels the statistics pool all of them).

    Returns
    -------
    dict
        ``undershoot`` = min / max (negative when the map dips below 0), ``negative_share`` = the
        fraction of pixels below 0, ``min`` and ``peak``.

    Examples
    --------
    >>> ringing_statistics(np.array([[-1.0, 4.0], [2.0, 3.0]]))
    {'undershoot': -0.25, 'negative_share': 0.25, 'min': -1.0, 'peak': 4.0}
    """
    v = np.asarray(values, dtype=np.float64)
    peak = float(v.max())
    low = float(v.min())
    return {
        "undershoot": low / peak if peak > 0 else float("nan"),
        "negative_share": float((v < 0).mean()),
        "min": low,
        "peak": peak,
    }

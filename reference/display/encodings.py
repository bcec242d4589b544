"""Display encodings: linear display RGB to the values sent to a display, and back.

A registry of encodings, each a pair of functions between linear values in [0, 1] and encoded values
in
[0, 1]:

- ``srgb``: the IEC 61966-2-1 transfer function (through colour-science);
- ``linear``: no encoding;
- ``gamma_1.8`` and ``gamma_2.2``: the plain power laws of Eq. (6), Herbert et al.;
- ``lstar``: Herbert's L*-linear calibration, Eq. (7), Herbert et al.

References
----------
- F. Herbert, J. Kirkenaer, O. Unter Ecker, "Achieving a Multi-spectral Virtual Reality", 2004, §6.
- IEC 61966-2-1:1999, sRGB.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from reference.registry import Method, Registry

__all__ = [
    "ENCODINGS",
    "decode_gamma",
    "decode_lstar_Herbert",
    "decode_srgb",
    "display_to_linear",
    "encode_gamma",
    "encode_linear",
    "encode_lstar_Herbert",
    "encode_srgb",
    "linear_to_display",
    "to_8bit",
]


def encode_srgb(linear):
    """SRGB encoding (IEC 61966-2-1 inverse EOTF) of linear values, through colour-science.

    Parameters
    ----------
    linear : array_like
        Linear values; clipped to [0, 1] first.

    Returns
    -------
    ndarray
        Encoded values in [0, 1].

    Examples
    --------
    >>> encode_srgb([0.0, 0.0031308, 0.18, 1.0]).round(4)
    array([0.    , 0.0404, 0.4614, 1.    ])
    """
    import colour

    return colour.models.eotf_inverse_sRGB(np.clip(np.asarray(linear, dtype=np.float64), 0.0, 1.0))


def decode_srgb(encoded):
    """Inverse of :func:`encode_srgb`.

    Examples
    --------
    >>> decode_srgb(encode_srgb([0.18])).round(12)
    array([0.18])
    """
    import colour

    return colour.models.eotf_sRGB(np.clip(np.asarray(encoded, dtype=np.float64), 0.0, 1.0))


def encode_gamma(linear, gamma: float = 2.2):
    """Power-law encoding, the inverse of Eq. (6), Herbert et al.: ``G/255 = (Y/Y_max)^(1/Gamma)``.

    Examples
    --------
    >>> encode_gamma([0.25], 2.0)
    array([0.5])
    """
    # Eq. (6), Herbert et al.: Y = (G/255)^Gamma · Y_max, solved for G/255
    return np.clip(np.asarray(linear, dtype=np.float64), 0.0, 1.0) ** (1.0 / gamma)


def decode_gamma(encoded, gamma: float = 2.2):
    """Eq. (6), Herbert et al.: ``Y/Y_max = (G/255)^Gamma``.

    Examples
    --------
    >>> decode_gamma([0.5], 2.0)
    array([0.25])
    """
    # Eq. (6), Herbert et al.
    return np.clip(np.asarray(encoded, dtype=np.float64), 0.0, 1.0) ** gamma


# Y/Y_max at G = 0 under Eq. (7), Herbert et al.: (16/116)^3. The paper's calibration does not
# reach zero; see docs/errata.md.
_LSTAR_BLACK = (16.0 / 116.0) ** 3


def decode_lstar_Herbert(encoded):
    """Herbert's L*-linear display calibration: relative luminance from the digital value.

    Eq. (7), Herbert et al.: ``Y = (((G/255)·100 + 16)/116)^3 · Y_max``.

    Parameters
    ----------
    encoded : array_like
        ``G/255`` in [0, 1].

    Returns
    -------
    ndarray
        ``Y/Y_max``, in [(16/116)^3, 1]: the printed formula gives 0.26 % of peak at G = 0 (no toe),
        which is kept as printed.

    Examples
    --------
    >>> decode_lstar_Herbert([0.0, 0.5, 1.0]).round(5)
    array([0.00262, 0.18419, 1.     ])
    """
    G = np.clip(np.asarray(encoded, dtype=np.float64), 0.0, 1.0)
    # Eq. (7), Herbert et al.: Y = (((G/255)·100 + 16)/116)^3 · Y_max
    return ((G * 100.0 + 16.0) / 116.0) ** 3


def encode_lstar_Herbert(linear):
    """Inverse of Eq. (7), Herbert et al.: ``G/255 = (116·(Y/Y_max)^(1/3) - 16)/100``, in [0, 1].

    Values below ``(16/116)^3`` (the calibration's black) encode to 0.

    Examples
    --------
    >>> encode_lstar_Herbert(decode_lstar_Herbert([0.25, 0.75])).round(12)
    array([0.25, 0.75])
    """
    Y = np.clip(np.asarray(linear, dtype=np.float64), _LSTAR_BLACK, 1.0)
    # Eq. (7), Herbert et al., solved for G/255
    return np.clip((116.0 * np.cbrt(Y) - 16.0) / 100.0, 0.0, 1.0)


def encode_linear(values):
    """No encoding: linear values clipped to [0, 1] (also its own inverse).

    Examples
    --------
    >>> encode_linear([-0.5, 0.25, 2.0])
    array([0.  , 0.25, 1.  ])
    """
    return np.clip(np.asarray(values, dtype=np.float64), 0.0, 1.0)


@dataclass(frozen=True, kw_only=True)
class Encoding(Method):
    """A display encoding: ``reference`` encodes linear values, ``decode`` goes back.

    Parameters
    ----------
    decode : callable
        The inverse of ``reference`` on [0, 1].
    kwargs : dict
        Keyword arguments passed to both (``{"gamma": 2.2}``).
    """

    decode: Callable[..., np.ndarray]
    kwargs: dict = field(default_factory=dict)


#: Display encodings by the keys of scene files (``display.encoding``) and the CLI.
ENCODINGS = Registry("encoding", Encoding)
ENCODINGS.register(Encoding("srgb", encode_srgb, None, "IEC 61966-2-1", decode=decode_srgb))
ENCODINGS.register(Encoding("linear", encode_linear, None, "none", decode=encode_linear))
for _gamma in (1.8, 2.2):
    ENCODINGS.register(
        Encoding(
            f"gamma_{_gamma}",
            encode_gamma,
            None,
            "Eq. (6), Herbert et al.",
            decode=decode_gamma,
            kwargs={"gamma": _gamma},
        )
    )
ENCODINGS.register(
    Encoding(
        "lstar", encode_lstar_Herbert, None, "Eq. (7), Herbert et al.", decode=decode_lstar_Herbert
    )
)


def linear_to_display(linear, encoding: str = "srgb", exposure: float = 1.0) -> np.ndarray:
    """Encode linear display RGB for the display: scale by ``exposure``, clip to [0, 1], encode.

    Parameters
    ----------
    linear : array_like, shape (..., 3)
        Linear display RGB (1 = display white).
    encoding : str
        A key of :data:`ENCODINGS`.
    exposure : float
        Multiplier applied before clipping.

    Returns
    -------
    ndarray
        Encoded values in [0, 1], same shape.

    Examples
    --------
    >>> linear_to_display([[0.0, 0.18, 2.0]], "srgb").round(4)
    array([[0.    , 0.4614, 1.    ]])
    """
    entry = ENCODINGS.lookup(encoding)
    return entry.reference(np.asarray(linear, dtype=np.float64) * exposure, **entry.kwargs)


def display_to_linear(encoded, encoding: str = "srgb") -> np.ndarray:
    """Decode display values back to linear (the inverse of :func:`linear_to_display` on [0, 1]).

    Examples
    --------
    >>> display_to_linear(linear_to_display([0.5], "gamma_2.2"), "gamma_2.2").round(12)
    array([0.5])
    """
    entry = ENCODINGS.lookup(encoding)
    return entry.decode(encoded, **entry.kwargs)


def to_8bit(encoded) -> np.ndarray:
    """Quantize encoded values in [0, 1] to uint8 with round-half-up.

    Examples
    --------
    >>> to_8bit([0.0, 0.5, 1.0])
    array([  0, 128, 255], dtype=uint8)
    """
    values = np.clip(np.asarray(encoded, dtype=np.float64), 0.0, 1.0)
    return np.floor(values * 255.0 + 0.5).astype(np.uint8)

"""Two-flux Kubelka–Munk slab of a pigmented polymer: the generator of Herbert et al.'s chip matrix.

§3.1, Herbert et al. measured polymer chips at three thicknesses (0.03", 0.06", 0.120") and several
TiO2 loads, over black and white backing and in transmission, and built "a matrix of colour values
as a function of thickness and TiO2 concentration". specref has no chips, so this module models
them, band by band:

- the **body**: a layer of thickness ``d`` (mm) with absorption ``K`` and scattering ``S`` (1/mm),
  where ``K = K_base + c K_TiO2`` and ``S = S_base + c S_TiO2`` for a TiO2 load ``c`` (% by weight)
  (:func:`polymer_K_S`, constituents from ``shrm/polymer/data/polymer_hdpe_tio2.toml``);
  its reflectance over black and transmittance are Kubelka's hyperbolic solution (:func:`km_slab`),
  and over a backing ``R_g`` the two combine by adding the layers (:func:`km_over_backing`);
- the **surfaces**: the Saunderson correction, a smooth interface of index ``n`` on each side with
  constants from the exact Fresnel formulae (:class:`SaundersonConstants`), and an air gap between
  the chip and its backing (:func:`slab_measured`);
- the **inverse**: K and S per band from reflectances over black and over white at a known
  thickness (:func:`km_invert`), so real measurements predict any other thickness and load.

Conventions: thickness in mm, K and S in 1/mm, loads in % TiO2 by weight, spectra on the last axis.
Reflectances are hemispherical (d/8 geometry, specular included), as a sphere spectrophotometer
such as Herbert's Datacolor Spectraflash 600 measures them.

References
----------
Herbert, M., et al. (2004). Multispectral Virtual Reality: Spectral Shading with Spherical
    Harmonics. (specref's Herbert et al.)
Kubelka, P., & Munk, F. (1931). Ein Beitrag zur Optik der Farbanstriche. Z. Tech. Phys. 12, 593–601.
Kubelka, P. (1948). New contributions to the optics of intensely light-scattering materials. Part I.
    J. Opt. Soc. Am. 38, 448–457 (the hyperbolic solution, R over a backing, the inversion).
Saunderson, J. L. (1942). Calculation of the color of pigmented plastics. J. Opt. Soc. Am. 32,
    727–736 (the surface correction, applied to exactly this problem: TiO2 in a polymer).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from reference.colour.spectra import DEFAULT_GRID, SpectralGrid
from reference.errors import SpecrefError, require, require_finite
from reference.materials.fresnel import (
    MAX_REFRACTIVE_INDEX,
    fresnel_dielectric,
    fresnel_diffuse,
)
from reference.scene.loader import read_toml_file

__all__ = [
    "DEFAULT_CONSTITUENTS",
    "PolymerConstituents",
    "SaundersonConstants",
    "km_R_infinity",
    "km_invert",
    "km_over_backing",
    "km_slab",
    "km_tinted_K",
    "polymer_K_S",
    "polymer_constituents",
    "saunderson_constants",
    "slab_measured",
]

#: The shipped constituents: an "HDPE-like" base and rutile TiO2 (sources in the file).
DEFAULT_CONSTITUENTS = Path(__file__).with_name("data") / "polymer_hdpe_tio2.toml"


def _nonnegative(values, where: str) -> np.ndarray:
    values = require_finite(values, where)
    require(bool(np.all(values >= 0.0)), f"{where}: must be >= 0, got {values.min()!r}")
    return values


@dataclass(frozen=True)
class PolymerConstituents:
    """K and S spectra of a base polymer and of the TiO2 opacifier on one grid.

    Parameters
    ----------
    grid : SpectralGrid
        The wavelengths of every spectrum.
    K_base, S_base : ndarray, shape (n_bands,)
        Absorption and scattering of the base polymer, 1/mm.
    K_TiO2, S_TiO2 : ndarray, shape (n_bands,)
        Absorption and scattering added per 1 % TiO2 by weight, 1/mm.
    index : float
        Refractive index of the base polymer (> 1).
    name : str
        A label for reports.
    """

    grid: SpectralGrid
    K_base: np.ndarray
    S_base: np.ndarray
    K_TiO2: np.ndarray
    S_TiO2: np.ndarray
    index: float
    name: str = "polymer"


#: Bounds of a constituents file's numbers (the forms are in the shipped file): K and S up to
#: 1e4 per mm (opaque within 0.1 µm: any chip), scattering no steeper than Rayleigh's λ⁻⁴, widths
#: and the absorption edge within the spectrum. S_exponent = 1e308 made infinite S, refused by
#: km_slab naming neither file nor key.
CONSTITUENT_BOUNDS = {
    "index": (1.0, MAX_REFRACTIVE_INDEX, "a refractive index, > 1"),
    "K_0": (0.0, 1e4, "1/mm"),
    "K_blue": (0.0, 1e4, "1/mm"),
    "K_tau_nm": (0.0, 1000.0, "nm, > 0"),
    "S_560": (0.0, 1e4, "1/mm"),
    "S_exponent": (0.0, 4.0, "the power of 560/λ, at most Rayleigh's 4"),
    "K_edge": (0.0, 1e4, "1/mm"),
    "edge_nm": (0.0, 2000.0, "nm"),
    "edge_width_nm": (0.0, 1000.0, "nm, > 0"),
    "K_floor": (0.0, 1e4, "1/mm"),
}


def _number(table: dict, key: str, where: str) -> float:
    require(key in table, f"{where}: missing key {key!r}")
    value = table[key]
    low, high, meaning = CONSTITUENT_BOUNDS[key]
    require(
        isinstance(value, int | float)
        and not isinstance(value, bool)
        and np.isfinite(value)
        and low <= value <= high,
        f"{where}.{key}: must be a number in [{low:g}, {high:g}] ({meaning}), got {value!r}",
    )
    return float(value)


def polymer_constituents(
    grid: SpectralGrid = DEFAULT_GRID, path: str | Path | None = None
) -> PolymerConstituents:
    """Evaluate a constituents file (``[base]`` and ``[tio2]`` tables) on a spectral grid.

    The forms and the reasoning behind the shipped values are in the file itself
    (``shrm/polymer/data/polymer_hdpe_tio2.toml``).

    Parameters
    ----------
    grid : SpectralGrid
        Wavelengths to evaluate on.
    path : str or Path, optional
        A TOML file with the keys of the shipped one; default :data:`DEFAULT_CONSTITUENTS`.

    Returns
    -------
    PolymerConstituents

    Raises
    ------
    SpecrefError
        For a missing table or key, a negative or non-finite value, or an index <= 1.

    Examples
    --------
    >>> c = polymer_constituents()
    >>> c.name, c.index, c.K_base.shape
    ('HDPE-like', 1.54, (41,))
    >>> bool(c.K_base[0] > c.K_base[-1])  # absorbs more in the blue: yellowish
    True
    """
    path = Path(DEFAULT_CONSTITUENTS if path is None else path)
    data = read_toml_file(path)
    for table in ("base", "tio2"):
        require(isinstance(data.get(table), dict), f"{path}: missing table [{table}]")
    allowed = {
        "": {"base", "tio2"},
        "base": {"name", "index", "K_0", "K_blue", "K_tau_nm", "S_560", "S_exponent"},
        "tio2": {"name", "S_560", "S_exponent", "K_edge", "edge_nm", "edge_width_nm", "K_floor"},
    }
    for table, keys in allowed.items():  # a misspelt key would be ignored and its default used
        extra = sorted(set(data[table] if table else data) - keys)
        where = f"{table}." if table else ""
        require(
            not extra,
            f"{path}: {where}{extra[0] if extra else ''}: unknown key; allowed: "
            f"{', '.join(sorted(keys))}",
        )
    base = data["base"]
    num = {
        (t, k): _number(data[t], k, f"{path}: {t}")
        for t, keys in (
            ("base", ("index", "K_0", "K_blue", "K_tau_nm", "S_560", "S_exponent")),
            ("tio2", ("S_560", "S_exponent", "K_edge", "edge_nm", "edge_width_nm", "K_floor")),
        )
        for k in keys
    }
    require(num["base", "index"] > 1, f"{path}: base.index: must be > 1, got {base['index']!r}")
    for t, k in (("base", "K_tau_nm"), ("tio2", "edge_width_nm")):
        require(num[t, k] > 0, f"{path}: {t}.{k}: must be > 0, got {data[t][k]!r}")
    wl = grid.wavelengths_nm
    K_base = num["base", "K_0"] + num["base", "K_blue"] * np.exp(
        -(wl - 380.0) / num["base", "K_tau_nm"]
    )
    S_base = num["base", "S_560"] * (560.0 / wl) ** num["base", "S_exponent"]
    edge = (wl - num["tio2", "edge_nm"]) / num["tio2", "edge_width_nm"]
    K_TiO2 = num["tio2", "K_floor"] + num["tio2", "K_edge"] / (1.0 + np.exp(edge))
    S_TiO2 = num["tio2", "S_560"] * (560.0 / wl) ** num["tio2", "S_exponent"]
    name = str(base.get("name", path.stem))
    return PolymerConstituents(grid, K_base, S_base, K_TiO2, S_TiO2, num["base", "index"], name)


def polymer_K_S(constituents: PolymerConstituents, tio2_pct) -> tuple[np.ndarray, np.ndarray]:
    """Absorption and scattering of the pigmented polymer at a TiO2 load.

    ``K = K_base + c K_TiO2``, ``S = S_base + c S_TiO2`` (Duncan's additive mixing of K and S).

    Parameters
    ----------
    constituents : PolymerConstituents
        From :func:`polymer_constituents`.
    tio2_pct : float or array_like, shape (...,)
        TiO2 load c, % by weight, >= 0.

    Returns
    -------
    K, S : ndarray, shape (..., n_bands)
        1/mm.

    Raises
    ------
    SpecrefError
        For a negative or non-finite load.

    Examples
    --------
    >>> K, S = polymer_K_S(polymer_constituents(), [0.0, 1.0])
    >>> K.shape, bool(S[1, 18] > 10 * S[0, 18])
    ((2, 41), True)
    """
    c = _nonnegative(tio2_pct, "polymer_K_S: tio2_pct")[..., None]
    return (
        constituents.K_base + c * constituents.K_TiO2,
        constituents.S_base + c * constituents.S_TiO2,
    )


def _tanh_over_x(x: np.ndarray) -> np.ndarray:
    """tanh(x)/x for x >= 0, exact to rounding at x = 0."""
    small = x < 1e-4
    safe = np.where(small, 1.0, x)
    return np.where(small, 1.0 - x**2 / 3.0 + 2.0 * x**4 / 15.0, np.tanh(safe) / safe)


def km_slab(K, S, d) -> tuple[np.ndarray, np.ndarray]:
    """Kubelka's reflectance over an ideal black backing and transmittance of a slab (no surfaces).

    With ``β = sqrt(K (K + 2S))`` (``= b S`` in Kubelka's ``a = 1 + K/S``, ``b = sqrt(a² − 1)``):
    ``R_0 = S sinh(βd) / ((K+S) sinh(βd) + β cosh(βd))``, ``T = β / ((K+S) sinh(βd) + β cosh(βd))``.
    The code divides by ``cosh(βd)`` and uses ``tanh(βd)/β``, so it neither overflows for thick
    slabs nor divides by zero without absorption (K = 0) or without scattering (S = 0, where
    ``T = exp(−Kd)``).

    Parameters
    ----------
    K, S : array_like, shape (..., n_bands)
        Absorption and scattering, 1/mm, >= 0.
    d : float or array_like, broadcasting with K
        Thickness, mm, >= 0.

    Returns
    -------
    R_0, T : ndarray
        Diffuse reflectance over black and diffuse transmittance of the body, in [0, 1].

    Raises
    ------
    SpecrefError
        For a negative or non-finite K, S or d.

    Examples
    --------
    >>> R_0, T = km_slab(0.0, 1.0, 1.0)  # no absorption: R_0 = Sd / (1 + Sd)
    >>> float(R_0), float(T)
    (0.5, 0.5)
    >>> R_0, T = km_slab(1.0, 0.0, 2.0)  # no scattering: Beer-Lambert
    >>> float(R_0), float(T).__round__(6)
    (0.0, 0.135335)
    """
    K = _nonnegative(K, "km_slab: K")
    S = _nonnegative(S, "km_slab: S")
    d = _nonnegative(d, "km_slab: d (thickness, mm)")
    beta = np.sqrt(K * (K + 2.0 * S))
    x = beta * d
    # Kubelka (1948): R_0 and T with numerator and denominator divided by β cosh(βd)
    q = d * _tanh_over_x(x)  # tanh(βd) / β
    denominator = (K + S) * q + 1.0
    sech = 2.0 * np.exp(-x) / (1.0 + np.exp(-2.0 * x))
    return S * q / denominator, sech / denominator


def km_R_infinity(K, S) -> np.ndarray:
    """Reflectance of an opaque layer (d → ∞): ``R_∞ = 1 + K/S − sqrt((K/S)² + 2K/S)``.

    Kubelka & Munk (1931); written as ``S / (K + S + sqrt(K (K + 2S)))`` to avoid cancellation.

    Parameters
    ----------
    K, S : array_like, shape (..., n_bands)
        1/mm, >= 0, S > 0 where K = 0.

    Returns
    -------
    ndarray
        R_∞ in [0, 1].

    Examples
    --------
    >>> float(km_R_infinity(1.0, 4.0))  # K/S = 1/4: 1.25 - sqrt(0.5625)
    0.5
    """
    K = _nonnegative(K, "km_R_infinity: K")
    S = _nonnegative(S, "km_R_infinity: S")
    return S / (K + S + np.sqrt(K * (K + 2.0 * S)))


#: Smallest opaque reflectance a tint may ask for (a tint of 0 would need infinite absorption).
TINT_MIN_R_INFINITY = 1e-6


def km_tinted_K(K, S, tint, r_t: float = 0.0) -> np.ndarray:
    """Absorption of the slab with a dye: an opaque chip's diffuse reflectance times ``tint``.

    Not in Herbert et al., whose ``Tint_polymer`` (Eq. (2), Herbert et al.) multiplies the
    hybrid's diffuse term; the layered model needs the tint inside the slab (erratum E115). A dye
    absorbs and does not scatter (Duncan's additive mixing keeps ``S``), and its amount is set so
    that an opaque chip's diffuse reflectance seen from outside, ``ρ = (1 − r_t) R_∞ / (1 − r_t
    R_∞)`` (Saunderson 1942, the front surface's internal reflectance ``r_t``), becomes ``tint``
    times the untinted one, as the hybrid's tint makes it (a spot colour is measured from
    outside). Inverting Saunderson, ``R'_∞ = ρ' / ((1 − r_t) + r_t ρ')`` with ``ρ' = tint · ρ``,
    and from Kubelka & Munk's ``K/S = (1 − R_∞)² / (2 R_∞)``,

        ``K' = S (1 − R'_∞)² / (2 R'_∞)``.

    A thin or translucent chip then follows the slab's physics (its transmission is tinted as
    well); ``tint = 1`` leaves ``K`` unchanged; ``R'_∞`` is held at least
    :data:`TINT_MIN_R_INFINITY`; where ``S = 0`` there is no body to tint and ``K`` is kept.

    Parameters
    ----------
    K, S : array_like, shape (..., n_bands)
        The untinted slab, 1/mm.
    tint : float or array_like, shape (n_bands,)
        In [0, 1].
    r_t : float
        Internal diffuse reflectance of the front surface (``Coupling.r_i`` of
        ``shrm.polymer.oracle``), in [0, 1); 0 scales ``R_∞`` itself.

    Returns
    -------
    ndarray, shape (..., n_bands)
        ``K'``, 1/mm, >= ``K``.

    Examples
    --------
    >>> K, S = np.array([0.1, 0.1]), np.array([20.0, 20.0])
    >>> K2 = km_tinted_K(K, S, np.array([1.0, 0.5]))
    >>> bool(K2[0] == K[0]), (km_R_infinity(K2, S) / km_R_infinity(K, S)).round(12)
    (True, array([1. , 0.5]))
    """
    K = _nonnegative(K, "km_tinted_K: K")
    S = _nonnegative(S, "km_tinted_K: S")
    t = require_finite(tint, "km_tinted_K: tint")
    require(bool(np.all((t >= 0) & (t <= 1))), f"km_tinted_K: tint: must be in [0, 1], got {t!r}")
    r = float(r_t)
    require(0.0 <= r < 1.0, f"km_tinted_K: r_t: must be in [0, 1), got {r_t!r}")
    R = km_R_infinity(K, S)
    # Saunderson (1942): the opaque chip seen from outside, tinted, then back inside
    rho = t * (1.0 - r) * R / (1.0 - r * R)
    R_tinted = np.maximum(rho / ((1.0 - r) + r * rho), TINT_MIN_R_INFINITY)
    # Kubelka & Munk (1931): K/S = (1 − R_∞)² / (2 R_∞)
    K_tinted = S * (1.0 - R_tinted) ** 2 / (2.0 * R_tinted)
    return np.where((t == 1.0) | (S == 0.0), K, np.maximum(K_tinted, K))


def km_over_backing(R_0, T, R_g) -> np.ndarray:
    """Reflectance of a symmetric layer (R_0, T) over a backing of reflectance R_g.

    Kubelka (1948), the adding of two layers: ``R = R_0 + T² R_g / (1 − R_0 R_g)``.

    Parameters
    ----------
    R_0, T : array_like
        The layer's reflectance over black and its transmittance.
    R_g : array_like
        Diffuse reflectance of the backing, in [0, 1].

    Returns
    -------
    ndarray

    Examples
    --------
    >>> float(km_over_backing(0.5, 0.5, 1.0))  # lossless layer on a white mirror
    1.0
    """
    R_0, T, R_g = (np.asarray(v, dtype=np.float64) for v in (R_0, T, R_g))
    return R_0 + T**2 * R_g / (1.0 - R_0 * R_g)


@dataclass(frozen=True)
class SaundersonConstants:
    """Reflectances of the chip's smooth surfaces (Saunderson 1942).

    Parameters
    ----------
    k_1 : float or ndarray, shape (n_bands,)
        External reflectance for the instrument's light (d/8: Fresnel at 8°, specular included).
    k_2 : float or ndarray
        Internal reflectance for diffuse light inside the slab (Fresnel, hemispherical, with total
        internal reflection).
    k_e : float or ndarray
        External reflectance for diffuse light (between the chip's back and its backing).
    """

    k_1: float | np.ndarray
    k_2: float | np.ndarray
    k_e: float | np.ndarray


def saunderson_constants(n) -> SaundersonConstants:
    """The Saunderson constants of a smooth surface of index ``n``, from the exact Fresnel formulae.

    ``k_1 = F(8°)`` (the d/8 geometry of a sphere spectrophotometer, specular included),
    ``k_2`` the hemispherical internal reflectance, ``k_e`` the hemispherical external one
    (``reference.materials.fresnel.fresnel_diffuse``). For n = 1.5 these are Saunderson's and Judd's
    classic 0.04, 0.596 and 0.092.

    Parameters
    ----------
    n : float or array_like, shape (n_bands,)
        Refractive index, > 1.

    Returns
    -------
    SaundersonConstants

    Raises
    ------
    SpecrefError
        For an index <= 1.

    Examples
    --------
    >>> c = saunderson_constants(1.5)
    >>> round(float(c.k_1), 4), round(float(c.k_2), 3), round(float(c.k_e), 3)
    (0.04, 0.596, 0.092)
    """
    k_1 = fresnel_dielectric(np.cos(np.radians(8.0)), n)
    return SaundersonConstants(k_1, fresnel_diffuse(n, "inside"), fresnel_diffuse(n, "outside"))


def _backing_seen_from_inside(R_g, c: SaundersonConstants) -> np.ndarray:
    """The chip's back surface, an air gap and the backing, as one reflector seen from inside."""
    # Saunderson (1942): interface (k_2 inside, k_e outside) added to the backing R_g
    return c.k_2 + (1.0 - c.k_2) * (1.0 - c.k_e) * R_g / (1.0 - c.k_e * R_g)


def slab_measured(K, S, d, R_g=0.0, constants: SaundersonConstants | None = None, n=1.54):
    """What a sphere spectrophotometer measures on a chip: R over a backing, and T.

    The body (:func:`km_slab`) with a smooth surface on each side (Saunderson 1942), lying on a
    backing of reflectance ``R_g`` behind an air gap; T is the free-standing chip's diffuse
    transmittance. Light in the body is diffuse, so both surfaces reflect ``k_2`` from inside.

    Parameters
    ----------
    K, S : array_like, shape (..., n_bands)
        1/mm, >= 0.
    d : float or array_like
        Thickness, mm, >= 0.
    R_g : float or array_like, shape (n_bands,)
        Backing reflectance in [0, 1]: 0 for black.
    constants : SaundersonConstants, optional
        Default: :func:`saunderson_constants` of ``n``.
    n : float or array_like
        Refractive index used when ``constants`` is None.

    Returns
    -------
    R, T : ndarray, shape (..., n_bands)
        Measured reflectance (specular included) over the backing and transmittance.

    Raises
    ------
    SpecrefError
        For negative or non-finite K, S, d, or R_g outside [0, 1].

    Examples
    --------
    >>> R, T = slab_measured(0.0, 0.0, 1.0)  # a clear, lossless sheet: surfaces only
    >>> round(float(R + T), 12)
    1.0
    """
    c = saunderson_constants(n) if constants is None else constants
    R_g = require_finite(R_g, "slab_measured: R_g")
    require(
        bool(np.all((R_g >= 0) & (R_g <= 1))),
        f"slab_measured: R_g: must be in [0, 1], got {R_g.min()!r}",
    )
    R_i, T_i = km_slab(K, S, d)
    # Kubelka (1948): the body over the back surface, the gap and the backing
    R_down = km_over_backing(R_i, T_i, _backing_seen_from_inside(R_g, c))
    T_down = T_i * (1.0 - c.k_2) / (1.0 - R_i * c.k_2)
    # Saunderson (1942): the front surface
    R = c.k_1 + (1.0 - c.k_1) * (1.0 - c.k_2) * R_down / (1.0 - c.k_2 * R_down)
    R_free = km_over_backing(R_i, T_i, c.k_2)
    T = (1.0 - c.k_1) * T_down / (1.0 - c.k_2 * R_free)
    return R, T


def km_invert(
    R_black,
    R_white,
    d,
    R_g_black=0.0,
    R_g_white=1.0,
    constants: SaundersonConstants | None = None,
    n=1.54,
):
    """K and S per band from a chip's reflectance over black and over white at thickness d.

    The classic Kubelka–Munk inversion, through the surfaces of :func:`slab_measured`: undo the
    front surface (Saunderson 1942), solve the two "layer over backing" equations for the body's
    R_0 and T (the R_0² terms cancel, so it is linear), then
    ``a = ((1 − R_0)² − T² + 2R_0) / (2R_0)``, ``b = sqrt(a² − 1)``,
    ``S = arsinh(b R_0 / T) / (b d)``, ``K = S (a − 1)`` (Kubelka 1948).

    Parameters
    ----------
    R_black, R_white : array_like, shape (..., n_bands)
        Measured reflectances over the black and the white backing, R_white > R_black.
    d : float
        Thickness, mm, > 0.
    R_g_black, R_g_white : float or array_like, shape (n_bands,)
        The backings' reflectances, in [0, 1], R_g_white > R_g_black.
    constants, n
        As in :func:`slab_measured`.

    Returns
    -------
    K, S : ndarray, shape (..., n_bands)
        1/mm.

    Raises
    ------
    SpecrefError
        For R_white <= R_black (the inversion is undefined: the chip is opaque or the data are
        swapped), reflectances the surfaces cannot produce, or a thickness <= 0.

    Examples
    --------
    >>> R_b, _ = slab_measured(0.2, 3.0, 1.0)
    >>> R_w, _ = slab_measured(0.2, 3.0, 1.0, R_g=0.9)
    >>> K, S = km_invert(R_b, R_w, 1.0, R_g_white=0.9)
    >>> round(float(K), 9), round(float(S), 9)
    (0.2, 3.0)
    """
    c = saunderson_constants(n) if constants is None else constants
    R_1 = require_finite(R_black, "km_invert: R_black")
    R_2 = require_finite(R_white, "km_invert: R_white")
    d = require_finite(d, "km_invert: d (thickness, mm)")
    require(bool(np.all(d > 0)), f"km_invert: d (thickness, mm): must be > 0, got {d.min()!r}")
    g_1 = _backing_seen_from_inside(require_finite(R_g_black, "km_invert: R_g_black"), c)
    g_2 = _backing_seen_from_inside(require_finite(R_g_white, "km_invert: R_g_white"), c)
    require(bool(np.all(g_2 > g_1)), "km_invert: R_g_white must exceed R_g_black in every band")
    R_1, R_2 = np.broadcast_arrays(R_1, R_2)
    bad = np.argwhere(~(R_2 > R_1))
    if bad.size:
        at = tuple(int(i) for i in bad[0])
        raise SpecrefError(
            "km_invert: reflectance over white must exceed reflectance over black (KM inversion "
            f"undefined: an opaque chip or swapped data), got {R_2[at]:.6g} <= {R_1[at]:.6g} at "
            f"index {at[0] if len(at) == 1 else at}"
        )
    # Saunderson (1942), inverted: the body seen through the front surface
    R_1, R_2 = (
        (R - c.k_1) / ((1.0 - c.k_1) * (1.0 - c.k_2) + c.k_2 * (R - c.k_1)) for R in (R_1, R_2)
    )
    # Kubelka (1948): R_m = R_0 + T² g_m / (1 − R_0 g_m) for both backings, solved for R_0 and T²
    R_0 = (g_1 * R_2 - g_2 * R_1) / (g_1 - g_2 + g_1 * g_2 * (R_2 - R_1))
    T2 = (R_2 - R_0) * (1.0 - R_0 * g_2) / g_2
    require(
        bool(np.all((R_0 >= 0) & (T2 > 0) & (R_0 + np.sqrt(np.clip(T2, 0, None)) <= 1 + 1e-12))),
        "km_invert: the reflectances are not those of a slab with these surfaces and backings",
    )
    return _km_K_S(R_0, np.sqrt(T2), d)


def _km_K_S(R_0, T, d):
    """K and S of a body of thickness d, mm, from its reflectance R_0 and transmittance T."""
    # Kubelka (1948): a − 1 = ((1 − R_0)² − T²) / (2 R_0), b, S and K
    scattering = R_0 > 1e-14
    R_0s = np.where(scattering, R_0, 1.0)
    a_minus_1 = np.clip((1.0 - R_0s - T) * (1.0 - R_0s + T), 0.0, None) / (2.0 * R_0s)
    b = np.sqrt(a_minus_1 * (a_minus_1 + 2.0))
    b_safe = np.where(b > 0, b, 1.0)
    # b → 0 (no absorption): arsinh(b R_0/T)/b → R_0/T
    S_d = np.where(b > 1e-12, np.arcsinh(b * R_0s / T) / b_safe, R_0s / T)
    S = np.where(scattering, S_d / d, 0.0)
    K = np.where(scattering, S * a_minus_1, -np.log(T) / d)
    return K, S

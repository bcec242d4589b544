"""A spectral display: three primaries' spectra, non-ideal tone responses, black, channel drift.

The display that Herbert et al. calibrate (§6) and Ferwerda characterises (§3.4) is simulated
spectrally (no hardware here). For channel drives ``d_c`` in [0, 1] it emits the spectral radiance

    L(λ; d) = L_K(λ) + Σ_c r_c(d_c) · S_c(λ − δ_c (1 − d_c)),

with ``S_c`` the primary's spectrum at full drive (colour-science's display primaries datasets,
selectable by :data:`DISPLAY_PRIMARIES`), ``L_K`` the black (light leaking through all three
channels, bluish by default), ``r_c`` the channel's tone response, gain-offset-gamma
``r_c(d) = max((1 − o_c) d + o_c, 0)^γ_c`` with its own exponent and offset per channel (or a
tabulated ramp), and ``δ_c`` a wavelength shift of the primary that grows as the drive falls: the
channel interaction that makes a channel's chromaticity drift with its drive (0 disables it).

The colorimetric summary of this display, Eq. (1), Ferwerda, is *derived* from it through
measurements: :func:`spectral_display_measurements` measures the black, the primaries, the ramps and
the angular falloff in the format of ``reference.display.model`` and
:func:`spectral_to_display_model` builds the :class:`~reference.display.model.DisplayModel` from
them. Every departure from a real display is listed in ``docs/errata.md`` (E50).

References
----------
- F. Herbert, J. Kirkenaer, O. Unter Ecker, "Achieving a Multi-spectral Virtual Reality", 2004, §6.
- J. A. Ferwerda, "ImpastoR: A realistic surface display system", Vision Research 109, 2015, §3.4.
- R. S. Berns, "Methods for characterizing CRT displays", Displays 16(4), 1996 (the GOG model).
- D. H. Brainard, D. G. Pelli, T. Robson, "Display characterization", 2002 (primaries datasets).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache, lru_cache

import numpy as np

from reference.display.model import DisplayModel, display_from_measurements
from reference.errors import SpecrefError, require, require_finite
from reference.registry import Method, Registry

__all__ = [
    "CMFS_NAME",
    "DISPLAY_PRIMARIES",
    "K_M",
    "SpectralDisplay",
    "cmfs_on",
    "display_drives_to_XYZ",
    "display_drives_to_spectra",
    "load_spectral_display",
    "primaries_from_chromaticities",
    "spectra_to_absolute_XYZ",
    "spectral_display",
    "spectral_display_from_doc",
    "spectral_display_measurements",
    "spectral_to_display_model",
    "tone_response",
]

#: Luminous efficacy, lm/W: XYZ in cd/m² from spectral radiance in W/(sr·m²·nm).
K_M = 683.0
#: The observer of every absolute XYZ here.
CMFS_NAME = "CIE 1931 2 Degree Standard Observer"


@cache
def _colour_primaries_table(key: str) -> tuple[np.ndarray, np.ndarray]:
    # read once per process: colour-science builds the table's signals on every access
    import colour

    table = colour.MSDS_DISPLAY_PRIMARIES[key]
    return np.asarray(table.wavelengths, dtype=np.float64), np.asarray(table.values, float).T


def _primaries_from_colour(key: str):
    wavelengths, spectra = _colour_primaries_table(key)
    return wavelengths.copy(), spectra.copy()


def primaries_apple_studio():
    """Apple Studio Display primaries (colour-science dataset), 380-780 nm at 5 nm.

    Returns
    -------
    wavelengths_nm : ndarray, shape (81,)
    spectra : ndarray, shape (3, 81)
        R, G, B at full drive, relative units.

    Examples
    --------
    >>> w, s = primaries_apple_studio()
    >>> w.shape, s.shape
    ((81,), (3, 81))
    """
    return _primaries_from_colour("Apple Studio Display")


def primaries_crt_brainard():
    """Typical CRT primaries, Brainard 1997 (colour-science dataset), 380-780 nm at 5 nm.

    Examples
    --------
    >>> w, s = primaries_crt_brainard()
    >>> float(w[0]), float(w[-1]), s.shape
    (380.0, 780.0, (3, 81))
    """
    return _primaries_from_colour("Typical CRT Brainard 1997")


def _gaussian_primaries(centres_nm, widths_nm):
    """Three Gaussian primaries on a 1 nm grid, 380-780 nm, peak 1 (synthetic, erratum E105)."""
    w = np.arange(380.0, 781.0, 1.0)
    return w, np.stack(
        [np.exp(-0.5 * ((w - c) / s) ** 2) for c, s in zip(centres_nm, widths_nm, strict=True)]
    )


def primaries_led_wide():
    """A wide-gamut LED-like display: Gaussians at 630, 530, 460 nm (σ 12, 15, 10 nm), 1 nm grid.

    Examples
    --------
    >>> w, s = primaries_led_wide()
    >>> w.shape, s.shape
    ((401,), (3, 401))
    """
    return _gaussian_primaries((630.0, 530.0, 460.0), (12.0, 15.0, 10.0))


def primaries_laser():
    """A narrow-band laser-like display: Gaussians at 638, 532, 450 nm (σ 1.5 nm), 1 nm grid.

    Lines narrower than a 5 nm instrument's band pass (erratum E105).

    Examples
    --------
    >>> w, s = primaries_laser()
    >>> int(w[np.argmax(s[1])])
    532
    """
    return _gaussian_primaries((638.0, 532.0, 450.0), (1.5, 1.5, 1.5))


#: How close a primary's stand-in spectrum must come to its stated chromaticity (CIE 1931 xy):
#: half the last digit of a datasheet's three decimals (a primary on the spectrum locus, as
#: BT.2020's, is reached only in the limit of a line; a 0.5 nm Gaussian comes within 3e-4).
XY_TOLERANCE = 5e-4


def _inside_locus(xy, w: np.ndarray) -> bool:
    """Whether ``xy`` is inside the locus and the line of purples, or within the tolerance of it.

    A datasheet's locus point, rounded to three decimals, may lie just outside.
    """
    from matplotlib.path import Path as Polygon

    locus = cmfs_on(w)
    locus = locus[:, :2] / locus.sum(axis=1, keepdims=True)
    if Polygon(locus).contains_point(xy):
        return True
    # the distance to the closed outline, segment by segment
    a, b = locus, np.roll(locus, -1, axis=0)
    t = np.clip(np.einsum("ij,ij->i", xy - a, b - a) / np.einsum("ij,ij->i", b - a, b - a), 0, 1)
    return float(np.min(np.linalg.norm(a + t[:, None] * (b - a) - xy, axis=1))) <= XY_TOLERANCE


def _gaussian_xy(centre_nm: float, width_nm: float, w: np.ndarray) -> np.ndarray:
    XYZ = spectra_to_absolute_XYZ(np.exp(-0.5 * ((w - centre_nm) / width_nm) ** 2), w)
    return XYZ[:2] / XYZ.sum()


def _gaussian_for_xy(xy, w: np.ndarray) -> tuple[np.ndarray, float]:
    """The Gaussian whose chromaticity is nearest ``xy`` (started at the nearest hue), its miss."""
    from scipy.optimize import least_squares

    target = np.asarray(xy, dtype=np.float64)
    locus = np.array([_gaussian_xy(c, 2.0, w) for c in w[::5]])
    start = float(w[::5][np.argmin(np.linalg.norm(locus - target, axis=1))])
    best = None
    for width in (5.0, 20.0, 60.0):
        fit = least_squares(
            lambda p: _gaussian_xy(p[0], p[1], w) - target,
            (start, width),
            bounds=((w[0], 0.5), (w[-1], 150.0)),
            xtol=1e-12,
            ftol=1e-12,
        )
        if best is None or fit.cost < best.cost:
            best = fit
    centre, width = best.x
    return np.exp(-0.5 * ((w - centre) / width) ** 2), float(np.linalg.norm(best.fun))


def _smooth_for_xy(xy, w: np.ndarray) -> tuple[np.ndarray, float]:
    """The smoothest non-negative spectrum of chromaticity ``xy`` (Meng et al. 2015), its miss."""
    import warnings

    import colour

    shape = colour.SpectralShape(float(w[0]), float(w[-1]), 5.0)
    cmfs = colour.MSDS_CMFS[CMFS_NAME].copy().align(shape)
    target = np.asarray(xy, dtype=np.float64)
    aim, spectrum, miss = target.copy(), np.zeros_like(w), np.inf
    Y = 0.05  # dark enough that the object colours reach saturated chromaticities
    for _ in range(3):  # solved at 5 nm, read at 1 nm: aim off by what the 1 nm grid shows
        x, y = aim
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                sd = colour.XYZ_to_sd(
                    np.array([x / y * Y, Y, (1 - x - y) / y * Y]),
                    method="Meng 2015",
                    cmfs=cmfs,
                    illuminant=colour.sd_constant(1.0, shape),
                )
        except RuntimeError:  # no spectrum in [0, 1] of that colour at that luminance
            break
        spectrum = np.clip(np.interp(w, sd.wavelengths, sd.values), 0.0, None)
        XYZ = spectra_to_absolute_XYZ(spectrum, w)
        error = XYZ[:2] / XYZ.sum() - target
        miss = float(np.linalg.norm(error))
        if miss <= XY_TOLERANCE:
            break
        aim = aim - error
    return spectrum, miss


def _primary_for_xy(xy, w: np.ndarray, where: str) -> np.ndarray:
    """A Gaussian where one has the colour, else Meng et al.'s smoothest spectrum (E109)."""
    require(
        _inside_locus(xy, w),
        f"{where}: chromaticity ({xy[0]:g}, {xy[1]:g}) is outside the spectrum locus: no light "
        "has that colour",
    )
    spectrum, miss = _gaussian_for_xy(xy, w)
    if miss > XY_TOLERANCE:
        smooth, smooth_miss = _smooth_for_xy(xy, w)
        spectrum, miss = (smooth, smooth_miss) if smooth_miss < miss else (spectrum, miss)
    require(
        miss <= XY_TOLERANCE,
        f"{where}: chromaticity ({xy[0]:g}, {xy[1]:g}) is not the colour of a Gaussian nor of "
        f"a smooth spectrum (closest Δxy {miss:.2g}: on or outside the spectrum locus); give "
        "the primary's spectrum (wavelengths_nm, R, G, B) instead",
    )
    return spectrum


def primaries_from_chromaticities(xy, white_xy=(0.3127, 0.3290), where: str = "primaries"):
    """Spectral stand-ins for primaries given by chromaticities (erratum E109).

    A display known by its datasheet (the xy of R, G, B and of the white) has no spectra, but
    specref's displays and instruments are spectral. Each primary becomes, on a 1 nm grid, the
    Gaussian whose CIE 1931 chromaticity is the stated one (a display-like band; it reaches the
    spectrum locus as it narrows), or where no Gaussian has that colour (towards the purples:
    sRGB's red) the smoothest non-negative spectrum that does (Meng et al. 2015, through
    colour-science), each within :data:`XY_TOLERANCE`. The three are weighted so that full drive
    gives the white's chromaticity: ``S = M⁻¹ XYZ_w`` of the usual RGB-to-XYZ derivation (``M``:
    the primaries' XYZ at Y = 1).

    Parameters
    ----------
    xy : (3, 2) array_like
        R, G, B chromaticities.
    white_xy : (2,) array_like
        The white's chromaticity (default D65).
    where : str
        What a refusal names (the file and key).

    Returns
    -------
    (ndarray (401,), ndarray (3, 401))
        Wavelengths (nm) and spectra, relative (the display scales them to its white).

    Raises
    ------
    SpecrefError
        A chromaticity no Gaussian reaches, or a white outside the primaries' triangle.

    Examples
    --------
    >>> w, spectra = primaries_from_chromaticities([[0.64, 0.33], [0.30, 0.60], [0.15, 0.06]])
    >>> XYZ = spectra_to_absolute_XYZ(spectra, w)
    >>> (XYZ[:, :2] / XYZ.sum(axis=1, keepdims=True)).round(4).tolist()
    [[0.64, 0.33], [0.3, 0.6], [0.15, 0.06]]
    >>> white = XYZ.sum(axis=0)
    >>> (white[:2] / white.sum()).round(4).tolist()
    [0.3127, 0.329]
    """
    xy = require_finite(xy, where)
    white = require_finite(white_xy, f"{where}: white")
    require(xy.shape == (3, 2), f"{where}: must be three [x, y] pairs (R, G, B), got {xy.shape}")
    require(white.shape == (2,), f"{where}: white: must be one [x, y] pair, got {white.shape}")
    for label, (x, y) in zip("RGBW", [*xy, white], strict=True):
        require(
            0 < x < 1 and 0 < y < 1 and x + y <= 1,
            f"{where}: {label}: ({x:g}, {y:g}) is not a chromaticity (x, y > 0, x + y <= 1)",
        )
    w = np.arange(380.0, 781.0, 1.0)
    try:
        unit = _unit_primaries(tuple(map(tuple, xy.tolist())))
    except SpecrefError as error:
        raise SpecrefError(f"{where}: {error}") from None
    # M: the primaries' XYZ at Y = 1, columns R, G, B; S = M⁻¹ XYZ_w (white at Y = 1)
    M = np.stack([[x / y, 1.0, (1 - x - y) / y] for x, y in xy]).T
    S = np.linalg.solve(M, [white[0] / white[1], 1.0, (1 - white.sum()) / white[1]])
    require(
        bool((S > 0).all()),
        f"{where}: white ({white[0]:g}, {white[1]:g}) is outside the primaries' triangle",
    )
    Y_unit = spectra_to_absolute_XYZ(unit, w)[:, 1]
    return w, unit * (S / Y_unit)[:, None]


@lru_cache(maxsize=16)
def _unit_primaries(xy: tuple) -> np.ndarray:
    """The three stand-in spectra (1 nm, 380-780 nm), once per set of chromaticities."""
    w = np.arange(380.0, 781.0, 1.0)
    unit = np.stack([_primary_for_xy(c, w, k) for c, k in zip(xy, "RGB", strict=True)])
    unit.flags.writeable = False  # shared by every caller of the cache
    return unit


#: Display primaries by the keys of display files and the CLI; ``reference()`` returns
#: ``(wavelengths_nm, spectra (3, n))``.
DISPLAY_PRIMARIES = Registry("display primaries")
DISPLAY_PRIMARIES.register(
    Method("apple_studio", primaries_apple_studio, None, "colour: Apple Studio Display")
)
DISPLAY_PRIMARIES.register(
    Method("crt_brainard", primaries_crt_brainard, None, "colour: Typical CRT Brainard 1997")
)
DISPLAY_PRIMARIES.register(
    Method("led_wide", primaries_led_wide, None, "synthetic: Gaussian LED-like primaries")
)
DISPLAY_PRIMARIES.register(
    Method("laser", primaries_laser, None, "synthetic: 1.5 nm laser-like lines")
)


def cmfs_on(wavelengths_nm) -> np.ndarray:
    """CIE 1931 2° colour matching functions at the given wavelengths, shape (n, 3).

    Examples
    --------
    >>> cmfs_on([555.0]).round(4)
    array([[0.5121, 1.    , 0.0057]])
    """
    w = np.asarray(wavelengths_nm, dtype=np.float64)
    return _cmfs_on_grid(w.tobytes(), w.shape).copy()


@lru_cache(maxsize=64)
def _cmfs_on_grid(grid: bytes, shape: tuple) -> np.ndarray:
    # the calibration's instruments ask for the same grids thousands of times
    import colour

    cmfs = colour.MSDS_CMFS[CMFS_NAME]
    w = np.frombuffer(grid, dtype=np.float64).reshape(shape)
    return np.stack([np.interp(w, cmfs.wavelengths, cmfs.values[:, i]) for i in range(3)], -1)


def spectra_to_absolute_XYZ(spectra, wavelengths_nm) -> np.ndarray:
    """Absolute XYZ (cd/m²) of spectral radiances (W/(sr·m²·nm)) on a uniform grid.

    ``X = K_m Σ L(λ) x̄(λ) Δλ`` (rectangle rule on the grid; the CIE 15 summation).

    Parameters
    ----------
    spectra : array_like, shape (..., n)
    wavelengths_nm : array_like, shape (n,), uniform

    Returns
    -------
    ndarray, shape (..., 3)

    Examples
    --------
    >>> w = np.arange(380.0, 781.0, 5.0)
    >>> float(spectra_to_absolute_XYZ(np.where(w == 555.0, 1 / 5 / 683, 0.0), w)[1])
    1.0
    """
    w = np.asarray(wavelengths_nm, dtype=np.float64)
    step = float(w[1] - w[0])
    return K_M * step * np.asarray(spectra, dtype=np.float64) @ cmfs_on(w)


def tone_response(drives, gamma, offset, ramp_drive=None, ramp_Y=None) -> np.ndarray:
    """Relative output of each channel for its drive: gain-offset-gamma, or a tabulated ramp.

    ``r_c(d) = max((1 − o_c) d + o_c, 0)^γ_c`` (Berns 1996), so ``r_c(1) = 1``; with a ramp,
    ``r_c`` is its linear interpolation (``ramp_Y`` from 0 to 1).

    Parameters
    ----------
    drives : array_like, shape (..., 3), in [0, 1]
    gamma, offset : array_like, shape (3,)
    ramp_drive : array_like, shape (m,), optional
    ramp_Y : array_like, shape (3, m), optional

    Returns
    -------
    ndarray, shape (..., 3), in [0, 1]

    Examples
    --------
    >>> tone_response([[0.5, 0.5, 0.5]], [2.0, 2.0, 2.0], [0.0, 0.0, -1.0]).round(4)
    array([[0.25, 0.25, 0.  ]])
    """
    d = np.clip(np.asarray(drives, dtype=np.float64), 0.0, 1.0)
    if ramp_drive is not None:
        return np.stack([np.interp(d[..., c], ramp_drive, ramp_Y[c]) for c in range(3)], -1)
    gamma, offset = np.asarray(gamma, float), np.asarray(offset, float)
    # gain-offset-gamma (Berns 1996): r = ((1 − o) d + o)^γ, zero below the cut-off
    return np.maximum((1.0 - offset) * d + offset, 0.0) ** gamma


@dataclass(frozen=True)
class SpectralDisplay:
    """A simulated display, described spectrally (see the module docstring).

    Attributes
    ----------
    wavelengths_nm : ndarray, shape (n,)
        Uniform grid, nm.
    primaries : ndarray, shape (3, n)
        ``S_c``: spectral radiance of R, G, B at full drive, black excluded, W/(sr·m²·nm).
    black : ndarray, shape (n,)
        ``L_K``: spectral radiance at zero drive.
    gamma, offset : ndarray, shape (3,)
        Gain-offset-gamma tone response per channel.
    shift_nm : ndarray, shape (3,)
        Wavelength shift of each primary at zero drive (channel interaction; zeros: none).
    lfactor_coefficients : tuple of float
        ``(c0, p, q)`` of the angular falloff (Eq. (1), Ferwerda), for the derived model.
    ramp_drive, ramp_Y : ndarray or None
        A tabulated tone response (replaces gain-offset-gamma when given).
    name : str
    """

    wavelengths_nm: np.ndarray
    primaries: np.ndarray
    black: np.ndarray
    gamma: np.ndarray
    offset: np.ndarray
    shift_nm: np.ndarray
    lfactor_coefficients: tuple = (1.0, 0.547, 0.730)
    ramp_drive: np.ndarray | None = None
    ramp_Y: np.ndarray | None = None
    name: str = "spectral display"

    @property
    def white_XYZ(self) -> np.ndarray:
        """XYZ at full drive of all three channels, cd/m²."""
        return display_drives_to_XYZ(self, np.ones(3))

    @property
    def black_XYZ(self) -> np.ndarray:
        """XYZ at zero drive, cd/m²."""
        return display_drives_to_XYZ(self, np.zeros(3))


def display_drives_to_spectra(display: SpectralDisplay, drives) -> np.ndarray:
    """Spectral radiance the display emits for channel drives, W/(sr·m²·nm).

    ``L(λ; d) = L_K(λ) + Σ_c r_c(d_c) S_c(λ − δ_c (1 − d_c))`` (module docstring).

    Parameters
    ----------
    display : SpectralDisplay
    drives : array_like, shape (..., 3), in [0, 1]

    Returns
    -------
    ndarray, shape (..., n)

    Raises
    ------
    SpecrefError
        Drives outside [0, 1] or not finite.

    Examples
    --------
    >>> d = spectral_display()
    >>> display_drives_to_spectra(d, [[1.0, 1.0, 1.0], [0.5, 0.5, 0.5]]).shape
    (2, 81)
    """
    d = require_finite(drives, "display drives")
    require(
        d.shape[-1:] == (3,) and d.min() >= 0.0 and d.max() <= 1.0,
        f"display drives: must have shape (..., 3) in [0, 1], got shape {d.shape} and range "
        f"{d.min():g}..{d.max():g}",
    )
    r = tone_response(d, display.gamma, display.offset, display.ramp_drive, display.ramp_Y)
    w = display.wavelengths_nm
    out = np.broadcast_to(display.black, d.shape[:-1] + w.shape).copy()
    for c in range(3):
        shift = display.shift_nm[c] * (1.0 - d[..., c])
        # channel drift: the primary's spectrum shifted by δ_c (1 − d_c) nm
        shifted = np.interp(w - shift[..., None], w, display.primaries[c], left=0.0, right=0.0)
        out += r[..., c, None] * shifted
    return out


def display_drives_to_XYZ(display: SpectralDisplay, drives) -> np.ndarray:
    """XYZ (cd/m²) the display emits for channel drives, shape (..., 3).

    Examples
    --------
    >>> d = spectral_display()
    >>> display_drives_to_XYZ(d, [1.0, 1.0, 1.0]).round(1)
    array([105.9, 120. , 111.2])
    """
    spectra = display_drives_to_spectra(display, drives)
    return spectra_to_absolute_XYZ(spectra, display.wavelengths_nm)


def spectral_display(
    primaries: str = "apple_studio",
    white_cd_m2: float = 120.0,
    black_cd_m2: float = 0.25,
    gamma=(2.35, 2.2, 2.05),
    offset=(-0.03, 0.0, -0.015),
    shift_nm=(0.0, 3.0, -4.0),
    black_leak=(1.0, 1.0, 1.3),
) -> SpectralDisplay:
    """The built-in simulated display: registered primaries scaled to a white luminance.

    Parameters
    ----------
    primaries : str or tuple
        A key of :data:`DISPLAY_PRIMARIES`, or ``(wavelengths_nm (n,), spectra (3, n))``.
    white_cd_m2, black_cd_m2 : float
        Luminance of full drive and of zero drive (the black is included in the white).
    gamma, offset : sequence of 3 floats
        Gain-offset-gamma per channel (different on purpose: the calibration must balance them).
    shift_nm : sequence of 3 floats
        Channel drift at zero drive, nm (zeros for no interaction).
    black_leak : sequence of 3 floats
        Relative leak of R, G, B into the black (bluish by default, as LCDs are).

    Returns
    -------
    SpectralDisplay

    Examples
    --------
    >>> d = spectral_display()
    >>> round(float(d.white_XYZ[1]), 6), round(float(d.black_XYZ[1]), 6)
    (120.0, 0.25)
    """
    require(
        0.0 <= black_cd_m2 < white_cd_m2,
        f"display: black_cd_m2 must be in [0, white_cd_m2), got {black_cd_m2} and {white_cd_m2}",
    )
    # Erratum E50: a simulated display (colour-science primaries, our tone responses and black)
    if isinstance(primaries, str):
        w, spectra = DISPLAY_PRIMARIES.lookup(primaries).reference()
    else:
        (w, spectra), primaries = primaries, "file"
    Y = spectra_to_absolute_XYZ(spectra, w)[:, 1]
    leak = np.asarray(black_leak, float) * (spectra / Y[:, None]).T
    black = leak.sum(axis=1)
    black = black * black_cd_m2 / max(spectra_to_absolute_XYZ(black, w)[1], 1e-300)
    scaled = spectra * (white_cd_m2 - black_cd_m2) / Y.sum()
    return SpectralDisplay(
        w,
        scaled,
        black,
        np.asarray(gamma, float),
        np.asarray(offset, float),
        np.asarray(shift_nm, float),
        name=f"simulated display ({primaries} primaries, {white_cd_m2:g} cd/m² white)",
    )


def spectral_display_measurements(display: SpectralDisplay, levels: int = 33) -> dict:
    """Measure the display in the measurement-file format of ``reference.display.model``.

    The black, each primary at full drive (black included), each channel's ramp (luminance at
    ``levels`` drives) and the angular falloff (±30° at 5° in landscape and portrait), as a
    noise-free spectroradiometer reads them. 11-bit counts, as Ferwerda's tables.

    Examples
    --------
    >>> doc = spectral_display_measurements(spectral_display())
    >>> doc["bits"], len(doc["ramps"]["G"]["Y"]), round(doc["black_XYZ"][1], 3)
    (11, 33, 0.25)
    """
    top = 2**11 - 1
    counts = np.round(np.linspace(0, top, levels)).astype(int)
    black = display.black_XYZ
    primaries, ramps = {}, {}
    for c, name in enumerate("RGB"):
        drives = np.zeros((levels, 3))
        drives[:, c] = counts / top
        XYZ = display_drives_to_XYZ(display, drives)
        primaries[name] = XYZ[-1].tolist()
        ramps[name] = {"counts": counts.tolist(), "Y": XYZ[:, 1].tolist()}
    c0, p, q = display.lfactor_coefficients
    theta = np.radians(np.abs(np.arange(-30, 31, 5)))
    landscape, portrait = c0 - p * theta**2, c0 - q * theta**2
    phi = np.where(np.arange(-30, 31, 5) < 0, 180.0, 0.0)
    return {
        "name": display.name,
        "bits": 11,
        "black_XYZ": black.tolist(),
        "primaries_XYZ": primaries,
        "ramps": ramps,
        "angular": {
            "theta_deg": np.degrees(np.concatenate([theta, theta])).tolist(),
            "phi_deg": np.concatenate([phi, phi + 90.0]).tolist(),
            "Y_relative": np.concatenate([landscape, portrait]).tolist(),
        },
    }


def spectral_to_display_model(display: SpectralDisplay) -> DisplayModel:
    """The colorimetric summary of a spectral display: Eq. (1), Ferwerda, from its measurements.

    Examples
    --------
    >>> d = spectral_display()
    >>> model = spectral_to_display_model(d)
    >>> bool(np.allclose(model.white_XYZ, d.white_XYZ))
    True
    """
    return display_from_measurements(spectral_display_measurements(display), display.name)


def _spectrum(doc, key, where, n):
    values = require_finite(doc.get(key), f"{where}: {key}")
    require(values.shape == (n,), f"{where}: {key}: must have {n} values, got shape {values.shape}")
    if (values < 0).any():
        i = int(np.argmax(values < 0))
        raise SpecrefError(f"{where}: {key}: spectra must be >= 0, got {values[i]:g} at index {i}")
    return values


#: The brightest white a display file may state, cd/m²: the top of SMPTE ST 2084 (PQ), beyond
#: any display; 1e308 used to print overflowing figures.
MAX_WHITE_CD_M2 = 10_000.0


#: Bounds of a display file's per-channel keys, with what each bounds: an offset o of the tone
#: response ((1 − o) d + o)^γ beyond ±0.5 leaves too little gain to calibrate (0.99 ended in a
#: singular matrix); a primary drifted by more than 50 nm is another primary.
CHANNEL_BOUNDS = {
    "offset": (-0.5, 0.5, "", "each channel's offset o of ((1 - o) d + o)^gamma"),
    "shift_nm": (-50.0, 50.0, " nm", "each channel's drift at zero drive"),
    "black_leak": (0.0, 100.0, "", "each channel's relative leak into the black"),
}


def spectral_display_from_doc(doc: dict, where: str = "display file") -> SpectralDisplay:
    """A spectral display from a display file (JSON; format in ``docs/display.md``).

    Keys, all optional: ``primaries`` (a :data:`DISPLAY_PRIMARIES` key, or an object with
    ``wavelengths_nm``, ``R``, ``G``, ``B`` spectra), ``white_cd_m2``, ``black_cd_m2``, ``gamma``,
    ``offset``, ``shift_nm``, ``black_leak``, and ``ramps`` (``drive`` and ``R``, ``G``, ``B``
    relative outputs from 0 to 1, increasing) to replace gain-offset-gamma.

    Raises
    ------
    SpecrefError
        Negative spectra, a non-monotonic ramp, an unknown key or primaries set.

    Examples
    --------
    >>> spectral_display_from_doc({"ramps": {"drive": [0, 0.5, 1], "R": [0, 0.6, 0.5],
    ...     "G": [0, 0.5, 1], "B": [0, 0.5, 1]}}, "lcd.json")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: lcd.json: ramps.R: must increase with the drive (a
    non-monotonic ramp cannot be calibrated), got 0.5 after 0.6 at index 2
    """
    require(isinstance(doc, dict), f"{where}: must be a JSON object")
    allowed = {"primaries", "white_cd_m2", "black_cd_m2", "gamma", "offset", "shift_nm"}
    allowed |= {"black_leak", "ramps", "name"}
    unknown = sorted(set(doc) - allowed)
    if unknown:
        raise SpecrefError(
            f"{where}: unknown key {unknown[0]!r}; allowed: {', '.join(sorted(allowed))}"
        )
    kwargs = {
        k: doc[k]
        for k in ("white_cd_m2", "black_cd_m2", "gamma", "offset", "shift_nm", "black_leak")
        if k in doc
    }
    for key, value in kwargs.items():
        shape = () if key.endswith("cd_m2") else (3,)
        array = require_finite(value, f"{where}: {key}")
        require(array.shape == shape, f"{where}: {key}: must have shape {shape}, got {array.shape}")
        if key in CHANNEL_BOUNDS:  # 1e308 made NaN drives, 0.99 a singular matrix
            low, high, unit, meaning = CHANNEL_BOUNDS[key]
            require(
                bool(((array >= low) & (array <= high)).all()),
                f"{where}: {key}: {meaning} must be in [{low:g}, {high:g}]{unit}, "
                f"got {array.tolist()}",
            )
    if "gamma" in kwargs:
        gamma = np.asarray(kwargs["gamma"], dtype=float)
        require(
            bool(((gamma > 0) & (gamma <= 10)).all()),
            f"{where}: gamma: each channel's exponent must be in (0, 10], got {gamma.tolist()}",
        )
    white = float(kwargs.get("white_cd_m2", 120.0))
    require(
        0.0 < white <= MAX_WHITE_CD_M2,
        f"{where}: white_cd_m2: must be in (0, {MAX_WHITE_CD_M2:g}] cd/m², got {white:g}",
    )
    primaries = doc.get("primaries", "apple_studio")
    if isinstance(primaries, str):
        display = spectral_display(primaries, **kwargs)
    else:
        require(isinstance(primaries, dict), f"{where}: primaries: must be a key or an object")
        if "xy" in primaries:
            display = _display_from_xy(primaries, kwargs, f"{where}: primaries")
            return _finish_display(display, doc, where)
        w = require_finite(primaries.get("wavelengths_nm"), f"{where}: primaries.wavelengths_nm")
        require(
            w.ndim == 1 and w.size >= 3 and np.allclose(np.diff(w), w[1] - w[0]) and w[1] > w[0],
            f"{where}: primaries.wavelengths_nm: must be a uniform increasing grid",
        )
        spectra = np.stack([_spectrum(primaries, c, f"{where}: primaries", w.size) for c in "RGB"])
        display = _replace(spectral_display((w, spectra), **kwargs), name=where)
    return _finish_display(display, doc, where)


def _finish_display(display, doc, where) -> SpectralDisplay:
    if "ramps" in doc:
        display = _with_ramps(display, doc["ramps"], where)
    if "name" in doc:
        display = _replace(display, name=str(doc["name"]))
    return display


def _display_from_xy(primaries: dict, kwargs: dict, where: str) -> SpectralDisplay:
    """``primaries = {"xy": {"R": [x, y], "G": ..., "B": ...}, "white_xy": [x, y]}``."""
    unknown = sorted(set(primaries) - {"xy", "white_xy"})
    shown = unknown[0] if unknown else ""
    require(not unknown, f"{where}: unknown key {shown!r}; allowed: white_xy, xy")
    xy = primaries["xy"]
    require(
        isinstance(xy, dict) and sorted(xy) == ["B", "G", "R"],
        f"{where}.xy: must be an object with R, G and B, each [x, y]",
    )
    white = primaries.get("white_xy", [0.3127, 0.3290])
    spectra = primaries_from_chromaticities([xy[c] for c in "RGB"], white, f"{where}.xy")
    return _replace(spectral_display(spectra, **kwargs), name=where.split(":")[0])


def _replace(display, **changes):
    from dataclasses import replace

    return replace(display, **changes)


def _with_ramps(display, ramps, where) -> SpectralDisplay:
    require(isinstance(ramps, dict), f"{where}: ramps: must be an object with drive, R, G, B")
    for key in ("drive", "R", "G", "B"):  # a missing one was "must be finite, got nan"
        require(key in ramps, f"{where}: ramps: missing key {key!r}; it needs drive, R, G and B")
    unknown = sorted(set(ramps) - {"drive", "R", "G", "B"})
    if unknown:
        raise SpecrefError(f"{where}: ramps: unknown key {unknown[0]!r}; allowed: B, G, R, drive")
    drive = require_finite(ramps.get("drive"), f"{where}: ramps.drive")
    require(
        drive.ndim == 1 and drive.size >= 2 and drive[0] == 0 and drive[-1] == 1,
        f"{where}: ramps.drive: must run from 0 to 1",
    )
    require((np.diff(drive) > 0).all(), f"{where}: ramps.drive: must increase")
    table = []
    for c in "RGB":
        Y = require_finite(ramps.get(c), f"{where}: ramps.{c}")
        require(Y.shape == drive.shape, f"{where}: ramps.{c}: must have {drive.size} values")
        steps = np.diff(Y)
        if (steps <= 0).any():
            i = int(np.argmax(steps <= 0)) + 1
            raise SpecrefError(
                f"{where}: ramps.{c}: must increase with the drive (a non-monotonic ramp cannot "
                f"be calibrated), got {Y[i]:g} after {Y[i - 1]:g} at index {i}"
            )
        table.append((Y - Y[0]) / (Y[-1] - Y[0]))
    return _replace(display, ramp_drive=drive, ramp_Y=np.array(table))


def load_spectral_display(path) -> SpectralDisplay:
    """Read a display file (JSON; see :func:`spectral_display_from_doc`).

    Examples
    --------
    >>> load_spectral_display("/nonexistent/display.json")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent/display.json: file not found
    """
    from reference.files import read_json

    doc = read_json(path, "JSON display file")
    return spectral_display_from_doc(doc, str(path))

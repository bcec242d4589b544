"""Display calibration to any white and tone curve, the way Herbert et al. describe it (§6).

The display is calibrated "to any specified white point or matching illuminant" (D65, F2, A, D50,
or chromaticity coordinates), with a tone curve of gamma 1.8 or 2.2 (Eq. (6), Herbert et al.),
linear in L* (Eq. (7), Herbert et al.), sRGB or BT.1886 (:data:`CALIBRATION_CURVES`), holding the
white's chromaticity across the tonal range. :func:`calibrate_display`:

1. characterises the display with the instrument: black, primaries at full drive, a 33-step ramp
   per channel (the Eq. (1), Ferwerda model ``XYZ = XYZ_K + P ρ(d)``, an initial guess only);
2. finds the brightest white of the target chromaticity (one channel at full drive);
3. iterates per control point, from the white down: measure, correct the three channel drives
   through the model's Jacobian, re-measure, until the chromaticity (Δu'v') and the curve's
   luminance hold, the difference left is within the instrument's noise, or the iterations run
   out. Each measurement averages repeated readings, doubling their count until the mean's u'v'
   noise is half the tolerance (at most :data:`MAX_READINGS`): a real instrument integrates
   longer in the shadows, where one reading's noise exceeds the target. The points are denser in
   the highlights and the lowest sits at 1 % of white; the black is left alone (§6: "we do not
   try to adjust the black point");
4. fills the 256-entry per-channel look-up table between the points: each point's correction to
   the model is interpolated (monotone cubic in the gray level) and added to the model's answer;
   below the lowest point the channels keep its ratio (the display's own colour, as the paper says).

:func:`verify_calibration` reads the calibrated ramp with the
:class:`~reference.display.instruments.ReferenceMeter` (1 nm, no band pass, no noise), independent
of the instrument that calibrated, and :func:`calibration_targets` holds it to :data:`TARGET_DUV`
above 5 % of white and :data:`TARGET_Y` above 1 %.

References
----------
- F. Herbert, J. Kirkenaer, O. Unter Ecker, "Achieving a Multi-spectral Virtual Reality", 2004, §6.
- ITU-R BT.1886 (2011), the reference EOTF.
"""

from __future__ import annotations

import functools
import numbers
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from reference.display.encodings import decode_gamma, decode_lstar_Herbert, decode_srgb
from reference.display.instruments import INSTRUMENTS, ReferenceMeter
from reference.display.spectral import SpectralDisplay
from reference.errors import SpecrefError, require
from reference.registry import Method, Registry

__all__ = [
    "CALIBRATION_CURVES",
    "LUT_SIZE",
    "MAX_READINGS",
    "TARGET_DUV",
    "TARGET_Y",
    "WHITES",
    "Calibration",
    "XYZ_to_uv",
    "calibrate_display",
    "calibration_points",
    "calibration_targets",
    "curve_bt1886",
    "curve_gamma_18",
    "curve_gamma_22",
    "curve_lstar_Herbert",
    "curve_srgb",
    "curve_target",
    "targets_message",
    "verify_calibration",
    "white_xy",
]

#: Entries of the per-channel look-up tables (8-bit input, as the paper's G = 0..255).
LUT_SIZE = 256
#: Readings averaged per measurement at most (the count doubles from two until the mean's u'v'
#: noise is half the chromaticity tolerance; erratum E53).
MAX_READINGS = 256
#: The targets a calibration is held to, read by the reference meter (docs/display.md): the gray
#: ramp's Δu'v' from the white above ``TARGET_DUV[1]`` of white, and its luminance error |ΔY|/Y
#: above ``TARGET_Y[1]`` of white.
TARGET_DUV = (0.001, 0.05)
TARGET_Y = (0.01, 0.01)


def curve_bt1886(G, black_relative: float = 0.0):
    """ITU-R BT.1886 EOTF relative to white, through colour-science, with the display's black.

    Examples
    --------
    >>> curve_bt1886([0.0, 1.0], 0.01).round(6)
    array([0.01, 1.  ])
    """
    import colour

    G = np.clip(np.asarray(G, dtype=np.float64), 0.0, 1.0)
    return colour.models.eotf_BT1886(G, L_B=black_relative, L_W=1.0)


def curve_gamma_18(G, black_relative: float = 0.0):
    """Gamma 1.8, Eq. (6), Herbert et al.: ``Y/Y_max = (G/255)^1.8`` (the black is ignored).

    Examples
    --------
    >>> curve_gamma_18([0.5]).round(4)
    array([0.2872])
    """
    return decode_gamma(G, 1.8)


def curve_gamma_22(G, black_relative: float = 0.0):
    """Gamma 2.2, Eq. (6), Herbert et al.: ``Y/Y_max = (G/255)^2.2`` (the black is ignored).

    Examples
    --------
    >>> curve_gamma_22([0.5]).round(4)
    array([0.2176])
    """
    return decode_gamma(G, 2.2)


def curve_lstar_Herbert(G, black_relative: float = 0.0):
    """Linear in L*, Eq. (7), Herbert et al.: ``Y/Y_max = (((G/255)·100 + 16)/116)^3``.

    Examples
    --------
    >>> curve_lstar_Herbert([0.5]).round(4)
    array([0.1842])
    """
    return decode_lstar_Herbert(G)


def curve_srgb(G, black_relative: float = 0.0):
    """The sRGB EOTF (IEC 61966-2-1), through colour-science (the black is ignored).

    Examples
    --------
    >>> curve_srgb([0.5]).round(4)
    array([0.214])
    """
    return decode_srgb(G)


#: Target tone curves ``Y/Y_white`` of the gray level ``G/255``; ``reference(G, black_relative)``.
CALIBRATION_CURVES = Registry("calibration curve")
CALIBRATION_CURVES.register(Method("gamma1.8", curve_gamma_18, None, "Eq. (6), Herbert et al."))
CALIBRATION_CURVES.register(Method("gamma2.2", curve_gamma_22, None, "Eq. (6), Herbert et al."))
CALIBRATION_CURVES.register(Method("lstar", curve_lstar_Herbert, None, "Eq. (7), Herbert et al."))
CALIBRATION_CURVES.register(Method("srgb", curve_srgb, None, "IEC 61966-2-1"))
CALIBRATION_CURVES.register(Method("bt1886", curve_bt1886, None, "ITU-R BT.1886"))

#: The paper's whites (§6, Herbert et al.): D65, F2, A and D50 (CIE 1931 2° chromaticities).
WHITES = {"D65": "D65", "F2": "FL2", "A": "A", "D50": "D50"}


def white_xy(white: str) -> np.ndarray:
    """Chromaticity (x, y) of a white: a key of :data:`WHITES` or ``"x,y"``.

    Raises
    ------
    SpecrefError
        An unknown name, or coordinates outside the chromaticity diagram's square.

    Examples
    --------
    >>> white_xy("D65").round(4), white_xy("0.3457,0.3585")
    (array([0.3127, 0.329 ]), array([0.3457, 0.3585]))
    """
    import colour

    if white in WHITES:
        ccs = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]
        return np.asarray(ccs[WHITES[white]], dtype=np.float64)
    try:
        xy = np.array([float(v) for v in str(white).split(",")])
    except ValueError:
        xy = np.zeros(0)
    require(
        xy.shape == (2,) and (xy > 0).all() and xy.sum() < 1,
        f"white: must be one of {', '.join(WHITES)} or 'x,y' with x, y > 0 and x + y < 1, "
        f"got {white!r}",
    )
    return xy


def XYZ_to_uv(XYZ) -> np.ndarray:
    """CIE 1976 u', v' of XYZ, shape (..., 2).

    Examples
    --------
    >>> XYZ_to_uv([95.047, 100.0, 108.883]).round(4)
    array([0.1978, 0.4683])
    """
    X, Y, Z = np.moveaxis(np.asarray(XYZ, dtype=np.float64), -1, 0)
    denominator = X + 15.0 * Y + 3.0 * Z
    return np.stack([4.0 * X / denominator, 9.0 * Y / denominator], axis=-1)


def curve_target(curve: str, G, black_relative: float = 0.0) -> np.ndarray:
    """``Y/Y_white`` that the curve asks for at gray level ``G`` in [0, 1].

    Examples
    --------
    >>> curve_target("gamma2.2", [0.5]).round(4)
    array([0.2176])
    """
    return CALIBRATION_CURVES.lookup(curve).reference(G, black_relative)


def calibration_points(n: int, G_low: float) -> np.ndarray:
    """``n`` control gray levels from ``G_low`` to 1, denser in the highlights (§6, Herbert et al.).

    ``G_k = G_low + (1 − G_low)(1 − (1 − t_k)^1.3)`` with ``t_k`` uniform: the spacing shrinks
    towards the white.

    Examples
    --------
    >>> calibration_points(5, 0.1).round(3)
    array([0.1  , 0.381, 0.634, 0.852, 1.   ])
    """
    require(
        isinstance(n, int | np.integer) and 2 <= n <= 64,
        f"points: must be an integer in 2..64, got {n!r}",
    )
    t = np.linspace(0.0, 1.0, n)
    return G_low + (1.0 - G_low) * (1.0 - (1.0 - t) ** 1.3)


@dataclass(frozen=True)
class Calibration:
    """A display calibration: per-channel look-up tables and how they were reached.

    Attributes
    ----------
    lut : ndarray, shape (3, LUT_SIZE)
        Drive of R, G, B for each input level ``i/(LUT_SIZE − 1)``, in [0, 1], non-decreasing.
    white_xy : ndarray, shape (2,)
    white : str
        As given (``D65`` or ``x,y``).
    curve : str
        A key of :data:`CALIBRATION_CURVES`.
    Y_white, Y_black : float
        Calibrated white and the (untouched) black, cd/m², as the instrument read them.
    points : dict
        ``G`` (n,), ``drives`` (n, 3) and ``XYZ`` (n, 3) of the reading kept (the best), and
        ``iterations`` (n,): which reading that was (1 = the first).
    instrument : str
    display : str
    """

    lut: np.ndarray
    white_xy: np.ndarray
    white: str
    curve: str
    Y_white: float
    Y_black: float
    points: dict = field(default_factory=dict)
    instrument: str = "spectro"
    display: str = ""

    def target_Y(self, G) -> np.ndarray:
        """Target luminance (cd/m²) at gray levels ``G`` in [0, 1]."""
        return self.Y_white * curve_target(self.curve, G, self.Y_black / self.Y_white)

    def drives(self, RGB) -> np.ndarray:
        """Drives (..., 3) for device values ``RGB`` (..., 3) in [0, 1], through the tables."""
        RGB = np.asarray(RGB, dtype=np.float64)
        x = np.linspace(0.0, 1.0, self.lut.shape[1])
        return np.stack([np.interp(RGB[..., c], x, self.lut[c]) for c in range(3)], axis=-1)


@dataclass(frozen=True)
class _Characterization:
    """The instrument's view of the display: black, primaries matrix, ramps (Eq. (1), Ferwerda)."""

    black_XYZ: np.ndarray
    P: np.ndarray
    ramp_drive: np.ndarray
    ramp_rho: np.ndarray  # (3, m), increasing from 0 to 1

    def rho_to_drives(self, rho) -> np.ndarray:
        # interpolated in ρ^(1/2.2), where a display's ramp is nearly straight
        rho = np.clip(np.asarray(rho, dtype=np.float64), 0.0, 1.0) ** (1 / 2.2)
        ramps = self.ramp_rho ** (1 / 2.2)
        return np.stack([np.interp(rho[..., c], ramps[c], self.ramp_drive) for c in range(3)], -1)

    def XYZ_to_rho(self, XYZ) -> np.ndarray:
        # Eq. (1), Ferwerda, inverted on axis: ρ = P⁻¹ (XYZ − XYZ_K)
        rho = (np.asarray(XYZ, dtype=np.float64) - self.black_XYZ) @ np.linalg.inv(self.P).T
        # a channel that would go below zero stays at zero; the others match Y (see _correct)
        flat, targets = rho.reshape(-1, 3), np.reshape(XYZ, (-1, 3))
        for i in np.flatnonzero((flat < 0.0).any(axis=1)):
            flat[i] = _correct(self.P, np.zeros(3), targets[i] - self.black_XYZ)
        return flat.reshape(rho.shape)


class _Reading(NamedTuple):
    """A measurement: mean XYZ, the standard errors of its u'v' and relative Y, readings taken.

    ``XYZ`` (..., 3); ``se_uv`` (Euclidean over u', v'), ``se_Y`` and ``count`` (...).
    """

    XYZ: np.ndarray
    se_uv: np.ndarray
    se_Y: np.ndarray
    count: np.ndarray


@dataclass(frozen=True)
class _Reader:
    """Repeated readings of the instrument, averaged until the mean is quiet enough.

    From two readings, the count doubles until the standard error of the mean's u'v' is at most
    half ``tolerance_uv``, or ``max_readings`` are taken (the noise floor is then what is left). A
    noise-free instrument gives two equal readings and stops there.
    """

    measure: Callable  # drives (..., 3) -> XYZ (..., 3), cd/m²
    tolerance_uv: float
    max_readings: int

    def __post_init__(self):
        require(
            isinstance(self.max_readings, numbers.Integral)
            and not isinstance(self.max_readings, bool)
            and self.max_readings >= 2,
            f"max_readings: must be an integer >= 2, got {self.max_readings!r}",
        )

    def __call__(self, drives) -> _Reading:
        drives = np.asarray(drives, dtype=np.float64)
        flat = drives.reshape(-1, 3)
        readings = [np.empty((0, 3))] * len(flat)
        todo, taken, n = np.arange(len(flat)), 0, 2
        while todo.size:  # every drive still to do has ``taken`` readings
            new = self.measure(np.repeat(flat[todo, None], n - taken, axis=1))
            for i, rows in zip(todo, new, strict=True):
                readings[i] = np.concatenate([readings[i], rows])
            _, se_uv, _ = _mean_and_errors(np.stack([readings[i] for i in todo]))
            todo = todo[(se_uv > 0.5 * self.tolerance_uv) & (2 * n <= self.max_readings)]
            taken, n = n, 2 * n
        XYZ, se_uv, se_Y = np.empty((len(flat), 3)), np.empty(len(flat)), np.empty(len(flat))
        count = np.array([len(r) for r in readings])
        for m in np.unique(count):  # drives with as many readings, at once
            (rows,) = np.nonzero(count == m)
            XYZ[rows], se_uv[rows], se_Y[rows] = _mean_and_errors(
                np.stack([readings[i] for i in rows])
            )
        shape = drives.shape[:-1]
        return _Reading(XYZ.reshape(*shape, 3), *(a.reshape(shape) for a in (se_uv, se_Y, count)))


def _mean_and_errors(readings: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mean XYZ and the standard errors of its u'v' and relative Y, per drive.

    ``readings`` (drives, n, 3): n readings of each drive.
    """
    XYZ = readings.mean(axis=1)
    se_uv = np.linalg.norm(XYZ_to_uv(readings).std(axis=1, ddof=1), axis=-1)
    se_Y = readings[..., 1].std(axis=1, ddof=1) / np.maximum(np.abs(XYZ[:, 1]), 1e-300)
    count = np.sqrt(readings.shape[1])
    return XYZ, se_uv / count, se_Y / count


def _characterize(display, measure, levels: int = 33) -> _Characterization:
    drive = np.linspace(0.0, 1.0, levels) ** 2  # denser near black, where ramps bend
    black = measure(np.zeros(3))
    P = np.stack([measure(np.eye(3)[c]) - black for c in range(3)], axis=1)
    ramps = []
    for c in range(3):
        drives = np.zeros((levels, 3))
        drives[:, c] = drive
        # the channel's own share, from the dominant tristimulus value of its primary
        k = int(np.argmax(P[:, c] / P.sum(axis=1)))
        rho = (measure(drives)[:, k] - black[k]) / P[k, c]
        rho[0], rho[-1] = 0.0, 1.0
        # noisy readings near black: keep the ramp strictly increasing so it can be inverted
        rho = np.maximum.accumulate(np.clip(rho, 0.0, 1.0)) + np.linspace(0.0, 1e-9, levels)
        ramps.append(rho / rho[-1])
    return _Characterization(black, P, drive, np.array(ramps))


def _gamut_message(xy, P, white) -> str:
    import colour

    uv_primaries = XYZ_to_uv(P.T)
    uv = colour.xy_to_Luv_uv(xy)
    distances = []
    for i in range(3):
        a, b = uv_primaries[i], uv_primaries[(i + 1) % 3]
        t = np.clip(np.dot(uv - a, b - a) / np.dot(b - a, b - a), 0.0, 1.0)
        distances.append(np.linalg.norm(uv - (a + t * (b - a))))
    return (
        f"white: {white!r} (x, y = {xy[0]:.4f}, {xy[1]:.4f}) is outside the display's gamut by "
        f"Δu'v' = {min(distances):.4f}; the calibration would have to clip a channel and could "
        f"not hold that chromaticity: choose a white inside the primaries' triangle"
    )


def calibrate_display(
    display: SpectralDisplay,
    white: str = "D65",
    curve: str = "gamma2.2",
    points: int = 15,
    instrument: str = "spectro",
    seed: int = 0,
    tolerance_uv: float = 2e-4,
    tolerance_Y: float = 2e-3,
    max_iterations: int = 12,
    refine_rounds: int = 2,
    max_readings: int = MAX_READINGS,
) -> Calibration:
    """Calibrate a display to a white and a tone curve, iterating per point (module docstring).

    §6, Herbert et al.; the curves are Eqs. (6)-(7), Herbert et al. (and sRGB, BT.1886).

    Parameters
    ----------
    display : SpectralDisplay
    white : str
        A key of :data:`WHITES` or ``"x,y"``.
    curve : str
        A key of :data:`CALIBRATION_CURVES`.
    points : int
        Control points, 2..64 (the paper used up to 15).
    instrument : str
        A key of :data:`~reference.display.instruments.INSTRUMENTS`.
    seed : int
        Seed of the instrument's noise.
    tolerance_uv, tolerance_Y : float
        A point is done when Δu'v' and |ΔY|/Y are both within these.
    max_iterations : int
        Measurements per point at most.
    refine_rounds : int
        Rounds of adding points where the table misses between points (0: none); at most 64
        points in all.
    max_readings : int
        Readings averaged per measurement at most (module docstring, 3.).

    Returns
    -------
    Calibration

    Raises
    ------
    SpecrefError
        A white outside the gamut, points out of range, an unknown curve or instrument.

    Examples
    --------
    >>> from reference.display.spectral import spectral_display
    >>> cal = calibrate_display(spectral_display(), "D65", "lstar", points=8, instrument="ideal")
    >>> cal.lut.shape, round(cal.Y_white, 1), bool(cal.points["iterations"].max() <= 12)
    ((3, 256), 100.0, True)
    """
    CALIBRATION_CURVES.lookup(curve)
    make_instrument = INSTRUMENTS.lookup(instrument).reference
    xy = white_xy(white)
    calibration_points(points, 0.5)  # checks the count first
    # the instrument reading the display: drives (..., 3) -> XYZ (..., 3); erratum E53: the
    # loop's heuristics (characterisation, placement, tolerances, repeated readings) are ours
    measure = functools.partial(make_instrument().measure, display, rng=np.random.default_rng(seed))
    read = _Reader(measure, tolerance_uv, max_readings)
    model = _characterize(display, lambda drives: read(drives).XYZ)
    XYZ_w1, Y_white = _brightest_white(model, xy, white)
    loop = _Loop(model, read, XYZ_w1, tolerance_uv, tolerance_Y, max_iterations)
    # the white first: one channel stays at full drive
    done = {1.0: loop.run_point(Y_white * XYZ_w1, model.XYZ_to_rho(Y_white * XYZ_w1), True)}
    Y_white, Y_black = float(done[1.0].XYZ[1]), float(model.black_XYZ[1])
    aim = _Aim(Y_white, Y_black / Y_white, CALIBRATION_CURVES.lookup(curve).reference)
    loop.add_points(done, aim, points, refine_rounds)
    lut, record = loop.lut(done, aim), _points_record(done)
    name = getattr(display, "name", "")
    return Calibration(lut, xy, str(white), curve, Y_white, Y_black, record, instrument, name)


def _points_record(done: dict) -> dict:
    """``Calibration.points``: the points' gray levels, drives, XYZ and iterations, by level."""
    rows = [done[g] for g in sorted(done)]
    return {
        "G": np.array(sorted(done)),
        "drives": np.array([r.drives for r in rows]),
        "XYZ": np.array([r.XYZ for r in rows]),
        "iterations": np.array([r.iteration for r in rows]),
        "readings": np.array([r.readings for r in rows]),
        "floor_uv": np.array([r.floor_uv for r in rows]),
    }


def _brightest_white(model: _Characterization, xy, white: str) -> tuple[np.ndarray, float]:
    """The target white's XYZ at Y = 1, and the largest Y the display gives that chromaticity."""
    # the target white's direction, Y = 1
    XYZ_w1 = np.array([xy[0] / xy[1], 1.0, (1.0 - xy.sum()) / xy[1]])
    direction = np.linalg.solve(model.P, XYZ_w1)
    if (direction <= 0).any():
        raise SpecrefError(_gamut_message(xy, model.P, white))
    # the brightest white of that chromaticity: ρ = P⁻¹(Y XYZ_w1 − XYZ_K) <= 1
    offset = np.linalg.solve(model.P, model.black_XYZ)
    return XYZ_w1, float(np.min((1.0 + offset) / direction))


class _Point(NamedTuple):
    """A control point's best measurement and how it was reached.

    Drives, XYZ, linear drives ρ, which measurement it was (1 = first), the readings taken for
    the point in all and the u'v' standard error of the one kept.
    """

    drives: np.ndarray
    XYZ: np.ndarray
    rho: np.ndarray
    iteration: int
    readings: int
    floor_uv: float


class _Aim(NamedTuple):
    """The calibrated white's luminance (cd/m²), the black relative to it, and the tone curve."""

    Y_white: float
    black_relative: float
    curve: Callable  # a CALIBRATION_CURVES reference: curve(G, black_relative)

    def Y(self, G):
        """Target luminance (cd/m²) at gray levels ``G``."""
        return self.Y_white * self.curve(G, self.black_relative)


@dataclass(frozen=True)
class _Loop:
    """The calibration loop: the display's model, the instrument, the target white, tolerances."""

    model: _Characterization
    read: _Reader  # drives (..., 3) -> averaged reading
    XYZ_w1: np.ndarray  # the target white, Y = 1
    tolerance_uv: float
    tolerance_Y: float
    max_iterations: int

    def run_point(self, target_XYZ, rho, is_white) -> _Point:
        """Measure and correct one point until it holds; the best reading (module docstring, 3.)."""
        best, readings = None, 0
        for iteration in range(1, self.max_iterations + 1):
            drives = self.model.rho_to_drives(rho)
            reading = self.read(drives)
            XYZ, readings = reading.XYZ, readings + int(reading.count)
            duv = float(np.linalg.norm(XYZ_to_uv(XYZ) - XYZ_to_uv(target_XYZ)))
            dY = abs(XYZ[1] / target_XYZ[1] - 1.0)
            # the reading kept: the luminance held first (where the black makes the white's
            # chromaticity unreachable, a reading closer in colour but off in Y is worse)
            Y_held = is_white or dY <= max(self.tolerance_Y, 2.0 * reading.se_Y)
            score = (
                not Y_held,
                duv / self.tolerance_uv + (0.0 if is_white else dY / self.tolerance_Y),
            )
            if best is None or score < best[0]:
                best = (score, drives, XYZ, rho, iteration, float(reading.se_uv))
            # done when within the tolerances, or within what the instrument can still resolve
            if duv <= max(self.tolerance_uv, 2.0 * reading.se_uv) and (
                is_white or dY <= max(self.tolerance_Y, 2.0 * reading.se_Y)
            ):
                break
            if is_white:  # the white's luminance is whatever full drive gives
                target_XYZ = XYZ[1] * self.XYZ_w1
            rho = _correct(self.model.P, rho, target_XYZ - XYZ)
            if is_white:  # the brightest white: one channel at full drive
                rho = rho / rho.max()
        return _Point(*best[1:5], readings, best[5])

    def add_point(self, done: dict, aim: _Aim, G_k) -> None:
        """Run the point at gray level ``G_k`` and record it in ``done``."""
        target_XYZ = aim.Y_white * float(aim.curve(G_k, aim.black_relative)) * self.XYZ_w1
        done[float(G_k)] = self.run_point(target_XYZ, self.model.XYZ_to_rho(target_XYZ), False)

    def add_points(self, done: dict, aim: _Aim, points: int, refine_rounds: int) -> None:
        """The control points from the white down, then those the refinement rounds add."""
        G_low = _level_at(aim.curve, 0.008, aim.black_relative)
        for G_k in calibration_points(points, G_low)[-2::-1]:
            self.add_point(done, aim, G_k)
        # "the ability to add more points where required" (§6): check the middle of each interval
        # and add a point where the table misses by more than three tolerances
        for _ in range(refine_rounds):
            G = np.array(sorted(done))
            lut = self.lut(done, aim)
            middles = 0.5 * (G[1:] + G[:-1])
            room = 64 - len(G)
            if room <= 0:
                break
            XYZ = self.read(_interp_lut(lut, middles)).XYZ
            target_XYZ = aim.Y(middles)[:, None] * self.XYZ_w1
            miss_uv = np.linalg.norm(XYZ_to_uv(XYZ) - XYZ_to_uv(target_XYZ), axis=-1)
            miss_Y = np.abs(XYZ[:, 1] / target_XYZ[:, 1] - 1.0)
            worst = np.maximum(miss_uv / self.tolerance_uv, miss_Y / self.tolerance_Y)
            add = middles[worst > 3.0]
            if add.size == 0:
                break
            for G_k in add[np.argsort(-worst[worst > 3.0])][:room]:
                self.add_point(done, aim, G_k)

    def lut(self, done: dict, aim: _Aim) -> np.ndarray:
        """The tables between the points: the model's answer plus the interpolated corrections."""
        from scipy.interpolate import PchipInterpolator

        model = self.model
        G = np.array(sorted(done))
        rho_points = np.array([done[g].rho for g in G])
        levels = np.linspace(0.0, 1.0, LUT_SIZE)
        Y = aim.Y(levels)
        rho_model = model.XYZ_to_rho(Y[:, None] * self.XYZ_w1)
        rho_model_points = model.XYZ_to_rho(aim.Y(G)[:, None] * self.XYZ_w1)
        corrections = PchipInterpolator(G, rho_points - rho_model_points, extrapolate=True)
        rho = rho_model + corrections(np.clip(levels, G[0], 1.0))
        # below the lowest point the black is left alone: its ratio, scaled to the luminance
        below = levels < G[0]
        Y_low = aim.Y(G[0]) - model.black_XYZ[1]
        scale = np.clip((Y[below] - model.black_XYZ[1]) / Y_low, 0.0, 1.0)
        rho[below] = scale[:, None] * rho_points[0]
        rho[0] = 0.0
        drives = model.rho_to_drives(rho).T
        # a table must not decrease (noise can make neighbouring corrections cross)
        return np.maximum.accumulate(drives, axis=1)


def _correct(P, rho, dXYZ) -> np.ndarray:
    """Correct the linear drives through the model's Jacobian: ``Δρ = P⁻¹ ΔXYZ``.

    A channel that would go below zero (a target darker or more saturated than the black allows)
    stays at zero, and the others hold the luminance exactly and come as close to the colour as
    they can (:func:`_holding_Y`): where the white's chromaticity is out of reach, the tone curve
    is not given up for it.

    Examples
    --------
    >>> P = np.array([[0.4, 0.35, 0.2], [0.2, 0.7, 0.1], [0.0, 0.1, 0.95]])
    >>> new = _correct(P, np.array([0.01, 0.01, 0.01]), np.array([0.0, 0.01, -0.05]))
    >>> bool(new[2] == 0.0), bool(np.isclose((P @ new)[1], 0.01 * P[1].sum() + 0.01))
    (True, True)
    """
    new = rho + np.linalg.solve(P, dXYZ)
    target = P @ rho + dXYZ  # the XYZ the channels must give
    free = new >= 0.0
    while (new < 0.0).any() and free.any():
        new = np.zeros(3)
        new[free] = _holding_Y(P[:, free], target)
        free &= new >= 0.0
    return np.maximum(new, 0.0)


def _holding_Y(A, target) -> np.ndarray:
    """``x`` with ``(A x)_Y = target_Y`` exactly, ``‖(A x − target)_{X,Z}‖`` least (Lagrange).

    Examples
    --------
    >>> _holding_Y(np.array([[0.4], [0.2], [0.0]]), np.array([1.0, 0.5, 1.0])).tolist()
    [2.5]
    """
    k = A.shape[1]
    xz = A[[0, 2]]
    # the normal equations of the X, Z residual, bordered by the luminance's constraint
    kkt = np.zeros((k + 1, k + 1))
    kkt[:k, :k] = xz.T @ xz
    kkt[:k, k] = kkt[k, :k] = A[1]
    rhs = np.concatenate([xz.T @ target[[0, 2]], [target[1]]])
    solution, *_ = np.linalg.lstsq(kkt, rhs, rcond=None)
    return solution[:k]


def _interp_lut(lut, G) -> np.ndarray:
    x = np.linspace(0.0, 1.0, lut.shape[1])
    return np.stack([np.interp(G, x, lut[c]) for c in range(3)], axis=-1)


def _level_at(target, fraction, black_relative) -> float:
    """The gray level where the curve reaches ``fraction`` of white (bisection; at least 1/255)."""
    lo, hi = 0.0, 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if target(mid, black_relative) < fraction else (lo, mid)
    return max(hi, 1.0 / (LUT_SIZE - 1))


def verify_calibration(
    display: SpectralDisplay, calibration: Calibration, instrument: str = "reference", seed: int = 1
) -> dict:
    """Measure the calibrated gray ramp at every input level (Figs. 6 and 7, Herbert et al.).

    Parameters
    ----------
    display : SpectralDisplay
    calibration : Calibration
    instrument : str
        Who reads the ramp: ``"reference"`` (default), the
        :class:`~reference.display.instruments.ReferenceMeter`, what the display really emits,
        independent of the calibrating instruments; or a key of :data:`INSTRUMENTS`.
    seed : int

    Returns
    -------
    dict
        ``G`` (LUT_SIZE,) input levels in [0, 1]; ``XYZ`` (LUT_SIZE, 3); ``xy``; ``duv``:
        Δu'v' from the target white; ``Y_target``; ``Y_error``: relative luminance error.

    Examples
    --------
    >>> from reference.display.spectral import spectral_display
    >>> d = spectral_display()
    >>> cal = calibrate_display(d, "D65", "gamma2.2", points=8, instrument="ideal")
    >>> v = verify_calibration(d, cal)
    >>> bool(v["duv"][v["Y_target"] > 0.05 * cal.Y_white].max() < 0.001)
    True
    """
    import colour

    meter = (
        ReferenceMeter()
        if instrument == "reference"
        else INSTRUMENTS.lookup(instrument).reference()
    )
    G = np.linspace(0.0, 1.0, calibration.lut.shape[1])
    XYZ = meter.measure(display, calibration.lut.T, np.random.default_rng(seed))
    target_uv = XYZ_to_uv(np.append(calibration.white_xy, 1.0 - calibration.white_xy.sum()))
    Y_target = calibration.target_Y(G)
    with np.errstate(divide="ignore", invalid="ignore"):
        return {
            "G": G,
            "XYZ": XYZ,
            "xy": colour.XYZ_to_xy(XYZ),
            "duv": np.linalg.norm(XYZ_to_uv(XYZ) - target_uv, axis=-1),
            "Y_target": Y_target,
            "Y_error": XYZ[:, 1] / Y_target - 1.0,
        }


def calibration_targets(display: SpectralDisplay, calibration: Calibration) -> dict:
    """The calibration against :data:`TARGET_DUV` and :data:`TARGET_Y`, read by the reference meter.

    Returns
    -------
    dict
        ``duv`` and ``Y``: the ``target``, the fraction of white it applies ``above``, the ``max``
        found there, the fraction of white ``at`` which it is found, and whether it is ``met``;
        ``met``: both; ``reachable_above``: the fraction of white below which no drives give the
        white's chromaticity on this display (its black is of another colour), 0 if none.

    Examples
    --------
    >>> from reference.display.spectral import spectral_display
    >>> d = spectral_display()
    >>> t = calibration_targets(d, calibrate_display(d, "D65", "gamma2.2", points=8))
    >>> t["met"], t["duv"]["target"], t["reachable_above"]
    (True, 0.001, 0.0)
    """
    v = verify_calibration(display, calibration)
    fraction = v["Y_target"] / calibration.Y_white
    found = {"meter": ReferenceMeter().name}
    for key, values, (target, above) in (
        ("duv", v["duv"], TARGET_DUV),
        ("Y", np.abs(v["Y_error"]), TARGET_Y),
    ):
        where = np.flatnonzero(fraction > above)
        worst = where[np.argmax(values[where])]
        found[key] = {
            "target": target,
            "above": above,
            "max": float(values[worst]),
            "at": float(fraction[worst]),
            "met": bool(values[worst] <= target),
        }
    found["met"] = found["duv"]["met"] and found["Y"]["met"]
    found["reachable_above"] = _reachable_above(display, calibration)
    return found


def _reachable_above(display: SpectralDisplay, calibration: Calibration) -> float:
    """The fraction of white below which the white's chromaticity needs a negative drive.

    ``ρ(Y) = P⁻¹ (Y XYZ_w1 − XYZ_K)`` is affine in Y: channel c reaches zero at
    ``Y = (P⁻¹ XYZ_K)_c / (P⁻¹ XYZ_w1)_c`` (read by the reference meter, channel drift aside).
    """
    meter = ReferenceMeter()
    black = meter.measure(display, np.zeros(3))
    P = (meter.measure(display, np.eye(3)) - black).T
    xy = calibration.white_xy
    direction = np.linalg.solve(P, [xy[0] / xy[1], 1.0, (1.0 - xy.sum()) / xy[1]])
    Y_min = float(np.max(np.linalg.solve(P, black) / direction))
    return max(Y_min / calibration.Y_white, 0.0)


def targets_message(targets: dict) -> str:
    """One line saying which target a calibration misses, where, and why if the display is why.

    Examples
    --------
    >>> targets_message({"duv": {"target": 0.001, "above": 0.05, "max": 0.0246, "at": 0.051,
    ...     "met": False}, "Y": {"met": True}, "met": False, "reachable_above": 0.062})
    "Δu'v' 0.0246 at 5.1 % of white exceeds the target 0.001 above 5 % (this display gives the \
white's chromaticity only above 6.2 % of white: its black is of another colour)"
    """
    parts = []
    for key, name in (("duv", "Δu'v'"), ("Y", "|ΔY|/Y")):
        t = targets[key]
        if not t["met"]:
            parts.append(
                f"{name} {t['max']:.4f} at {100 * t['at']:.1f} % of white exceeds the target "
                f"{t['target']:g} above {100 * t['above']:g} %"
            )
    line = "; ".join(parts)
    if targets["reachable_above"] > TARGET_DUV[1]:
        line += (
            f" (this display gives the white's chromaticity only above "
            f"{100 * targets['reachable_above']:.1f} % of white: its black is of another colour)"
        )
    return line

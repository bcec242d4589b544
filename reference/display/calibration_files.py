"""A calibration's outputs and its verification: ``.cal``, ``.cube``, ``.ti3``, a JSON summary.

:func:`write_calibration` writes what a DisplayCAL/ArgyllCMS user expects beside ``CAL``:

- ``CAL.cal``: the per-channel tables (ArgyllCMS CGATS, :func:`reference.display.cgats.write_cal`);
- ``CAL.cube``: the same tables as a 1-D ``.cube`` LUT (colour-science's LUT I/O);
- ``CAL.ti3``: verification measurements through the calibrated display (grays and a 5×5×5
  grid), which ArgyllCMS's ``colprof`` turns into an ICC profile;
- ``CAL.json``: the summary: white, curve, points, Δu'v' and luminance error of the gray ramp
  (Figs. 6 and 7, Herbert et al.) and ΔE00 of the ColorChecker shown through the display.

References
----------
- F. Herbert, J. Kirkenaer, O. Unter Ecker, "Achieving a Multi-spectral Virtual Reality", 2004, §6.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from reference.display.calibration import (
    Calibration,
    calibration_targets,
    curve_target,
    verify_calibration,
)
from reference.display.cgats import write_cal, write_ti3
from reference.display.instruments import INSTRUMENTS, ReferenceMeter
from reference.display.spectral import SpectralDisplay
from reference.errors import SpecrefError, require
from reference.files import write_text_atomic

__all__ = [
    "CalibratedDisplay",
    "XYZ_to_calibrated_values",
    "calibrated_values_to_XYZ",
    "calibration_summary",
    "colorchecker_through_display",
    "load_calibrated_display",
    "measure_through_calibration",
    "read_cube",
    "verification_patches",
    "write_calibration",
    "write_cube",
]


def verification_patches(grid: int = 5, grays: int = 17) -> np.ndarray:
    """Device RGB of the verification set: a gray ramp and a ``grid³`` cube, shape (n, 3).

    Examples
    --------
    >>> verification_patches().shape
    (137, 3)
    """
    g = np.linspace(0.0, 1.0, grid)
    cube = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)
    ramp = np.repeat(np.linspace(0.0, 1.0, grays)[:, None], 3, axis=1)
    patches = np.concatenate([ramp, cube])
    _, first = np.unique(patches.round(9), axis=0, return_index=True)
    return patches[np.sort(first)]


def measure_through_calibration(
    display: SpectralDisplay, calibration: Calibration, RGB, instrument: str = "ideal", seed=2
) -> np.ndarray:
    """XYZ (cd/m²) read for device RGB sent through the calibration's tables, shape (n, 3).

    Examples
    --------
    >>> from reference.display.calibration import calibrate_display
    >>> from reference.display.spectral import spectral_display
    >>> d = spectral_display(); cal = calibrate_display(d, points=6, instrument="ideal")
    >>> round(float(measure_through_calibration(d, cal, [[1.0, 1.0, 1.0]])[0, 1]), 1)
    100.0
    """
    drives = calibration.drives(np.asarray(RGB, dtype=np.float64))
    meter = INSTRUMENTS.lookup(instrument).reference()
    return meter.measure(display, drives, np.random.default_rng(seed))


def colorchecker_through_display(
    display: SpectralDisplay, calibration: Calibration, instrument: str = "ideal"
) -> dict:
    """ΔE00 of the ColorChecker shown through the calibrated display (relative colorimetric).

    The chart's D50 chromaticities (colour-science, 2014 edition) are adapted to the calibrated
    white (CAT02), scaled to its luminance, converted to device RGB with a matrix/curve profile of
    the calibrated display (primaries read through the tables, the calibration's curve), shown and
    read back. Out-of-gamut patches are clipped and counted.

    Returns
    -------
    dict
        ``delta_E00`` (24,), ``mean``, ``max``, ``out_of_gamut`` (count).

    Examples
    --------
    >>> from reference.display.calibration import calibrate_display
    >>> from reference.display.spectral import spectral_display
    >>> d = spectral_display(); cal = calibrate_display(d, points=8, instrument="ideal")
    >>> result = colorchecker_through_display(d, cal)
    >>> result["delta_E00"].shape, bool(result["mean"] < 1.0)
    ((24,), True)
    """
    import colour

    chart = colour.CCS_COLOURCHECKERS["ColorChecker24 - After November 2014"]
    XYZ_D50 = colour.xyY_to_XYZ(np.array(list(chart.data.values())))
    xy = calibration.white_xy
    white_rel = colour.xy_to_XYZ(xy)
    XYZ_rel = colour.adaptation.chromatic_adaptation_VonKries(
        XYZ_D50, colour.xy_to_XYZ(chart.illuminant), white_rel, transform="CAT02"
    )
    # the calibrated display's matrix/curve profile, read through the tables
    measured = measure_through_calibration(
        display, calibration, np.vstack([np.zeros(3), np.eye(3), np.ones(3)]), instrument
    )
    white = measured[4]
    profile = CalibratedDisplay(
        calibration.lut,
        measured[0] / white[1],
        (measured[1:4] - measured[0]).T / white[1],
        calibration.curve,
        float(white[1]),
    )
    RGB, in_gamut = XYZ_to_calibrated_values(XYZ_rel, profile)
    shown = measure_through_calibration(display, calibration, RGB, instrument)
    intended_Lab = colour.XYZ_to_Lab(XYZ_rel, xy)
    shown_Lab = colour.XYZ_to_Lab(shown / white[1], colour.XYZ_to_xy(white))
    dE = colour.delta_E(intended_Lab, shown_Lab, method="CIE 2000")
    return {
        "delta_E00": dE,
        "mean": float(dE.mean()),
        "max": float(dE.max()),
        "out_of_gamut": int((~in_gamut).sum()),
    }


def write_cube(path, lut, title: str = "specref calibration") -> Path:
    """Write per-channel tables (3, n) as a 1-D ``.cube`` LUT through colour-science, atomically.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     lut = np.tile(np.linspace(0, 1, 5) ** 2, (3, 1))
    ...     read_cube(write_cube(os.path.join(d, "x.cube"), lut))[0].round(4)
    array([0.    , 0.0625, 0.25  , 0.5625, 1.    ])
    """
    import colour

    from reference.files import atomic_path

    path = Path(path)
    table = colour.LUT3x1D(np.asarray(lut, dtype=np.float64).T, name=title)
    # the one atomic writer: synced, renamed, and with an ordinary file's permissions (mkstemp's
    # 0600 had stayed on the .cube while its sibling files were 0644)
    with atomic_path(path, suffix=".cube") as tmp:
        colour.io.write_LUT(table, str(tmp))
    return path


def read_cube(path) -> np.ndarray:
    """Read a 1-D ``.cube`` LUT through colour-science: the tables, shape (3, n).

    Examples
    --------
    >>> read_cube("/nonexistent.cube")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent.cube: file not found
    """
    import colour

    require(Path(path).exists(), f"{path}: file not found")
    try:
        table = colour.io.read_LUT(str(path))
    except Exception as error:  # colour raises several types for a malformed file
        raise SpecrefError(f"{path}: not a .cube LUT ({error})") from None
    return np.asarray(table.table, dtype=np.float64).T.copy()


def calibration_summary(display: SpectralDisplay, calibration: Calibration) -> dict:
    """The JSON summary: targets, points and the verification (read by the reference meter).

    ``targets`` is :func:`~reference.display.calibration.calibration_targets` and
    ``meets_targets`` whether both hold: a calibration that misses one is still written, marked.

    Examples
    --------
    >>> from reference.display.calibration import calibrate_display
    >>> from reference.display.spectral import spectral_display
    >>> d = spectral_display(); cal = calibrate_display(d, "A", "lstar", 8, "ideal")
    >>> s = calibration_summary(d, cal)
    >>> s["white"], s["curve"], bool(s["verification"]["max_duv_above_5pct"] < 0.001)
    ('A', 'lstar', True)
    >>> s["meets_targets"], s["verification"]["instrument"]
    (True, 'reference')
    """
    v = verify_calibration(display, calibration)
    targets = calibration_targets(display, calibration)
    above_5 = v["Y_target"] > 0.05 * calibration.Y_white
    above_1 = v["Y_target"] > 0.01 * calibration.Y_white
    levels = [*range(0, calibration.lut.shape[1], 16), calibration.lut.shape[1] - 1]
    chart = colorchecker_through_display(display, calibration)
    return {
        "display": calibration.display,
        "white": calibration.white,
        "white_xy": calibration.white_xy.tolist(),
        "curve": calibration.curve,
        "instrument": calibration.instrument,
        "Y_white_cd_m2": calibration.Y_white,
        "Y_black_cd_m2": calibration.Y_black,
        "points": {
            "G": calibration.points["G"].tolist(),
            "iterations": calibration.points["iterations"].tolist(),
            "readings": calibration.points["readings"].tolist(),
        },
        "meets_targets": targets["met"],
        "targets": targets,
        "verification": {
            "instrument": ReferenceMeter().name,
            "max_duv_above_5pct": float(v["duv"][above_5].max()),
            "max_abs_Y_error_above_1pct": float(np.abs(v["Y_error"][above_1]).max()),
            "gray": [
                {
                    "G": int(i),
                    "Y_cd_m2": float(v["XYZ"][i, 1]),
                    "Y_target_cd_m2": float(v["Y_target"][i]),
                    "x": float(v["xy"][i, 0]),
                    "y": float(v["xy"][i, 1]),
                    "duv": float(v["duv"][i]),
                }
                for i in levels
            ],
            "colorchecker_delta_E00": {
                "mean": chart["mean"],
                "max": chart["max"],
                "out_of_gamut": chart["out_of_gamut"],
            },
        },
    }


def write_calibration(
    path, display: SpectralDisplay, calibration: Calibration, seed: int = 2
) -> dict:
    """Write ``.cal``, ``.cube``, ``.ti3`` and ``.json`` for a calibration; return the summary.

    ``path`` names the ``.cal``; the others take its stem. The ``.ti3`` holds the verification
    patches read by the calibration's own instrument (what a user would profile from).

    Examples
    --------
    >>> import tempfile, os
    >>> from reference.display.calibration import calibrate_display
    >>> from reference.display.spectral import spectral_display
    >>> d = spectral_display(); cal = calibrate_display(d, points=6, instrument="ideal")
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     s = write_calibration(os.path.join(folder, "d65.cal"), d, cal)
    ...     sorted(os.listdir(folder))
    ['d65.cal', 'd65.cube', 'd65.json', 'd65.ti3']
    """
    path = Path(path)
    require(path.suffix == ".cal", f"{path}: the calibration file must end in .cal")
    description = f"{calibration.white} white, {calibration.curve} curve, {calibration.display}"
    write_cal(path, calibration.lut, description)
    write_cube(path.with_suffix(".cube"), calibration.lut, description)
    RGB = verification_patches()
    XYZ = measure_through_calibration(display, calibration, RGB, calibration.instrument, seed)
    white = XYZ[int(np.argmax(RGB.sum(axis=1)))]
    write_ti3(path.with_suffix(".ti3"), RGB, XYZ, white, description)
    summary = calibration_summary(display, calibration)
    summary["files"] = {k: str(path.with_suffix(k)) for k in (".cal", ".cube", ".ti3", ".json")}
    write_text_atomic(path.with_suffix(".json"), json.dumps(summary, indent=1) + "\n")
    return summary


@dataclass(frozen=True)
class CalibratedDisplay:
    """A calibrated display as a render sees it: read from ``CAL.cal`` and its ``.ti3``/``.json``.

    Attributes
    ----------
    lut : ndarray, shape (3, LUT_SIZE)
        The video card tables (``CAL.cal``).
    black_XYZ : ndarray, shape (3,)
        Black, relative to white Y = 1.
    P : ndarray, shape (3, 3)
        Columns: each primary at full device value minus the black, white Y = 1.
    curve : str
        The calibration's tone curve (``CAL.json``).
    Y_white : float
        cd/m².
    """

    lut: np.ndarray
    black_XYZ: np.ndarray
    P: np.ndarray
    curve: str
    Y_white: float
    path: str = ""

    def share(self, values) -> np.ndarray:
        """Each channel's share of its primary for device values ``(..., 3)`` in [0, 1].

        The calibration makes every gray ``(G, G, G)`` show the white's chromaticity at the
        curve's luminance, ``Y_t(G) W``, whatever the colour of the display's own black ``K``
        (erratum E47): the channels' shares on the gray axis are ``s(G) = P⁻¹ (Y_t(G) W − K)``,
        and each channel keeps its own, ``s_c(v_c) = Y_t(v_c) + k_c (Y_t(v_c) − 1)`` with
        ``k = P⁻¹ K`` (``W = K + P 1``). A neutral black (``k_c = Y_K / (1 − Y_K)``) gives
        every channel the curve, ``(Y_t − Y_K) / (1 − Y_K)``.
        """
        black = self.black_XYZ[1]
        Y_t = curve_target(self.curve, np.clip(values, 0.0, 1.0), black)
        k = np.linalg.solve(self.P, self.black_XYZ)
        return np.maximum(Y_t + k * (Y_t - 1.0), 0.0)

    def values_for_share(self, share) -> np.ndarray:
        """Device values ``(..., 3)`` whose channels have ``share``: :meth:`share` inverted."""
        G = np.linspace(0.0, 1.0, 4097)
        tables = np.maximum.accumulate(self.share(np.repeat(G[:, None], 3, axis=1)), axis=0)
        tables += np.linspace(0.0, 1e-12, G.size)[:, None]
        share = np.asarray(share, dtype=np.float64)
        return np.stack([np.interp(share[..., c], tables[:, c], G) for c in range(3)], axis=-1)


def load_calibrated_display(cal_path) -> CalibratedDisplay:
    """Read ``CAL.cal``, ``CAL.ti3`` and ``CAL.json`` (:func:`write_calibration`) for rendering.

    Raises
    ------
    SpecrefError
        A missing file, a ``.ti3`` without the black, primaries and white patches.

    Examples
    --------
    >>> load_calibrated_display("/nonexistent/d65.cal")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent/d65.cal: file not found
    """
    from reference.display.cgats import read_cal, read_ti3

    path = Path(cal_path)
    lut = read_cal(path)
    summary_path = path.with_suffix(".json")
    require(summary_path.exists(), f"{summary_path}: file not found (written beside the .cal)")
    try:
        summary = json.loads(summary_path.read_text())
        curve, Y_white = str(summary["curve"]), float(summary["Y_white_cd_m2"])
    except (ValueError, KeyError, TypeError) as error:
        raise SpecrefError(f"{summary_path}: not a calibration summary ({error})") from None
    RGB, XYZ = read_ti3(path.with_suffix(".ti3"))
    wanted = np.vstack([np.zeros(3), np.eye(3), np.ones(3)])
    rows = []
    for patch in wanted:
        found = np.flatnonzero(np.abs(RGB - patch).max(axis=1) < 1e-6)
        require(
            found.size,
            f"{path.with_suffix('.ti3')}: no patch {patch.tolist()} (need black, "
            "R, G, B and white)",
        )
        rows.append(XYZ[found[0]] / 100.0)
    black = rows[0] / rows[4][1]
    P = np.stack([(r - rows[0]) / rows[4][1] for r in rows[1:4]], axis=1)
    return CalibratedDisplay(lut, black, P, curve, Y_white, str(path))


def XYZ_to_calibrated_values(XYZ, display: CalibratedDisplay) -> tuple[np.ndarray, np.ndarray]:
    """Device values in [0, 1] that show XYZ (relative, white Y = 1) on a calibrated display.

    The inverse of :func:`calibrated_values_to_XYZ`: ``ρ = P⁻¹ (XYZ − XYZ_K)`` (Eq. (1),
    Ferwerda, on the calibrated display), then each channel through the calibration's curve.

    Returns
    -------
    values : ndarray, shape (..., 3)
        What the application sends (the ``.cal`` is in the video card).
    in_gamut : ndarray of bool, shape (...,)

    Examples
    --------
    >>> d = CalibratedDisplay(np.zeros((3, 2)), np.zeros(3), np.eye(3), "gamma2.2", 100.0)
    >>> XYZ_to_calibrated_values([0.25, 0.25, 0.25], d)[0].round(4)
    array([0.5325, 0.5325, 0.5325])
    """
    XYZ = np.asarray(XYZ, dtype=np.float64)
    rho = np.linalg.solve(display.P, (XYZ - display.black_XYZ)[..., None])[..., 0]
    in_gamut = ((rho >= -1e-3) & (rho <= 1 + 1e-3)).all(axis=-1)
    return display.values_for_share(rho), in_gamut


def calibrated_values_to_XYZ(values, display: CalibratedDisplay) -> np.ndarray:
    """XYZ (relative, white Y = 1) a calibrated display shows for device values (..., 3).

    Examples
    --------
    >>> d = CalibratedDisplay(np.zeros((3, 2)), np.zeros(3), np.eye(3), "gamma2.2", 100.0)
    >>> calibrated_values_to_XYZ([0.5325, 0.5325, 0.5325], d).round(3)
    array([0.25, 0.25, 0.25])
    """
    # Eq. (1), Ferwerda, on the calibrated display: XYZ = XYZ_K + P · share(values)
    return display.black_XYZ + display.share(np.asarray(values, float)) @ display.P.T

"""Report section "Display calibration": Herbert et al. §6 on the simulated display.

compute → :func:`display_calibration`; present → :func:`present`; checks → :func:`checks`.

Figs. 6 and 7 of the paper reproduced on the simulated display (``reference.display_spectral``):
the tone curves reached (gamma 1.8, 2.2 and L*), the white's chromaticity against the gray level
when the calibration is read by a spectroradiometer and by a colorimeter, the verification table
for the four whites, and the instrument comparison (the colorimeter's shadow failure).
"""

from __future__ import annotations

import numpy as np

from reference.calibration import (
    CALIBRATION_CURVES,
    WHITES,
    calibrate_display,
    verify_calibration,
)
from reference.calibration_files import colorchecker_through_display
from reference.display_spectral import spectral_display
from reference.instruments import INSTRUMENTS
from validation.report import Check, ReportContext, ReportSection, SectionData, Table, Text

#: Fig. 6, Herbert et al.: the three curves of the paper.
FIG6_CURVES = ("gamma1.8", "gamma2.2", "lstar")
#: Luminance bands of the instrument comparison, fractions of white.
BANDS = ((0.5, 1.01), (0.25, 0.5), (0.125, 0.25), (0.05, 0.125), (0.02, 0.05))
#: Δu'v' below which a calibration "holds" the white (a just-noticeable difference, about 0.004).
HOLD_DUV = 0.004
# Issue 16's targets with the noise-free spectroradiometer.
TARGET_DUV, TARGET_Y = 0.001, 0.01


def _verification(display, white, curve, instrument, points=15):
    cal = calibrate_display(display, white, curve, points=points, instrument=instrument)
    return cal, verify_calibration(display, cal)


def display_calibration(ctx: ReportContext | None = None) -> SectionData:
    """Calibrate the simulated display for every white, curve and instrument; verify each.

    Returns
    -------
    SectionData
        ``results["targets"]["<white> <curve>"]``: max Δu'v' above 5 % and max |ΔY|/Y above 1 %
        (noise-free instrument); ``results["whites"][white]``: the L* calibration read by each
        instrument, with ColorChecker ΔE00; ``results["instruments"][name]``: max Δu'v' per
        luminance band and the lowest luminance where the white holds; ``arrays``: the curves.
        (About 20 s; ``tests/validation/test_section_display.py`` runs it.)
    """
    display = spectral_display()
    data = SectionData()
    data.results["display"] = display.name
    targets = {}
    for white in WHITES:
        for curve in CALIBRATION_CURVES.names():
            cal, v = _verification(display, white, curve, "ideal")
            targets[f"{white} {curve}"] = {
                "max_duv_above_5pct": float(v["duv"][v["Y_target"] > 0.05 * cal.Y_white].max()),
                "max_abs_Y_error_above_1pct": float(
                    np.abs(v["Y_error"][v["Y_target"] > 0.01 * cal.Y_white]).max()
                ),
                "points": len(cal.points["G"]),
            }
            if white == "D65" and curve in FIG6_CURVES:
                data.arrays[("fig6", curve)] = (v["G"], v["XYZ"][:, 1] / cal.Y_white)
    data.results["targets"] = targets
    whites = {}
    for white in WHITES:
        whites[white] = {}
        for instrument in INSTRUMENTS.names():
            cal, v = _verification(display, white, "lstar", instrument)
            chart = colorchecker_through_display(display, cal)
            above_5 = v["Y_target"] > 0.05 * cal.Y_white
            whites[white][instrument] = {
                "Y_white_cd_m2": cal.Y_white,
                "x_white": float(v["xy"][-1, 0]),
                "y_white": float(v["xy"][-1, 1]),
                "max_duv_above_5pct": float(v["duv"][above_5].max()),
                "colorchecker_dE00_mean": chart["mean"],
                "colorchecker_dE00_max": chart["max"],
                "points": len(cal.points["G"]),
            }
            if white == "D65":
                data.arrays[("fig7", instrument)] = (v["G"], v["xy"], cal.white_xy)
                data.results.setdefault("instruments", {})[instrument] = _bands(cal, v)
    data.results["whites"] = whites
    data.results["screen"] = screen_compensation()
    return data


#: Observers for the screen study: on axis, and off axis to the side and above (metres).
OBSERVERS = {
    "on axis": (0.0, 0.0, 0.6),
    "30° to the side": (0.35, 0.0, 0.6),
    "above, tilted": (0.0, 0.4, 0.45),
}


def screen_compensation() -> dict:
    """A mid-gray image through Eq. (1), Ferwerda, per pixel: seen against intended luminance.

    For each observer (:data:`OBSERVERS`; the display tilted 15° for the last), with and without
    the compensation of §3.4.2–3.4.3 (``L_factor`` and the booth light's diffuse and specular
    flare, 1000 lx on the screen and a 3000 cd/m² light above): the worst relative error of the
    seen luminance over the screen.
    """
    from reference.display_model import virtual_display
    from reference.display_pipeline import ScreenGeometry, image_to_display_counts

    display = virtual_display()
    white = display.white_XYZ / display.white_XYZ[1]
    image = np.broadcast_to(60.0 * white, (24, 32, 3))
    light = {"E_XYZ": 1000.0 * white, "light_position": (0.0, 1.2, 0.9), "light_XYZ": 3000 * white}
    found = {}
    for name, eye in OBSERVERS.items():
        geometry = ScreenGeometry(tilt=np.radians(15.0) if "tilted" in name else 0.0)
        for compensate in (True, False):
            out = image_to_display_counts(
                image, display, geometry, eye, compensate=compensate, **light
            )
            error = out["seen_XYZ"][..., 1] / image[..., 1] - 1.0
            found[f"{name}, {'compensated' if compensate else 'not compensated'}"] = {
                "max_theta_deg": float(np.degrees(out["theta"].max())),
                "max_abs_Y_error": float(np.abs(error).max()),
                "mean_Y_error": float(error.mean()),
            }
    return found


def _bands(cal, v) -> dict:
    relative = v["Y_target"] / cal.Y_white
    bands = {}
    for low, high in BANDS:
        inside = (relative >= low) & (relative < high)
        bands[f"{100 * low:g}-{min(100 * high, 100):g} %"] = float(v["duv"][inside].max())
    # the lowest luminance above which every gray holds the white within HOLD_DUV
    lit = relative > 0.01
    failing = np.flatnonzero(lit & (v["duv"] > HOLD_DUV))
    holds_to = (
        float(v["XYZ"][failing.max() + 1, 1])
        if failing.size
        else float(v["XYZ"][np.flatnonzero(lit)[0], 1])
    )
    return {"bands": bands, "holds_down_to_cd_m2": holds_to, "Y_white_cd_m2": cal.Y_white}


def present(ctx: ReportContext, data: SectionData) -> list:
    """Figs. 6 and 7, the verification table for the four whites, the instrument comparison."""
    blocks = [
        Text(
            f"Herbert et al. §6 on a simulated display ({data.results['display']}; no hardware): "
            "per-point iteration to a white and a tone curve, points denser in the highlights, "
            "black left alone. Read back with the noise-free spectroradiometer unless stated."
        )
    ]
    blocks += _figures(ctx, data)
    blocks.append(_whites_table(data))
    blocks.append(_instrument_table(data))
    blocks.append(_screen_table(data))
    return blocks


def _figures(ctx: ReportContext, data: SectionData) -> list:
    """Figs. 6 and 7 of Herbert et al., reproduced."""
    import matplotlib.pyplot as plt

    from reference.calibration import curve_target

    blocks = []
    fig, ax = plt.subplots(figsize=(5.5, 4))
    for curve in FIG6_CURVES:
        G, Y = data.arrays[("fig6", curve)]
        ax.plot(255 * G, Y, lw=2, label=f"measured, {curve}")
        ax.plot(255 * G, curve_target(curve, G), "k:", lw=1)
    ax.set_xlabel("gray value G (0-255)")
    ax.set_ylabel("Y / Y_max")
    ax.legend(frameon=False)
    blocks.append(
        ctx.figure(
            "fig6", fig, "Fig. 6 reproduced: Y against G (dotted: Eqs. (6)-(7), Herbert et al.)"
        )
    )
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), sharex=True)
    for instrument in INSTRUMENTS.names():
        G, xy, white = data.arrays[("fig7", instrument)]
        for k, ax in enumerate(axes):
            ax.plot(255 * G[1:], xy[1:, k], lw=1.5, label=f"calibrated with {instrument}")
            ax.axhline(white[k], color="k", lw=0.8)
    for k, ax in enumerate(axes):
        ax.set_xlabel("gray value G (0-255)")
        ax.set_ylabel("xy"[k])
        ax.set_ylim(white[k] - 0.03, white[k] + 0.03)
    axes[0].legend(frameon=False, fontsize=8)
    blocks.append(
        ctx.figure("fig7", fig, "Fig. 7 reproduced: x and y of gray against G, D65, L* curve")
    )
    return blocks


def _whites_table(data: SectionData) -> Table:
    """The verification of the four whites."""
    rows = []
    for white, by_instrument in data.results["whites"].items():
        for instrument, r in by_instrument.items():
            rows.append(
                [
                    white,
                    instrument,
                    r["Y_white_cd_m2"],
                    r["x_white"],
                    r["y_white"],
                    r["max_duv_above_5pct"],
                    r["colorchecker_dE00_mean"],
                    r["colorchecker_dE00_max"],
                    r["points"],
                ]
            )
    return Table(
        [
            "white",
            "calibrated with",
            "Y white cd/m²",
            "x",
            "y",
            "max Δu'v' >5 %",
            "ColorChecker ΔE00 mean",
            "max",
            "points",
        ],
        rows,
        "Verification of the four whites (L* curve), read by the noise-free instrument",
    )


def _instrument_table(data: SectionData) -> Table:
    """Spectroradiometer against colorimeter, band by band in luminance."""
    names = list(data.results["instruments"])
    band_names = list(data.results["instruments"][names[0]]["bands"])
    rows = [
        [
            name,
            *data.results["instruments"][name]["bands"].values(),
            data.results["instruments"][name]["holds_down_to_cd_m2"],
        ]
        for name in names
    ]
    return Table(
        [
            "calibrated with",
            *[f"max Δu'v' {b}" for b in band_names],
            f"holds Δu'v' <= {HOLD_DUV} down to cd/m²",
        ],
        rows,
        "Instrument comparison, D65, L*: the colorimeter loses the white in the shadows",
    )


def _screen_table(data: SectionData) -> Table:
    """A gray seen from three positions, with and without compensation (Eq. (1), Ferwerda)."""
    rows = [
        [k, r["max_theta_deg"], r["mean_Y_error"], r["max_abs_Y_error"]]
        for k, r in data.results["screen"].items()
    ]
    return Table(
        ["observer", "max θ (deg)", "mean ΔY/Y", "max |ΔY/Y|"],
        rows,
        "ImpastoR's display (Eq. (1), Ferwerda) per pixel: a 60 cd/m² gray seen from three "
        "positions, with and without the L_factor and screen-flare compensation",
    )


def checks(data: SectionData) -> list[Check]:
    """Issue 16's targets for every white and curve, and the colorimeter's shadow failure."""
    found = []
    for key, r in data.results["targets"].items():
        found.append(
            Check(
                f"max Δu'v' above 5 % of white, {key}",
                f"<= {TARGET_DUV}",
                r["max_duv_above_5pct"],
                r["max_duv_above_5pct"] <= TARGET_DUV,
            )
        )
        found.append(
            Check(
                f"max |ΔY|/Y above 1 % of white, {key}",
                f"<= {TARGET_Y}",
                r["max_abs_Y_error_above_1pct"],
                r["max_abs_Y_error_above_1pct"] <= TARGET_Y,
            )
        )
    spectro = data.results["instruments"]["spectro"]["holds_down_to_cd_m2"]
    colorimeter = data.results["instruments"]["colorimeter"]["holds_down_to_cd_m2"]
    found.append(
        Check(
            "the spectroradiometer holds the white further into the shadows than the colorimeter "
            "(§6, Herbert et al.)",
            "spectro < colorimeter (cd/m²)",
            f"{spectro:.2f} < {colorimeter:.2f}",
            spectro < colorimeter,
        )
    )
    for key, r in data.results["screen"].items():
        if "not compensated" in key:
            continue
        found.append(
            Check(
                f"seen luminance, compensated, {key.split(',')[0]}",
                "max |ΔY/Y| <= 0.005",
                r["max_abs_Y_error"],
                r["max_abs_Y_error"] <= 0.005,
            )
        )
    return found


SECTION = ReportSection(
    "display-calibration", "Display calibration", display_calibration, present, checks
)

"""Report section "Display calibration": Herbert et al. §6 on the simulated display.

compute → :func:`display_calibration`; present → :func:`present`; checks → :func:`checks`.

Figs. 6 and 7 of the paper reproduced on the simulated display (``reference.display.spectral``):
the tone curves reached (gamma 1.8, 2.2 and L*), the white's chromaticity against the gray level
when the calibration is read by a spectroradiometer and by a colorimeter, the verification table
for the four whites, and the instrument comparison (the colorimeter's shadow failure). Then a scene
with ``[display] calibration`` as the display emits it against the intended XYZ, and ImpastoR's
painting seen on and off axis with and without the compensation of §3.4, Ferwerda.
"""

from __future__ import annotations

import numpy as np

from reference.display import calibration as _calibration
from reference.display.calibration import (
    CALIBRATION_CURVES,
    WHITES,
    calibrate_display,
    calibration_targets,
    verify_calibration,
)
from reference.display.calibration_files import colorchecker_through_display
from reference.display.instruments import INSTRUMENTS
from reference.display.spectral import spectral_display
from validation.report import (
    Check,
    Headline,
    ReportContext,
    ReportSection,
    SectionData,
    Table,
    Text,
)

#: Fig. 6, Herbert et al.: the three curves of the paper.
FIG6_CURVES = ("gamma1.8", "gamma2.2", "lstar")
#: Luminance bands of the instrument comparison, fractions of white.
BANDS = ((0.5, 1.01), (0.25, 0.5), (0.125, 0.25), (0.05, 0.125), (0.02, 0.05))
#: Δu'v' below which a calibration "holds" the white (a just-noticeable difference, about 0.004).
HOLD_DUV = 0.004
# The calibration targets (docs/display.md, "Calibrating"; read by the reference meter).
TARGET_DUV, TARGET_Y = _calibration.TARGET_DUV[0], _calibration.TARGET_Y[0]
#: Displays the default instrument calibrates: the one the loop was designed on, then held-out
#: ones (keys of ``DISPLAY_PRIMARIES``), each at two white × curve pairs.
INSTRUMENT_DISPLAYS = {
    "apple_studio": "designed on",
    "led_wide": "held out",
    "laser": "held out",
    "crt_brainard": "held out",
}
INSTRUMENT_CASES = (("D65", "gamma2.2"), ("D50", "lstar"))
#: ΔE00 below which a displayed image counts as the intended one (about one just-noticeable step).
TARGET_SCENE_DE = 1.0


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
        (About 20 s; ``tests/validation/report/sections/test_display.py`` runs it.)
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
    data.results["default_instrument"] = default_instrument_study(
        INSTRUMENT_CASES[:1] if ctx is None or ctx.quick else INSTRUMENT_CASES
    )
    data.results["screen"] = screen_compensation()
    data.results["scene"], data.arrays["scene"] = scene_on_calibrated_display(display)
    data.results["painting"], data.arrays["painting"] = painting_on_screen(
        16 if ctx is None or ctx.quick else 48
    )
    return data


def default_instrument_study(cases=INSTRUMENT_CASES) -> dict:
    """The default spectroradiometer on the design display and held-out ones, against the targets.

    ``cases``: ``(white, curve)`` pairs (the quick report runs the first, about 5 s).

    Returns
    -------
    dict
        ``"<display> <white> <curve>"`` -> the display key, whether it was ``designed on`` or
        ``held out``, the worst Δu'v' above 5 % of white and |ΔY|/Y above 1 % (reference meter),
        where each is found, and the fraction of white above which the display can give the
        white's chromaticity (``calibration_targets``).
    """
    found = {}
    for key, role in INSTRUMENT_DISPLAYS.items():
        display = spectral_display(key)
        for white, curve in cases:
            t = calibration_targets(display, calibrate_display(display, white, curve))
            found[f"{key} {white} {curve}"] = {
                "display": key,
                "role": role,
                "max_duv_above_5pct": t["duv"]["max"],
                "duv_at": t["duv"]["at"],
                "max_abs_Y_error_above_1pct": t["Y"]["max"],
                "Y_at": t["Y"]["at"],
                "reachable_above": t["reachable_above"],
            }
    return found


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
    from reference.display.model import virtual_display
    from reference.display.pipeline import ScreenGeometry, image_to_display_counts

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


#: The scene shown on the calibrated display (data:examples), its size and the calibration.
SCENE_FILE = "colorchecker-d65.toml"
SCENE_SIZE = (90, 60)
SCENE_CALIBRATION = ("D65", "gamma2.2")


def _delta_E00(XYZ, reference_XYZ, white_XYZ) -> np.ndarray:
    """CIEDE2000 between two XYZ images (cd/m²), both in Lab relative to ``white_XYZ``."""
    import colour

    xy = colour.XYZ_to_xy(white_XYZ)
    Lab = colour.XYZ_to_Lab(XYZ / white_XYZ[1], xy)
    Lab_reference = colour.XYZ_to_Lab(reference_XYZ / white_XYZ[1], xy)
    return colour.delta_E(Lab, Lab_reference, method="CIE 2000")


def scene_on_calibrated_display(display) -> tuple[dict, dict]:
    """A scene with ``[display] calibration``: what the display emits against the intended XYZ.

    Erratum E47: the ColorChecker example is calibrated for (:data:`SCENE_CALIBRATION`, 15 points,
    noise-free instrument), written as ``CAL.cal`` and named by the scene file; the render's device
    values are sent through the ``.cal`` tables to the simulated spectral display
    (``measure_through_calibration``, noise-free) and compared, in CIEDE2000 relative to the
    emitted white, with the intended XYZ (the render's XYZ times the calibrated white's luminance,
    relative colorimetric). Pixels outside the display's gamut (``in_gamut`` of
    ``XYZ_to_calibrated_values``: the black frame, below the display's black) are counted apart;
    the figures are given over the pixels in gamut and over those above 5 % of white (erratum E47).
    """
    import tempfile
    from pathlib import Path

    from reference.data import data_path
    from reference.display.calibration_files import (
        XYZ_to_calibrated_values,
        measure_through_calibration,
        write_calibration,
    )
    from reference.scene.loader import loads_scene
    from reference.scene.render import render_scene

    white, curve = SCENE_CALIBRATION
    cal = calibrate_display(display, white, curve, points=15, instrument="ideal")
    text = data_path(f"examples/{SCENE_FILE}").read_text(encoding="utf-8")
    with tempfile.TemporaryDirectory() as folder:
        cal_path = Path(folder) / "display.cal"
        write_calibration(cal_path, display, cal)
        shown = text.replace("[display]\n", f'[display]\ncalibration = "{cal_path}"\n', 1)
        scene = loads_scene(shown, SCENE_FILE, data_path("examples"))
        result = render_scene(scene, *SCENE_SIZE, supersample=1)
    _, in_gamut = XYZ_to_calibrated_values(
        result.XYZ * scene.display.exposure, scene.display.calibration
    )
    # what the display emits for the device values, through the video card's tables
    values = result.encoded.reshape(-1, 3)
    emitted = measure_through_calibration(display, cal, values).reshape(result.XYZ.shape)
    white_XYZ = measure_through_calibration(display, cal, np.ones((1, 3)))[0]
    intended = result.XYZ * scene.display.exposure * cal.Y_white
    dE = _delta_E00(emitted, intended, white_XYZ)
    inside = dE[in_gamut]
    # the range the calibration targets speak for: above 5 % of white luminance
    lit = dE[in_gamut & (intended[..., 1] > 0.05 * white_XYZ[1])]
    found = {
        "scene": SCENE_FILE,
        "calibration": f"{white} {curve}",
        "pixels": int(dE.size),
        "out_of_gamut": int((~in_gamut).sum()),
        "dE00_mean": float(inside.mean()),
        "dE00_p95": float(np.percentile(inside, 95)),
        "dE00_max": float(inside.max()),
        "pixels_above_5pct": int(lit.size),
        "dE00_mean_above_5pct": float(lit.mean()),
        "dE00_max_above_5pct": float(lit.max()),
    }
    return found, {"intended": intended, "emitted": emitted, "dE00": dE, "white": white_XYZ}


def painting_on_screen(size: int) -> tuple[dict, dict]:
    """The demo painting displayed for each observer of :data:`OBSERVERS`, compensated or not.

    Eq. (1), Ferwerda per pixel with ``L_factor`` and the diffuse and specular flare of §3.4.3
    (:func:`validation.studies.impastor_commands.painting_on_display`, the booth light of ``specref
    impastor render`` at 1000 lx on the screen), for the painting rendered under D65 (median-cut
    lights):
    CIEDE2000 of what the observer sees against the intended painting, relative to the display
    white, over the pixels the display can show.
    """
    from impastor.painting import booth_lamp_kind, booth_light_image, render_painting
    from reference.display.model import virtual_display
    from reference.display.pipeline import ScreenGeometry
    from validation.studies.impastor_commands import DEFAULT_LIGHT_POSITION, painting_on_display

    XYZ = render_painting("D65", size, "median_cut")["XYZ"]
    luminance = float(booth_light_image(booth_lamp_kind("D65")).mean())
    flare = {"screen_lux": 1000.0, "position": DEFAULT_LIGHT_POSITION, "luminance": luminance}
    white = virtual_display().white_XYZ
    found, seen = {}, {}
    for name, eye in OBSERVERS.items():
        geometry = ScreenGeometry(tilt=np.radians(15.0) if "tilted" in name else 0.0)
        for compensate in (True, False):
            out = painting_on_display(XYZ, geometry, eye, flare, compensate)
            dE = _delta_E00(out["seen_XYZ"], XYZ, white)[out["in_gamut"]]
            key = f"{name}, {'compensated' if compensate else 'not compensated'}"
            found[key] = {"dE00_mean": float(dE.mean()), "dE00_max": float(dE.max())}
            seen[key] = out["seen_XYZ"]
    return found, {"intended": XYZ, "seen": seen, "white": white}


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
            "black left alone. Read back with the reference meter (1 nm, no band pass, no "
            "noise; erratum E105), independent of the calibrating instrument."
        )
    ]
    blocks += _figures(ctx, data)
    blocks.append(_whites_table(data))
    blocks.append(_instrument_table(data))
    blocks.append(_default_instrument_table(data))
    blocks.append(_screen_table(data))
    blocks += _scene_blocks(ctx, data)
    blocks += _painting_blocks(ctx, data)
    return blocks


def _to_sRGB(XYZ, white_XYZ) -> np.ndarray:
    """XYZ (cd/m²) as sRGB for a figure: the display white maps to sRGB white (von Kries)."""
    import colour

    D65 = colour.xy_to_XYZ(colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"])
    XYZ_D65 = XYZ / white_XYZ[1] * (D65 / (white_XYZ / white_XYZ[1]))
    return np.clip(colour.XYZ_to_sRGB(XYZ_D65), 0.0, 1.0)


def _scene_blocks(ctx: ReportContext, data: SectionData) -> list:
    """A scene through its calibration: emitted against intended (erratum E47)."""
    import matplotlib.pyplot as plt

    r, a = data.results["scene"], data.arrays["scene"]
    fig, axes = plt.subplots(1, 3, figsize=(11, 2.8))
    axes[0].imshow(_to_sRGB(a["intended"], a["white"]))
    axes[0].set_title("intended")
    axes[1].imshow(_to_sRGB(a["emitted"], a["white"]))
    axes[1].set_title("emitted by the simulated display")
    shown = axes[2].imshow(a["dE00"], cmap="magma", vmin=0.0, vmax=max(2.0, r["dE00_p95"]))
    axes[2].set_title("ΔE00")
    fig.colorbar(shown, ax=axes[2], fraction=0.03)
    for ax in axes:
        ax.set_axis_off()
    caption = (
        f"{r['scene']} with [display] calibration ({r['calibration']}): device values through "
        "the .cal to the simulated spectral display, against the intended XYZ"
    )
    table = Table(
        [
            *("scene", "calibration", "pixels", "out of gamut", "ΔE00 mean", "p95", "max"),
            *("pixels > 5 % white", "ΔE00 mean", "max"),
        ],
        [
            [r[k] for k in ("scene", "calibration", "pixels", "out_of_gamut")]
            + [r["dE00_mean"], r["dE00_p95"], r["dE00_max"], r["pixels_above_5pct"]]
            + [r["dE00_mean_above_5pct"], r["dE00_max_above_5pct"]]
        ],
        "A scene on its calibrated display: emitted against intended, pixels in gamut (all, and "
        "above 5 % of white luminance; erratum E47)",
    )
    return [ctx.figure("scene", fig, caption), table]


def _painting_blocks(ctx: ReportContext, data: SectionData) -> list:
    """The painting seen from three positions, with and without compensation (§3.4, Ferwerda)."""
    import matplotlib.pyplot as plt

    a = data.arrays["painting"]
    keys = list(a["seen"])
    fig, axes = plt.subplots(2, len(OBSERVERS) + 1, figsize=(12, 5.8))
    axes[0, 0].imshow(_to_sRGB(a["intended"], a["white"]))
    axes[0, 0].set_title("intended", fontsize=8)
    axes[1, 0].set_axis_off()
    for k, key in enumerate(keys):
        ax = axes[k % 2, 1 + k // 2]
        ax.imshow(_to_sRGB(a["seen"][key], a["white"]))
        ax.set_title(key, fontsize=8)
    for ax in axes.ravel():
        ax.set_xticks([])
        ax.set_yticks([])
    rows = [[k, r["dE00_mean"], r["dE00_max"]] for k, r in data.results["painting"].items()]
    return [
        ctx.figure(
            "painting",
            fig,
            "The painting as each observer sees it (emission at their angle plus the booth "
            "light's screen flare), with the compensation of Eq. (1), Ferwerda (top) and without",
        ),
        Table(
            ["observer", "ΔE00 mean", "max"],
            rows,
            "The painting seen against intended (CIEDE2000, display white; pixels in gamut)",
        ),
    ]


def _figures(ctx: ReportContext, data: SectionData) -> list:
    """Figs. 6 and 7 of Herbert et al., reproduced."""
    import matplotlib.pyplot as plt

    from reference.display.calibration import curve_target

    blocks = []
    fig, ax = plt.subplots(figsize=(5.5, 4))
    gaps = {}
    for curve in FIG6_CURVES:
        G, Y = data.arrays[("fig6", curve)]
        ax.plot(255 * G, Y, lw=2, label=f"measured, {curve}")
        ax.plot(255 * G, curve_target(curve, G), "k:", lw=1)
        gaps[curve] = float(np.max(np.abs(np.asarray(Y) - curve_target(curve, G))))
    ax.set_xlabel("gray value G (0-255)")
    ax.set_ylabel("Y / Y_max")
    ax.legend(frameon=False)
    blocks.append(
        ctx.figure(
            "fig6",
            fig,
            "Fig. 6 reproduced: the calibrated Y follows each target curve (dotted: Eqs. (6)-(7), "
            "Herbert et al.) within "
            + ", ".join(f"{gap:.1e} of Y_max ({curve})" for curve, gap in gaps.items()),
        )
    )
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), sharex=True)
    drift = {}
    for instrument in INSTRUMENTS.names():
        G, xy, white = data.arrays[("fig7", instrument)]
        upper = np.asarray(G) >= 0.2  # near black, the gray's xy is the black level's
        drift[instrument] = float(np.max(np.abs(np.asarray(xy)[upper] - np.asarray(white)[:2])))
        for k, ax in enumerate(axes):
            ax.plot(255 * G[1:], xy[1:, k], lw=1.5, label=f"calibrated with {instrument}")
            ax.axhline(white[k], color="k", lw=0.8)
    for k, ax in enumerate(axes):
        ax.set_xlabel("gray value G (0-255)")
        ax.set_ylabel("xy"[k])
        ax.set_ylim(white[k] - 0.03, white[k] + 0.03)
    axes[0].legend(frameon=False, fontsize=8)
    blocks.append(
        ctx.figure(
            "fig7",
            fig,
            "Fig. 7 reproduced (D65, L* curve): the gray's x and y stay within "
            + ", ".join(f"{d:.4f} of the white's ({name})" for name, d in drift.items())
            + " from G = 51 up (near black, xy is the black level's)",
        )
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
        "Verification of the four whites (L* curve), read by the reference meter",
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


def _default_instrument_table(data: SectionData) -> Table:
    """The default spectroradiometer on the design display and held-out ones (reference meter)."""
    rows = [
        [
            r["display"],
            r["role"],
            key.split()[1],
            key.split()[2],
            r["max_duv_above_5pct"],
            f"{100 * r['duv_at']:.1f} %",
            r["max_abs_Y_error_above_1pct"],
            f"{100 * r['Y_at']:.1f} %",
            f"{100 * r['reachable_above']:.1f} %",
        ]
        for key, r in data.results["default_instrument"].items()
    ]
    return Table(
        [
            "primaries",
            "display",
            "white",
            "curve",
            "max Δu'v' >5 %",
            "at",
            "max |ΔY|/Y >1 %",
            "at",
            "white reachable above",
        ],
        rows,
        "The default spectroradiometer (repeated readings) on the display the loop was designed on "
        "and on held-out ones, read by the reference meter (1 nm, no band pass): below "
        "'reachable above' no drives give the white's chromaticity (the black is of another "
        "colour), and the command says so (erratum E105)",
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
    """The calibration targets for every white and curve, and the colorimeter's shadow failure."""
    found = []
    for key, r in data.results["targets"].items():
        found.append(
            Check(
                f"max Δu'v' above 5 % of white, {key}",
                f"<= {TARGET_DUV}",
                r["max_duv_above_5pct"],
                r["max_duv_above_5pct"] <= TARGET_DUV,
                "design",
            )
        )
        found.append(
            Check(
                f"max |ΔY|/Y above 1 % of white, {key}",
                f"<= {TARGET_Y}",
                r["max_abs_Y_error_above_1pct"],
                r["max_abs_Y_error_above_1pct"] <= TARGET_Y,
                "design",
            )
        )
    found += _default_instrument_checks(data)
    spectro = data.results["instruments"]["spectro"]["holds_down_to_cd_m2"]
    colorimeter = data.results["instruments"]["colorimeter"]["holds_down_to_cd_m2"]
    found.append(
        Check(
            "the spectroradiometer holds the white further into the shadows than the colorimeter "
            "(§6, Herbert et al.)",
            "spectro < colorimeter (cd/m²)",
            f"{spectro:.2f} < {colorimeter:.2f}",
            spectro < colorimeter,
            "design",
        )
    )
    scene = data.results["scene"]
    found.append(
        Check(
            f"{scene['scene']} on its calibrated display: emitted against intended, in gamut "
            "above 5 % of white",
            f"mean ΔE00 <= {TARGET_SCENE_DE}",
            scene["dE00_mean_above_5pct"],
            scene["dE00_mean_above_5pct"] <= TARGET_SCENE_DE,
        )
    )
    found.append(
        Check(
            f"{scene['scene']} on its calibrated display: emitted against intended, every pixel "
            "in gamut (the shadows too, erratum E47)",
            f"mean ΔE00 <= {TARGET_SCENE_DE}",
            scene["dE00_mean"],
            scene["dE00_mean"] <= TARGET_SCENE_DE,
        )
    )
    for key, r in data.results["painting"].items():
        if "not compensated" in key:
            continue
        found.append(
            Check(
                f"painting seen, compensated, {key.split(',')[0]}",
                f"max ΔE00 <= {TARGET_SCENE_DE}",
                r["dE00_max"],
                r["dE00_max"] <= TARGET_SCENE_DE,
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


def _default_instrument_checks(data: SectionData) -> list[Check]:
    """Both targets with the default instrument, labelled designed on or held out.

    Δu'v' where the display can give the white's chromaticity above 5 % of white.
    """
    found = []
    for key, r in data.results.get("default_instrument", {}).items():
        where = f"default spectroradiometer, {r['role']}: {key}, reference meter"
        basis = "design" if r["role"] == "designed on" else "held out"
        duv, dY = r["max_duv_above_5pct"], r["max_abs_Y_error_above_1pct"]
        if r["reachable_above"] <= 0.05:
            name = f"max Δu'v' above 5 % of white, {where}"
            found.append(Check(name, f"<= {TARGET_DUV}", duv, duv <= TARGET_DUV, basis))
        name = f"max |ΔY|/Y above 1 % of white, {where}"
        found.append(Check(name, f"<= {TARGET_Y}", dY, dY <= TARGET_Y, basis))
    return found


def headlines(data: SectionData) -> list[Headline]:
    """The summary's figures: the calibration targets, and the instruments' shadow limits."""
    targets = data.results["targets"].values()
    duv = max(r["max_duv_above_5pct"] for r in targets)
    dY = max(r["max_abs_Y_error_above_1pct"] for r in targets)
    instruments = data.results["instruments"]
    spectro = instruments["spectro"]["holds_down_to_cd_m2"]
    colorimeter = instruments["colorimeter"]["holds_down_to_cd_m2"]
    return [
        Headline(
            f"calibrated to {len(data.results['targets'])} white × curve pairs: gray within "
            f"Δu'v' {duv:.1e} above 5 % of white, luminance within {100 * dY:.2f} %",
            f"targets ≤ {TARGET_DUV} and ≤ {100 * TARGET_Y:g} %",
        ),
        Headline(
            f"the spectroradiometer holds the white down to {spectro:.1f} cd/m², the "
            f"colorimeter only to {colorimeter:.1f} cd/m²",
            "paper §6: only spectrometers held x, y below about 15 cd/m²",
        ),
    ]


SECTION = ReportSection(
    "display-calibration",
    "Display calibration",
    display_calibration,
    present,
    checks,
    headlines=headlines,
    basis="design",  # the built-in display; the held-out displays say so
)

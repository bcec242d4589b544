"""Report section "ImpastoR: settings from a tolerance": frame time against error, held out.

compute → :func:`settings_figures`; present → :func:`present`; checks → :func:`checks`.

Each held-out painting (seeds from 85; the ladders, the pilot margin and the cost model of
:mod:`impastor.settings` were set on seeds 41-44, erratum E96) is rendered under a booth light at
the fixed 32 lights, 32 samples, 36 sectors with the fail-safe, and at the settings each
tolerance chooses; every frame is timed (best of a few, horizon map precomputed) and measured
against the brute force on the frame's own pixels.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from validation.report import (
    Check,
    Headline,
    ReportContext,
    ReportSection,
    SectionData,
    Table,
    Text,
)
from validation.studies.impastor_settings import (
    EQUAL_ERROR,
    METHODS_SIZE,
    best_speedup_at_fixed_error,
    method_speed_accuracy,
    tolerance_study,
)

__all__ = [
    "FULL",
    "QUICK",
    "SPEEDUP_TARGET",
    "SettingsStudy",
    "settings_figures",
    "time_error_caption",
]

#: The target: frames at least this much faster than the fixed settings at no more error.
SPEEDUP_TARGET = 2.0


@dataclass(frozen=True)
class SettingsStudy:
    """The cases and sizes of the study (see :func:`validation.studies.impastor_settings`)."""

    cases: tuple
    tolerances: tuple
    size: int
    light_resolution: tuple
    eval_pixels: int
    repeats: int
    backend: str = "numba"


#: ``specref report --full``: four held-out paintings under both booth lights, at the render's
#: sizes (256², the 128 × 64 booth light).
FULL = SettingsStudy(
    tuple((seed, light) for seed in (85, 86, 87, 88) for light in ("D65", "A")),
    (0.005, 0.01, 0.02, 0.04),
    256,
    (128, 64),
    3000,
    3,
)
#: The default and quick reports: two held-out paintings, one per booth light, at 128².
QUICK = SettingsStudy(((85, "D65"), (86, "A")), (0.01, 0.02, 0.04), 128, (64, 32), 1500, 2)
#: Seconds: for doctests.
TINY = SettingsStudy(((61, "A"),), (0.05,), 16, (16, 8), 40, 1, "numpy")


def settings_figures(ctx: ReportContext | None = None, study: SettingsStudy | None = None):
    """Frame time and error of each case at fixed settings and at each tolerance's.

    Parameters
    ----------
    ctx : ReportContext, optional
        ``ctx.quick`` picks :data:`QUICK` (else :data:`FULL`); ``ctx.run_tasks`` runs the cases.
    study : SettingsStudy, optional
        Overrides ``ctx``.

    Returns
    -------
    SectionData
        ``results``: ``cases`` (:func:`~validation.studies.impastor_settings.tolerance_case`
        per case, with ``speedup_at_fixed_error``), ``study`` (the settings of the study).

    Examples
    --------
    >>> data = settings_figures(study=TINY)
    >>> [c.passed for c in checks(data)][:1], len(data.results["cases"])
    ([True], 1)
    """
    if study is None:
        study = FULL if ctx is not None and not ctx.quick else QUICK
    run = ctx.run_tasks if ctx is not None else None
    cases = tolerance_study(
        study.cases, run, tolerances=study.tolerances, size=study.size,
        light_resolution=study.light_resolution, eval_pixels=study.eval_pixels,
        repeats=study.repeats, backend=study.backend,
    )  # fmt: skip
    for case in cases:
        case["speedup_at_fixed_error"] = best_speedup_at_fixed_error(case)
    seed, light = study.cases[0]
    methods = method_speed_accuracy(
        seed, light, min(METHODS_SIZE, study.size), study.light_resolution,
        repeats=study.repeats, backend=study.backend,
    )  # fmt: skip
    settings = {
        "size": study.size, "light_resolution": list(study.light_resolution),
        "tolerances": list(study.tolerances), "eval_pixels": study.eval_pixels,
    }  # fmt: skip
    return SectionData({"cases": cases, "study": settings, "methods": methods})


def _figure(cases: list):
    """Error against frame time: each case's tolerances joined, its fixed settings a star."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for k, case in enumerate(cases):
        colour = f"C{k % 10}"
        fixed, *chosen = case["rows"]
        label = f"seed {case['seed']}, {case['light']}"
        ax.plot(
            [r["frame_seconds"] for r in chosen], [100 * r["error"] for r in chosen], "o-",
            color=colour, label=label,
        )  # fmt: skip
        for r in chosen:
            ax.annotate(r["label"], (r["frame_seconds"], 100 * r["error"]), fontsize=7,
                        xytext=(3, 3), textcoords="offset points")  # fmt: skip
        ax.plot(fixed["frame_seconds"], 100 * fixed["error"], "*", color=colour, markersize=12)
        if case.get("matched"):
            matched = case["matched"]
            ax.plot(matched["frame_seconds"], 100 * matched["error"], "D", color=colour)
    ax.plot([], [], "k*", markersize=10, label="fixed 32/32/36, fail-safe")
    ax.plot([], [], "kD", label="no worse than fixed, on the pilot")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("frame time (s)")
    ax.set_ylabel("relative RMS error of XYZ against brute force (%)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def _methods_figure(methods: dict):
    """Each lighting method's shading time per pixel against its error, brute force beside."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
    per_pixel = 1e3 / methods["pixels"]
    labels = list(dict.fromkeys(r["method"] for r in methods["rows"]))
    for k, label in enumerate(labels):
        rows = [r for r in methods["rows"] if r["method"] == label]
        x = [per_pixel * r["seconds"] for r in rows]
        y = [100 * r["error"] for r in rows]
        ax.plot(x, y, "o-", color=f"C{k}", label=label)
    brute = per_pixel * methods["brute_force_seconds"]
    ax.axvline(brute, color="k", ls="--", lw=0.8, label="brute force (the reference)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    counts = ", ".join(str(r["count"]) for r in methods["rows"] if r["method"] == labels[0])
    ax.set_xlabel(f"shading time per pixel (ms); each line N = K = {counts}, left to right")
    ax.set_ylabel("relative RMS error of XYZ (%)")
    fig.legend(fontsize=7, loc="outside right center")
    return fig


def _methods_caption(methods: dict) -> str:
    """The chart's conclusion, from its own rows: the fail-safe's price at N = K = 32."""
    at = {r["method"]: r for r in methods["rows"] if r["count"] == 32}
    if "hybrid" not in at or "hybrid, no fail-safe" not in at:
        return "Shading time against error for each lighting method, brute force dashed"
    on, off = at["hybrid"], at["hybrid, no fail-safe"]
    brute, price = methods["brute_force_seconds"], on["seconds"] / off["seconds"]
    return (
        f"At the paper's N = K = 32 the hybrid's fail-safe costs {price:.1f}× "
        f"the hybrid's time for {100 * on['error']:.2g} % error against {100 * off['error']:.2g} % "
        f"without it; brute force is {brute / on['seconds']:.0f}× slower than the hybrid with it, "
        f"{brute / off['seconds']:.0f}× without (time per pixel, log-log; brute force dashed)"
    )


def _rows(cases: list) -> list:
    rows = []
    for case in cases:
        fixed = case["rows"][0]
        for r in case["rows"] + ([case["matched"]] if case.get("matched") else []):
            s = r["settings"]
            rows.append([
                f"{case['seed']} {case['light']}", r["label"], s["n_lights"], s["n_samples"],
                s["n_sectors"], "on" if s["failsafe"] else "off", _shares(r.get("shares")),
                "" if r["pilot_error"] is None else 100 * r["pilot_error"], 100 * r["error"],
                r["frame_seconds"], fixed["frame_seconds"] / r["frame_seconds"],
            ])  # fmt: skip
    return rows


def _shares(shares) -> str:
    """The pixels' shares of the point lights, FIS and the hybrid, in percent.

    Examples
    --------
    >>> _shares((0.7, 0.2, 0.1)), _shares(None)
    ('70 / 20 / 10', '0 / 0 / 100')
    """
    return " / ".join(f"{100 * x:.0f}" for x in (shares or (0.0, 0.0, 1.0)))


def present(ctx: ReportContext, data: SectionData) -> list:
    """What is compared, the chart, and the table of settings, errors and times."""
    cases, study = data.results["cases"], data.results["study"]
    pilot = np.mean([c["pilot_seconds"] for c in cases])
    return [
        Text(
            "Ferwerda fixes 32 lights, 32 samples and 18 sectors (specref 36) for every painting; "
            "`impastor.settings` chooses them, whether the hybrid runs its fail-safe, and which "
            "groups of similar roughness take the point lights or FIS alone instead of the hybrid "
            "(which evaluates both, and more, at every pixel), from a tolerance on the frame's "
            "error against brute force (erratum E96; `specref impastor render --tolerance`). "
            "Held-out paintings (seeds from 85; the method was designed on "
            f"41-44) at {study['size']}², each frame timed and measured on "
            f"{cases[0]['eval_pixels']} of its own pixels, evenly spread, against the brute force "
            "(every light pixel shadowed by its own horizon test, the specular integral over "
            "every light sub-pixel, each shadowed likewise); the pilot is a stratified sample of "
            "other pixels of the same "
            f"frame. The pilot's brute force costs {pilot:.1f} s per painting and light, "
            "once; each tolerance's descent a few seconds more (the table's frames exclude both, "
            "as they exclude the horizon map)."
        ),
        ctx.figure(
            "time-vs-error",
            _figure(cases),
            time_error_caption(cases),
        ),
        *_methods_blocks(ctx, data.results["methods"]),
        Table(
            [
                "case",
                "settings",
                "N",
                "K",
                "S",
                "fail-safe",
                "point lights / FIS / hybrid (% of pixels)",
                "pilot error (%)",
                "frame error (%)",
                "frame (s)",
                "speed-up vs fixed",
            ],
            _rows(cases),
            "Settings chosen per tolerance on held-out paintings, their errors and frame times",
            "{:.3g}",
        ),
    ]


def time_error_caption(cases: list) -> str:
    """The time-against-error chart's caption from its cases: what the tolerances buy, or not.

    Examples
    --------
    >>> rows = [{"frame_seconds": 2.0, "error": 0.01, "label": "fixed"},
    ...         {"frame_seconds": 0.5, "error": 0.03, "label": "4 %"}]
    >>> cases = [{"rows": rows, "speedup_at_fixed_error": 0.8}, {"rows": rows,
    ...           "speedup_at_fixed_error": 1.5}]
    >>> print(time_error_caption(cases))
    Frame error against frame time (joined: the settings each tolerance chooses; stars: the fixed
    32/32/36; diamonds: the settings the pilot finds no worse than the fixed ones): at no more
    than the fixed settings' error the chosen frames are 0.8–1.5× as fast (slower in 1 of 2
    cases); the loosest tolerance (4 %) is 4× as fast at 3 % error
    """
    at_fixed = [c["speedup_at_fixed_error"] for c in cases if c["speedup_at_fixed_error"]]
    loose = [c["rows"][0]["frame_seconds"] / c["rows"][-1]["frame_seconds"] for c in cases]
    errors = [100 * c["rows"][-1]["error"] for c in cases]
    text = (
        "Frame error against frame time (joined: the settings each tolerance chooses; stars: the "
        "fixed 32/32/36; diamonds: the settings the pilot finds no worse than the fixed ones): "
    )
    if at_fixed:
        slower = sum(s < 1 for s in at_fixed)
        text += (
            f"at no more than the fixed settings' error the chosen frames are "
            f"{_span(at_fixed)}× as fast"
            + (f" (slower in {slower} of {len(at_fixed)} cases); " if slower else "; ")
        )
    return text + (
        f"the loosest tolerance ({cases[0]['rows'][-1]['label']}) is {_span(loose)}× as fast at "
        f"{_span(errors)} % error"
    )


def _span(values) -> str:
    """``"a–b"`` of the smallest and largest value (one value when they agree), 2 digits."""
    low, high = f"{min(values):.2g}", f"{max(values):.2g}"
    return low if low == high else f"{low}–{high}"


def _methods_blocks(ctx: ReportContext, methods: dict) -> list:
    rows = [
        [r["method"], r["count"], 1e3 * r["seconds"] / methods["pixels"], 100 * r["error"]]
        for r in methods["rows"]
    ]
    rows.append(["brute force", "every light pixel", 1e3 * methods["brute_force_seconds"] /
                 methods["pixels"], 0.0])  # fmt: skip
    return [
        Text(
            "Speed against accuracy of every lighting method (§3.5, Ferwerda): on the "
            f"{methods['pixels']} visible canvas pixels of a {METHODS_SIZE}² frame of the first "
            "painting, each "
            "method shades with N point lights and K FIS samples (N = K), shadows from the "
            "36-sector horizon, timed (best of the repeats, the horizon look-up included) and "
            "measured against the brute force above."
        ),
        ctx.figure("methods", _methods_figure(methods), _methods_caption(methods)),
        Table(
            ["method", "N = K", "ms per pixel", "error (%)"],
            rows,
            f"Each lighting method's shading time and error on a {METHODS_SIZE}² frame's pixels",
            "{:.3g}",
        ),
    ]


def _kept(cases: list) -> list:
    """The ladder's frames whose pilot met their tolerance.

    The matched frames promise no tolerance: they count in the speed-up, at no more than the
    fixed frame's error.
    """
    return [r for c in cases for r in c["rows"][1:] if r["met"]]


def checks(data: SectionData) -> list[Check]:
    """The promise on held-out frames, and the speed-up at no more than the fixed error."""
    cases = data.results["cases"]
    kept = _kept(cases)
    worst = max((r["error"] / r["tolerance"] for r in kept), default=0.0)
    speedups = [c["speedup_at_fixed_error"] for c in cases]
    reached = [s for s in speedups if s is not None]
    return [
        Check(
            f"held-out frames within their tolerance ({len(kept)} frames whose pilot met it)",
            "frame error / tolerance <= 1",
            worst,
            bool(kept) and worst <= 1.0,
            "held out",
        ),
        Check(
            f"frame-time speed-up over fixed 32/32/36 at no more than its error (within "
            f"{100 * (EQUAL_ERROR - 1):g} %; worst case)",
            f">= {SPEEDUP_TARGET:g}× on every case",
            min(reached) if len(reached) == len(cases) else float("nan"),
            len(reached) == len(cases) and min(reached) >= SPEEDUP_TARGET,
            "held out",  # the same held-out paintings
        ),
    ]


def headlines(data: SectionData) -> list[Headline]:
    """The promise kept, and the speed-ups the tolerances buy."""
    cases = data.results["cases"]
    kept = _kept(cases)
    worst = max((r["error"] / r["tolerance"] for r in kept), default=0.0)
    reached = [c["speedup_at_fixed_error"] for c in cases]
    text = ", ".join("–" if s is None else f"{s:.2f}×" for s in reached)
    return [
        Headline(
            f"settings from a tolerance: held-out frames at most {worst:.2f} of their tolerance; "
            f"at no more than the fixed settings' error, frames {text} faster",
            f"target ≤ 1 and ≥ {SPEEDUP_TARGET:g}×",
        )
    ]


SECTION = ReportSection(
    "impastor-settings",
    "ImpastoR: settings from a tolerance",
    settings_figures,
    present,
    checks,
    headlines=headlines,
    hero="time-vs-error",
    default_effort="quick",  # the full study renders 8 cases at 256²: specref report --full
)

"""Report section "SHRMs on full-resolution maps": the default path against brute force.

The figures (``validation.studies.shrm_fullres``): for every shipped environment map at its full
resolution and every BRDF of :data:`validation.studies.shrm_fullres.FULLRES_BRDFS`, an orthographic
sphere rendered by the SH + angular split (the default of ``specref render``, Herbert §9 done), by
the SHRM alone (the same settings, and half the lighting order), by Monte Carlo given the split's
frame time and by brute force over every texel: the largest error relative to the peak, the mean
|ΔY/Y| over pixels brighter than 1 % of the peak, what the split promised and its spot check, and
the seconds of a frame after the first, charted over all cases and per map and BRDF. The SHRM
section's study on maps box-filtered to 64 rows stays there, labelled as such.

compute → :func:`fullres_study`; present → :func:`present`; checks → :func:`checks`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from reference.data import environment_maps
from validation.report import Check, ReportContext, ReportSection, SectionData, Table, Text
from validation.studies.shrm_fullres import FULLRES_BRDFS, fullres_case, sphere_points

__all__ = ["SETTINGS", "fullres_study"]

#: The targets (docs/shrm.md, §6): within 1 % of the peak, mean |ΔY/Y| <= 1 % over pixels above
#: 1 % of it.
PEAK_LIMIT_PCT = 1.0
MEAN_LIMIT_PCT = 1.0
#: The split's per-pixel tolerance (``render.options.shrm_tol``'s default).
TOL = 0.005

#: Sizes per mode: the maps' rows (None: full resolution), the sphere's side, the BRDFs; the
#: targets are checked at full resolution only (quick mode measures the same code on small maps).
SETTINGS = {
    "full": {
        "rows": None,
        "pixels": 12,
        "brdfs": FULLRES_BRDFS,
        "label": "full resolution",
        "targets": True,
        # a finer sphere where the grazing pixels are hardest (the view order runs out there)
        "extra": (
            ("venice_sunset_1k.hdr", "ggx", 0.3, 16),
            ("venice_sunset_1k.hdr", "ggx", 0.3, 32),
            ("studio_small_03_1k.hdr", "ggx", 0.1, 32),
        ),
    },
    "quick": {
        "rows": 32,
        "pixels": 6,
        "brdfs": (("ggx", 0.3),),
        "label": "quick settings: maps box-filtered to 32 rows; the full-resolution targets run "
        "under specref report --full",
        "targets": False,
    },
}


def fullres_study(ctx: ReportContext, settings: dict | None = None, maps=None) -> SectionData:
    """Every shipped map × BRDF, one task each (``ctx.run_tasks``).

    Examples
    --------
    >>> import tempfile
    >>> from reference.images.formats import write_exr
    >>> sky = np.ones((16, 32, 3)); sky[3, 5] = 400.0
    >>> path = write_exr(Path(tempfile.mkdtemp()) / "sky.exr", sky)
    >>> s = {"rows": None, "pixels": 5, "brdfs": (("ggx", 0.3),), "label": "test", "targets": True}
    >>> data = fullres_study(ReportContext(Path(".")), s, [path])
    >>> [c.passed for c in checks(data)]
    [True]
    """
    s = settings or SETTINGS["quick" if ctx.quick else "full"]
    maps = maps if maps is not None else environment_maps()
    tasks = [
        (str(path), brdf, alpha, s["pixels"], s["rows"], TOL)
        for path in maps
        for brdf, alpha in s["brdfs"]
    ]
    by_name = {Path(path).name: path for path in maps}
    tasks += [
        (str(by_name[name]), brdf, alpha, pixels, s["rows"], TOL)
        for name, brdf, alpha, pixels in s.get("extra", ())
        if name in by_name
    ]
    rows = ctx.run_tasks(fullres_case, tasks, "SHRM full-resolution cases")
    return SectionData({"cases": rows, "label": s["label"], "tol": TOL, "targets": s["targets"]})


def _holds(row: dict) -> bool:
    split = row["split"]
    return split["pct_of_peak"] <= PEAK_LIMIT_PCT and split["mean_rel_pct"] <= MEAN_LIMIT_PCT


#: The methods of both charts: label and marker (brute force is drawn at :data:`FLOOR_PCT`).
STYLES = {
    "split": ("SH + angular split (default)", "o"),
    "shrm": ("SHRM alone, same settings", "s"),
    "shrm_half_F": ("SHRM alone, half F", "^"),
    "mc": ("Monte Carlo, importance-sampled, split's time", "D"),
}
#: Where exact results sit on the charts' log error axis, % of the peak.
FLOOR_PCT = 1e-4


def _chart(ctx: ReportContext, rows: list):
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 4.0))
    for key, (label, marker) in STYLES.items():
        x = [1e3 * r[key]["shade_seconds"] / r["pixels"] for r in rows]
        y = [max(r[key]["pct_of_peak"], FLOOR_PCT) for r in rows]
        ax.scatter(x, y, marker=marker, label=label, alpha=0.8)
    brute = [1e3 * r["bruteforce_seconds"] / r["pixels"] for r in rows]
    ax.scatter(brute, [FLOOR_PCT] * len(rows), marker="x", color="k", label="brute force (exact)")
    ax.axhline(PEAK_LIMIT_PCT, color="gray", linestyle="--", label="target 1 % of peak")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("ms per pixel, a frame after the first")
    ax.set_ylabel("largest error, % of the peak")
    ax.legend(fontsize=8)
    held = sum(_holds(r) for r in rows)
    worst = max(rows, key=lambda r: r["split"]["pct_of_peak"])
    speed = np.median([r["bruteforce_seconds"] / r["split"]["shade_seconds"] for r in rows])
    caption = (
        f"Time against error per case: the split meets both targets in {held} of {len(rows)} "
        f"cases; its worst is {worst['split']['pct_of_peak']:.2f} % of the peak "
        f"({worst['map']}, {worst['brdf']} α {worst['alpha']:g}); a frame after the first is "
        f"{speed:.0f}× faster than brute force (median)."
    )
    return ctx.figure("time-error", fig, caption)


def _case_label(r: dict) -> str:
    return f"{r['brdf']} α {r['alpha']:g}" + (" (tabulated GGX)" if r["brdf"] == "table" else "")


def _map_panels(ctx: ReportContext, rows: list, name: str):
    """One map's cases, a panel each (at most four across): ms per point against % of the peak."""
    import matplotlib.pyplot as plt
    from matplotlib import ticker

    cases = list(dict.fromkeys((_case_label(r), r["side"]) for r in rows))
    columns = min(4, len(cases))
    lines = -(-len(cases) // columns)
    fig, axes = plt.subplots(
        lines,
        columns,
        figsize=(3.3 * columns, 2.7 * lines + 0.5),
        squeeze=False,
        layout="constrained",
    )
    for r in rows:
        ax = axes.flat[cases.index((_case_label(r), r["side"]))]
        for key, (label, marker) in STYLES.items():
            ms = 1e3 * r[key]["shade_seconds"] / r["pixels"]
            ax.scatter(ms, max(r[key]["pct_of_peak"], FLOOR_PCT), marker=marker, label=label)
        brute = 1e3 * r["bruteforce_seconds"] / r["pixels"]
        ax.scatter(brute, FLOOR_PCT, marker="x", color="k", label="brute force (exact)")
        ax.axhline(PEAK_LIMIT_PCT, color="gray", linestyle="--", linewidth=0.8)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(f"{_case_label(r)}, {r['side']}²", fontsize=9)
        ax.set_xlabel("ms per point", fontsize=8)
        ax.set_ylabel("% of peak", fontsize=8)
        ax.tick_params(which="both", labelsize=7)
        for axis in (ax.xaxis, ax.yaxis):  # short labels: a narrow log range labels its minors
            axis.set_major_formatter(ticker.FormatStrFormatter("%.2g"))
            axis.set_minor_formatter(ticker.FormatStrFormatter("%.2g"))
        ax.yaxis.set_minor_formatter(ticker.NullFormatter())
    for ax in axes.flat[len(cases) :]:
        ax.set_axis_off()
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=3, fontsize=8)
    held = sum(_holds(r) for r in rows)
    caption = (
        f"{name}: the split meets both targets in {held} of {len(rows)} cases. Per case, the SHRM "
        "alone at two lighting orders, the split, Monte Carlo given the split's frame time and "
        f"brute force (exact, drawn at {FLOOR_PCT:g} %); the dashed line is the 1 % target."
    )
    return ctx.figure(f"speed-accuracy-{name.split('.')[0]}", fig, caption)


def _panels(ctx: ReportContext, rows: list) -> list:
    """Speed against accuracy per case, one figure per map (readable panels, not a wall of 35)."""
    maps = sorted({r["map"] for r in rows})
    return [_map_panels(ctx, [r for r in rows if r["map"] == m], m) for m in maps]


def present(ctx: ReportContext, data: SectionData) -> list:
    """The table of cases, the time–error chart and the per-case speed–accuracy panels."""
    rows = data.results["cases"]
    sizes = " or ".join(f"{n} × {n}" for n in sorted({r["side"] for r in rows}))
    # the brute force of a 128 × 128 sphere (as in erratum E94), from this run's seconds per point
    per_point = np.median([r["bruteforce_seconds"] / r["pixels"] for r in rows])
    minutes_128 = per_point * len(sphere_points(128)[0]) / 60
    table = [
        [
            r["map"],
            _case_label(r),
            r["pixels"],
            r["split"]["pct_of_peak"],
            r["split"]["mean_rel_pct"],
            r["promised_pct_of_peak"],
            r["check_pct_of_peak"],
            "yes" if r["meets_tolerance"] else "no",
            r["shrm"]["pct_of_peak"],
            r["shrm_half_F"]["pct_of_peak"],
            r["mc"]["pct_of_peak"],
            r["mc"]["samples"],
            f"{r['F']}/{r['P']}/{r['size']}",
            r["residual_texels"],
            r["bruteforce_seconds"] / r["split"]["shade_seconds"],
        ]
        for r in rows
    ]
    return [
        Text(
            f"Measured on the shipped maps ({data.results['label']}): an orthographic "
            f"sphere at the pixel centres of a {sizes} image (a 128 × 128 image would take "
            f"about {minutes_128:.0f} minutes of brute force per case at this run's speed) of each "
            "BRDF (GGX with ρ_d 0 and F_0 1, Ward, the thin-film effect pigment, GGX α 0.3 "
            "tabulated at 5° × 15° through the BRDF-table path) rendered by the "
            "default SH + angular split, by the SHRM alone and by brute force over every texel "
            f"(the oracle of --oracle). Split tolerance {data.results['tol']:g} of the peak. "
            "'Promised' is the split's bound on the lighting truncation; 'spot check' its "
            "error against brute force at 8 points chosen by the renderer (half of them the "
            "most grazing), which covers the view order and the cube interpolation too; "
            "'meets tolerance' needs both within the tolerance (erratum E92). The Monte Carlo "
            "column is the importance-sampled estimator of shrm.montecarlo given the split's "
            "frame time (erratum E58)."
            + ("" if data.results["targets"] else " Targets are checked in the full report only.")
        ),
        _chart(ctx, rows),
        *_panels(ctx, rows),
        Table(
            [
                "map",
                "BRDF",
                "points",
                "split: % of peak",
                "split: mean |ΔY/Y| %",
                "promised % of peak",
                "spot check: % of peak",
                "meets tolerance",
                "SHRM alone: % of peak",
                "SHRM half F: % of peak",
                "MC equal time: % of peak",
                "MC samples per point",
                "F/P/cube",
                "residual texels",
                "frame speed-up vs brute force",
            ],
            table,
            "The default path against brute force; targets: ≤ 1 % of the peak, mean ≤ 1 %",
            "{:.3g}",
        ),
    ]


def checks(data: SectionData) -> list[Check]:
    """One check per map and BRDF: both targets, on the split (the default).

    None in quick mode: the targets are for the full-resolution maps.
    """
    found = []
    for r in data.results["cases"] if data.results["targets"] else ():
        split = r["split"]
        found.append(
            Check(
                f"SHRM split, {r['map']}, {r['brdf']} α {r['alpha']:g} ({data.results['label']}, "
                f"{r['pixels']} sphere points): % of peak / mean |ΔY/Y| %",
                f"<= {PEAK_LIMIT_PCT:g} / <= {MEAN_LIMIT_PCT:g}",
                f"{split['pct_of_peak']:.3g} / {split['mean_rel_pct']:.3g}",
                _holds(r),
            )
        )
    return found


SECTION = ReportSection(
    "shrm-fullres",
    "SHRMs on full-resolution maps",
    fullres_study,
    present,
    checks,
    default_effort="quick",  # the full settings take minutes: specref report --full
)

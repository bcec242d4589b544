"""Report section "Spectral Phong tables": speed against accuracy, failure sweeps, tolerance picks.

Full mode renders at 256×256 with the numba kernels; ``--quick`` renders at 24×24 with the NumPy
references (timings are then not representative, and the charts say so). ``specref phong table1``
gives Table 1 itself at 512×512.
"""

from __future__ import annotations

import numpy as np

from phong_table.scenes import SCENES, constant_material
from phong_table.table import build_table
from validation.phong import (
    ENTRY_LADDER,
    INTERPOLATIONS,
    NEVER_WORSE_INTERPOLATIONS,
    TABLE1_ENTRIES,
    TABLE_VARIANTS,
    bimodal_material,
    table_error_row,
    time_row,
    time_shading,
    tolerance_search,
    view_state,
)
from validation.phong_table1 import target_checks
from validation.report import (
    ReportContext,
    ReportSection,
    SectionResult,
    Table,
    Text,
)

QUICK_NOTE = " with the NumPy references (quick mode: times not representative)"
#: Image size of the in-run speed-up in full mode: Table 1's.
SPEED_RESOLUTION = 512
VARIANT_NAMES = ("importance p=m", "importance p=m/10", "uniform", "error")


def _pareto(points):
    """Indices of the points not dominated in (time, rms), both smaller-is-better."""
    order = sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1]))
    front, best = [], np.inf
    for i in order:
        if points[i][1] < best:
            front.append(i)
            best = points[i][1]
    return front


def _floor(x):
    return max(float(x), 1e-9)


def _bench_speedups(bench) -> list[float]:
    # per benchmark group "phong <scene> <view>": exact / table(error, monotone), minima
    speed = []
    for _, records in sorted(bench.items()):
        exact = [r for r in records if r["name"].startswith("test_exact")]
        table = [r for r in records if r["name"].endswith("-error-monotone]")]
        if exact and table:
            speed.append(exact[0]["stats"]["min"] / table[0]["stats"]["min"])
    return speed


def run(ctx: ReportContext) -> SectionResult:
    """Sweeps of the table methods against the exact render, with charts."""
    import matplotlib.pyplot as plt

    quick = ctx.quick
    resolution, compiled, repeats = (24, False, 1) if quick else (256, True, 5)
    ladder = (25, 100, 400) if quick else ENTRY_LADDER
    scenes = ("R1", "R3") if quick else ("R1", "R2", "R3")
    views = ("near",) if quick else ("far", "near")
    results, blocks, nonfinite = {}, [], 0
    records, speed, picks = [], [], []
    bench_speed = _bench_speedups(ctx.bench_groups("phong"))
    blocks.append(
        Text(
            f"RMS (8-bit, the larger of display and linear) against shading time (build included) "
            f"for every placement, interpolation and m in {list(ladder)}, at {resolution}×"
            f"{resolution}{QUICK_NOTE if quick else ''}. "
            "Black line: the Pareto front. `specref phong table1` gives Table 1 at 512×512."
        )
    )
    # speed vs accuracy, one panel per scene and view
    fig, axes = plt.subplots(
        len(views), len(scenes), figsize=(4.2 * len(scenes), 3.6 * len(views)), squeeze=False
    )
    markers = dict(zip(VARIANT_NAMES, "s^vo", strict=True))
    colours = dict(zip(INTERPOLATIONS, ("C3", "C1", "C0", "C2"), strict=True))
    for col, scene in enumerate(scenes):
        model = SCENES.lookup(scene).build()
        for row, view in enumerate(views):
            state = view_state(model, view, resolution, compiled)
            exact_s = time_shading(state, None, repeats=repeats)
            points, labels = [], []
            for (placement, segments), name in zip(TABLE_VARIANTS, VARIANT_NAMES, strict=True):
                for interpolation in INTERPOLATIONS:
                    for m in ladder:
                        r = table_error_row(state, placement, interpolation, m, segments(m))
                        records.append({"scene": scene, "view": view, **r})
                        seen = (state.buffer.t_range, state.buffer.t_density)
                        table = build_table(model, m, placement, r["segments"], compiled, *seen)
                        shade_s = time_shading(state, table, interpolation, repeats)
                        nonfinite += int(not np.isfinite(r["rms"]))
                        points.append((shade_s, _floor(r["rms"])))
                        labels.append((name, interpolation, m))
            results[f"{scene} {view}"] = {
                "exact_shade_s": exact_s,
                "points": [
                    {"variant": v, "interpolation": i, "entries": m, "shade_s": s, "rms": e}
                    for (v, i, m), (s, e) in zip(labels, points, strict=True)
                ],
            }
            # the 200-entry error rows of the targets, and the in-run speed-up of error + monotone
            for interpolation in () if TABLE1_ENTRIES in ladder else NEVER_WORSE_INTERPOLATIONS:
                r = table_error_row(state, "error", interpolation, TABLE1_ENTRIES)
                records.append({"scene": scene, "view": view, **r})
            if not bench_speed and not quick:
                # at Table 1's size, compiled (the target's); quick mode's NumPy times mean nothing
                timed = view_state(model, view, SPEED_RESOLUTION, compiled)
                timed_exact_s = time_shading(timed, None, repeats=repeats)
                r = table_error_row(timed, "error", "monotone", TABLE1_ENTRIES)
                speed.append(time_row(timed, r, timed_exact_s, 0.0, repeats)["speedup"])
            ax = axes[row][col]
            for (name, interpolation, _), (s, e) in zip(labels, points, strict=True):
                ax.scatter(s, e, marker=markers[name], c=colours[interpolation], s=14)
            front = _pareto(points)
            ax.plot([points[i][0] for i in front], [points[i][1] for i in front], "k-", lw=0.8)
            ax.axvline(exact_s, color="grey", ls=":", lw=0.8)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_title(f"{scene} {view}")
            ax.set_xlabel("shading time incl. build (s); dotted: exact")
            ax.set_ylabel("RMS (8-bit)")
    handles = [plt.Line2D([], [], marker=markers[n], ls="", c="k", label=n) for n in VARIANT_NAMES]
    handles += [
        plt.Line2D([], [], marker="o", ls="", c=colours[i], label=i) for i in INTERPOLATIONS
    ]
    axes[0][0].legend(handles=handles, fontsize=7)
    blocks.append(
        ctx.figure("pareto", fig, "Speed against accuracy, log-log, Pareto front in black")
    )

    # failure sweeps (far view)
    state_of = {}

    def sweep(materials, xs, xlabel, name, caption, variants=TABLE_VARIANTS, m=200):
        nonlocal nonfinite
        fig, axes = plt.subplots(1, 3, figsize=(13, 3.4))
        data = {}
        for ax, interpolation in zip(axes, ("linear", "parabolic", "monotone"), strict=True):
            for (placement, segments), vname in zip(variants, VARIANT_NAMES, strict=True):
                ys = []
                for material in materials:
                    key = id(material)
                    if key not in state_of:
                        state_of[key] = view_state(material, "far", resolution, compiled)
                    r = table_error_row(state_of[key], placement, interpolation, m, segments(m))
                    nonfinite += int(not np.isfinite(r["rms"]))
                    ys.append(_floor(r["rms"]))
                data[f"{vname} {interpolation}"] = ys
                ax.plot(xs, ys, marker=markers[vname], label=vname, ms=4)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel(xlabel)
            ax.set_ylabel("RMS (8-bit)")
            ax.set_title(f"{interpolation}, m = {m}")
        axes[0].legend(fontsize=7)
        results[name] = {"x": list(xs), "rms": data}
        blocks.append(ctx.figure(name, fig, caption))

    scales = (1, 10, 100, 1000, 10000) if quick else (1, 3, 10, 30, 100, 300, 1000, 3000, 10000)
    sweep(
        [constant_material(float(n)) for n in scales],
        scales,
        "exponent n (constant)",
        "exponent-scale",
        "Where methods fail: RMS against the exponent scale (far view)",
    )
    highs = (5, 50, 500, 5000) if quick else (5, 20, 50, 200, 500, 2000, 5000)
    sweep(
        [bimodal_material(5.0, float(h)) for h in highs],
        highs,
        "n above 580 nm (n = 5 below)",
        "exponent-spread",
        "Where methods fail: RMS against the exponent spread of a bimodal n(λ) (far view)",
    )
    # segment count p for the importance table at m = 200
    divisors = (1, 10, 200) if quick else (1, 2, 4, 5, 8, 10, 20, 25, 40, 50, 100, 200)
    fig, ax = plt.subplots(figsize=(6, 3.6))
    seg = {}
    for scene in ("R1", "R2", "R3", "bimodal"):
        state = view_state(SCENES.lookup(scene).build(), "far", resolution, compiled)
        ys = []
        for p in divisors:
            r = table_error_row(state, "importance", "parabolic", 200, p)
            nonfinite += int(not np.isfinite(r["rms"]))
            ys.append(_floor(r["rms"]))
        seg[scene] = ys
        ax.plot(divisors, ys, marker="o", ms=4, label=scene)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("segments p (importance, m = 200, t-parabola)")
    ax.set_ylabel("RMS (8-bit)")
    ax.legend(fontsize=7)
    results["segments"] = {"p": list(divisors), "rms": seg}
    blocks.append(ctx.figure("segments", fig, "RMS against the importance table's segment count p"))

    # tolerance search
    rows = []
    for scene in scenes:
        for view in views:
            state = view_state(SCENES.lookup(scene).build(), view, resolution, compiled)
            pick = tolerance_search(state, 0.05, "monotone", max_entries=256 if quick else 4096)
            results[f"tolerance {scene} {view}"] = pick
            picks.append({"scene": scene, "view": view, **pick})
            rows.append(
                [
                    scene,
                    view,
                    pick["placement"],
                    pick["entries"],
                    pick["verified_rms"],
                    "yes" if pick["verified"] else "no",
                ]
            )
    blocks.append(
        Table(
            ["scene", "view", "placement", "entries", "verified RMS", "meets 0.05"],
            rows,
            "--tolerance 0.05 (monotone): the smallest table, verified on the image",
            "{:.3g}",
        )
    )
    # the paper's failure modes (far view, t-parabola)
    n2000 = view_state(SCENES.lookup("n2000").build(), "far", resolution, compiled)
    bimodal = view_state(SCENES.lookup("bimodal").build(), "far", resolution, compiled)
    failure = {
        "n2000_overshoot": table_error_row(n2000, "importance", "parabolic", 200, 200)["overshoot"],
        "importance_rms": [
            table_error_row(bimodal, "importance", "parabolic", m, m)["rms"] for m in (200, 800)
        ],
        "error_rms": [table_error_row(bimodal, "error", "parabolic", m)["rms"] for m in (200, 800)],
    }
    results["failure_modes"] = failure
    results["nonfinite"] = nonfinite
    blocks.append(Text(f"Non-finite RMS values in all sweeps: {nonfinite} (must be 0)."))
    bench = ctx.bench_groups("phong")
    if bench:
        table_rows = []
        for group, group_records in sorted(bench.items()):
            base = [r for r in group_records if "exact" in r["name"]]
            base_s = base[0]["stats"]["min"] if base else None
            for r in group_records:
                ratio = base_s / r["stats"]["min"] if base_s else float("nan")
                table_rows.append([group, r["name"], r["stats"]["min"] * 1e3, ratio])
        blocks.append(
            Table(
                ["group", "benchmark", "min ms", "exact / this"],
                table_rows,
                "Benchmarks (make bench), same-run exact baseline",
                "{:.3g}",
            )
        )
        results["bench"] = table_rows
    if bench_speed:
        speed, speed_source = bench_speed, "from benchmark JSON (make bench, 512×512)"
    else:
        speed_source = (
            "not measured in --quick mode without make bench"
            if quick
            else f"measured in this run at {SPEED_RESOLUTION}×{SPEED_RESOLUTION} (compiled)"
        )
    scope = (
        f" [quick: {', '.join(scenes)} {', '.join(views)} only, {resolution}×{resolution}, "
        f"m in {list(ladder)}]"
        if quick
        else f" [{len(scenes) * len(views)} rows, {resolution}×{resolution}]"
    )
    checks = target_checks(records, picks, failure, speed, speed_source, scope)
    results["speedups"] = {"source": speed_source, "values": speed}
    blocks.append(
        Table(
            ["target", "limit", "measured", "holds"],
            [[c.name, c.target, c.measured, "yes" if c.passed else "NO"] for c in checks],
            "The issue's targets, from this section's figures",
            "{:.3g}",
        )
    )
    return SectionResult(blocks, results, checks)


SECTION = ReportSection("phong", "Spectral Phong tables", legacy_run=run)

"""Report section "Spectral Phong tables": speed against accuracy, failure sweeps, tolerance picks.

Full mode renders at 256×256 with the numba kernels; ``--quick`` renders at 24×24 with the NumPy
references (timings are then not representative, and the charts say so). ``specref phong table1``
gives Table 1 itself at 512×512. The paper's Figs. 2-7 and Table 1 in its layout, beside the printed
figures, come from ``validation.studies.phong_figures`` (``PhongStudy.figures``: 32×32 quick,
256×256 full).

compute → :func:`phong_speed_accuracy`; present → :func:`present`; checks → :func:`checks`. The
table variants and interpolations come from the registries
(``validation.studies.phong.table_variants``, ``phong_table.INTERPOLATION_METHODS``).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from phong_table.interpolation import INTERPOLATION_METHODS
from phong_table.scenes import SCENES, VIEWS, constant_material
from phong_table.table import build_table
from validation.report import (
    Check,
    Headline,
    Image,
    ReportContext,
    ReportSection,
    SectionData,
    Table,
    Text,
)
from validation.studies.phong import (
    ENTRY_LADDER,
    TABLE1_ENTRIES,
    bimodal_material,
    never_worse_interpolations,
    table1_scenes,
    table_error_row,
    table_variants,
    time_row,
    time_shading,
    tolerance_search,
    view_state,
)
from validation.studies.phong_table1 import target_checks

__all__ = [
    "FULL",
    "QUICK",
    "PhongStudy",
    "phong_speed_accuracy",
    "segments_caption",
    "sweep_caption",
]

QUICK_NOTE = " with the NumPy references (quick mode: times not representative)"
#: Image size of the in-run speed-up in full mode: Table 1's.
SPEED_RESOLUTION = 512
#: Markers of the table variants and colours of the interpolations, in registry order.
MARKERS, COLOURS = "s^vo<>Dph", ("C3", "C1", "C0", "C2", "C4", "C5", "C6")


@dataclass(frozen=True)
class PhongStudy:
    """The sizes of the section's studies.

    Attributes
    ----------
    resolution, compiled, repeats
        Image size of the sweeps, numba kernels (else NumPy references), timing repetitions.
    ladder, scenes, views
        Entry counts, scenes and views of the speed-accuracy study and the tolerance picks.
    scales, highs, divisors
        Exponents of the exponent-scale sweep, upper exponents of the exponent-spread sweep and
        the importance table's segment counts (all at m = 200, far view).
    max_entries : int
        Largest table the tolerance search tries.
    quick : bool
        Quick mode: no in-run speed-up, and the labels say so.
    figures : int
        Image size of the paper's figures and Table 1 (``validation.studies.phong_figures``); 0:
        none.
    """

    resolution: int
    compiled: bool
    repeats: int
    ladder: tuple
    scenes: tuple
    views: tuple
    scales: tuple
    highs: tuple
    divisors: tuple
    max_entries: int
    quick: bool
    figures: int = 0


#: The ``--quick`` sizes: 24×24 with the NumPy references.
QUICK = PhongStudy(
    resolution=24,
    compiled=False,
    repeats=1,
    ladder=(25, 100, 400),
    scenes=("R1", "R3"),
    views=("near",),
    scales=(1, 10, 100, 1000, 10000),
    highs=(5, 50, 500, 5000),
    divisors=(1, 10, 200),
    max_entries=256,
    quick=True,
    figures=32,
)
#: The full sizes: 256×256 with the numba kernels.
FULL = PhongStudy(
    resolution=256,
    compiled=True,
    repeats=5,
    ladder=ENTRY_LADDER,
    scenes=table1_scenes(),
    views=tuple(VIEWS),
    scales=(1, 3, 10, 30, 100, 300, 1000, 3000, 10000),
    highs=(5, 20, 50, 200, 500, 2000, 5000),
    divisors=(1, 2, 4, 5, 8, 10, 20, 25, 40, 50, 100, 200),
    max_entries=4096,
    quick=False,
    figures=256,
)


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


def _speed_accuracy_task(task) -> tuple[dict, dict]:
    """A task of the section: ``(study, scene, view, benched)`` → the view's points, its finds."""
    study, scene, view, benched = task
    found = {"records": [], "speed": [], "nonfinite": 0, "bench_speed": [1.0] if benched else []}
    view_result = _speed_accuracy_view(study, SCENES.lookup(scene).build(), scene, view, found)
    return view_result, found


def _speed_accuracy_view(study: PhongStudy, model, scene: str, view: str, found: dict) -> dict:
    """Every table variant, interpolation and m of the ladder on one view: time and RMS."""
    state = view_state(model, view, study.resolution, study.compiled)
    exact_s = time_shading(state, None, repeats=study.repeats)
    points = []
    for variant in table_variants():
        for interpolation in INTERPOLATION_METHODS.names():
            for m in study.ladder:
                r = table_error_row(state, variant.placement, interpolation, m, variant.segments(m))
                found["records"].append({"scene": scene, "view": view, **r})
                seen = (state.buffer.t_range, state.buffer.t_density, interpolation)
                table = build_table(
                    model, m, variant.placement, r["segments"], study.compiled, *seen
                )
                shade_s = time_shading(state, table, interpolation, study.repeats)
                found["nonfinite"] += int(not np.isfinite(r["rms"]))
                points.append(
                    {
                        "variant": variant.name,
                        "interpolation": interpolation,
                        "entries": m,
                        "shade_s": shade_s,
                        "rms": _floor(r["rms"]),
                    }
                )
    # the 200-entry error rows of the targets, and the in-run speed-up of error + monotone
    for interpolation in () if TABLE1_ENTRIES in study.ladder else never_worse_interpolations():
        r = table_error_row(state, "error", interpolation, TABLE1_ENTRIES)
        found["records"].append({"scene": scene, "view": view, **r})
    if not found["bench_speed"] and not study.quick:
        # at Table 1's size, compiled (the target's); quick mode's NumPy times mean nothing
        timed = view_state(model, view, SPEED_RESOLUTION, study.compiled)
        timed_exact_s = time_shading(timed, None, repeats=study.repeats)
        r = table_error_row(timed, "error", "monotone", TABLE1_ENTRIES)
        found["speed"].append(time_row(timed, r, timed_exact_s, 0.0, study.repeats)["speedup"])
    return {"exact_shade_s": exact_s, "points": points}


def _failure_sweep(study: PhongStudy, materials, xs, found: dict, m: int = 200) -> dict:
    """RMS of every table variant against a material parameter (far view), per interpolation."""
    states = [
        view_state(material, "far", study.resolution, study.compiled) for material in materials
    ]
    rms = {}
    for interpolation in never_worse_interpolations():
        for variant in table_variants():
            ys = []
            for state in states:
                r = table_error_row(state, variant.placement, interpolation, m, variant.segments(m))
                found["nonfinite"] += int(not np.isfinite(r["rms"]))
                ys.append(_floor(r["rms"]))
            rms[f"{variant.name} {interpolation}"] = ys
    return {"x": list(xs), "rms": rms}


def _segments_study(study: PhongStudy, found: dict) -> dict:
    """RMS of the importance table (m = 200, t-parabola, far view) against its segment count p.

    On the scenes of Table 1 and the bimodal failure case.
    """
    seg = {}
    for scene in (*table1_scenes(), "bimodal"):
        state = view_state(SCENES.lookup(scene).build(), "far", study.resolution, study.compiled)
        ys = []
        for p in study.divisors:
            r = table_error_row(state, "importance", "parabolic", 200, p)
            found["nonfinite"] += int(not np.isfinite(r["rms"]))
            ys.append(_floor(r["rms"]))
        seg[scene] = ys
    return {"p": list(study.divisors), "rms": seg}


def _failure_modes(study: PhongStudy) -> dict:
    """The paper's failure modes (far view, t-parabola): n ≡ 2000 overshoot, bimodal RMS."""
    n2000 = view_state(SCENES.lookup("n2000").build(), "far", study.resolution, study.compiled)
    bimodal = view_state(SCENES.lookup("bimodal").build(), "far", study.resolution, study.compiled)
    return {
        "n2000_overshoot": table_error_row(n2000, "importance", "parabolic", 200, 200)["overshoot"],
        "importance_rms": [
            table_error_row(bimodal, "importance", "parabolic", m, m)["rms"] for m in (200, 800)
        ],
        "error_rms": [table_error_row(bimodal, "error", "parabolic", m)["rms"] for m in (200, 800)],
    }


def _bench_table(bench: dict) -> list[list]:
    """Rows ``[group, benchmark, min ms, exact / this]`` of the ``phong`` benchmark groups."""
    table_rows = []
    for group, group_records in sorted(bench.items()):
        base = [r for r in group_records if "exact" in r["name"]]
        base_s = base[0]["stats"]["min"] if base else None
        for r in group_records:
            ratio = base_s / r["stats"]["min"] if base_s else float("nan")
            table_rows.append([group, r["name"], r["stats"]["min"] * 1e3, ratio])
    return table_rows


def _speed_source(study: PhongStudy, from_bench: bool) -> str:
    if from_bench:
        return "from benchmark JSON (make bench, 512×512)"
    if study.quick:
        return "not measured in --quick mode without make bench"
    return f"measured in this run at {SPEED_RESOLUTION}×{SPEED_RESOLUTION} (compiled)"


def _scope(study: PhongStudy) -> str:
    if study.quick:
        return (
            f" [quick: {', '.join(study.scenes)} {', '.join(study.views)} only, "
            f"{study.resolution}×{study.resolution}, m in {list(study.ladder)}]"
        )
    return f" [{len(study.scenes) * len(study.views)} rows, {study.resolution}×{study.resolution}]"


def phong_speed_accuracy(
    ctx: ReportContext | None = None, study: PhongStudy | None = None
) -> SectionData:
    """Sweeps of the table methods against the exact render: speed, accuracy, failures, picks.

    Parameters
    ----------
    ctx : ReportContext, optional
        ``ctx.quick`` picks :data:`QUICK` (else :data:`FULL`); ``ctx.bench`` the ``phong``
        benchmark groups, whose speed-ups replace the in-run measurement.
    study : PhongStudy, optional
        Other sizes (e.g. tiny ones for a test).

    Returns
    -------
    SectionData
        ``results``: per ``"<scene> <view>"`` the exact shading time and the ``points`` (variant,
        interpolation, entries, shade_s, rms); the sweeps ``exponent-scale``, ``exponent-spread``
        and ``segments``; ``"tolerance <scene> <view>"`` picks; ``failure_modes``; ``nonfinite``
        (RMS values that are not finite); ``bench`` (with benchmarks) and ``speedups``. ``arrays``:
        ``study``; ``records`` (the rows of ``validation.studies.phong.table_error_row``) and
        ``picks`` that the checks read; ``scope`` (appended to the check names).

    Examples
    --------
    >>> tiny = PhongStudy(8, False, 1, (25,), ("R1",), ("near",), (10,), (50,), (10,), 64, True)
    >>> data = phong_speed_accuracy(study=tiny)
    >>> len(data.results["R1 near"]["points"]), data.results["nonfinite"]
    (16, 0)
    >>> [c.passed for c in checks(data)][-3:]
    [True, True, False]
    """
    study = study or (QUICK if ctx is not None and ctx.quick else FULL)
    bench = ctx.bench_groups("phong") if ctx is not None else {}
    found = {"records": [], "speed": [], "nonfinite": 0, "bench_speed": _bench_speedups(bench)}
    results = {}
    # one task per scene and view (ReportContext.run_tasks: serial, or the report's cluster);
    # each times its exact render and its tables in one process
    benched = bool(found["bench_speed"])
    tasks = [(study, scene, view, benched) for scene in study.scenes for view in study.views]
    run = ctx.run_tasks if ctx is not None else (lambda f, ts, desc: [f(t) for t in ts])
    for (_, scene, view, _), (view_result, part) in zip(
        tasks, run(_speed_accuracy_task, tasks, "phong views"), strict=True
    ):
        results[f"{scene} {view}"] = view_result
        for key in ("records", "speed"):
            found[key] += part[key]
        found["nonfinite"] += part["nonfinite"]
    scales, highs = study.scales, study.highs
    results["exponent-scale"] = _failure_sweep(
        study, [constant_material(float(n)) for n in scales], scales, found
    )
    results["exponent-spread"] = _failure_sweep(
        study, [bimodal_material(5.0, float(h)) for h in highs], highs, found
    )
    results["segments"] = _segments_study(study, found)
    picks = []
    for scene in study.scenes:
        for view in study.views:
            state = view_state(SCENES.lookup(scene).build(), view, study.resolution, study.compiled)
            pick = tolerance_search(state, 0.05, "monotone", max_entries=study.max_entries)
            results[f"tolerance {scene} {view}"] = pick
            picks.append({"scene": scene, "view": view, **pick})
    results["failure_modes"] = _failure_modes(study)
    results["nonfinite"] = found["nonfinite"]
    if bench:
        results["bench"] = _bench_table(bench)
    speed = found["bench_speed"] or found["speed"]
    source = _speed_source(study, bool(found["bench_speed"]))
    results["speedups"] = {"source": source, "values": speed}
    arrays = {"study": study, "records": found["records"], "picks": picks, "scope": _scope(study)}
    return SectionData(results, arrays)


def _pareto_figure(data: SectionData):
    """Speed against accuracy, one log-log panel per scene and view, with the Pareto front."""
    import matplotlib.pyplot as plt

    study = data.arrays["study"]
    scenes, views = study.scenes, study.views
    fig, axes = plt.subplots(
        len(views),
        len(scenes),
        figsize=(3.6 * len(scenes) + 1.6, 3.2 * len(views)),
        squeeze=False,
        layout="constrained",  # no label runs into the next panel's title
    )
    names = [v.name for v in table_variants()]
    markers = dict(zip(names, itertools.cycle(MARKERS), strict=False))
    colours = dict(zip(INTERPOLATION_METHODS.names(), itertools.cycle(COLOURS), strict=False))
    for col, scene in enumerate(scenes):
        for row, view in enumerate(views):
            found = data.results[f"{scene} {view}"]
            points = [(p["shade_s"], p["rms"]) for p in found["points"]]
            ax = axes[row][col]
            for p in found["points"]:
                ax.scatter(
                    p["shade_s"],
                    p["rms"],
                    marker=markers[p["variant"]],
                    c=colours[p["interpolation"]],
                    s=14,
                )
            front = _pareto(points)
            ax.plot([points[i][0] for i in front], [points[i][1] for i in front], "k-", lw=0.8)
            ax.axvline(found["exact_shade_s"], color="grey", ls=":", lw=0.8)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_title(f"{scene} {view}")
            ax.set_xlabel("shading time incl. build (s)")
            ax.set_ylabel("RMS (8-bit)")
    handles = [plt.Line2D([], [], marker=markers[n], ls="", c="k", label=n) for n in names]
    handles += [plt.Line2D([], [], marker="o", ls="", c=c, label=i) for i, c in colours.items()]
    handles += [
        plt.Line2D([], [], c="k", lw=0.8, label="Pareto front"),
        plt.Line2D([], [], c="grey", ls=":", lw=0.8, label="exact shading"),
    ]
    fig.legend(handles=handles, loc="outside right center", fontsize=8)  # beside, not on, the data
    return fig


def _pareto_caption(data: SectionData) -> str:
    """The chart's conclusion from its points: which table is on the Pareto fronts most often."""
    from collections import Counter

    study = data.arrays["study"]
    front = Counter()
    for scene in study.scenes:
        for view in study.views:
            points = data.results[f"{scene} {view}"]["points"]
            for i in _pareto([(p["shade_s"], p["rms"]) for p in points]):
                front[f"{points[i]['variant']}, {points[i]['interpolation']}"] += 1
    if not front:
        return "Speed against accuracy, log-log, Pareto front in black"
    (best, count), total = front.most_common(1)[0], sum(front.values())
    return (
        f"Speed against accuracy (log-log): {best} gives {count} of the {total} points on the "
        f"Pareto fronts (black) of the {len(study.scenes) * len(study.views)} panels"
    )


def _sweep_figure(sweep: dict, xlabel: str, m: int = 200):
    """One panel per interpolation: RMS of every table variant against the swept parameter."""
    import matplotlib.pyplot as plt

    interpolations = never_worse_interpolations()
    fig, axes = plt.subplots(1, len(interpolations), figsize=(13, 3.4))
    names = [v.name for v in table_variants()]
    for ax, interpolation in zip(axes, interpolations, strict=True):
        for name, marker in zip(names, itertools.cycle(MARKERS), strict=False):
            ax.plot(
                sweep["x"], sweep["rms"][f"{name} {interpolation}"], marker=marker, label=name, ms=4
            )
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(xlabel)
        ax.set_ylabel("RMS (8-bit)")
        ax.set_title(f"{interpolation}, m = {m}")
    axes[0].legend(fontsize=7)
    return fig


def sweep_caption(sweep: dict, what: str, unit: str) -> str:
    """A failure sweep's caption from its figures: where the lines end, and which fail.

    ``sweep`` as the failure sweeps give it (``x``, and ``rms`` per "variant interpolation").

    Examples
    --------
    >>> sweep = {"x": [1, 10, 100], "rms": {"uniform linear": [0.1, 1.0, 50.0],
    ...                                     "error monotone": [0.01, 0.01, 0.02]}}
    >>> print(sweep_caption(sweep, "the exponent scale", "n"))
    Where methods fail, against the exponent scale (far view, m = 200): at n = 100 the worst is
    uniform linear (RMS 50, 500× its value at n = 1), the best error monotone (RMS 0.02); 1 of 2
    lines grow more than tenfold
    """
    x, rms = sweep["x"], sweep["rms"]
    last = {name: ys[-1] for name, ys in rms.items()}
    worst, best = max(last, key=last.get), min(last, key=last.get)
    grows = sum(ys[-1] > 10 * ys[0] for ys in rms.values())
    growth = rms[worst][-1] / max(rms[worst][0], 1e-12)
    return (
        f"Where methods fail, against {what} (far view, m = 200): at {unit} = {x[-1]:g} the worst "
        f"is {worst} (RMS {last[worst]:.3g}, {growth:.3g}× its value at {unit} = {x[0]:g}), the "
        f"best {best} (RMS {last[best]:.3g}); {grows} of {len(rms)} lines grow more than tenfold"
    )


def segments_caption(segments: dict) -> str:
    """The segment chart's caption from its figures: the best p per scene against p = m.

    Examples
    --------
    >>> print(segments_caption({"p": [1, 10, 200], "rms": {"R1": [5, 0.5, 2], "R2": [1, 2, 3]}}))
    Importance tables (m = 200, t-parabola) against their segment count p: the best p is 10 for
    R1 (RMS 0.5 against 2 at p = 200), 1 for R2 (RMS 1 against 3)
    """
    ps, parts = segments["p"], []
    for k, (scene, ys) in enumerate(segments["rms"].items()):
        i = int(np.argmin(ys))
        at = f" at p = {ps[-1]:g}" if k == 0 else ""
        parts.append(f"{ps[i]:g} for {scene} (RMS {ys[i]:.3g} against {ys[-1]:.3g}{at})")
    return (
        "Importance tables (m = 200, t-parabola) against their segment count p: the best p is "
        + ", ".join(parts)
    )


def _segments_figure(segments: dict):
    """RMS of the importance table against its segment count p, one line per scene."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 3.6))
    for scene, ys in segments["rms"].items():
        ax.plot(segments["p"], ys, marker="o", ms=4, label=scene)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("segments p (importance, m = 200, t-parabola)")
    ax.set_ylabel("RMS (8-bit)")
    ax.legend(fontsize=7)
    return fig


def _tolerance_table(data: SectionData) -> Table:
    rows = []
    for pick in data.arrays["picks"]:
        verified = "yes" if pick["verified"] else "no"
        rows.append(
            [
                pick["scene"],
                pick["view"],
                pick["placement"],
                pick["entries"],
                pick["verified_rms"],
                verified,
            ]
        )
    return Table(
        ["scene", "view", "placement", "entries", "verified RMS", "meets 0.05"],
        rows,
        "--tolerance 0.05 (monotone): the smallest table, verified on the image",
        "{:.3g}",
    )


def present(ctx: ReportContext, data: SectionData) -> list:
    """The Pareto chart, the failure sweeps, the segment chart, the picks, benchmarks, targets."""
    study, results = data.arrays["study"], data.results
    blocks = [
        Text(
            f"RMS (8-bit, the larger of display and linear) against shading time (build included) "
            f"for every placement, interpolation and m in {list(study.ladder)}, at "
            f"{study.resolution}×{study.resolution}{QUICK_NOTE if study.quick else ''}. "
            "Black line: the Pareto front. `specref phong table1` gives Table 1 at 512×512."
        ),
        ctx.figure("pareto", _pareto_figure(data), _pareto_caption(data)),
        ctx.figure(
            "exponent-scale",
            _sweep_figure(results["exponent-scale"], "exponent n (constant)"),
            sweep_caption(results["exponent-scale"], "a constant exponent", "n"),
        ),
        ctx.figure(
            "exponent-spread",
            _sweep_figure(results["exponent-spread"], "n above 580 nm (n = 5 below)"),
            sweep_caption(
                results["exponent-spread"], "the spread of a bimodal n(λ) (n = 5 below 580 nm)", "n"
            ),
        ),
        ctx.figure(
            "segments", _segments_figure(results["segments"]), segments_caption(results["segments"])
        ),
        _tolerance_table(data),
        Text(f"Non-finite RMS values in all sweeps: {results['nonfinite']} (must be 0)."),
    ]
    if study.figures:
        from validation.studies.phong_figures import paper_figures

        blocks.append(
            Text(
                f"The paper's figures and Table 1 at {study.figures}×{study.figures} "
                "(`specref phong table1 --images DIR` writes them at 512×512)."
            )
        )
        blocks += paper_figures(
            ctx, study.figures, study.compiled, repeats=study.repeats, quick=study.quick
        )
    blocks += editor_blocks(ctx, screenshot=not study.quick)
    if "bench" in results:
        blocks.append(
            Table(
                ["group", "benchmark", "min ms", "exact / this"],
                results["bench"],
                "Benchmarks (make bench), same-run exact baseline",
                "{:.3g}",
            )
        )
    return blocks


def editor_blocks(ctx: ReportContext, screenshot: bool = True) -> list:
    """The material editor (§1, §5, Wang et al.): what it does, and a screenshot of it.

    The screenshot is taken by :func:`phong_table.editor.browser.editor_screenshot` (a server on a
    free port, headless Chromium); without Chromium, or when ``screenshot`` is False (the quick
    report), a line says how to get it.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> with tempfile.TemporaryDirectory() as d:
    ...     blocks = editor_blocks(ReportContext(Path(d)), screenshot=False)
    >>> len(blocks), "specref phong edit" in blocks[0].text
    (2, True)
    """
    import shutil

    from phong_table.editor.app import MAX_SESSIONS
    from phong_table.editor.state import CONTROL_STRIDE, CURVES
    from reference.browser import find_chromium
    from reference.errors import SpecrefError

    curves = ", ".join(label for label, *_ in CURVES.values())
    about = Text(
        "The material editor Wang et al. build their tables for (§1, §5): "
        "`specref phong edit [MATERIAL.toml]` serves a page on 127.0.0.1 with the "
        f"{len(CURVES)} curves ({curves}), each kept whole (the light at its own sampling) and "
        f"edited through control points at every {CONTROL_STRIDE}th wavelength of the grid "
        "(Erratum E28). Every drag re-renders the sphere through the table path; the exact image "
        "follows once the drag ends (Erratum E29), then the RMS and the difference image. It is "
        "built as a local web app: its own Host only, messages as text, saves inside one folder, "
        f"at most {MAX_SESSIONS} pages (docs/phong-tables.md)."
    )
    if not screenshot:
        return [about, Text("The screenshot is in the default report (`specref phong edit "
                            "--screenshot PNG` writes it).")]  # fmt: skip
    if find_chromium() is None or shutil.which("chromedriver") is None:
        return [about, Text("No screenshot: Chromium and chromedriver are not installed here.")]
    from phong_table.editor.browser import editor_screenshot

    rel = f"images/{ctx.section or 'phong'}-editor.png"
    (ctx.out_dir / "images").mkdir(parents=True, exist_ok=True)
    try:
        editor_screenshot(None, ctx.out_dir / rel)
    except SpecrefError as error:
        return [about, Text(f"No screenshot: {str(error).splitlines()[0]}")]
    from PIL import Image as PILImage

    with PILImage.open(ctx.out_dir / rel) as png:
        width, height = png.size
    caption = (
        "The editor after the k_s point at 500 nm was dragged to 0.8 with 50 uniform entries: "
        "the table's highlight departs from the exact one where the difference image is bright"
    )
    return [about, Image(rel, caption, width, height)]


def checks(data: SectionData) -> list[Check]:
    """The targets (``validation.studies.phong_table1.target_checks``) on the section's figures."""
    speedups = data.results["speedups"]
    return target_checks(
        data.arrays["records"],
        data.arrays["picks"],
        data.results["failure_modes"],
        speedups["values"],
        speedups["source"],
        data.arrays["scope"],
    )


def printed_algorithm_ratios(
    results: dict, interpolation: str = "parabolic", entries: int = 200
) -> dict[str, float]:
    """Per Table 1 row: RMS of the paper's algorithm over a uniform table's, same interpolation.

    The algorithm as printed: importance placement with p = m and the parabola in t
    (``parabolic``; ``parabolic_w`` reads it in w, Erratum E19); the uniform table with the same
    interpolation; both at ``entries`` (rows that lack either are left out).

    Examples
    --------
    >>> pts = [{"variant": "importance p=m", "interpolation": "parabolic", "entries": 200,
    ...         "rms": 2.0}, {"variant": "uniform", "interpolation": "parabolic",
    ...         "entries": 200, "rms": 0.01}]
    >>> printed_algorithm_ratios({"R1 far": {"points": pts}, "nonfinite": 0})
    {'R1 far': 200.0}
    """
    ratios = {}
    for row, found in results.items():
        if not (isinstance(found, dict) and "points" in found):
            continue
        rms = {
            p["variant"]: p["rms"]
            for p in found["points"]
            if p["interpolation"] == interpolation and p["entries"] == entries
        }
        if rms.get("uniform", 0.0) > 0.0 and "importance p=m" in rms:
            ratios[row] = float(rms["importance p=m"] / rms["uniform"])
    return ratios


def headlines(data: SectionData) -> list[Headline]:
    """The summary's figures: the error-placed table's accuracy and speed; the tolerance pick."""
    found = checks(data)

    def first(prefix):
        return next(c for c in found if c.name.startswith(prefix))

    rms = first("error/monotone RMS at 200 entries")
    speed = first("shading speed-up")
    pick = first("--tolerance 0.05")
    lines = [
        Headline(
            f"error-placed table, monotone interpolation: RMS {rms.measured:.1e} at 200 entries "
            "(8-bit display, against the exact render)",
            f"target {rms.target}",
        )
    ]
    if isinstance(speed.measured, float | int):
        lines.append(
            Headline(
                f"shading {speed.measured:.1f}× faster than exact, table build included",
                f"target {speed.target}; Table 1 of the paper: about 10×",
            )
        )
    else:
        lines.append(Headline("shading speed-up: measured by `make bench` (not in quick mode)"))
    lines.append(
        Headline(
            f"`--tolerance 0.05` picks a table of {pick.measured:.0f} entries, verified on the "
            "image",
            f"target {pick.target}",
        )
    )
    t, w = (printed_algorithm_ratios(data.results, i) for i in ("parabolic", "parabolic_w"))
    if t and w:
        worse = [r for r in t.values() if r > 1.0]
        lines.append(
            Headline(
                "the paper's algorithm as printed (importance placement p = m, parabola in t) has "
                f"{min(t.values()):.3g}–{max(t.values()):,.0f}× the RMS of a uniform table at 200 "
                f"entries: worse on {len(worse)} of {len(t)} Table 1 rows",
                f"read with the parabola in w (erratum E19): {min(w.values()):.2g}–"
                f"{max(w.values()):.3g}× the uniform table's",
            )
        )
    return lines


SECTION = ReportSection(
    "phong",
    "Spectral Phong tables",
    phong_speed_accuracy,
    present,
    checks,
    headlines=headlines,
    basis="design",  # Table 1's rows and the paper's failure cases
)

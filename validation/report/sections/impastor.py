"""Report section "ImpastoR" (Ferwerda 2015): Table 1, channels, metamers, gloss, lighting, shadows.

compute → :func:`impastor_validation`; present → :func:`present`; checks → :func:`checks`.

Quick mode (``specref report --quick``, :data:`QUICK`) uses the NumPy twins on small problems, so
it needs no JIT warm-up; the full report (:data:`FULL`) uses the numba kernels at the paper's sizes
(512×512 frames); :data:`TINY` runs in seconds, for doctests and tests.
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, field

import numpy as np

from reference.data import data_path
from validation.report import (
    Check,
    Headline,
    ReportContext,
    ReportSection,
    SectionData,
    Table,
    Text,
)

__all__ = [
    "FULL",
    "QUICK",
    "TARGETS",
    "TINY",
    "ImpastorSettings",
    "checks",
    "frame_methods",
    "impastor_validation",
]

#: Our targets for the held-out ColorChecker (mean, max ΔE00 per light, one matrix).
TARGETS = {"box": (0.8, 2.2), "optimized": (0.25, 0.6)}
#: Other targets: metamers (ΔE00 under A below, under D65 above), the hybrid against
#: the better of median cut and FIS, and horizon-map disagreement at every elevation at the
#: renderer's sector count (``impastor.painting.HORIZON_SECTORS``; erratum E95).
METAMER_TARGETS = {"A": 0.5, "D65": 3.0}
HYBRID_LIMIT = 1.1
#: The hybrid on held-out cases (erratum E17): within HYBRID_LIMIT in this share of (case, α)
#: pairs, and never worse than HELD_OUT_MAX times the better method.
HELD_OUT_SHARE = 0.95
HELD_OUT_MAX = 1.5
SHADOW_LIMIT = 0.02
#: The painting images: under these lights, lit by the paper's pipeline (the hybrid, §3.5.2).
PAINTING_LIGHTS = ("D65", "A")
PAINTING_METHOD = "hybrid"
#: A captured room the painting is also shown in (``--light-map``; shipped, CC0).
ROOM_MAP = data_path("environments/st_fagans_interior_1k.hdr")
#: Lights of the naive RGB-product baseline.
NAIVE_LIGHTS = ("D65", "A")


@dataclass(frozen=True)
class ImpastorSettings:
    """Problem sizes of the section's studies (see :data:`QUICK`, :data:`FULL`, :data:`TINY`).

    Attributes
    ----------
    backend : {"numba", "numpy"}
        Kernels, or their NumPy twins (no JIT warm-up: for small problems).
    channel_counts : tuple of int
        Channel counts N of :func:`validation.studies.impastor.channel_count_errors` (6 must be
        one).
    alpha, shadows, gloss, albedo : dict
        Keywords of :func:`validation.studies.impastor_lighting.specular_error_vs_alpha`,
        ``shadow_agreement`` (``HORIZON_SECTORS`` must be among them), ``gloss_validation`` and
        ``ward_duer_albedo``; defaults where empty.
    alpha_painting_size : int or None
        Side of the painting (seed 2) of the error-against-α study; None for the study's own.
    frame_size : int
        Side of the painting images and timed frames, pixels.
    light_resolution : tuple of int
        Booth light image of the frames (width, height).
    every_frame_method : bool
        Time a frame per lighting method, or one per specular estimator (:func:`frame_methods`).
    held_out : dict
        The hybrid's held-out sweep (erratum E17): ``n_paintings`` and ``first_seed`` of
        :func:`validation.studies.impastor_hybrid.held_out_cases`, and keywords of
        ``hybrid_case_ratios``.
    """

    backend: str
    channel_counts: tuple
    alpha: dict = field(default_factory=dict)
    shadows: dict = field(default_factory=dict)
    gloss: dict = field(default_factory=dict)
    albedo: dict = field(default_factory=dict)
    alpha_painting_size: int | None = None
    frame_size: int = 512
    light_resolution: tuple = (128, 64)
    every_frame_method: bool = True
    held_out: dict = field(default_factory=lambda: dict(HELD_OUT_FULL))


#: The held-out sweep (erratum E17) in the full report: painting seeds 201-224 (never used by the
#: design, ``validation.studies.impastor_hybrid.TRAINING``), the report's α grid, 36 points,
#: 64 × 32 lights.
HELD_OUT_FULL = {"n_paintings": 24, "first_seed": 201, "supersample": 6}


#: The full report: the paper's sizes, numba kernels.
FULL = ImpastorSettings("numba", tuple(range(3, 11)), alpha={"supersample": 4})
#: ``specref report --quick``: small problems, NumPy twins.
QUICK = ImpastorSettings(
    "numpy",
    (3, 6, 10),
    alpha=dict(alphas=(0.01, 0.05, 0.2), n_side=3, light_resolution=(32, 16), supersample=2),
    shadows=dict(
        sector_counts=(6, 18, 36),
        size=64,
        n_azimuths=4,
        elevations_deg=(10.0, 30.0, 60.0),
        max_steps=16,
    ),
    gloss=dict(gloss=((0.06, 0.02), (0.06, 0.15)), angles_deg=[6, 7.5, 10, 20]),
    alpha_painting_size=32,
    frame_size=48,
    light_resolution=(32, 16),
    every_frame_method=False,
    held_out=dict(
        n_paintings=2,
        first_seed=201,
        alphas=(0.03, 0.2),
        n_side=3,
        painting_size=32,
        light_resolution=(32, 16),
        supersample=2,
        backend="numpy",
    ),
)
#: Seconds in all (once colour-science is loaded): for doctests and tests, not for the targets.
TINY = ImpastorSettings(
    "numpy",
    (6,),
    alpha=dict(alphas=(0.05,), n_side=2, light_resolution=(16, 8), supersample=1),
    shadows=dict(
        sector_counts=(36,),
        size=16,
        n_azimuths=2,
        elevations_deg=(15.0,),
        max_steps=4,
        fields=(("default", 1.0, 0.0),),
    ),
    gloss=dict(gloss=((0.06, 0.05),), angles_deg=[7.5]),
    albedo=dict(alphas=(0.1,), thetas_deg=(0.0, 60.0)),
    alpha_painting_size=16,
    frame_size=16,
    light_resolution=(16, 8),
    every_frame_method=False,
    held_out=dict(
        n_paintings=1,
        first_seed=201,
        alphas=(0.1,),
        n_side=2,
        painting_size=16,
        light_resolution=(16, 8),
        supersample=1,
        backend="numpy",
    ),
)


# --- compute -------------------------------------------------------------------------------------


def frame_methods(every: bool = True) -> list[str]:
    """Keys of ``impastor.painting.PAINTING_LIGHTING_METHODS`` whose frames the section times.

    Every method, or (``every=False``, quick mode) one per specular estimator: ``variance_min``
    shares ``median_cut``'s, and the :data:`PAINTING_METHOD` frames are the painting images.

    Examples
    --------
    >>> frame_methods(every=False)
    ['median_cut', 'fis']
    """
    from impastor.painting import PAINTING_LIGHTING_METHODS

    if every:
        return PAINTING_LIGHTING_METHODS.names()
    timed = {PAINTING_LIGHTING_METHODS.lookup(PAINTING_METHOD).reference}
    names = []
    for name, method in PAINTING_LIGHTING_METHODS.items():
        if method.reference not in timed:
            timed.add(method.reference)
            names.append(name)
    return names


def _targets_met(channel_table: dict) -> dict:
    # Both targets of each design with targets, under each booth light, six channels.
    from validation.studies.impastor import LIGHTS

    verdicts = {}
    for design, table in channel_table.items():
        if design in TARGETS:
            limit_mean, limit_max = TARGETS[design]
            for light in LIGHTS:
                s = table["6"][light]
                verdicts[f"{design} {light}"] = s["mean"] <= limit_mean and s["max"] <= limit_max
    return verdicts


def _colour_figures(settings: ImpastorSettings) -> SectionData:
    # Table 1, the channel counts against the naive RGB product, metamers.
    from validation.studies import impastor as imp

    channel_table = imp.channel_count_errors(counts=settings.channel_counts)
    naive = {light: imp.naive_rgb_delta_E(light) for light in NAIVE_LIGHTS}
    results = {
        "table1": imp.table1(),
        "channels": channel_table,
        "targets_met": _targets_met(channel_table),
        "naive_rgb": {
            k: {"mean": float(v.mean()), "max": float(v.max())} for k, v in naive.items()
        },
        "metamers": imp.metamer_delta_E(),
    }
    return SectionData(results, {"naive_rgb": naive})


def _hybrid_over_best(alpha: dict) -> np.ndarray:
    # The hybrid's error over the better of median cut and FIS, per α.
    return np.asarray(alpha["hybrid"]) / np.minimum(alpha["median_cut"], alpha["fis"])


def _lighting_figures(settings: ImpastorSettings) -> dict:
    # Error against α, horizon-map shadows, gloss curves, the display round trip, the albedo.
    from impastor.painting import impasto_painting
    from validation.studies import impastor as imp
    from validation.studies import impastor_lighting as lit

    backend = settings.backend
    options = dict(settings.alpha)
    if settings.alpha_painting_size is not None:
        options["painting"] = impasto_painting(settings.alpha_painting_size, seed=2)
    alpha = lit.specular_error_vs_alpha(**options, backend=backend)
    return {
        "error_vs_alpha": {
            **alpha,
            "worst_hybrid_over_best": float(_hybrid_over_best(alpha).max()),
        },
        "shadows": lit.shadow_agreement(**settings.shadows, backend=backend),
        "gloss": lit.gloss_validation(**settings.gloss, backend=backend),
        "display_round_trip": imp.display_round_trip(),
        "ward_duer_albedo": lit.ward_duer_albedo(**settings.albedo),
    }


def _held_out_task(task) -> dict:
    # one held-out case (a task of ReportContext.run_tasks)
    from validation.studies.impastor_hybrid import hybrid_case_ratios

    case, options = task
    return hybrid_case_ratios(case, **options)


def _held_out_figures(settings: ImpastorSettings, run) -> dict:
    """The hybrid over the better method on cases the design never saw (erratum E17), per case."""
    from validation.studies.impastor_hybrid import held_out_cases, ratio_distribution

    options = dict(settings.held_out)
    cases = held_out_cases(options.pop("n_paintings"), options.pop("first_seed"))
    found = run(_held_out_task, [(case, options) for case in cases], "held-out hybrid cases")
    ratios = [r for f in found for r in f["ratio"]]
    worst_case, worst_alpha, worst_ratio = max(
        ((case.name, a, r) for case, f in zip(cases, found, strict=True)
         for a, r in zip(f["alpha"], f["ratio"], strict=True)),
        key=lambda x: x[2],
    )  # fmt: skip
    return {
        "cases": [case.name for case in cases],
        "per_case": found,
        "distribution": ratio_distribution(ratios),
        "worst": {"case": worst_case, "alpha": worst_alpha, "ratio": worst_ratio},
    }


def _ceiling_contrast(resolution) -> dict:
    """Peak over mean luminance of the booth's ceiling and of the captured room seen through it."""
    from impastor.painting import booth_plane_light, booth_plane_light_from_map

    ratio = {}
    for name, plane in (
        ("booth", booth_plane_light("fluorescent", *resolution)),
        ("room", booth_plane_light_from_map(ROOM_MAP, *resolution)),
    ):
        ratio[name] = float(plane.image.max() / plane.image.mean())
    return ratio


def _frame_figures(settings: ImpastorSettings, spectra: dict) -> SectionData:
    # The painting under each booth light, then one timed frame per lighting method (the horizon
    # map, computed once per height field, is cached by the painting images).
    from impastor.painting import impasto_painting, render_painting

    size = settings.frame_size
    painting = impasto_painting(size, seed=1)

    def render(light, method, n_channels=6, light_map=None):
        return render_painting(
            light,
            size,
            method,
            painting,
            spectra=spectra,
            light_resolution=settings.light_resolution,
            backend=settings.backend,
            n_channels=n_channels,
            light_map=light_map,
        )

    data = SectionData(arrays={"painting": {}, "frame_stages": {}})
    for light in PAINTING_LIGHTS:
        start = time.perf_counter()
        data.arrays["painting"][light] = render(light, PAINTING_METHOD)["sRGB"]
        data.results[f"painting_{light}_seconds"] = time.perf_counter() - start
    data.arrays["painting_room"] = render("D65", PAINTING_METHOD, light_map=ROOM_MAP)["sRGB"]
    data.results["room_ceiling"] = _ceiling_contrast(settings.light_resolution)
    for method in frame_methods(settings.every_frame_method):
        seconds = render("D65", method)["seconds"]
        data.arrays["frame_stages"][method] = seconds
        data.results[f"frame_seconds_{method}"] = sum(seconds.values())
    # speed against accuracy of the channel count: the same frame at each count (the error is the
    # ColorChecker's, per count, in "channels")
    data.results["channel_frame_seconds"] = {
        str(n): sum(render("D65", PAINTING_METHOD, int(n))["seconds"].values())
        for n in settings.channel_counts
    }
    return data


def impastor_validation(
    ctx: ReportContext | None = None, settings: ImpastorSettings | None = None
) -> SectionData:
    """Table 1, channel counts, metamers, lighting errors, shadows, gloss and frame times.

    Parameters
    ----------
    ctx : ReportContext, optional
        Its ``quick`` flag picks :data:`QUICK` or :data:`FULL` (default :data:`QUICK`).
    settings : ImpastorSettings, optional
        Overrides ``ctx``.

    Returns
    -------
    SectionData
        ``results``: ``table1``, ``channels`` (``[design][N][light]`` ΔE00 statistics),
        ``targets_met``, ``naive_rgb``, ``metamers``, ``error_vs_alpha``, ``held_out_hybrid``
        (the hybrid on held-out cases, run through ``ctx.run_tasks``), ``shadows``, ``gloss``,
        ``display_round_trip``, ``ward_duer_albedo``, ``painting_<light>_seconds``,
        ``frame_seconds_<method>``, ``channel_frame_seconds`` (the hybrid's D65 frame per channel
        count); ``arrays``: ``naive_rgb`` (per-patch ΔE00), ``painting``
        (encoded sRGB images), ``frame_stages`` (seconds per stage), ``settings``.

    Raises
    ------
    SpecrefError
        When the shared measured spectra are missing (before anything is computed).

    Examples
    --------
    >>> data = impastor_validation(settings=TINY)
    >>> len(checks(data)), data.arrays["painting"]["A"].shape
    (21, (16, 16, 3))
    >>> sorted(k for k in data.results if k.startswith("frame_seconds"))
    ['frame_seconds_fis', 'frame_seconds_median_cut']
    """
    from impastor.painting import load_paint_spectra

    if settings is None:
        settings = FULL if ctx is not None and not ctx.quick else QUICK
    spectra = load_paint_spectra()  # fails first, with a clear message, without shared data
    colour = _colour_figures(settings)
    lighting = _lighting_figures(settings)
    run = ctx.run_tasks if ctx is not None else (lambda f, tasks, desc: [f(t) for t in tasks])
    lighting["held_out_hybrid"] = _held_out_figures(settings, run)
    frames = _frame_figures(settings, spectra)
    return SectionData(
        {**colour.results, **lighting, **frames.results},
        {**colour.arrays, **frames.arrays, "settings": settings},
    )


# --- present -------------------------------------------------------------------------------------


def _stats_cells(stats):
    if stats is None:
        return [float("nan")] * 4
    return [stats["mean"], stats["std"], stats["p90"], stats["max"]]


def _table1_blocks(result) -> list:
    rows = [
        [row["label"], *_stats_cells(row["simulation"]), *_stats_cells(row["screen"])]
        for row in result["rows"]
    ]
    gamut = "; ".join(
        f"{light}: {len(info['out_of_gamut'])} ({', '.join(info['out_of_gamut']) or 'none'})"
        for light, info in result["lights"].items()
    )
    return [
        Table(
            [
                "light (patches)",
                *("sim mean", "sim std", "sim 90th", "sim max"),
                *("screen mean", "screen std", "screen 90th", "screen max"),
            ],
            rows,
            f"Table 1: CIEDE2000 against the 5 nm spectral truth ({result['n_channels']}-channel "
            f"{result['design']} design; screen output through the virtual display at "
            f"{result['white_luminance_cd_m2']:g} cd/m² white)",
            "{:.2f}",
        ),
        Text(f"Out-of-gamut patches on the virtual display: {gamut}."),
    ]


def _channel_rows(results: dict, naive: dict) -> list:
    rows = []
    for design, table in results["channels"].items():
        for light, s in table["6"].items():
            target = ""
            if f"{design} {light}" in results["targets_met"]:
                ok = results["targets_met"][f"{design} {light}"]
                limit_mean, limit_max = TARGETS[design]
                target = f"≤ {limit_mean} / ≤ {limit_max}: {'met' if ok else 'MISSED'}"
            rows.append([design, light, s["mean"], s["p90"], s["max"], target])
    for light, dE in naive.items():
        stats = (float(dE.mean()), float(np.percentile(dE, 90)), float(dE.max()))
        rows.append(["naive RGB", light, *stats, "none"])
    return rows


def _channel_blocks(ctx, results: dict, naive: dict) -> list:
    import matplotlib.pyplot as plt

    blocks = [
        Table(
            ["design", "light", "mean ΔE00", "p90", "max", "target (mean / max)"],
            _channel_rows(results, naive),
            "Six channels on the held-out ColorChecker N Ohta (fit: D65, D50, A; FL2 and LED-B3 "
            "are outside the fit)",
            "{:.3f}",
        )
    ]
    channel_table = results["channels"]
    fig, (ax, ax_time) = plt.subplots(
        1, 2, figsize=(10, 3.6), width_ratios=(3, 2), constrained_layout=True
    )
    for design, style in zip(channel_table, itertools.cycle(("--", "-", ":", "-.")), strict=False):
        counts = sorted(int(n) for n in channel_table[design])
        for light, colour in (("D65", "tab:blue"), ("A", "tab:orange"), ("FL2", "tab:green")):
            means = [channel_table[design][str(n)][light]["mean"] for n in counts]
            ax.plot(counts, means, style, color=colour, marker="o", label=f"{design}, {light}")
    ax.set_yscale("log")
    ax.set_xlabel("channels N")
    ax.set_ylabel("mean ΔE00 (ColorChecker)")
    ax.legend(fontsize=7, ncol=2)
    ax.grid(alpha=0.3)
    optimized = channel_table["optimized"]
    fewest = str(min(int(n) for n in optimized))
    six = {light: optimized["6"][light]["mean"] for light in ("D65", "A")}
    few = {light: optimized[fewest][light]["mean"] for light in ("D65", "A")}
    caption = (
        "ColorChecker error against the channel count: six optimized channels bring the mean "
        f"ΔE00 from {few['D65']:.2f} (D65) and {few['A']:.2f} (A) with {fewest} channels to "
        f"{six['D65']:.2f} and {six['A']:.2f}"
    )
    times = results.get("channel_frame_seconds")
    if times:
        counts = sorted(times, key=int)
        ax_time.plot([int(n) for n in counts], [times[n] for n in counts], "o-", color="k")
        ax_time.set_ylim(0, 1.2 * max(times.values()))
        ax_time.set_xlabel("channels N")
        ax_time.set_ylabel("frame time, s (D65, hybrid)")
        ax_time.grid(alpha=0.3)
        growth = times[counts[-1]] / times[counts[0]]
        verdict = (
            "the channels cost little: the achromatic specular sampling is the frame's cost"
            if growth <= 1.25
            else f"the frame's time grows {growth:.2g}× from {counts[0]} to {counts[-1]} channels"
        )
        caption += (
            f"; right: the painting's frame takes {times[counts[0]]:.2g} s with {counts[0]} "
            f"channels, {times.get('6', float('nan')):.2g} s with 6 and {times[counts[-1]]:.2g} s "
            f"with {counts[-1]} (one run each): {verdict}"
        )
    else:
        ax_time.set_axis_off()
    blocks.append(ctx.figure("channels", fig, caption))
    return blocks


def _metamer_blocks(ctx, result) -> list:
    from reference.colour.colorimetry import XYZ_to_display_RGB
    from reference.display.encodings import linear_to_display

    rows = [[light, r["pipeline"], r["truth"]] for light, r in result.items() if light != "image"]
    image = np.zeros((40, 80, 3))
    for k, light in enumerate(("A", "D65")):
        XYZ = np.asarray(result[light]["XYZ"])
        rgb = linear_to_display(XYZ_to_display_RGB(XYZ / 1.25), "srgb")
        image[k * 20 : (k + 1) * 20, :40] = rgb[0]
        image[k * 20 : (k + 1) * 20, 40:] = rgb[1]
    return [
        Table(
            ["light", "ΔE00 rendered (6 channels)", "ΔE00 true (5 nm)"],
            rows,
            "Metamers (Fig. 4): two reflectances that match under A, not under D65",
            "{:.3f}",
        ),
        ctx.image(
            "metamers",
            image,
            f"Metamer pair rendered under A (top: ΔE00 {result['A']['pipeline']:.2f}, a match) and "
            f"D65 (bottom: ΔE00 {result['D65']['pipeline']:.1f}, two colours)",
        ),
    ]


def _alpha_caption(result) -> str:
    """The α chart's conclusion, from its figures: where FIS beats median cut, and the hybrid."""
    alpha = np.asarray(result["alpha"], dtype=float)
    fis_wins = np.asarray(result["fis"]) < np.asarray(result["median_cut"])
    ratio = _hybrid_over_best(result)
    if fis_wins.all() or not fis_wins.any():
        who = "FIS" if fis_wins.all() else "median cut"
        where = f"{who} is the better method at every α"
    else:
        edges = alpha[np.flatnonzero(np.diff(fis_wins.astype(int)))]
        side = "below" if fis_wins[0] else "above"
        where = f"FIS beats median cut {side} α ≈ {edges[0]:.2g}"
    return (
        f"Specular error against roughness, against the brute-force integral: {where}; the "
        f"hybrid stays within {ratio.max():.2f}× of the better one (worst α "
        f"{alpha[int(np.argmax(ratio))]:g})"
    )


def _alpha_blocks(ctx, result) -> list:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 3.5))
    for key, label in (
        ("median_cut", "median cut (32 lights)"),
        ("fis", "FIS (32 samples)"),
        ("hybrid", "hybrid"),
    ):
        ax.plot(result["alpha"], result[key], marker="o", label=label)
    ax.plot(result["alpha"], result["reference_error"], ":", color="gray", label="reference")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("roughness α")
    ax.set_ylabel("relative RMS error")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    columns = ("alpha", "median_cut", "fis", "hybrid")
    rows = [
        [*values, ratio, share]
        for *values, ratio, share in zip(
            *(result[k] for k in columns),
            _hybrid_over_best(result),
            result["fis_share"],
            strict=True,
        )
    ]
    return [
        ctx.figure("alpha", fig, _alpha_caption(result)),
        Table(
            ["α", "median cut", "FIS", "hybrid", "hybrid / best", "FIS share"],
            rows,
            f"Relative RMS specular error over the painting (target: hybrid / best ≤ "
            f"{HYBRID_LIMIT:g})",
            "{:.4g}",
        ),
    ]


def _held_out_blocks(ctx, result) -> list:
    import matplotlib.pyplot as plt

    d, worst = result["distribution"], result["worst"]
    ratios = np.sort([r for f in result["per_case"] for r in f["ratio"]])
    fig, ax = plt.subplots(figsize=(6.5, 3.2))
    ax.step(ratios, np.arange(1, ratios.size + 1) / ratios.size, where="post", label="hybrid")
    for limit, style in ((HYBRID_LIMIT, "--"), (HELD_OUT_MAX, ":")):
        ax.axvline(limit, color="gray", linestyle=style, label=f"{limit:g}×")
    ax.set_xscale("log")
    ax.set_xlabel("hybrid error / better of median cut and FIS")
    ax.set_ylabel("share of (case, α) pairs")
    ax.legend(fontsize=8)
    caption = (
        f"{len(result['cases'])} held-out cases, {d['n']} (case, α) pairs: "
        f"{100 * d['share_within_1.1']:.1f} % within {HYBRID_LIMIT:g}× of the better method "
        f"(target ≥ {100 * HELD_OUT_SHARE:g} %), {100 * d['share_within_1.5']:.1f} % within "
        f"{HELD_OUT_MAX:g}×; worst {worst['ratio']:.2f}× ({worst['case']}, α = {worst['alpha']:g})"
    )
    rows = [
        [name, f["alpha"][int(np.argmax(f["ratio"]))], max(f["ratio"]), min(f["ratio"])]
        for name, f in zip(result["cases"], result["per_case"], strict=True)
    ]
    return [
        ctx.figure("held-out-hybrid", fig, caption),
        Table(
            ["held-out case", "worst α", "worst ratio", "best ratio"],
            rows,
            "The hybrid on cases the design never saw (erratum E17; painting seeds from "
            "validation.studies.impastor_hybrid.held_out_cases)",
            "{:.3g}",
        ),
    ]


def _shadow_blocks(ctx, result) -> list:
    import matplotlib.pyplot as plt

    from impastor.painting import HORIZON_SECTORS

    elevations, sectors = result["elevation_deg"], result["sectors"]
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.4))
    for label in result["fields"]:
        rows = np.asarray(result["disagreement"][label])
        line = axes[0].plot(elevations, 100 * rows[sectors.index(HORIZON_SECTORS)], marker="o",
                            label=f"{label}, {HORIZON_SECTORS} sectors")[0]  # fmt: skip
        axes[0].plot(elevations, 100 * np.asarray(result["one_pixel_steps"][label]), ":",
                     color=line.get_color(), label=f"{label}, first version")  # fmt: skip
        axes[1].plot(result["images"], 100 * rows.max(axis=1), marker="o", label=label)
    for ax in axes:
        ax.axhline(100 * SHADOW_LIMIT, color="gray", ls="--", lw=0.8)
        ax.set_ylabel("pixels that disagree, %")
        ax.grid(alpha=0.3)
    axes[0].set_xlabel("light elevation, degrees")
    axes[1].set_xlabel("three-channel images stored (S / 3)")
    axes[0].legend(fontsize=6)
    axes[1].legend(fontsize=7)
    rows = [
        [label, e, 100 * result["reference_error"][label][k],
         *(100 * np.asarray(result["disagreement"][label])[:, k])]
        for label in result["fields"] for k, e in enumerate(elevations)
    ]  # fmt: skip
    return [
        ctx.figure(
            "shadows",
            fig,
            "Horizon map vs ray-marched shadows per light elevation (left: the renderer's sectors, "
            "and dotted the first version: one-pixel steps, no interpolation; right: worst "
            "elevation against storage)",
        ),
        Table(
            ["field", "elevation °", "reference's own error %", *(f"S={S} %" for S in sectors)],
            rows,
            f"Pixels that disagree, per elevation ({result['step']:g}-pixel march; the "
            "reference's own error is its march against one with half the step)",
            "{:.3g}",
        ),
    ]


def _gloss_blocks(ctx, result) -> list:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 3.5))
    for sample in result["samples"]:
        line = ax.plot(result["angles_deg"], sample["reference"], lw=2, alpha=0.5)[0]
        ax.plot(
            result["angles_deg"],
            sample["pipeline"],
            "o",
            ms=3,
            color=line.get_color(),
            label=f"ρ_s {sample['rho_s']:g}, α {sample['alpha']:g}",
        )
    ax.set_yscale("log")
    ax.set_xlabel("detector angle from the normal, degrees")
    ax.set_ylabel("luminance, cd/m²")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    rows = [[s["rho_s"], s["alpha"], s["max_relative_error"]] for s in result["samples"]]
    return [
        ctx.figure(
            "gloss",
            fig,
            "Gloss validation (Fig. 15): the pipeline (dots) follows the brute force (lines) "
            f"within {100 * max(r[2] for r in rows):.2g} % on {len(rows)} glosses",
        ),
        Table(["ρ_s", "α", "max relative error"], rows, "Goniometric curves", "{:.4g}"),
    ]


def _frame_blocks(ctx, data: SectionData) -> list:
    settings = data.arrays["settings"]
    size = settings.frame_size
    blocks = []
    for light, image in data.arrays["painting"].items():
        blocks.append(
            ctx.image(
                f"painting-{light}",
                image,
                f"Demo painting under the booth light, {light}: the whole {size}×{size} frame "
                "that `specref impastor render` writes, the canvas seen from the booth's viewer",
            )
        )
    if "painting_room" in data.arrays:
        contrast = data.results["room_ceiling"]
        blocks.append(
            ctx.image(
                "painting-room",
                data.arrays["painting_room"],
                f"Demo painting lit by a captured room ({ROOM_MAP.name} seen through the booth's "
                f"ceiling, `--light-map`; D65 lamp, the booth's illuminance at the centre): its "
                f"ceiling peaks at {contrast['room']:.3g}× its mean against the booth's "
                f"{contrast['booth']:.3g}×, so the gloss shows the room's few bright sources",
            )
        )
    rows = [
        [method, size, s["shadows"], s["diffuse"], s["specular"], sum(s.values())]
        for method, s in data.arrays["frame_stages"].items()
    ]
    blocks.append(
        Table(
            ["specular lighting", "size", "shadows s", "diffuse s", "specular s", "frame s"],
            rows,
            f"Frame time ({settings.backend} backend; G-buffer and materials excluded; the horizon "
            "map is computed once per height field, before these frames; one shared core)",
            "{:.3g}",
        )
    )
    for group, records in sorted(ctx.bench_groups("impastor").items()):
        rows = [[r["name"], r["stats"]["mean"]] for r in records]
        blocks.append(Table(["benchmark", "mean s"], rows, f"make bench: {group}", "{:.4g}"))
    return blocks


def present(ctx: ReportContext, data: SectionData) -> list:
    """Tables, charts and images of each study, the painting, frame times and benchmarks."""
    results = data.results
    return [
        Text(
            "ImpastoR (Ferwerda 2015): six-channel colour, Ward–Dür gloss under booth-ceiling "
            "lights (median cut, filtered importance sampling and a per-pixel hybrid), horizon-map "
            "shadows and a characterised display. See docs/impastor.md."
        ),
        *_table1_blocks(results["table1"]),
        *_channel_blocks(ctx, results, data.arrays["naive_rgb"]),
        *_metamer_blocks(ctx, results["metamers"]),
        *_alpha_blocks(ctx, results["error_vs_alpha"]),
        *_held_out_blocks(ctx, results["held_out_hybrid"]),
        *_shadow_blocks(ctx, results["shadows"]),
        *_gloss_blocks(ctx, results["gloss"]),
        *_frame_blocks(ctx, data),
    ]


# --- checks --------------------------------------------------------------------------------------


def _colour_checks(channel_table: dict, metamers: dict) -> list:
    from validation.studies.impastor import LIGHTS

    found = []
    for design, (limit_mean, limit_max) in TARGETS.items():
        for light in LIGHTS:
            s = channel_table[design]["6"][light]
            name = f"{design} 6 channels, ColorChecker under {light}"
            found.append(
                Check(f"{name}, mean ΔE00", f"<= {limit_mean}", s["mean"], s["mean"] <= limit_mean)
            )
            found.append(
                Check(f"{name}, max ΔE00", f"<= {limit_max}", s["max"], s["max"] <= limit_max)
            )
    a, d65 = metamers["A"]["pipeline"], metamers["D65"]["pipeline"]
    limit_a, limit_d65 = METAMER_TARGETS["A"], METAMER_TARGETS["D65"]
    found.append(Check("metamers rendered under A, ΔE00", f"< {limit_a}", a, a < limit_a))
    found.append(Check("metamers rendered under D65, ΔE00", f"> {limit_d65}", d65, d65 > limit_d65))
    return found


def _lighting_checks(alpha: dict, shadows: dict) -> list:
    from impastor.painting import HORIZON_SECTORS

    ratio = _hybrid_over_best(alpha)
    worst = int(np.argmax(ratio))
    row = shadows["sectors"].index(HORIZON_SECTORS)
    worst_share, where = max(
        (value, (label, e))
        for label in shadows["fields"]
        for value, e in zip(shadows["disagreement"][label][row], shadows["elevation_deg"],
                            strict=True)
    )  # fmt: skip
    return [
        Check(
            f"hybrid / better of median cut and FIS, worst α ({alpha['alpha'][worst]:g})",
            f"<= {HYBRID_LIMIT} at every α",
            float(ratio[worst]),
            bool(ratio.max() <= HYBRID_LIMIT),
        ),
        Check(
            f"horizon map ({HORIZON_SECTORS} sectors) vs ray-marched shadows, pixels that "
            f"disagree at the worst field and elevation ({where[0]}, {where[1]:g}°)",
            f"<= {100 * SHADOW_LIMIT:g} % at every elevation",
            f"{100 * worst_share:.3g} %",
            worst_share <= SHADOW_LIMIT,
        ),
    ]


def _bound_checks(round_trip: dict, albedo: dict) -> list:
    mismatches = round_trip["counts_mismatches"]
    over = round_trip["XYZ_error_over_bound"]
    within = all(a - e <= 1.0 for a, e in zip(albedo["albedo"], albedo["error"], strict=True))
    return [
        Check(
            "display round trip counts → XYZ → counts, mismatches",
            f"0 of {round_trip['n_counts']}",
            mismatches,
            mismatches == 0,
        ),
        Check(
            "display round trip XYZ → counts → XYZ, error / one 11-bit LUT step",
            "<= 1",
            over,
            over <= 1.0,
        ),
        Check(
            f"Ward–Dür white-furnace albedo (ρ_s = 1), max over α and θ_i ≤ "
            f"{max(albedo['theta_deg']):g}°",
            "<= 1",
            max(albedo["albedo"]),
            within,
        ),
    ]


def checks(data: SectionData) -> list[Check]:
    """One check per target, from ``data.results`` alone.

    Six channels on the ColorChecker (:data:`TARGETS`, per design and booth light), metamers,
    the hybrid against the better of median cut and FIS at every α, horizon-map shadows at every
    elevation at the renderer's sector count, the display round trips, and the Ward–Dür
    white-furnace albedo (within its error).

    Examples
    --------
    >>> six = {"6": {x: {"mean": 0.2, "max": 0.5} for x in ("D65", "D50", "A")}}
    >>> trip = {"counts_mismatches": 0, "n_counts": 4, "XYZ_error_over_bound": 0.5}
    >>> results = {
    ...     "channels": {design: six for design in TARGETS},
    ...     "metamers": {"A": {"pipeline": 0.1}, "D65": {"pipeline": 4.0}},
    ...     "error_vs_alpha": {"alpha": [0.1], "median_cut": [1], "fis": [0.1], "hybrid": [0.12]},
    ...     "shadows": {"sectors": [36], "fields": ["default"], "elevation_deg": [10.0],
    ...                 "disagreement": {"default": [[0.01]]}},
    ...     "display_round_trip": trip,
    ...     "ward_duer_albedo": {"albedo": [0.99], "error": [1e-4], "theta_deg": [60.0]},
    ... }
    >>> [c.name for c in checks(SectionData(results)) if not c.passed]
    ['hybrid / better of median cut and FIS, worst α (0.1)']
    """
    r = data.results
    return [
        *_colour_checks(r["channels"], r["metamers"]),
        *_lighting_checks(r["error_vs_alpha"], r["shadows"]),
        *_held_out_checks(r.get("held_out_hybrid")),
        *_bound_checks(r["display_round_trip"], r["ward_duer_albedo"]),
    ]


def _held_out_checks(result) -> list:
    if result is None:
        return []
    d, worst = result["distribution"], result["worst"]
    pairs = f"{d['n']} held-out (case, α) pairs"
    return [
        Check(
            f"hybrid within {HYBRID_LIMIT:g}× of the better method, share of {pairs}",
            f">= {100 * HELD_OUT_SHARE:g} %",
            f"{100 * d['share_within_1.1']:.1f} %",
            d["share_within_1.1"] >= HELD_OUT_SHARE,
            "held out",
        ),
        Check(
            f"hybrid / better method, worst of {pairs} ({worst['case']}, α = {worst['alpha']:g})",
            f"<= {HELD_OUT_MAX:g}",
            float(worst["ratio"]),
            worst["ratio"] <= HELD_OUT_MAX,
            "held out",
        ),
    ]


def _six_channel_headline(six: dict) -> Headline:
    """The six optimized channels' headline, with the lights the targets check.

    The worst mean of the lights they were designed for, then each light outside the fit with its
    own figure.
    """
    from validation.studies.impastor import LIGHTS

    worst = max(six[light]["mean"] for light in LIGHTS)
    others = "".join(
        f"; {six[light]['mean']:.2f} under {light} (outside the fit)"
        for light in six
        if light not in LIGHTS
    )
    return Headline(
        f"six optimized channels render the ColorChecker within mean ΔE00 {worst:.2f} under the "
        f"booth lights they were designed for ({', '.join(LIGHTS)}){others}",
        f"target ≤ {TARGETS['optimized'][0]} under {', '.join(LIGHTS)}",
    )


def headlines(data: SectionData) -> list[Headline]:
    """The summary's figures: six channels, the metamers, and the horizon shadows."""
    r = data.results
    a, d65 = r["metamers"]["A"]["pipeline"], r["metamers"]["D65"]["pipeline"]
    found = checks(data)
    shadows = next(c for c in found if c.name.startswith("horizon map"))
    hybrid = next(c for c in found if c.name.startswith("hybrid"))
    held_out = r.get("held_out_hybrid")
    lines = [
        _six_channel_headline(r["channels"]["optimized"]["6"]),
        Headline(
            f"a metameric pair matches under A (ΔE00 {a:.2f}) and splits under D65 ({d65:.1f})",
            "the paper's demonstration of why six channels",
        ),
        Headline(
            f"horizon-map shadows disagree with ray marching on {shadows.measured} of pixels at "
            f"the worst elevation; the hybrid is {hybrid.measured:.2f}× the better lighting "
            "method at its worst α",
            f"targets {shadows.target}; {hybrid.target}",
        ),
    ]
    if held_out is not None:
        d = held_out["distribution"]
        lines.append(
            Headline(
                f"on {d['n']} held-out (case, α) pairs the hybrid is within {HYBRID_LIMIT:g}× of "
                f"the better method in {100 * d['share_within_1.1']:.1f} % (worst "
                f"{d['max']:.2f}×)",
                f"target ≥ {100 * HELD_OUT_SHARE:g} %, never above {HELD_OUT_MAX:g}×",
            )
        )
    return lines


SECTION = ReportSection(
    "impastor",
    "ImpastoR",
    impastor_validation,
    present,
    checks,
    headlines=headlines,
    hero="painting-D65",
    default_effort="quick",  # the full settings take minutes: specref report --full
    basis="design",  # the built-in painting and lights; the held-out cases say so
)

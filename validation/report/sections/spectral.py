"""Report section "Spectral core": ColorChecker accuracy of the band weights (2 grids, 4 lights).

compute → :func:`colorchecker_band_weights`; present → :func:`present`; checks → :func:`checks`.
"""

from __future__ import annotations

import numpy as np

from reference.colour.spectra import GRID_31, GRID_41
from validation.report import (
    Check,
    Headline,
    ReportContext,
    ReportSection,
    SectionData,
    Table,
    Text,
)
from validation.studies.metrics import COLORCHECKER, colorchecker_delta_E, delta_E_stats

LIGHTS = ("D65", "A", "D50", "FL2")
GRIDS = (GRID_41, GRID_31)
BAND_WEIGHTS = ("astm_e308", "point")
# Our targets for the band weights of erratum E7: ΔE00 against the 5 nm truth, (mean, max), for
# the shipped E308 weights.
TARGETS = {"D65": (0.03, 0.10), "A": (0.03, 0.10), "D50": (0.03, 0.10), "FL2": (0.06, 0.15)}


def colorchecker_band_weights(ctx: ReportContext | None = None) -> SectionData:
    """ΔE00 of the ColorChecker per grid, light and band-weight method, against the 5 nm truth.

    Returns
    -------
    SectionData
        ``results["<grid> <light> <method>"]``: ΔE00 statistics (mean, p90, max, ...);
        ``arrays[(grid label, light, method)]``: the 24 per-patch ΔE00.

    Examples
    --------
    >>> data = colorchecker_band_weights()
    >>> round(data.results["380-780/10 FL2 point"]["mean"], 1)
    4.0
    """
    data = SectionData()
    for grid in GRIDS:
        for light in LIGHTS:
            for method in BAND_WEIGHTS:
                dE = colorchecker_delta_E(grid, light, method)
                data.results[f"{grid.label} {light} {method}"] = delta_E_stats(dE)
                data.arrays[(grid.label, light, method)] = dE
    return data


def present(ctx: ReportContext, data: SectionData) -> list:
    """The statistics table and the per-patch chart under FL2."""
    import colour
    import matplotlib.pyplot as plt

    rows = []
    for grid in GRIDS:
        for light in LIGHTS:
            for method in BAND_WEIGHTS:
                stats = data.results[f"{grid.label} {light} {method}"]
                rows.append([grid.label, light, method, stats["mean"], stats["p90"], stats["max"]])
    blocks = [
        Text(
            "ColorChecker (N Ohta) under four lights: specref's band weights (ASTM E2022 factors "
            "with E308 end-band folding, light folded in) against colour-science's 5 nm "
            "computation, in CIEDE2000 relative to the true white. `point` samples light × CMF at "
            "the grid nodes: it misses FL2's mercury lines."
        ),
        Table(
            ["grid", "light", "weights", "mean ΔE00", "p90 ΔE00", "max ΔE00"],
            rows,
            "ColorChecker accuracy against the 5 nm truth",
            "{:.3f}",
        ),
    ]
    names = list(colour.SDS_COLOURCHECKERS[COLORCHECKER])
    fig, ax = plt.subplots(figsize=(9, 3.6))
    x = np.arange(len(names))
    for offset, method in ((-0.2, "astm_e308"), (0.2, "point")):
        ax.bar(x + offset, data.arrays[(GRID_41.label, "FL2", method)], width=0.4, label=method)
    ax.set_yscale("log")
    ax.set_xticks(x, names, rotation=60, ha="right", fontsize=8)
    ax.set_ylabel("ΔE00 under FL2 (41 bands)")
    ax.legend(ncol=2, loc="lower center", bbox_to_anchor=(0.5, 1.0), frameon=False)
    folded = np.asarray(data.arrays[(GRID_41.label, "FL2", "astm_e308")])
    sampled = np.asarray(data.arrays[(GRID_41.label, "FL2", "point")])
    worst = int(np.argmax(sampled))
    caption = (
        f"Under FL2 on the 41-band grid, point sampling is worse than the folded weights on "
        f"{int((sampled > folded).sum())} of {len(names)} patches (worst {names[worst]}, ΔE00 "
        f"{sampled[worst]:.2f}); the folded weights stay within {folded.max():.3f} (log scale)"
    )
    blocks.append(ctx.figure("fl2-patches", fig, caption))
    return blocks


def checks(data: SectionData) -> list[Check]:
    """Mean and max ΔE00 of the E308 weights against their targets, per grid and light."""
    found = []
    for grid in GRIDS:
        for light in LIGHTS:
            stats = data.results[f"{grid.label} {light} astm_e308"]
            for stat, limit in zip(("mean", "max"), TARGETS[light], strict=True):
                found.append(
                    Check(
                        f"{stat} ΔE00, {light}, {grid.n_bands} bands",
                        f"<= {limit}",
                        stats[stat],
                        stats[stat] <= limit,
                        "independent",  # the truth is colour.sd_to_XYZ on the 5 nm data
                    )
                )
    return found


def headlines(data: SectionData) -> list[Headline]:
    """The summary's figures: the 41-band ColorChecker under D65 and FL2, and point sampling."""
    r = data.results
    d65, fl2 = (r[f"{GRID_41.label} {light} astm_e308"]["mean"] for light in ("D65", "FL2"))
    point = r[f"{GRID_41.label} FL2 point"]["mean"]
    return [
        Headline(
            f"41-band ColorChecker renders match the 5 nm truth: mean ΔE00 {d65:.3f} under D65, "
            f"{fl2:.3f} under FL2",
            f"targets ≤ {TARGETS['D65'][0]} and ≤ {TARGETS['FL2'][0]}",
        ),
        Headline(
            f"point-sampled bands miss FL2's mercury lines: mean ΔE00 {point:.2f}, "
            f"{point / fl2:.0f}× the band weights' error",
            "why specref folds the light into ASTM E308 weights",
        ),
    ]


SECTION = ReportSection(
    "spectral-core",
    "Spectral core",
    colorchecker_band_weights,
    present,
    checks,
    headlines=headlines,
)

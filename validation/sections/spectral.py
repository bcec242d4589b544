"""Report section "Spectral core": ColorChecker accuracy of the band weights (2 grids, 4 lights)."""

from __future__ import annotations

import numpy as np

from reference.spectra import GRID_31, GRID_41
from validation.metrics import COLORCHECKER, colorchecker_delta_E, delta_E_stats
from validation.report import (
    REPORT_SECTIONS,
    Check,
    ReportContext,
    ReportSection,
    SectionResult,
    Table,
    Text,
)

LIGHTS = ("D65", "A", "D50", "FL2")
# Targets of issue 3: ΔE00 against the 5 nm truth, (mean, max), for the shipped E308 weights.
TARGETS = {"D65": (0.03, 0.10), "A": (0.03, 0.10), "D50": (0.03, 0.10), "FL2": (0.06, 0.15)}


def run(ctx: ReportContext) -> SectionResult:
    """ΔE00 statistics of E308 and point-sampled band weights, per grid and light, and a chart."""
    import matplotlib.pyplot as plt

    rows, results, per_patch, checks = [], {}, {}, []
    for grid in (GRID_41, GRID_31):
        for light in LIGHTS:
            for method in ("astm_e308", "point"):
                dE = colorchecker_delta_E(grid, light, method)
                stats = delta_E_stats(dE)
                key = f"{grid.label} {light} {method}"
                results[key] = stats
                per_patch[(grid.label, light, method)] = dE
                rows.append([grid.label, light, method, stats["mean"], stats["p90"], stats["max"]])
                if method == "astm_e308":
                    for stat, limit in zip(("mean", "max"), TARGETS[light], strict=True):
                        checks.append(
                            Check(
                                f"{stat} ΔE00, {light}, {grid.n_bands} bands",
                                f"<= {limit}",
                                stats[stat],
                                stats[stat] <= limit,
                            )
                        )
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
    import colour

    names = list(colour.SDS_COLOURCHECKERS[COLORCHECKER])
    fig, ax = plt.subplots(figsize=(9, 3.6))
    x = np.arange(len(names))
    for offset, method in ((-0.2, "astm_e308"), (0.2, "point")):
        ax.bar(x + offset, per_patch[(GRID_41.label, "FL2", method)], width=0.4, label=method)
    ax.set_yscale("log")
    ax.set_xticks(x, names, rotation=60, ha="right", fontsize=8)
    ax.set_ylabel("ΔE00 under FL2 (41 bands)")
    ax.legend(ncol=2, loc="lower center", bbox_to_anchor=(0.5, 1.0), frameon=False)
    blocks.append(ctx.figure("fl2-patches", fig, "Per-patch ΔE00 under FL2, 41-band grid"))
    return SectionResult(blocks, results, checks)


REPORT_SECTIONS.register(ReportSection("spectral-core", "Spectral core", 10, run))

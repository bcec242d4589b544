"""Report section "Cross-check against Mitsuba 3": the same scenes in specref and Mitsuba, z-scores.

Shown when Mitsuba 3 is installed (``pip install '.[mitsuba]'``); otherwise the section says how to
enable it. The figures come from :func:`validation.studies.crosscheck.run_crosscheck` (``FULL``
settings; ``QUICK`` under ``specref report --quick``), the same function ``specref crosscheck``
runs. Full reports also hold the layered polymer model in its opaque smooth limit against
Mitsuba's ``plastic`` (:func:`validation.studies.polymer_mitsuba.plastic_against_mitsuba`).
"""

from __future__ import annotations

import numpy as np

from validation.report.types import Check, Headline, ReportSection, SectionData, Table, Text

#: Agreement targets (erratum E83): the RMS z of a case within this factor of Student's t
#: expectation, and its mean relative difference in Y below MEAN_REL_Y_TARGET. Both allow for the
#: documented systematic differences (band grid, Jakob tables, Mitsuba's separate interpolation of
#: spectral shape and scale between texels; errata E81-E82), which grow in z with the samples.
RMS_Z_FACTOR = 2.0
MEAN_REL_Y_TARGET = 0.02
#: The layered polymer model in its opaque smooth limit against Mitsuba 3's ``plastic``: mean
#: block ΔE00 from Mitsuba's mean of two seeds at PLASTIC_SPP samples per pixel each.
PLASTIC_TARGET = 0.3
PLASTIC_SPP = 16384


def crosscheck_figures(ctx) -> SectionData:
    """Run the cross-check, or record why not (compute half of the section)."""
    from validation.studies.crosscheck import (
        FULL,
        QUICK,
        crosscheck_summary,
        mitsuba_missing,
        run_crosscheck,
    )

    missing = mitsuba_missing()
    if missing is not None:
        return SectionData(results={"available": False, "reason": missing})
    settings = QUICK if ctx.quick else FULL
    result = run_crosscheck(None, settings)
    plastic = None
    if not ctx.quick:  # four renders at 16,384 spp and the oracle: minutes, --full only
        from validation.studies.polymer_mitsuba import plastic_against_mitsuba

        plastic = plastic_against_mitsuba(PLASTIC_SPP)
    return SectionData(
        results={
            "available": True,
            "variant": result["variant"],
            "settings": vars(settings),
            "cases": crosscheck_summary(result),
            "plastic": plastic,
        },
        arrays={"cases": result["cases"]},
    )


def present(ctx, data: SectionData) -> list:
    """The summary table and a chart of z per pixel, or the install hint."""
    r = data.results
    if not r["available"]:
        return [Text(f"The cross-check did not run: {r['reason']}.")]
    s = r["settings"]
    blocks = [
        Text(
            f"Each case is rendered by specref (brute-force environment integration, "
            f"`jakob2019` upsampling, Mitsuba's texel placement) and by Mitsuba 3 "
            f"(`{r['variant']}`, {s['seeds']} seeds × {s['spp']} samples per pixel) at "
            f"{s['size']}×{s['size']} pixels (the chart: per patch); z = (specref − Mitsuba "
            f"mean) / Mitsuba's standard error from the seeds. If the two agree, z follows "
            f"Student's t with {s['seeds'] - 1} degrees of freedom."
        ),
        Table(
            ["case", "values", "mean ΔY/Y", "max |ΔY/Y|", "RMS z", "expected", "max |z|", "|z|>4"],
            [
                [
                    c["name"],
                    c["values"],
                    c["mean_rel_Y"],
                    c["max_rel_Y"],
                    c["rms_z"],
                    c["expected_rms_z"],
                    c["max_abs_z"],
                    c["frac_abs_z_over_4"],
                ]
                for c in r["cases"]
            ],
            caption="specref against Mitsuba 3, per pixel (X, Y, Z).",
            fmt="{:.3g}",
        ),
    ]
    blocks.append(_z_chart(ctx, data))
    return blocks + _plastic_blocks(r.get("plastic"))


def _plastic_blocks(p: dict | None) -> list:
    """The polymer's opaque smooth limit against Mitsuba's ``plastic`` (full reports)."""
    if p is None:
        return [
            Text(
                "The layered polymer model against Mitsuba 3's `plastic` runs in full reports "
                "(`specref report --full`): four renders at 16,384 samples per pixel."
            )
        ]
    rows = [
        ["layered model (shrm.polymer.layered)", p["layered"], p["seeds"]],
        ["oracle (shrm.polymer.oracle)", p["oracle"], p["seeds"]],
        ["control: grey Lambertian, specref render_scene", p["lambert"], p["lambert_seeds"]],
    ]
    return [
        Text(
            "The layered polymer model in its opaque smooth limit (a Kubelka–Munk body with "
            "R∞ = 0.5 under a smooth coat of index 1.54) on the conformance suite's studio sphere "
            f"(`validation.studies.polymer_mitsuba`), against Mitsuba 3's `plastic` at {p['spp']} "
            "samples per pixel and two seeds: mean ΔE00 over 4 × 4-pixel blocks from Mitsuba's "
            f"mean (worst block {p['worst_block']:.2f}; ΣY ratio {p['sum_Y_ratio']:.4f}). The "
            "control is the same scene's Lambertian sphere rendered by both: the pipeline's "
            "floor. specref reads the map constant over each texel, as the scene defines it "
            "(docs/herbert-polymer.md)."
        ),
        Table(
            ["specref", "mean ΔE00 from Mitsuba's mean", "Mitsuba's two seeds apart"],
            rows,
            caption="The opaque smooth polymer and its Lambertian control against Mitsuba 3",
            fmt="{:.3g}",
        ),
    ]


def _z_chart(ctx, data):
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 3.2))
    bins = np.linspace(-6, 6, 49)
    for case in data.arrays["cases"]:
        z = np.clip(case["z"].ravel(), -6, 6)
        ax.hist(z, bins=bins, histtype="step", density=True, label=case["name"])
    ax.set_xlabel("z (specref − Mitsuba) / standard error")
    ax.set_ylabel("density")
    ax.legend(fontsize=6)
    fig.tight_layout()
    rms = {c["name"]: float(np.sqrt(np.mean(np.square(c["z"])))) for c in data.arrays["cases"]}
    worst = max(rms, key=rms.get) if rms else None
    caption = "z-scores of every case"
    if worst is not None:
        caption = (
            f"z-scores of every case: RMS z {min(rms.values()):.2f}–{rms[worst]:.2f} (widest: "
            f"{worst}); the table gives each case's expectation from Mitsuba's noise alone"
        )
    return ctx.figure("crosscheck_z", fig, caption)


def checks(data: SectionData) -> list:
    """Per case: RMS z near Student's expectation, and a small mean difference in Y."""
    r = data.results
    if not r["available"]:
        return []
    out = []
    for c in r["cases"]:
        limit = RMS_Z_FACTOR * c["expected_rms_z"]
        out.append(
            Check(
                f"{c['name']}: RMS z",
                f"<= {limit:.3g}",
                c["rms_z"],
                c["rms_z"] <= limit,
                "independent",
            )
        )
        out.append(
            Check(
                f"{c['name']}: mean ΔY/Y",
                f"|.| <= {MEAN_REL_Y_TARGET}",
                c["mean_rel_Y"],
                abs(c["mean_rel_Y"]) <= MEAN_REL_Y_TARGET,
                "independent",
            )
        )
    plastic = r.get("plastic")
    if plastic is not None:
        out.append(
            Check(
                f"layered polymer, opaque smooth limit, vs Mitsuba 3 plastic under "
                f"studio_small_03: mean block ΔE00 ({plastic['spp']} spp, two seeds)",
                f"<= {PLASTIC_TARGET}",
                plastic["layered"],
                plastic["layered"] <= PLASTIC_TARGET,
                "independent",
            )
        )
    return out


def headlines(data: SectionData) -> list[Headline]:
    """The summary's figure: agreement with Mitsuba 3 within its Monte Carlo error."""
    r = data.results
    if not r["available"]:
        return [Headline("Mitsuba 3 cross-check: not run (`pip install .[mitsuba]`)")]
    worst = max(r["cases"], key=lambda c: c["rms_z"] / c["expected_rms_z"])
    mean = max(abs(c["mean_rel_Y"]) for c in r["cases"])
    return [
        Headline(
            f"Mitsuba 3 agrees on {len(r['cases'])} scenes: RMS z at most "
            f"{worst['rms_z']:.2f} (expected {worst['expected_rms_z']:.2f}), mean |ΔY/Y| at "
            f"most {100 * mean:.1f} %",
            f"targets RMS z ≤ {RMS_Z_FACTOR:g}× expected, |mean ΔY/Y| ≤ {MEAN_REL_Y_TARGET}",
        )
    ]


SECTION = ReportSection(
    "crosscheck",
    "Cross-check against Mitsuba 3",
    crosscheck_figures,
    present,
    checks,
    headlines=headlines,
)

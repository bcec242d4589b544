"""Report section "Conformance": Mitsuba 3 checked against specref's conformance suite.

The figures come from :func:`validation.conformance.mitsuba.run_mitsuba_proof`, the function the
proof test runs: the scenes Mitsuba 3 can express (the three of ``QUICK_PROOF`` under the
default and quick efforts), checked as ``specref conformance check`` checks a user's renders,
and four renders broken on purpose, each of which must fail with the mistake made. Shown when
Mitsuba 3 is installed; otherwise the section says how to enable it (docs/conformance.md).
"""

from __future__ import annotations

import tempfile

from validation.report.types import Check, Headline, ReportSection, SectionData, Table, Text


def conformance_figures(ctx) -> SectionData:
    """Run the proof on Mitsuba 3, or record why not (compute half of the section)."""
    from validation.conformance.mitsuba import QUICK_PROOF, run_mitsuba_proof
    from validation.studies.crosscheck import mitsuba_missing

    missing = mitsuba_missing()
    if missing is not None:
        return SectionData(results={"available": False, "reason": missing})
    with tempfile.TemporaryDirectory() as folder:
        proof = run_mitsuba_proof(folder, QUICK_PROOF if ctx.quick else None)
    scenes = [{k: v for k, v in row.items() if k != "pixels"} for row in proof["check"]["scenes"]]
    broken = [
        {"scene": name, "made": r["made"], "passed": r["passed"],
         "named": (r.get("diagnosis") or {}).get("mistake"), "detail": r.get("diagnosis")}
        for name, r in proof["broken"].items()
    ]  # fmt: skip
    return SectionData(results={"available": True, "scenes": scenes, "broken": broken})


def present(ctx, data: SectionData) -> list:
    """The check's table for Mitsuba's renders, and the broken renders with their diagnoses."""
    from validation.conformance.mitsuba import proof_spp

    r = data.results
    if not r["available"]:
        return [Text(f"The conformance proof did not run: {r['reason']}.")]
    return [
        Text(
            "The conformance scenes that Mitsuba 3 can express, exported by `specref "
            "conformance export --format mitsuba` and rendered by Mitsuba 3 (`scalar_spectral`, "
            "at the samples per pixel of the column spp), checked by `specref conformance check` "
            "against "
            "specref's references: the mean relative ΔY and ΔE00 of 4 × 4-pixel blocks against "
            "their tolerances (docs/conformance.md)."
        ),
        Table(
            ["scene", "spp", "passed", "ΔY blocks", "tolerance", "ΔE00 blocks", "ΣY ratio − 1"],
            [
                [
                    s["scene"],
                    proof_spp(s["scene"]),
                    s["passed"],
                    s["block_rel_Y"],
                    s["tol_Y"],
                    s["block_dE00"],
                    s["ratio_Y"],
                ]
                for s in r["scenes"]
            ],
            caption="Mitsuba 3 against the conformance references.",
            fmt="{:.3g}",
        ),
        Table(
            ["scene", "mistake made", "passed", "diagnosis"],
            [[b["scene"], b["made"], b["passed"], b["named"]] for b in r["broken"]],
            caption="Mitsuba's renders broken on purpose: each must fail and be diagnosed.",
        ),
    ]


def checks(data: SectionData) -> list:
    """Every scene passes; every broken render fails with the mistake that was made."""
    r = data.results
    if not r["available"]:
        return []
    out = [
        Check(
            f"{s['scene']}: Mitsuba 3 passes",
            "passed",
            s["block_rel_Y"],
            s["passed"],
            "independent",
        )
        for s in r["scenes"]
    ]
    out += [
        Check(
            f"{b['scene']} broken ({b['made']}): named",
            b["made"],
            b["named"],
            (not b["passed"]) and b["named"] == b["made"],
            "independent",
        )
        for b in r["broken"]
    ]
    return out


def headlines(data: SectionData) -> list[Headline]:
    """The summary's figure: how many conformance scenes Mitsuba 3 passes."""
    r = data.results
    if not r["available"]:
        return [Headline("Conformance: not run (`pip install .[mitsuba]`)")]
    passed = sum(s["passed"] for s in r["scenes"])
    named = sum((not b["passed"]) and b["named"] == b["made"] for b in r["broken"])
    return [
        Headline(
            f"Mitsuba 3 passes {passed} of {len(r['scenes'])} conformance scenes; "
            f"{named} of {len(r['broken'])} broken renders diagnosed",
            "every scene passes; every broken render named",
        )
    ]


SECTION = ReportSection(
    "conformance",
    "Conformance: Mitsuba 3 against the suite",
    conformance_figures,
    present,
    checks,
    headlines=headlines,
    default_effort="quick",
)

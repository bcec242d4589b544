"""Tests of the report section "ImpastoR": compute, checks (one per target), images."""

from __future__ import annotations

import copy

import pytest

from impastor.multispectral import MULTISPECTRAL_DESIGNS
from impastor.painting import PAINTING_LIGHTING_METHODS
from validation.report import ReportContext, SectionData
from validation.report.runner import run_report
from validation.report.sections.impastor import (
    PAINTING_METHOD,
    SECTION,
    TARGETS,
    TINY,
    checks,
    frame_methods,
    impastor_validation,
    present,
)


def _results(**changes):
    # Figures that meet every target (the section's limits, with margin), then one changed.
    results = {
        "channels": {
            design: {"6": {light: {"mean": 0.1, "max": 0.3} for light in ("D65", "D50", "A")}}
            for design in ("box", "optimized")
        },
        "metamers": {"A": {"pipeline": 0.1}, "D65": {"pipeline": 4.0}},
        "error_vs_alpha": {"alpha": [0.01, 0.1], "median_cut": [1.0, 0.1], "fis": [0.1, 1.0],
                           "hybrid": [0.105, 0.105]},
        "shadows": {"sectors": [6, 36], "fields": ["default", "relief ×4"],
                    "elevation_deg": [10.0, 45.0],
                    "disagreement": {"default": [[0.05, 0.03], [0.01, 0.005]],
                                     "relief ×4": [[0.08, 0.05], [0.015, 0.01]]}},
        "display_round_trip": {"counts_mismatches": 0, "n_counts": 100,
                               "XYZ_error_over_bound": 0.5},
        "ward_duer_albedo": {"albedo": [0.9, 0.99], "error": [1e-3, 1e-3], "theta_deg": [0, 60]},
    }  # fmt: skip
    results = copy.deepcopy(results)
    for path, value in changes.items():
        *keys, last = path.split("/")
        node = results
        for key in keys:
            node = node[int(key) if isinstance(node, list) else key]
        node[int(last) if isinstance(node, list) else last] = value
    return checks(SectionData(results))


@pytest.fixture(scope="module")
def tiny():
    # The whole compute step at tiny sizes (seconds): the figures, not the targets.
    return impastor_validation(settings=TINY)


def test_checks_cover_every_target_and_pass_when_met():
    found = _results()
    # 2 designs × 3 lights × (mean, max), 2 metamers, hybrid, shadows, 2 display round trips,
    # the Ward–Dür albedo.
    assert len(found) == 12 + 2 + 1 + 1 + 2 + 1
    assert all(c.passed for c in found), [c for c in found if not c.passed]


def test_the_six_channel_headline_is_the_targets_lights_and_names_the_others():
    # The headline's figure is the worst of the lights the channels were designed for (what the
    # targets check), and a light outside the fit is named with its own figure, not folded in
    from validation.report.sections import impastor as section

    six = {light: {"mean": 0.2, "max": 0.5} for light in ("D65", "D50", "A")}
    six["FL2"] = {"mean": 2.11, "max": 4.0}
    text = (
        "six optimized channels render the ColorChecker within mean ΔE00 0.20 under the booth "
        "lights they were designed for (D65, D50, A); 2.11 under FL2 (outside the fit)"
    )
    first = section._six_channel_headline(six)
    assert first.text == text
    assert first.anchor == f"target ≤ {TARGETS['optimized'][0]} under D65, D50, A"


def test_a_failing_figure_fails_its_check():
    # path: (value just past the limit, words in the check's name, measured as shown)
    cases = {
        "channels/optimized/6/A/max": (0.61, "optimized 6 channels, ColorChecker under A", 0.61),
        "channels/box/6/D50/mean": (0.81, "box 6 channels, ColorChecker under D50", 0.81),
        "metamers/A/pipeline": (0.6, "metamers rendered under A", 0.6),
        "metamers/D65/pipeline": (2.5, "metamers rendered under D65", 2.5),
        "error_vs_alpha/hybrid/1": (0.111, "hybrid / better", 0.111 / 0.1),
        "shadows/disagreement/relief ×4/1/0": (0.021, "horizon map (36 sectors)", "2.1 %"),
        "display_round_trip/counts_mismatches": (1, "counts → XYZ → counts", 1),
        "display_round_trip/XYZ_error_over_bound": (1.2, "XYZ → counts → XYZ", 1.2),
        "ward_duer_albedo/albedo/1": (1.002, "Ward–Dür white-furnace albedo", 1.002),
    }
    for path, (value, name, measured) in cases.items():
        failed = [c for c in _results(**{path: value}) if not c.passed]
        assert len(failed) == 1, (path, failed)
        assert name in failed[0].name
        if isinstance(measured, float):
            assert abs(failed[0].measured - measured) < 1e-12
        else:
            assert failed[0].measured == measured


def test_checks_are_a_pure_function_of_the_results(tiny):
    first = checks(tiny)
    # The same results give the same checks, with or without the presenter's arrays ...
    assert checks(SectionData(copy.deepcopy(tiny.results))) == first
    # ... and a changed figure changes its own check only.
    changed = copy.deepcopy(tiny.results)
    changed["metamers"]["D65"]["pipeline"] = 0.0
    after = checks(SectionData(changed))
    flipped = [b.name for a, b in zip(first, after, strict=True) if a != b]
    assert flipped == ["metamers rendered under D65, ΔE00"]
    assert checks(tiny) == first  # checks modified nothing


def test_compute_returns_every_figure_of_results_json(tiny):
    assert list(tiny.results) == [
        "table1",
        "channels",
        "targets_met",
        "naive_rgb",
        "metamers",
        "error_vs_alpha",
        "shadows",
        "gloss",
        "display_round_trip",
        "ward_duer_albedo",
        "held_out_hybrid",
        "painting_D65_seconds",
        "painting_A_seconds",
        "room_ceiling",
        *(f"frame_seconds_{m}" for m in frame_methods(every=False)),
        "channel_frame_seconds",
    ]
    # a frame timed at every channel count of the error study
    assert set(tiny.results["channel_frame_seconds"]) == set(tiny.results["channels"]["optimized"])
    # Every registered channel design is measured; the designs with targets are among them.
    assert list(tiny.results["channels"]) == MULTISPECTRAL_DESIGNS.names()
    assert set(TARGETS) <= set(MULTISPECTRAL_DESIGNS.names())
    assert list(tiny.results["targets_met"]) == [
        f"{design} {light}" for design in TARGETS for light in ("D65", "D50", "A")
    ]


def test_present_draws_every_study_from_the_data(tiny, tmp_path):
    record = {
        "group": "impastor-specular",
        "name": "test_bench_specular[fis]",
        "stats": {"mean": 1},
    }
    ctx = ReportContext(out_dir=tmp_path, section=SECTION.name, bench={"benchmarks": [record]})
    blocks = present(ctx, tiny)
    images = sorted(p.name for p in (tmp_path / "images").iterdir())
    assert images == [
        f"impastor-{name}.png"
        for name in (
            "alpha",
            "channels",
            "gloss",
            "held-out-hybrid",
            "metamers",
            "painting-A",
            "painting-D65",
            "painting-room",
        )
    ] + ["impastor-shadows.png"]
    # the captured room's ceiling is more concentrated than the booth's four tubes
    assert tiny.results["room_ceiling"]["room"] > tiny.results["room_ceiling"]["booth"]
    frame_table, bench_table = blocks[-2:]
    assert [row[0] for row in frame_table.rows] == frame_methods(every=False)
    assert bench_table.rows == [["test_bench_specular[fis]", 1]]


def test_frame_methods_come_from_the_registry():
    assert frame_methods() == PAINTING_LIGHTING_METHODS.names()
    quick = frame_methods(every=False)
    # One method per specular estimator, without the painting images' method.
    references = [PAINTING_LIGHTING_METHODS.lookup(m).reference for m in quick]
    assert len(set(references)) == len(quick)
    assert PAINTING_METHOD not in quick
    assert PAINTING_LIGHTING_METHODS.lookup(PAINTING_METHOD).reference not in references
    assert set(quick) <= set(PAINTING_LIGHTING_METHODS.names())


def test_report_section_quick(tmp_path):
    results = run_report(tmp_path, effort="quick", only=["impastor"], progress=False)
    found = {c["name"]: c for c in results["checks"] if c["section"] == "impastor"}
    assert len(found) == 21
    # Every target holds: colour, metamers, the hybrid (erratum E17), shadows and display; the
    # hybrid's held-out distribution (erratum E17) is a target of the full report only: quick mode's
    # two small cases are not the held-out set.
    failing = [name for name, c in found.items() if not c["passed"] and "held-out" not in name]
    assert not failing, failing
    assert sum("held-out" in name for name in found) == 2
    assert (tmp_path / "images" / "impastor-painting-A.png").exists()

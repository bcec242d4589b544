import json

import numpy as np
import pytest

from reference.errors import SpecrefError
from validation.report import (
    Check,
    ReportContext,
    ReportSection,
    SectionData,
    Table,
    Text,
    to_jsonable,
)
from validation.report.runner import REPORT_SECTIONS, SECTIONS, run_report


def test_report_spectral_section_quick(tmp_path):
    md = tmp_path / "results.md"
    results = run_report(
        tmp_path / "r", effort="quick", only=["spectral-core"], markdown=md, progress=False
    )
    stored = json.loads((tmp_path / "r" / "results.json").read_text())
    assert stored == json.loads(json.dumps(results))
    section = stored["sections"]["spectral-core"]
    # The published figures are the ones the tests check
    # (tests/reference/colour/test_colorimetry.py).
    assert section["380-780/10 FL2 astm_e308"]["mean"] < 0.06
    assert section["380-780/10 FL2 point"]["mean"] > 3.0
    html = (tmp_path / "r" / "index.html").read_text()
    assert "<h2>Spectral core</h2>" in html
    assert "ColorChecker accuracy" in html
    image = tmp_path / "r" / "images" / "spectral-core-fl2-patches.png"
    assert image.stat().st_size > 1000
    text = md.read_text()
    assert text.startswith("# specref results")
    assert "| grid | light | weights |" in text


def test_report_refuses_unknown_section_and_bad_bench(tmp_path):
    with pytest.raises(SpecrefError, match="unknown report section 'spectra'"):
        run_report(tmp_path, only=["spectra"], progress=False)
    with pytest.raises(SpecrefError, match=r"missing\.json: file not found"):
        run_report(tmp_path, only=["spectral-core"], bench_json=tmp_path / "missing.json")
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(SpecrefError, match="not a pytest-benchmark JSON file"):
        run_report(tmp_path, only=["spectral-core"], bench_json=bad, progress=False)


def test_registered_section_renders_blocks(tmp_path):
    def compute(ctx):
        assert ctx.quick
        return SectionData({"value": np.float64(2.5), "arr": np.arange(2)})

    def present(ctx, data):
        rows = [["a", 1.23456, float("nan")]]
        return [
            Text("hello `code`"),
            Table(["x", "y", "z"], rows, "T"),
            ctx.image("img", np.ones((2, 2, 3))),
        ]

    def checks(data):
        return [Check("a", "<= 1", 0.5, True), Check("b", "<= 1", 2.0, False)]

    section = ReportSection("test-only", "Test only", compute, present, checks)
    results = run_report(
        tmp_path, effort="quick", only=["test-only"], progress=False, sections=[section]
    )
    section = results["sections"]["test-only"]
    assert section["value"] == 2.5
    assert section["arr"] == [0, 1]
    html = (tmp_path / "index.html").read_text()
    assert "<code>code</code>" in html
    assert "<td class='n'>1.235</td>" in html  # a figure: kept on one line
    assert "<td class='n'>—</td>" in html
    assert (tmp_path / "images" / "test-only-img.png").is_file()
    assert "1 of 2 targets hold; 1 do not" in html
    assert [c["passed"] for c in results["checks"]] == [True, False]
    # The failing target is shown open in its section, the rest folded; all targets at the end.
    section_html = html[html.index("id='test-only'") : html.index("id='targets'")]
    assert section_html.index("Targets that do not hold") < section_html.index("<details>")
    assert html.index("id='summary'") < html.index("id='test-only'") < html.index("id='targets'")
    # A 2×2 render is shown enlarged without smoothing, its true size in the caption.
    assert "width='256' height='256' class='pixelated'" in html
    assert "true size 2×2 px, shown ×128" in html
    # Provenance: commit, cores and run times, in the page and in results.json.
    meta = results["meta"]
    assert {"commit", "cores", "total_seconds", "section_seconds"} <= set(meta)
    assert set(meta["section_seconds"]) == {"test-only"}
    assert f"cores: {meta['cores']}" in html


def test_each_target_says_what_it_is_measured_on(tmp_path):
    # A target's basis (design inputs, held-out inputs, an independent renderer) is a column of
    # every targets table and the summary counts each apart, with those not yet stated
    def checks(data):
        return [
            Check("a", "<= 1", 0.5, True, "design"),
            Check("b", "<= 1", 2.0, False, "held out"),
            Check("c", "<= 1", 0.1, True, "held out"),
            Check("d", "<= 1", 0.1, True, "independent"),
            Check("e", "<= 1", 0.1, True),
        ]

    section = ReportSection("test-only", "Test only", lambda ctx: SectionData(), lambda c, d: [],
                            checks)  # fmt: skip
    results = run_report(
        tmp_path, effort="quick", only=["test-only"], progress=False, sections=[section]
    )
    html = (tmp_path / "index.html").read_text()
    assert (
        "4 of 5 targets hold; 1 do not (measured on design 1 of 1, held out 1 of 2, "
        "independent 1 of 1, not stated 1 of 1)"
    ) in html
    assert "<th>measured on</th>" in html
    assert "<td>held out</td>" in html
    assert "<td>not stated</td>" in html
    assert [c["basis"] for c in results["checks"]] == [
        "design", "held out", "held out", "independent", ""
    ]  # fmt: skip
    with pytest.raises(ValueError, match="allowed: design, held out, independent"):
        Check("f", "<= 1", 0.1, True, "tuned")


def test_bench_groups_filters_by_prefix():
    ctx = ReportContext(out_dir=".", bench={"benchmarks": [{"group": "raster-a"}, {"group": "sh"}]})
    assert list(ctx.bench_groups("raster")) == ["raster-a"]
    assert ReportContext(out_dir=".").bench_groups("x") == {}


def test_to_jsonable():
    value = {"a": (np.int32(1), np.bool_(True)), 2: [np.inf, np.float32(0.5)]}
    assert to_jsonable(value) == {"a": [1, True], "2": [None, 0.5]}


def test_sections_compute_present_check(tmp_path):
    calls = []

    def compute(ctx):
        calls.append("compute")
        return SectionData({"x": np.float64(0.5)}, {"image": np.zeros((2, 2, 3))})

    def present(ctx, data):
        calls.append("present")
        assert "image" in data.arrays
        return [Text(f"x = {data.results['x']}"), ctx.image("img", data.arrays["image"])]

    def checks(data):
        calls.append("checks")
        return [Check("x", "<= 1", data.results["x"], data.results["x"] <= 1)]

    section = ReportSection("three-steps", "Three steps", compute, present, checks)
    results = run_report(tmp_path, effort="quick", progress=False, sections=[section])
    assert calls == ["compute", "present", "checks"]
    # The presenter's arrays stay out of results.json; the results go in.
    stored = json.loads((tmp_path / "results.json").read_text())["sections"]["three-steps"]
    assert stored["x"] == 0.5
    assert "image" not in stored
    assert results["checks"][0]["passed"] is True


def test_section_registry_is_the_tuple_of_sections():
    assert REPORT_SECTIONS.names() == [s.name for s in SECTIONS]
    assert len(set(REPORT_SECTIONS.names())) == len(SECTIONS)


def test_summary_shows_headlines_and_hero(tmp_path):
    from validation.report import Headline

    def present(ctx, data):
        return [ctx.image("small", np.zeros((4, 8, 3))), ctx.image("hero", np.ones((300, 400, 3)))]

    section = ReportSection(
        "with-headlines",
        "With headlines",
        lambda ctx: SectionData({"speed": 12.8}),
        present,
        lambda data: [Check("speed", ">= 10", data.results["speed"], True)],
        headlines=lambda data: [
            Headline(f"table {data.results['speed']:.1f}× faster than exact", "paper: ~10×")
        ],
        hero="hero",
    )
    md = tmp_path / "results.md"
    run_report(tmp_path / "r", effort="quick", progress=False, sections=[section], markdown=md)
    html = (tmp_path / "r" / "index.html").read_text()
    summary = html[html.index("id='summary'") : html.index("<nav>")]
    assert "table 12.8× faster than exact" in summary
    assert "(paper: ~10×)" in summary
    assert "images/with-headlines-hero.png" in summary
    assert "images/with-headlines-small.png" not in summary
    assert "1 of 1 targets hold" in summary
    text = md.read_text()
    assert text.index("## Summary") < text.index("## With headlines") < text.index("## All targets")
    assert "- table 12.8× faster than exact (paper: ~10×)" in text


def test_default_headlines_are_the_first_checks():
    section = ReportSection(
        "d",
        "D",
        lambda ctx: SectionData({}),
        lambda ctx, data: [],
        lambda data: [Check(f"c{i}", "<= 1", 0.5, True) for i in range(3)],
    )
    result = section.run(ReportContext(out_dir="."))
    assert [h.text for h in result.headlines] == ["c0: 0.5", "c1: 0.5"]
    assert [h.anchor for h in result.headlines] == ["<= 1", "<= 1"]


def test_comparison_layout(tmp_path):
    ctx = ReportContext(out_dir=tmp_path, section="cmp")
    rng = np.random.default_rng(7)
    reference = rng.random((16, 16, 3))
    image = ctx.comparison("a", reference, reference * 1.1, ("brute force", "SHRM"), "caption")
    assert (tmp_path / image.path).is_file()
    assert image.width > 3 * 200
    assert image.height > 150


def _recording_section(name, seen, stop_at=None, default_effort="full"):
    """A section that records the quick flag it ran with, and raises if it is ``stop_at``."""

    def compute(ctx):
        if name == stop_at:
            raise KeyboardInterrupt  # a user's Ctrl-C in the middle of the run
        seen[name] = ctx.quick
        return SectionData({"quick": ctx.quick})

    return ReportSection(
        name, name.title(), compute, lambda ctx, data: [], default_effort=default_effort
    )


def test_each_effort_runs_the_settings_it_names(tmp_path):
    for effort, expected in (
        ("quick", {"light": True, "heavy": True}),
        ("default", {"light": False, "heavy": True}),
        ("full", {"light": False, "heavy": False}),
    ):
        seen = {}
        sections = [
            _recording_section("light", seen),
            _recording_section("heavy", seen, default_effort="quick"),
        ]
        results = run_report(tmp_path / effort, effort, progress=False, sections=sections)
        assert seen == expected, effort
        assert results["meta"]["mode"] == effort
    with pytest.raises(
        SpecrefError, match="unknown report effort 'fast'; allowed: default, full, quick"
    ):
        run_report(tmp_path / "x", "fast", progress=False, sections=sections)


def test_a_stopped_run_leaves_a_page_with_the_rest_to_come(tmp_path, capsys):
    seen = {}
    sections = [_recording_section(n, seen, stop_at="third") for n in ("first", "second", "third")]
    with pytest.raises(KeyboardInterrupt):
        run_report(tmp_path, "default", progress=True, sections=sections)
    page = (tmp_path / "index.html").read_text()
    assert "id='first'" in page
    assert "id='second'" in page
    assert page.count("Still to come") == 1
    assert "id='third' class='pending'" in page
    assert "(1 sections still to come)" in page
    # Without a terminal, one line per finished section with its time.
    lines = [line for line in capsys.readouterr().err.splitlines() if line.startswith("[")]
    assert [line.split("]")[0] for line in lines] == ["[1/3", "[2/3"]
    assert all(line.endswith(" s") for line in lines)


def test_sections_side_by_side_give_the_serial_report(tmp_path):
    # Two processes, results in reading order and equal to the serial run's (timings aside).
    only = ["spectral-core", "rasterizer"]
    serial = run_report(tmp_path / "serial", "quick", only=only, progress=False)
    forked = run_report(tmp_path / "forked", "quick", only=only, progress=False, jobs=2)
    assert list(forked["sections"]) == only
    # The spectral core's figures have no timings: equal to the last digit.
    a, b = serial["sections"]["spectral-core"], forked["sections"]["spectral-core"]
    a.pop("section_seconds"), b.pop("section_seconds")
    assert json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)
    names = [(c["section"], c["name"], c["passed"]) for c in serial["checks"]]
    assert [(c["section"], c["name"], c["passed"]) for c in forked["checks"]] == names


def test_a_section_basis_labels_the_checks_that_state_none(tmp_path):
    from validation.report.types import Check, ReportContext, ReportSection, SectionData

    def two(data):
        return [Check("a", "<= 1", 0.5, True), Check("b", "<= 1", 0.5, True, "held out")]

    section = ReportSection(
        "demo", "Demo", lambda ctx: SectionData(), lambda ctx, d: [], two, basis="design"
    )
    result = section.run(ReportContext(out_dir=tmp_path))
    assert [c.basis for c in result.checks] == ["design", "held out"]
    with pytest.raises(SpecrefError, match="basis"):
        ReportSection("demo", "Demo", basis="tuned")


@pytest.mark.parametrize(
    "content", ["{not json", '{"meta": 3}', '{"meta": {"mode": "default", "section_seconds": 1}}']
)
def test_an_unreadable_earlier_results_file_falls_back_to_heavy_first(tmp_path, content):
    # a stopped or foreign results.json neither stops the run nor reorders it by guesswork
    from validation.report.runner import start_order
    from validation.report.types import ReportSection

    (tmp_path / "results.json").write_text(content)
    sections = [ReportSection("a", "A"), ReportSection("b", "B", default_effort="quick")]
    assert start_order(sections, tmp_path, "default") == [1, 0]
    assert (tmp_path / "results.json").read_text() == content

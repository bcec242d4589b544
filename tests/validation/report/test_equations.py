"""The equation index (validation/report/equations.py, docs/equations.md, ``specref equations``)."""

import os
import re
from pathlib import Path

import pytest

from validation.cli import main
from validation.report.citations import called_names
from validation.report.equations import (
    COMPUTES,
    PAPERS,
    REGENERATE,
    ROOT,
    Citation,
    collect_citations,
    equation_index,
    equation_problems,
    render_equation_index,
)


@pytest.fixture(scope="module")
def citations():
    return collect_citations()


@pytest.fixture(scope="module")
def rows(citations):
    return {(r.author, r.number): r for r in equation_index(citations=citations)}


def test_docs_equations_md_is_up_to_date(citations):
    committed = (ROOT / "docs" / "equations.md").read_text(encoding="utf-8")
    assert committed == render_equation_index(citations=citations), (
        f"docs/equations.md is out of date; regenerate it with `{REGENERATE}`"
    )


def test_code_and_index_agree(citations, rows):
    # Every cited equation is in the index, with an author, never as a range or list in a comment,
    # each cited on its own somewhere, and every function the index names imports.
    problems = equation_problems(citations, list(rows.values()))
    assert problems == [], "\n".join(problems)


def test_every_indexed_function_exists(rows):
    import importlib

    for row in rows.values():
        for function in row.functions:
            module, _, attr = function.name.rpartition(".")
            while module:
                try:
                    obj = importlib.import_module(module)
                    break
                except ImportError:
                    module, _, head = module.rpartition(".")
                    attr = f"{head}.{attr}"
            for part in attr.split("."):
                obj = getattr(obj, part)
            assert callable(obj) or isinstance(obj, property), function.name


def test_every_paper_equation_has_a_row(rows):
    for paper in PAPERS:
        numbers = [e.number for e in paper.equations]
        assert numbers == list(range(1, len(numbers) + 1)), paper.author
        assert all((paper.author, n) in rows for n in numbers)


def test_fixes_the_index_exposed(rows):
    # Herbert's Eq. (1) (the §5.1 shading sum) is cited by the polymer model, not by the cube-map
    # transforms (§7.1).
    names = [f.name for f in rows["Herbert et al.", 1].functions]
    assert names
    assert not [n for n in names if "cubemap" in n]
    assert "shrm.polymer.hybrid.polymer_terms" in names or any(
        n.startswith("shrm.polymer.hybrid") for n in names
    )
    assert "E5" in rows["Herbert et al.", 1].errata
    # Wang's Eq. (12) is cited on its own, not only inside a range.
    cited_alone = [f.name for f in rows["Wang et al.", 12].functions if not f.grouped_only]
    assert cited_alone == ["phong_table.placement.importance_ratio_Wang"]


def test_rows_name_functions_tests_and_errata(rows):
    row = rows["Wang et al.", 15]
    names = [f.name for f in row.functions]
    assert "phong_table.placement.inverse_importance_ratio_Wang" in names
    function = row.functions[names.index("phong_table.placement.inverse_importance_ratio_Wang")]
    assert "tests/phong_table/test_placement.py::test_ir_of_iir_is_identity" in function.tests
    # Source: docs/errata.md, the titles of E4 ("Eq. (15).") and E3/E20 ("Eq. (16), ...")
    assert row.errata == ("E4",)
    assert rows["Wang et al.", 16].errata == ("E3", "E20")
    # Registry entries name their registry and key
    importance = next(
        f for f in rows["Wang et al.", 16].functions if f.name.endswith("table_importance_Wang")
    )
    assert importance.registered == ("PLACEMENT_METHODS['importance']",)


def _section(text: str, heading: str) -> str:
    """The section of a rendered index under ``heading``, up to the next heading."""
    return text.split(f"### {heading}\n", 1)[1].split("\n#", 1)[0]


def _fake_package(tmp_path, monkeypatch, name: str, files: dict) -> list:
    """Write a package of ``files`` under ``tmp_path``, importable, and read its citations."""
    package = tmp_path / name
    package.mkdir()
    for filename, text in files.items():
        (package / filename).write_text(text)
    monkeypatch.syspath_prepend(str(tmp_path))
    return collect_citations(tmp_path, (name,))


def test_a_body_comment_marks_the_computing_function(tmp_path, monkeypatch):
    init = (
        "def average(n):\n"
        '    """The average exponent an of the proxy, Eq. (13), Wang et al."""\n'
        "    return sum(n) / len(n)\n\n\n"
        "def mean_exponent(n):\n"
        '    """The average exponent (no citation here)."""\n'
        "    # Eq. (13), Wang et al.: an = (1/N) sum of n\n"
        "    return sum(n) / len(n)\n\n\n"
        "def table(n):\n"
        "    # Eq. (13), Wang et al.: an, for the placement\n"
        "    return mean_exponent(n) + 1\n\n\n"
        "def closed_form(t, an):\n"
        '    """Eq. (15), Wang et al., used but computed nowhere."""\n'
        "    return t ** (1 / (an + 1))\n"
    )
    kernels = (
        "def mean_exponent_kernel(n, out):\n"
        "    acc = 0.0\n"
        "    for x in n:\n"
        "        acc += x  # Eq. (13), Wang et al.\n"
        "    out[0] = acc / len(n)\n\n\n"
        "def _ratio(t, an):\n"
        "    return t ** (an + 1)  # Eq. (14), Wang et al.\n"
    )
    files = {"__init__.py": init, "_kernels.py": kernels}
    found = _fake_package(tmp_path, monkeypatch, "fake_computing_code", files)
    calls = called_names(tmp_path, ("fake_computing_code",))
    rows = {(r.author, r.number): r for r in equation_index(citations=found, calls=calls)}

    # the body comment computes, the docstring mention and the comment over a call use
    row = rows["Wang et al.", 13]
    assert [f.name for f in row.computed_by] == ["fake_computing_code.mean_exponent"]
    twin = row.kernel_twin(row.computed_by[0])
    assert twin.name == "fake_computing_code._kernels.mean_exponent_kernel"
    assert twin.kernel
    assert [(f.name, f.calls) for f in row.used_by] == [
        ("fake_computing_code.average", ()),
        ("fake_computing_code.table", ("fake_computing_code.mean_exponent",)),
    ]
    # a kernel without a NumPy twin that computes is a computing function of its own
    (ratio,) = rows["Wang et al.", 14].computed_by
    assert (ratio.name, ratio.kernel, ratio.twin) == (
        "fake_computing_code._kernels._ratio",
        True,
        "",
    )
    # cited only in a docstring: no function computes it, and that is not a problem
    assert rows["Wang et al.", 15].computed_by == ()
    assert [f.name for f in rows["Wang et al.", 15].used_by] == ["fake_computing_code.closed_form"]
    assert equation_problems(found, list(rows.values())) == []

    # The page: "computed by" first, with the twin beside its reference; then "used by"
    text = render_equation_index(citations=found, calls=calls)
    section = _section(text, "Eq. (13), Wang et al.")
    computed, used = section.index("**Computed by**"), section.index("**Used by**")
    assert computed < used
    assert "  - `fake_computing_code.mean_exponent`; no test names it; numba twin " in section
    assert "`fake_computing_code._kernels.mean_exponent_kernel`" in section[computed:used]
    assert "`fake_computing_code.average`" in section[used:]
    assert "`fake_computing_code.table` (calls `mean_exponent`; no test names it)" in section
    assert "`fake_computing_code._kernels._ratio` (numba kernel)" in _section(
        text, "Eq. (14), Wang et al."
    )
    assert "- **Computed by**: none found (no comment in a function body names it)." in _section(
        text, "Eq. (15), Wang et al."
    )
    # the summary table names the computing function, or none
    assert "| Wang et al. | (13) | §3.2 | `mean_exponent` | 2 | " in text
    assert "| Wang et al. | (15) | §3.2 | **none** | 1 | " in text
    assert COMPUTES.split(";")[0] in " ".join(text.split())


def test_computing_functions_found_in_the_source(rows):
    # Source: phong_table/model.py, average_exponent_Wang's body comment "Eq. (13), Wang et
    # al. (Erratum E1): an = (1/N) Σ_λ n(λ)"; the placement's functions cite it in docstrings
    row = rows["Wang et al.", 13]
    assert [f.name for f in row.computed_by] == ["phong_table.model.average_exponent_Wang"]
    used = {f.name for f in row.used_by}
    assert {
        "phong_table.placement.table_importance_Wang",
        "phong_table.placement.table_error",
    } <= used
    # Source: impastor/point_lights.py, illuminance_point_lights's body comments "Eq. (2),
    # Ferwerda: ..."; median_cut places the lights (docstring and registry cites);
    # impastor/painting.py, shade_canvas comments "Eq. (2), Ferwerda" over a call of it
    row = rows["Ferwerda", 2]
    names = [f.name for f in row.computed_by]
    assert "impastor.point_lights.illuminance_point_lights" in names
    used = {f.name: f for f in row.used_by}
    assert "impastor.point_lights.median_cut" in used
    assert used["impastor.painting.shade_canvas"].calls == (
        "impastor.point_lights.illuminance_point_lights",
    )
    # Source: phong_table/placement.py, table_importance_Wang's "Eq. (15), Wang et al." comment
    # is over a call of inverse_importance_ratio_Wang, whose body computes t = w^(1/(an+1))
    row = rows["Wang et al.", 15]
    assert [f.name for f in row.computed_by] == [
        "phong_table.placement.inverse_importance_ratio_Wang"
    ]
    # Source: shrm/polymer/material.py and shrm/polymer/_kernels.py, both with the "Eq. (3),
    # Herbert et al.: + E_effect Mod_effect" comment, and POLYMER_KERNELS pairs them
    row = rows["Herbert et al.", 3]
    shade_parts = next(f for f in row.computed_by if f.name.endswith(".polymer_shade_parts"))
    kernel = row.kernel_twin(shade_parts)
    assert kernel.name == "shrm.polymer._kernels.polymer_shade_parts_kernel"
    assert kernel not in row.computed_by
    assert kernel not in row.used_by
    # Wang et al. (3) is cited nowhere: the row says that nothing computes it
    assert rows["Wang et al.", 3].computed_by == rows["Wang et al.", 3].functions == ()


def test_computes_follows_the_rule_on_the_whole_tree(citations, rows):
    commented = {(c.author, c.number, c.owner) for c in citations if c.kind == "comment"}
    for (author, number), row in rows.items():
        names = {f.name for f in row.functions}
        for f in row.functions:
            key = (author, str(number), f.name)
            # computes <=> a body comment names it and it calls no function that computes it
            assert f.computes == (key in commented and not f.calls), (key, f.calls)
            assert all((author, str(number), c) in commented and c in names for c in f.calls)
        # every function is shown once: computing, as a computing kernel's twin, or using
        twins = [row.kernel_twin(f) for f in row.computed_by]
        shown = [*row.computed_by, *(t for t in twins if t), *row.used_by]
        assert sorted(f.name for f in shown) == sorted(names), (author, number)


def test_ranges_and_lists_are_expanded_and_flagged(tmp_path, monkeypatch):
    init = (
        'def f():\n    """Eqs. (12)-(14), Wang et al."""\n\n\n'
        'def g():\n    """Eq. (13), Wang et al."""\n'
        "    # Eq. (5) and Eq. (6), Ferwerda: a list in a comment\n"
        "    return 1\n"
    )
    found = _fake_package(tmp_path, monkeypatch, "fake_paper_code", {"__init__.py": init})
    cited = sorted((c.owner, c.number, c.grouped) for c in found if c.author == "Wang et al.")
    assert cited == [
        ("fake_paper_code.f", "12", True),
        ("fake_paper_code.f", "13", True),
        ("fake_paper_code.f", "14", True),
        ("fake_paper_code.g", "13", False),
    ]
    problems = equation_problems(found, equation_index(citations=found))
    assert any("a comment cites Eq. (5), Eq. (6) as a range or list" in p for p in problems)
    # (12) and (14) are cited only inside the range; (13) on its own by g
    only = [p for p in problems if "Wang et al. is cited only in ranges or lists" in p]
    assert [p.split(",")[0] for p in only] == ["Eq. (12)", "Eq. (14)"]


def test_checker_catches_a_fake_citation_and_a_missing_or_unknown_author(citations, rows):
    fake = [
        Citation("phong_table/model.py", 7, "phong_table.model.f", "comment", "Wang et al.", "17"),
        Citation("shrm/sh.py", 9, "shrm.sh.g", "docstring", "Herbert et al.", "8"),
        Citation("impastor/horizon.py", 3, "impastor.horizon.h", "comment", None, "4"),
        Citation("shrm/sh.py", 11, "shrm.sh.k", "comment", "Herbert", "2"),
    ]
    baseline = set(equation_problems(citations, list(rows.values())))
    problems = [p for p in equation_problems([*citations, *fake], list(rows.values()))
                if p not in baseline]  # fmt: skip
    assert problems == [
        "impastor/horizon.py:3: impastor.horizon.h mentions Eq. (4) without an author "
        "(write `Eq. (N), Author`)",
        "phong_table/model.py:7: phong_table.model.f cites Eq. (17), Wang et al., which the paper "
        "does not have (it has (1)-(16))",
        "shrm/sh.py:11: shrm.sh.k cites Eq. (2), Herbert: not a paper of the index "
        "(Wang et al., Herbert et al., Ferwerda), nor a source with a year",
        "shrm/sh.py:9: shrm.sh.g cites Eq. (8), Herbert et al., which the paper does not have "
        "(it has (1)-(7))",
    ]


def test_checker_catches_a_missing_function(citations, rows):
    ghost = Citation(
        "phong_table/model.py", 1, "phong_table.model.no_such_function", "docstring",
        "Wang et al.", "11",
    )  # fmt: skip
    baseline = set(equation_problems(citations, list(rows.values())))
    with_ghost = equation_index(citations=[*citations, ghost])
    problems = [p for p in equation_problems([*citations, ghost], with_ghost) if p not in baseline]
    assert problems == [
        "Eq. (11), Wang et al.: phong_table.model.no_such_function does not exist (not importable)"
    ]


def test_cli_writes_and_checks(tmp_path, capsys):
    out = tmp_path / "equations.md"
    assert main(["equations", "-o", str(out)]) == 0
    assert out.read_text(encoding="utf-8").startswith("# Equation index")
    assert main(["equations", "--check", "-o", str(out)]) == 0
    out.write_text("stale\n", encoding="utf-8")
    assert main(["equations", "--check", "-o", str(out)]) == 1
    assert f"regenerate it with `{REGENERATE}`" in capsys.readouterr().err
    out.write_bytes(b"\xff\xfe\x00 binary")  # was a UnicodeDecodeError traceback
    assert main(["equations", "--check", "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "not UTF-8 text" in err
    assert len(err.splitlines()) == 1


#: Where each paper's text prints its equation numbers (docs/equations.md, "Numbering").
NUMBER_MARKS = {
    "wang-chern-lee-spectral-phong.txt": (
        "Wang et al.",
        r"(?:\\quad\s*\((\d+)\)|\\tag\{(\d+)\})\s*\$\$",
    ),
    "herbert-2004-multispectral-virtual-reality.txt": (
        "Herbert et al.",
        r"(?:\\quad\s*\((\d+)\)|\\tag\{(\d+)\})\s*\$\$",
    ),
    # The extraction turned the parentheses of "(N)" into ð and Þ
    "ferwerda-2015-impastor.txt": ("Ferwerda", r"ð(\d+)Þ()"),
}


#: The papers' text files: SPECREF_PAPERS_DIR, else ../shared/papers beside the repository.
PAPERS_DIR = Path(
    os.environ.get("SPECREF_PAPERS_DIR", Path(__file__).resolve().parents[4] / "shared" / "papers")
)


@pytest.mark.skipif(
    not PAPERS_DIR.is_dir(),
    reason="the papers' text files are not beside the repository (../shared/papers); set "
    "SPECREF_PAPERS_DIR to their folder to check the equation lists against them",
)
def test_equation_lists_match_the_paper_texts():
    folder = PAPERS_DIR
    papers = {p.author: p for p in PAPERS}
    for name, (author, pattern) in NUMBER_MARKS.items():
        text = (folder / name).read_text(encoding="utf-8")
        printed = [int(a or b) for a, b in re.findall(pattern, text)]
        assert printed == [e.number for e in papers[author].equations], name

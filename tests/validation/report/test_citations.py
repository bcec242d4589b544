"""Equation citations and the tests that name a function (validation.report.citations)."""

import pytest

from validation.report.citations import (
    called_names,
    collect_citations,
    is_kernel,
    kernel_reference,
    naming_tests,
    parse_citations,
    read_tests,
    registry_entries,
    registry_twins,
    resolve,
)


def test_parse_expands_ranges():
    assert parse_citations("Eqs. (12)-(14), Wang et al.") == [
        ("Wang et al.", "12", True),
        ("Wang et al.", "13", True),
        ("Wang et al.", "14", True),
    ]
    assert parse_citations("Eqs. (5)–(6), Ferwerda") == [
        ("Ferwerda", "5", True),
        ("Ferwerda", "6", True),
    ]


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("Eq. (11), Wang et al.", [("Wang et al.", "11", False)]),
        (
            "Eq. (7) and Eq. (11), Wang et al.",
            [("Wang et al.", "7", True), ("Wang et al.", "11", True)],
        ),
        (
            "Eqs. (7) and (11), Wang et al.",
            [("Wang et al.", "7", True), ("Wang et al.", "11", True)],
        ),
        (
            "Eq. (7), Ramamoorthi &\n    Hanrahan 2001",
            [("Ramamoorthi & Hanrahan 2001", "7", False)],
        ),
        ("Eq. (8.7), Ivanic & Ruedenberg 1996", [("Ivanic & Ruedenberg 1996", "8.7", False)]),
        ("the diffuse term of Eq. (2)", [(None, "2", False)]),
        ("Eq. (3), Wang", [("Wang", "3", False)]),
        ("Equation (3) and eq. 4", []),
    ],
)
def test_parse_lists_authors_and_bare_mentions(text, expected):
    assert parse_citations(text) == expected


def test_collect_reads_docstrings_comments_strings_and_owners(tmp_path, monkeypatch):
    package = tmp_path / "fake_cited_code"
    package.mkdir()
    (package / "__init__.py").write_text(
        '"""Module: Eq. (1), Ferwerda."""\n\n\n'
        "class A:\n"
        '    """Eq. (2), Ferwerda."""\n\n'
        "    def __init__(self):\n"
        '        """Eq. (3), Ferwerda.\n\n'
        '        >>> "Eq. (9), Ferwerda in a doctest"\n        """\n\n'
        "    def m(self):\n"
        "        def inner():\n"
        "            # Eq. (4), Ferwerda: a comment that\n"
        "            # goes on (Eq. (5), Ferwerda)\n"
        "            return 1\n\n"
        '        return "label: Eq. (6), Ferwerda"\n'
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    found = collect_citations(tmp_path, ("fake_cited_code",))
    assert sorted((c.number, c.owner, c.kind, c.line) for c in found) == [
        ("1", "fake_cited_code", "docstring", 1),
        ("2", "fake_cited_code.A", "docstring", 5),
        ("3", "fake_cited_code.A", "docstring", 8),  # a dunder method belongs to its class
        ("4", "fake_cited_code.A.m", "comment", 15),  # a nested function to the outer one
        ("5", "fake_cited_code.A.m", "comment", 15),  # consecutive comment lines are one text
        ("6", "fake_cited_code.A.m", "string", 19),
    ]


def test_called_names_belong_to_the_owners_of_citations(tmp_path, monkeypatch):
    package = tmp_path / "fake_calling_code"
    package.mkdir()
    (package / "__init__.py").write_text(
        "import functools\n\n\n"
        "@functools.lru_cache(maxsize=2)\n"  # a decorator runs in the enclosing scope
        "def f(x):\n"
        "    def inner():\n"
        "        return g(x)\n\n"  # a nested function's calls are the outer function's
        "    return inner() + x.h()\n\n\n"
        "class A:\n"
        "    def __init__(self):\n"
        "        self.v = f(1)\n\n"  # a dunder method's calls are its class's
        "    def m(self):\n"
        "        return k()\n\n\n"
        "TOP = sorted([2, 1])\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    calls = called_names(tmp_path, ("fake_calling_code",))
    assert calls == {
        "fake_calling_code": {"lru_cache", "sorted"},
        "fake_calling_code.f": {"inner", "g", "h"},
        "fake_calling_code.A": {"f"},
        "fake_calling_code.A.m": {"k"},
    }
    # the owners are those of the citations read from the same file
    (package / "__init__.py").write_text(
        (package / "__init__.py")
        .read_text()
        .replace("return k()", "return k()  # Eq. (4), Ferwerda")
    )
    found = collect_citations(tmp_path, ("fake_calling_code",))
    assert [c.owner for c in found] == ["fake_calling_code.A.m"]


def test_kernels_and_their_references():
    assert is_kernel("phong_table._kernels.tabulate_kernel")
    assert is_kernel("reference.geometry._raster_kernels.rasterize_triangles_kernel")
    assert not is_kernel("phong_table.table.tabulate")
    assert not is_kernel("shrm.kernels_of_lobes")  # only a private ``_*kernels`` module
    twins = registry_twins()
    # Source: phong_table/placement.py, PLACEMENT_METHODS: Method("error", table_error,
    # table_error_kernel, ...); Method("uniform", table_uniform, None, ...) has no kernel
    assert twins["phong_table.placement.table_error"] == {"phong_table._kernels.table_error_kernel"}
    assert twins["phong_table._kernels.table_error_kernel"] == {"phong_table.placement.table_error"}
    assert "phong_table.placement.table_uniform" not in twins
    # without a registry entry, f_kernel is the twin of f in the same package
    names = ["phong_table.table.tabulate", "shrm.tabulate", "phong_table._kernels.tabulate"]
    assert kernel_reference("phong_table._kernels.tabulate_kernel", names, {}) == names[0]
    assert kernel_reference("phong_table._kernels._helper", names, {}) == ""
    assert kernel_reference("impastor._kernels.tabulate_kernel", names, {}) == ""


def test_registry_entries_name_reference_and_kernel():
    entries = registry_entries()
    assert entries["phong_table.placement.table_error"] == {"PLACEMENT_METHODS['error']"}
    assert entries["phong_table._kernels.table_error_kernel"] == {"PLACEMENT_METHODS['error']"}


def test_registry_cites_are_citations_of_reference_and_kernel():
    found = collect_citations(packages=("reference",))
    cubemap = [c for c in found if c.kind == "registry" and "cubemap" in c.owner]
    # The cube-map transforms cite §7.1, Herbert et al., not an equation
    assert cubemap == []
    raster = {c.owner for c in found if c.kind == "registry" and c.author == "Pineda 1988"}
    assert raster == {
        "reference.geometry.raster.rasterize_triangles",
        "reference.geometry._raster_kernels.rasterize_triangles_kernel",
    }


def test_tests_of_puts_the_module_test_file_first_and_finds_registry_tests():
    tests = read_tests()
    found = naming_tests("phong_table.placement.table_error", ["PLACEMENT_METHODS['error']"], tests)
    assert found[0].startswith("tests/phong_table/test_placement.py::")
    # tests parametrized over PLACEMENT_METHODS check every entry
    assert "tests/phong_table/test_kernels.py::test_table_kernel_equals_numpy" in found
    assert naming_tests("phong_table.model.no_such_function", [], tests) == ()


def test_resolve():
    assert resolve("phong_table.model.SpectralPhong.an") is not None
    assert resolve("phong_table.model.SpectralPhong.nothing") is None
    assert resolve("no_such_package.f") is None

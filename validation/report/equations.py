"""The equation index: each numbered equation of the three papers, the code citing it, its tests.

``docs/equations.md`` is generated from this module (``make equations``, which runs ``specref
equations -o docs/equations.md``) and checked by ``tests/validation/report/test_equations.py``. The
source of truth is :data:`PAPERS`, the numbered equations of each paper read from its text (with the
section and a one-line description); everything else is found in the code:

- **Citations** (``Eq. (N), Wang et al.``, ``Eq. (N), Herbert et al.``, ``Eq. (N), Ferwerda``; lists
  and ranges expanded) in docstrings, comments and registry entries of every package
  (:func:`validation.report.citations.collect_citations`), each belonging to a function or class.
- **Which function computes the equation** (:data:`COMPUTES`): a function or class computes
  ``Eq. (N)`` when a comment in its body names it (STYLE.md §5: a comment names the equation its
  lines compute) and it calls no other function (a numba kernel aside) whose body comment names
  it; the others citing it (in a docstring, a registry's ``cites``, or a comment over a call of
  the computing function) use it. A numba kernel (a function of a ``_*kernels`` module) whose
  NumPy twin (the reference of its registry entry, or ``f`` for ``f_kernel``) also computes the
  equation is shown as that twin's.
- **Tests** that name each function, or are parametrized over its registry
  (:func:`validation.report.citations.naming_tests`).
- **Errata**: the entries of ``docs/errata.md`` whose bold title cites the equation (an equation
  without an author takes the paper of the entry's section).

Citations of other sources that give a year (``Eq. (7), Ramamoorthi & Hanrahan 2001``) are listed
as cited external equations, without a check of their numbers. :func:`equation_problems` lists what
breaks the index: a citation of an equation that the paper does not have, ``Eq. (N)`` without an
author or with an author that is neither a paper nor a source with a year, a range or list in a
comment (STYLE.md §5: comments name one equation each), an equation cited only in ranges or lists (a
grep for ``Eq. (N), Author`` would miss it), and an indexed function that cannot be imported.
"""

from __future__ import annotations

import re
import textwrap
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path

from reference.errors import require
from validation.report.citations import (
    ROOT,
    Citation,
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

__all__ = [
    "COMPUTES",
    "PAPERS",
    "REGENERATE",
    "Equation",
    "EquationRow",
    "IndexedFunction",
    "Paper",
    "equation_index",
    "equation_problems",
    "render_equation_index",
]

#: Another source's citation ends in its year: ``Ramamoorthi & Hanrahan 2001``.
_EXTERNAL = re.compile(r" \d{4}$")
#: The one command that regenerates ``docs/equations.md``.
REGENERATE = "make equations"
#: The rule that tells the function computing an equation from those using it (in the page).
COMPUTES = (
    "A function computes Eq. (N) when a comment in its body names the equation (STYLE.md §5: "
    "a comment names the equation its lines compute) and it calls no other function (a numba "
    "kernel aside) whose body comment names it; a docstring, a registry entry's `cites`, or a "
    "comment over a call of the computing function marks a use."
)


@dataclass(frozen=True)
class Equation:
    """One numbered equation of a paper: its number, section and a one-line description."""

    number: int
    section: str
    what: str
    note: str = ""


@dataclass(frozen=True)
class Paper:
    """A paper: the author string of its citations, its numbered equations, where they come from."""

    author: str
    title: str
    numbering: str
    equations: tuple[Equation, ...]


_WANG = (
    Equation(
        1,
        "§3.1",
        "Phong model: `I = I_a k_a + f_att I_p k_d cos θ + f_att I_p k_s cos^n α`, "
        "with `f_att = max(1/(c1 + c2 d_L + c3 d_L²), 1)`",
    ),
    Equation(
        2,
        "§3.1",
        "Spectral Phong model: `I(λ) = f_att I_p(λ) k_d(λ) cos θ + "
        "f_att I_p(λ) k_s(λ) cos^{n(λ)} α`",
    ),
    Equation(
        3,
        "§3.2",
        "CIE XYZ as integrals `k ∫ φ(λ) x̄(λ) dλ`",
        "computed as band integrals in the discrete form of Eq. (4) (erratum E7)",
    ),
    Equation(4, "§3.2", "Discrete XYZ: `X = k Σ_λ φ(λ) x̄(λ)`"),
    Equation(5, "§3.2", "RGB from XYZ: `[R G B] = [X Y Z] · XYZtoRGB`"),
    Equation(
        6,
        "§3.2",
        "XYZ of the spectral Phong model: Eq. (2) summed against the CMFs "
        "(the exact render of Figure 2)",
    ),
    Equation(7, "§3.2", "Eq. (6) with `k f_att cos θ` taken out of the diffuse sum"),
    Equation(
        8,
        "§3.2",
        "`X_sp, Y_sp, Z_sp`: the specular part of Eq. (7)",
        "computed as Eq. (11) in XYZ, without `f_att` (erratum E18)",
    ),
    Equation(9, "§3.2", "The spectra-to-RGB matrix: CMFs times XYZtoRGB"),
    Equation(
        10,
        "§3.2",
        "`R_sp, G_sp, B_sp`: the specular spectrum times the spectra-to-RGB matrix",
        "Eq. (11) at `t = cos α`",
    ),
    Equation(11, "§3.2", "The specular functions `[f_rsp f_gsp f_bsp](t)` of `t = cos α`"),
    Equation(12, "§3.2", "Importance ratio `ir(t₁) = ∫_0^t₁ f^app / ∫_0^1 f^app`"),
    Equation(13, "§3.2", "The proxy `f^app(t) = t^{an}`, `an` the average exponent"),
    Equation(14, "§3.2", "`ir(t) = t^{an+1}`, Eq. (12) in closed form"),
    Equation(15, "§3.2", "Inverse importance ratio `t = w^{1/(an+1)}`"),
    Equation(16, "§3.2", "Table nodes: `p` segments `S_i`, each of `m/p` equal intervals"),
)
_HERBERT = (
    Equation(
        1,
        "§5.1",
        "Shading sum `I_result = I_d + I_effect + I_r F_r + I_trans (1 − F_r)`",
        "`shrm.polymer.hybrid` (I_r read as I_s, erratum E5); not energy conserving as printed "
        "(E34); measured against the layered oracle `shrm.polymer.oracle` (E65–E69)",
    ),
    Equation(
        2,
        "§5.1",
        "Diffuse `I_d = E_d D_polymer Tint_polymer (1 − Mod_effect)`",
        "`shrm.polymer.hybrid`; the environment shaders' Lambert term is `E_d k_d` "
        "(no tint or effect)",
    ),
    Equation(
        3,
        "§5.1",
        "Effect `I_effect = E_effect Mod_effect`",
        "`shrm.polymer.hybrid`; E_effect from the pigment's SHRM "
        "(`effect_shrm`, `effect_radiance`)",
    ),
    Equation(
        4,
        "§5.1",
        "Transmission `I_trans = E_trans Col_trans`",
        "`shrm.polymer.hybrid`; E_trans from behind the surface is ours (erratum E33)",
    ),
    Equation(
        5,
        "§5.1",
        "Reflection `I_s = (E_s M_s + E_mirror (1 − M_s)) gloss`",
        "`shrm.polymer.hybrid` (M_s our design, E30); the environment shaders use `E_s k_s` "
        "(M_s = 1)",
    ),
    Equation(6, "§6", "Gamma calibration `Y = (G/255)^Gamma · Y_max`"),
    Equation(7, "§6", "L*-linear calibration `Y = (((G/255)·100 + 16)/116)³ · Y_max`"),
)
_FERWERDA = (
    Equation(
        1,
        "§3.4.1–3.4.2",
        "Display characterization: `XYZ = L_factor(θ,φ) [XYZ_max − XYZ_K] RGB + XYZ_K(θ,φ)`",
    ),
    Equation(
        2,
        "§3.5.1",
        "Illuminance `E = Σ_n L_n (N_surf·I_n)(N_light·I_n) (A/P) / d_n²` "
        "from 32 median-cut lights",
    ),
    Equation(3, "§3.5.1", "Diffuse reflection per channel `L_out,j = ρ_d,j S_j E / π`"),
    Equation(
        4, "§3.5.2", "Ward–Dür specular BRDF `ρ_s exp(−tan²θ_h/α²) / (4π α² cos θ_i cos θ_r)`"
    ),
    Equation(5, "§3.5.4", "Distance to the light plane `d = ((o_TL − p_surf)·n) / (i_world·n)`"),
    Equation(6, "§3.5.4", "Light intersection point `p_light = d i_world + p_surf`"),
    Equation(7, "§3.5.4", "Position on the light `p_relative = p_light − o_TL`"),
    Equation(8, "§3.5.4", "Unit pixel coordinates `(a, b) = pinv([l_A A, l_B B]) p_relative`"),
)

#: The numbered equations of each paper: the index's source of truth.
PAPERS = (
    Paper(
        "Wang et al.",
        "C.-M. Wang, J.-R. Chern, J. Lee, An Efficient Spectral Rendering Technique for Phong "
        "Illumination Model",
        'Printed as (1)–(16) at the right of each display; the prose calls them "equation (N)".',
        _WANG,
    ),
    Paper(
        "Herbert et al.",
        "F. Herbert, J. Kirkenaer, O. Unter Ecker, Achieving a Multi-spectral Virtual Reality "
        "(2004)",
        "Printed as (1)–(7) at the right of each display (§5.1 and §6). The prose of §6 calls "
        'Eq. (7) "equation 2".',
        _HERBERT,
    ),
    Paper(
        "Ferwerda",
        "J. A. Ferwerda, ImpastoR: A realistic surface display system, Vision Research 109 (2015)",
        "The text specref works from was extracted from the PDF and garbles the equations into "
        "runs of symbols; its parentheses come out as `ð` and `Þ` (`(θ,φ)` reads `ðh;/Þ`), so the "
        "numbers survive only as the markers `ð1Þ` … `ð8Þ` after each display, in reading order "
        'from §3.4.1 to §3.5.4. The prose cites the display characterization as "Eq. (1)" twice. '
        "specref numbers the equations (1)–(8) by those markers, as errata E11–E17 and "
        "docs/impastor.md do; the symbols are read as in E11 and E13–E16.",
        _FERWERDA,
    ),
)


@dataclass(frozen=True)
class IndexedFunction:
    """A function (or class) citing an equation, its registry entries and the tests naming it.

    ``computes`` follows :data:`COMPUTES`; ``calls`` names the functions whose body comment names
    the equation and that this one calls; ``kernel`` marks a numba kernel, ``twin`` its NumPy
    reference (or a reference's kernel) among the functions citing the equation.
    """

    name: str
    registered: tuple[str, ...] = ()
    grouped_only: bool = False
    tests: tuple[str, ...] = ()
    doctest: bool = False
    computes: bool = False
    calls: tuple[str, ...] = ()
    kernel: bool = False
    twin: str = ""


@dataclass(frozen=True)
class EquationRow:
    """One row of the index: an equation of a paper and what implements, tests and corrects it."""

    author: str
    number: int
    section: str
    what: str
    note: str
    functions: tuple[IndexedFunction, ...] = ()
    errata: tuple[str, ...] = ()

    @property
    def computed_by(self) -> tuple[IndexedFunction, ...]:
        """The functions computing the equation, NumPy first; a kernel only if its twin does not."""
        computing = {f.name for f in self.functions if f.computes}
        shown = [f for f in self.functions if f.computes and not (f.kernel and f.twin in computing)]
        return tuple(sorted(shown, key=lambda f: (f.kernel, f.name)))

    @property
    def used_by(self) -> tuple[IndexedFunction, ...]:
        """The functions citing the equation without computing it."""
        return tuple(f for f in self.functions if not f.computes)

    def kernel_twin(self, function: IndexedFunction) -> IndexedFunction | None:
        """The numba kernel computing the equation beside the NumPy ``function``, if any."""
        twins = [f for f in self.functions if f.kernel and f.computes and f.twin == function.name]
        return twins[0] if twins and not function.kernel else None


def _errata(root: Path) -> dict[tuple[str, str], set[str]]:
    """``(author, number) -> {"E<k>"}`` from the bold titles of ``docs/errata.md``."""
    found: dict[tuple[str, str], set[str]] = defaultdict(set)
    section_author = None
    for line in (root / "docs" / "errata.md").read_text(encoding="utf-8").splitlines():
        if line.startswith("## "):
            section_author = next(
                (p.author for p in PAPERS if line[3:].startswith(p.author.split()[0])), None
            )
        title = re.match(r"- \*\*(E\d+)\. (.*?)\*\*", line)
        if title:
            for author, number, _ in parse_citations(title.group(2)):
                if author or section_author:
                    found[(author or section_author, number)].add(title.group(1))
    return found


# --- the index ---------------------------------------------------------------------------------


def _is_function(c: Citation) -> bool:
    """Whether the citation is a function's or class's docstring, comment or registry entry.

    Module docstrings and other string constants (labels, ``Method(...)`` arguments, which the
    registries give) are checked but not indexed.
    """
    module = c.path[:-3].replace("/", ".").removesuffix(".__init__")
    return c.kind != "string" and "[" not in c.owner and c.owner != module


def _short(name: str) -> str:
    return name.rsplit(".", 1)[-1]


def _row_functions(cited, commented, calls, registered, twins, tests):
    """The :class:`IndexedFunction` of each function citing one equation.

    ``cited`` maps each function citing it to whether it does so only in ranges or lists;
    ``commented`` holds those whose body comment names it (see :data:`COMPUTES`).
    """
    kernels = {n: kernel_reference(n, cited, twins) for n in cited if is_kernel(n)}
    functions = []
    for name, grouped_only in sorted(cited.items()):
        called = tuple(
            other
            for other in sorted(commented)
            if other != name and not is_kernel(other) and _short(other) in calls.get(name, ())
        )
        twin = kernels.get(name) or next((k for k, t in sorted(kernels.items()) if t == name), "")
        functions.append(
            IndexedFunction(
                name,
                tuple(sorted(registered.get(name, ()))),
                grouped_only,
                naming_tests(name, registered.get(name, set()), tests),
                ">>>" in (getattr(resolve(name), "__doc__", None) or ""),
                computes=name in commented and not called,
                calls=called if name in commented else (),
                kernel=name in kernels,
                twin=twin,
            )
        )
    return tuple(functions)


def equation_index(root: Path | None = None, citations=None, calls=None) -> list[EquationRow]:
    """One row per numbered equation of each paper, in :data:`PAPERS` order.

    Parameters
    ----------
    root : Path, optional
        The repository root (default: the one this module is in).
    citations : list of Citation, optional
        Default :func:`collect_citations` (tests pass their own).
    calls : dict, optional
        ``function -> {names it calls}``, default
        :func:`~validation.report.citations.called_names` (tests pass their own).

    Returns
    -------
    list of EquationRow
        The functions (and classes) citing the equation, each with its registry entries, the
        tests that name it and whether it computes the equation (:data:`COMPUTES`), and the errata
        whose title cites the equation.

    Examples
    --------
    >>> rows = {(r.author, r.number): r for r in equation_index()}
    >>> [f.name for f in rows["Wang et al.", 15].functions]
    ['phong_table.placement.inverse_importance_ratio_Wang',
     'phong_table.placement.table_importance_Wang']
    >>> [f.name for f in rows["Wang et al.", 15].computed_by]
    ['phong_table.placement.inverse_importance_ratio_Wang']
    >>> "shrm.polymer.hybrid.polymer_terms" in [f.name for f in rows["Herbert et al.", 3].functions]
    True
    """
    root = ROOT if root is None else Path(root)
    require((root / "tests").is_dir(), f"equation index: no tests/ folder in {root}")
    citations = collect_citations(root) if citations is None else citations
    calls = called_names(root) if calls is None else calls
    registered, twins = registry_entries(root), registry_twins(root)
    tests, errata = read_tests(root), _errata(root)
    # (author, number) -> {owner: cited only in ranges or lists}
    owners: dict[tuple[str, str], dict[str, bool]] = defaultdict(dict)
    # (author, number) -> {owners with a body comment naming it}
    commented: dict[tuple[str, str], set[str]] = defaultdict(set)
    for c in citations:
        if c.author and _is_function(c):
            seen = owners[(c.author, c.number)]
            seen[c.owner] = seen.get(c.owner, True) and c.grouped
            if c.kind == "comment":
                commented[(c.author, c.number)].add(c.owner)
    rows = []
    for paper in PAPERS:
        for eq in paper.equations:
            key = (paper.author, str(eq.number))
            functions = _row_functions(
                owners.get(key, {}), commented.get(key, set()), calls, registered, twins, tests
            )
            found = tuple(sorted(errata.get(key, ()), key=lambda e: int(e[1:])))
            rows.append(
                EquationRow(paper.author, eq.number, eq.section, eq.what, eq.note, functions, found)
            )
    return rows


def equation_problems(citations=None, rows=None) -> list[str]:
    """What breaks the index, one line each (an empty list when the code and the index agree).

    - a citation of an equation that its paper does not have;
    - ``Eq. (N)`` without an author, or with one that is neither a paper of :data:`PAPERS` nor a
      source with a year (STYLE.md §5: one grep must find each equation);
    - a range or list in a comment (STYLE.md §5: comments name one equation each);
    - an equation that functions cite only in ranges or lists;
    - a function in the index that cannot be imported.

    Parameters
    ----------
    citations : list of Citation, optional
        Default :func:`collect_citations`.
    rows : list of EquationRow, optional
        Default :func:`equation_index` of ``citations``.

    Examples
    --------
    >>> equation_problems([Citation("x.py", 3, "x.f", "comment", "Wang et al.", "17")], rows=[])
    ['x.py:3: x.f cites Eq. (17), Wang et al., which the paper does not have (it has (1)-(16))']
    """
    citations = collect_citations() if citations is None else citations
    rows = equation_index(citations=citations) if rows is None else rows
    papers = {p.author: p for p in PAPERS}
    problems, bare, grouped = [], defaultdict(list), defaultdict(list)
    for c in citations:
        where = f"{c.path}:{c.line}: {c.owner}" if c.line else f"{c.path}: {c.entry or c.owner}"
        numbers = [str(e.number) for e in papers[c.author].equations] if c.author in papers else []
        if numbers and c.number not in numbers:
            problems.append(
                f"{where} cites Eq. ({c.number}), {c.author}, which the paper does not have "
                f"(it has (1)-({numbers[-1]}))"
            )
        if c.author is None:
            bare[where].append(c.number)
        elif c.author not in papers and not _EXTERNAL.search(c.author):
            problems.append(
                f"{where} cites Eq. ({c.number}), {c.author}: not a paper of the index "
                f"({', '.join(papers)}), nor a source with a year"
            )
        elif c.grouped and c.kind == "comment":
            grouped[where].append(c.number)
    problems += [
        f"{where} mentions {_numbers(n)} without an author (write `Eq. (N), Author`)"
        for where, n in bare.items()
    ]
    problems += [
        f"{where}: a comment cites {_numbers(n)} as a range or list (cite each `Eq. (N), Author`)"
        for where, n in grouped.items()
    ]
    for row in rows:
        if row.functions and all(f.grouped_only for f in row.functions):
            problems.append(
                f"Eq. ({row.number}), {row.author} is cited only in ranges or lists "
                f"(by {', '.join(f.name for f in row.functions)}); cite it on its own"
            )
        problems += [
            f"Eq. ({row.number}), {row.author}: {f.name} does not exist (not importable)"
            for f in row.functions
            if resolve(f.name) is None
        ]
    return sorted(set(problems))


def _numbers(numbers: list[str]) -> str:
    return ", ".join(f"Eq. ({n})" for n in dict.fromkeys(numbers))


# --- Markdown ----------------------------------------------------------------------------------


def _tested(function: IndexedFunction, shown: int = 2) -> str:
    """The first ``shown`` tests naming a function, and how many more."""
    if not function.tests:
        return "no test names it" + (" (its doctest runs)" if function.doctest else "")
    first = ", ".join(f"`{t}`" for t in function.tests[:shown])
    more = len(function.tests) - shown
    return f"tested by {first}" + (f" and {more} more" if more > 0 else "")


def _computing(row: EquationRow, function: IndexedFunction) -> str:
    """One function computing the equation: name, registry entries, tests, its kernel twin."""
    notes = [f"`{r}`" for r in function.registered]
    if function.kernel:
        notes.append("numba kernel" + (f", twin of `{function.twin}`" if function.twin else ""))
    text = f"`{function.name}`" + (f" ({', '.join(notes)})" if notes else "")
    text += f"; {_tested(function)}"
    twin = row.kernel_twin(function)
    if twin:
        text += f"; numba twin `{twin.name}`, {_tested(twin, 1)}"
    return text


def _using(function: IndexedFunction) -> str:
    """One function using the equation, compactly: name, registry entries, calls, tests."""
    notes = [", ".join(f"`{r}`" for r in function.registered)] if function.registered else []
    if function.calls:
        notes.append("calls " + ", ".join(f"`{_short(c)}`" for c in function.calls))
    if function.grouped_only:
        notes.append("only in a range or list")
    n = len(function.tests)
    if n:
        notes.append(f"{n} test{'s' * (n != 1)}")
    else:
        notes.append("no test names it" + ("; its doctest runs" if function.doctest else ""))
    return f"`{function.name}` ({'; '.join(notes)})"


def _row_markdown(row: EquationRow) -> list[str]:
    lines = [f"### Eq. ({row.number}), {row.author}", "", f"{row.section}. {row.what}.", ""]
    if row.note:
        lines += [f"*{row.note[0].upper()}{row.note[1:]}.*", ""]
    if row.computed_by:
        lines += ["- **Computed by**:", *[f"  - {_computing(row, f)}" for f in row.computed_by]]
    else:
        lines += ["- **Computed by**: none found (no comment in a function body names it)."]
    used = row.used_by
    if used:
        lines += [f"- **Used by** ({len(used)}): " + ", ".join(_using(f) for f in used) + "."]
    elif not row.functions:
        lines += ["- **Used by**: none (no function cites it)."]
    else:
        lines += ["- **Used by**: none."]
    if row.errata:
        lines += [f"- Errata: {', '.join(row.errata)} (docs/errata.md)."]
    return [*lines, ""]


def _external(citations) -> list[str]:
    """The table of cited external equations: source, equation, functions."""
    cited: dict[tuple[str, str], set[str]] = defaultdict(set)
    for c in citations:
        if c.author and _EXTERNAL.search(c.author) and _is_function(c):
            cited[(c.author, c.number)].add(c.owner)
    lines = ["| source | equation | functions |", "|---|---|---|"]
    for (author, number), owners in sorted(
        cited.items(), key=lambda kv: (kv[0][0], [int(x) for x in kv[0][1].split(".")])
    ):
        names = ", ".join(f"`{o}`" for o in sorted(owners))
        lines.append(f"| {author} | Eq. ({number}) | {names} |")
    return lines


def render_equation_index(root: Path | None = None, citations=None, calls=None) -> str:
    """``docs/equations.md``: the summary table, then each paper's equations, then the others.

    ``citations`` and ``calls`` are passed to :func:`equation_index`.

    Examples
    --------
    >>> text = render_equation_index()
    >>> text.splitlines()[0], "### Eq. (12), Wang et al." in text
    ('# Equation index', True)
    """
    root = ROOT if root is None else Path(root)
    citations = collect_citations(root) if citations is None else citations
    rows = equation_index(root, citations, calls)
    lines = [
        "# Equation index",
        "",
        f"Generated by `{REGENERATE}` (`specref equations -o docs/equations.md`) from",
        "`validation/report/equations.py`; do not edit by hand.",
        "`tests/validation/report/test_equations.py` fails when this page is out of date, when",
        "code cites an equation that a paper does not have or cites one without an author, and",
        "when a function named here does not exist.",
        "For each numbered equation of each paper: the functions and classes whose docstring,",
        "comments or registry entry cite it (`Eq. (N), Author`), split into those that compute",
        "it and those that use it, the tests that name each one, and the errata whose title cites",
        "the equation.",
        "",
        *textwrap.wrap(
            f"**Computes or uses.** {COMPUTES} A numba kernel whose NumPy twin (the reference of "
            "its registry entry, or `f` for `f_kernel`) also computes the equation is shown as "
            "that twin's. Where no comment in a function body names an equation, its row says "
            "so (**none**): a finding about the code, not an error of the index.",
            92,
        ),
        "",
        "| paper | Eq. | § | computed by | used by | errata | note |",
        "|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        computed = ", ".join(f"`{_short(f.name)}`" for f in row.computed_by) or "**none**"
        lines.append(
            f"| {row.author} | ({row.number}) | {row.section} | {computed} | "
            f"{len(row.used_by)} | {', '.join(row.errata)} | {row.note} |"
        )
    for paper in PAPERS:
        lines += ["", f"## {paper.author}: {paper.title}", "", f"Numbering: {paper.numbering}", ""]
        for row in (r for r in rows if r.author == paper.author):
            lines += _row_markdown(row)
    lines += [
        "## Cited external equations",
        "",
        "Equations of other sources that the code cites, with the functions citing them; their",
        "numbers are not checked.",
        "",
        *_external(citations),
    ]
    problems = equation_problems(citations, rows)
    if problems:
        lines += ["", "## Problems", "", *[f"- {p}" for p in problems]]
    return "\n".join(lines) + "\n"

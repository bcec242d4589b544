"""Equation citations in the code and the tests that name a function: what the equation index reads.

A citation follows the fixed format of STYLE.md §5, ``Eq. (N), Author`` (``Eq. (11), Wang et al.``,
``Eq. (4), Ferwerda``, ``Eq. (7), Ramamoorthi & Hanrahan 2001``), also as a list sharing one author
(``Eq. (7) and Eq. (11), Wang et al.``, ``Eqs. (7) and (11), Wang et al.``) or a range (``Eqs.
(5)-(8), Ferwerda``), which :func:`parse_citations` expands and marks as *grouped*.
:func:`collect_citations` reads them with :mod:`ast` and :mod:`tokenize` from docstrings (doctest
lines left out), other string constants and comments (consecutive comment lines joined) in every
package, and from the registries' ``cites``. A docstring or comment belongs to its enclosing
function or class (a nested function's, or a dunder method's, to the enclosing one); a registry
entry's to its ``reference`` (or ``cls``) and its ``kernel``. :func:`called_names` reads, with the
same owners, the names each function or class calls, and :func:`registry_twins` pairs each NumPy
reference with its numba kernel (STYLE.md §6); the index reads from them which function computes
an equation and which ones call it. :func:`read_tests` and :func:`naming_tests` find the tests that
name a function. ``validation.report.equations`` builds the index from them.
"""

from __future__ import annotations

import ast
import functools
import importlib
import importlib.util
import io
import pkgutil
import re
import tokenize
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path

from reference.registry import Registry

__all__ = [
    "PACKAGES",
    "ROOT",
    "Citation",
    "called_names",
    "collect_citations",
    "is_kernel",
    "kernel_reference",
    "naming_tests",
    "parse_citations",
    "read_tests",
    "registry_entries",
    "registry_twins",
    "resolve",
]

#: The repository root (sources, ``tests/`` and ``docs/`` are read there).
ROOT = Path(__file__).resolve().parents[2]
#: The packages whose code is read.
PACKAGES = ("reference", "phong_table", "shrm", "impastor", "validation")
#: Files not read: the equation index's own data (descriptions of the papers' equations).
SKIP = ("validation/report/equations.py",)


@dataclass(frozen=True)
class Citation:
    """One citation found in the code; ``author`` is None for ``Eq. (N)`` without an author."""

    path: str
    line: int
    owner: str
    kind: str
    author: str | None
    number: str
    grouped: bool = False
    entry: str = ""


_NUMBER = r"\((\d+(?:\.\d+)?)\)"
_ONE = rf"Eqs?\.\s*{_NUMBER}(?:\s*[-–]\s*{_NUMBER})?"
_MORE = r"(?:\s*,\s*and\s+|\s*,\s*|\s+and\s+)(?:Eqs?\.\s*)?\(\d+\)(?:\s*[-–]\s*\(\d+\))?"
#: An author: ``Ferwerda``, ``Wang et al.``, ``Ramamoorthi & Hanrahan 2001``, ``Walter et al. 2007``
_AUTHOR = r"[A-Z][\w\-]+(?: (?:&|and) [A-Z][\w\-]+)?(?: et al\.)?(?: \d{4})?"
_CHAIN = re.compile(rf"{_ONE}(?:{_MORE})*(?:,\s*(?P<author>{_AUTHOR}))?")
_PART = re.compile(r"\((\d+(?:\.\d+)?)\)(?:\s*[-–]\s*\((\d+)\))?")


def parse_citations(text: str) -> list[tuple[str | None, str, bool]]:
    """``(author, number, grouped)`` for each equation cited in ``text`` (whitespace-normalized).

    ``grouped`` marks an equation cited in a range or a list that shares one author, which a grep
    for ``Eq. (N), Author`` does not find.

    Examples
    --------
    >>> parse_citations("Eq. (11), Wang et al.; Eqs. (5)-(6), Ferwerda; Eq. (3)")
    [('Wang et al.', '11', False), ('Ferwerda', '5', True), ('Ferwerda', '6', True),
     (None, '3', False)]
    """
    found = []
    for match in _CHAIN.finditer(re.sub(r"\s+", " ", text)):
        author = match.group("author")
        chain = (
            match.group(0)[: match.start("author") - match.start()] if author else match.group(0)
        )
        numbers = []
        for part in _PART.finditer(chain):
            first, last = part.group(1), part.group(2)
            if last is None or "." in first:
                numbers.append(first)
            else:
                numbers += [str(n) for n in range(int(first), int(last) + 1)]
        found += [(author, number, len(numbers) > 1) for number in numbers]
    return found


def _without_doctests(doc: str) -> str:
    """A docstring without its doctest lines (a doctest is code, not a citation)."""
    return "\n".join(s for s in doc.splitlines() if not s.lstrip().startswith((">>>", "...")))


class _Owners(ast.NodeVisitor):
    """Maps each line to the outermost importable function or class around it (``""``: module)."""

    def __init__(self, docstrings: set[int]):
        self.docstrings, self.stack, self.spans, self.texts = docstrings, [], [], []
        self.calls: list[tuple[str, str]] = []  # (owner, name called)

    def _scope(self, node):
        kind = "class" if isinstance(node, ast.ClassDef) else "function"
        top = self.stack[-1] if self.stack else ("", "module")
        dunder = node.name.startswith("__") and node.name.endswith("__")
        if top[1] == "function" or (top[1] == "class" and dunder):  # belongs to the outer scope
            owner = top[0]
        else:
            owner = ".".join([s[0] for s in self.stack[-1:]] + [node.name])
        self.spans.append((node.lineno, node.end_lineno, owner, len(self.stack)))
        doc = ast.get_docstring(node)
        if doc:
            self.texts.append((node.body[0].lineno, owner, "docstring", doc))
        decorators = {id(d) for d in node.decorator_list}
        for decorator in node.decorator_list:  # run in the enclosing scope
            self.visit(decorator)
        self.stack.append((owner, kind))
        for child in ast.iter_child_nodes(node):
            if id(child) not in decorators:
                self.visit(child)
        self.stack.pop()

    visit_FunctionDef = visit_AsyncFunctionDef = visit_ClassDef = _scope

    def visit_Call(self, node):
        name = getattr(node.func, "id", None) or getattr(node.func, "attr", None)
        if name:
            self.calls.append((self.stack[-1][0] if self.stack else "", name))
        self.generic_visit(node)

    def visit_Constant(self, node):
        if isinstance(node.value, str) and "Eq" in node.value and id(node) not in self.docstrings:
            self.texts.append((node.lineno, None, "string", node.value))

    def owner(self, line: int) -> str:
        """The owner of ``line``: the innermost scope's (``""`` at module level)."""
        spans = [s for s in self.spans if s[0] <= line <= s[1]]
        return max(spans, key=lambda s: s[3])[2] if spans else ""


def _comment_blocks(source: str) -> list[tuple[int, str]]:
    """Consecutive comment lines joined into one text each, with the first line's number."""
    blocks: list[tuple[int, str]] = []
    last = -2
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        if token.type != tokenize.COMMENT:
            continue
        line, text = token.start[0], token.string.lstrip("#").strip()
        if line == last + 1 and blocks:
            blocks[-1] = (blocks[-1][0], blocks[-1][1] + " " + text)
        else:
            blocks.append((line, text))
        last = line
    return blocks


def _read(path: Path, root: Path):
    """``(source, tree, module, owners)`` of one source file, its owners visited.

    Parsed once per file version in a process (the index reads every file twice: citations and
    calls); an edited file (another size or modification time) is parsed again.
    """
    stat = path.stat()
    return _read_version(path, root, stat.st_mtime_ns, stat.st_size)


@functools.lru_cache(maxsize=4096)
def _read_version(path: Path, root: Path, mtime_ns: int, size: int):
    source = path.read_text(encoding="utf-8")
    tree = ast.parse(source)
    module = path.relative_to(root).as_posix()[:-3].replace("/", ".").removesuffix(".__init__")
    owners = _Owners({id(n.body[0].value) for n in ast.walk(tree) if _has_docstring(n)})
    owners.visit(tree)
    return source, tree, module, owners


def _file_citations(path: Path, root: Path) -> tuple[Citation, ...]:
    """The citations in one source file: docstrings, other string constants and comments.

    Found once per file version in a process, as :func:`_read` parses once.
    """
    stat = path.stat()
    return _file_citations_version(path, root, stat.st_mtime_ns, stat.st_size)


@functools.lru_cache(maxsize=4096)
def _file_citations_version(path: Path, root: Path, mtime_ns: int, size: int):
    source, tree, module, owners = _read_version(path, root, mtime_ns, size)
    relative = path.relative_to(root).as_posix()
    texts = [(t[0], t[1], t[2], _without_doctests(t[3])) for t in owners.texts]
    module_doc = ast.get_docstring(tree)
    if module_doc:
        texts.append((1, "", "docstring", _without_doctests(module_doc)))
    texts += [(line, None, "comment", text) for line, text in _comment_blocks(source)]
    found = []
    for line, owner, kind, text in texts:
        owner = owners.owner(line) if owner is None else owner
        name = f"{module}.{owner}" if owner else module
        for author, number, grouped in parse_citations(text):
            found.append(Citation(relative, line, name, kind, author, number, grouped))
    return tuple(found)


def _sources(root: Path, packages):
    for package in packages:
        for path in sorted((root / package).rglob("*.py")):
            if path.relative_to(root).as_posix() not in SKIP:
                yield path


def called_names(root: Path | None = None, packages=PACKAGES) -> dict[str, frozenset[str]]:
    """``owner -> {names}``: the names that each function or class of ``packages`` calls.

    A call ``f(...)`` gives ``f`` and ``x.f(...)`` gives ``f``; a call belongs to its owner as a
    citation does (a nested function's or a dunder method's to the enclosing one), so
    ``owner`` is a :attr:`Citation.owner`.

    Examples
    --------
    >>> calls = called_names(packages=("phong_table",))
    >>> "inverse_importance_ratio_Wang" in calls["phong_table.placement.table_importance_Wang"]
    True
    """
    root = ROOT if root is None else Path(root)
    calls: dict[str, set[str]] = defaultdict(set)
    for path in _sources(root, packages):
        module, owners = _read(path, root)[2:]
        for owner, name in owners.calls:
            calls[f"{module}.{owner}" if owner else module].add(name)
    return {owner: frozenset(names) for owner, names in calls.items()}


def _has_docstring(node) -> bool:
    return (
        isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
        and ast.get_docstring(node) is not None
    )


def _modules(packages):
    for package in packages:
        module = importlib.import_module(package)
        yield module
        for info in pkgutil.walk_packages(module.__path__, prefix=f"{package}."):
            if not info.name.endswith(".__main__"):
                yield importlib.import_module(info.name)


def _qualified(obj) -> str | None:
    """``module.qualname`` of a function or class, or None (a lambda, a partial, a local)."""
    module, qualname = getattr(obj, "__module__", None), getattr(obj, "__qualname__", None)
    if not module or not qualname or "<" in qualname:
        return None
    return f"{module}.{qualname}"


def _registry_homes(root: Path, packages) -> dict[str, set[str]]:
    """``NAME -> {modules}`` for each module-level ``NAME = Registry(...)`` in the sources."""
    homes = defaultdict(set)
    for package in packages:
        for path in sorted((root / package).rglob("*.py")):
            for node in ast.parse(path.read_text(encoding="utf-8")).body:
                if (
                    isinstance(node, ast.Assign)
                    and isinstance(node.value, ast.Call)
                    and ast.unparse(node.value.func).endswith("Registry")
                ):
                    module = path.relative_to(root).as_posix()[:-3].replace("/", ".")
                    for target in node.targets:
                        homes[ast.unparse(target)].add(module.removesuffix(".__init__"))
    return homes


@functools.lru_cache(maxsize=4)
def _registry_citations(root: Path, packages):
    """Citations in registry entries' ``cites``, ``function -> {registry names}``, twins."""
    homes = _registry_homes(root, packages)
    seen, found, registered, twins = set(), [], defaultdict(set), defaultdict(set)
    modules = list(_modules(packages))  # all imported first: importing one can register in another
    for module in modules:
        for var, registry in vars(module).items():
            if not isinstance(registry, Registry) or id(registry) in seen:
                continue
            if module.__name__ not in homes.get(var, ()):
                continue
            seen.add(id(registry))
            for key, entry in registry.items():
                where = f"{module.__name__}.{var}[{key!r}]"
                targets = [getattr(entry, a, None) for a in ("reference", "cls", "kernel")]
                names = [n for n in map(_qualified, targets) if n]
                for name in names:
                    registered[name].add(f"{var}[{key!r}]")
                reference, kernel = (
                    _qualified(getattr(entry, a, None)) for a in ("reference", "kernel")
                )
                if reference and kernel and reference != kernel:
                    twins[reference].add(kernel)
                    twins[kernel].add(reference)
                path = module.__name__.replace(".", "/") + ".py"
                for author, number, grouped in parse_citations(getattr(entry, "cites", "") or ""):
                    for name in names or [where]:
                        found.append(
                            Citation(path, 0, name, "registry", author, number, grouped, where)
                        )
    return found, registered, twins


def is_kernel(name: str) -> bool:
    """Whether ``name`` is in a ``_*kernels`` module: numba code, a NumPy reference's twin.

    Examples
    --------
    >>> is_kernel("phong_table._kernels.tabulate_kernel"), is_kernel("phong_table.table.tabulate")
    (True, False)
    """
    return any(p.startswith("_") and p.endswith("kernels") for p in name.split(".")[:-1])


def kernel_reference(kernel: str, names, twins: dict[str, set[str]]) -> str:
    """A kernel's NumPy reference (STYLE.md §6), or ``""``.

    The reference of the kernel's registry entry (one of ``names`` first), else the function of
    ``names`` in the same package that ``f_kernel`` is named after: ``f``.

    Examples
    --------
    >>> kernel_reference("phong_table._kernels.tabulate_kernel", ["phong_table.table.tabulate"], {})
    'phong_table.table.tabulate'
    """
    registered = sorted(twins.get(kernel, ()), key=lambda t: (t not in names, t))
    if registered:
        return registered[0]
    short = kernel.rsplit(".", 1)[-1]
    if not short.endswith("_kernel"):
        return ""
    package = kernel.split(".")[0]
    return next(
        (
            name
            for name in sorted(names)
            if name.rsplit(".", 1)[-1] == short.removesuffix("_kernel")
            and name.split(".")[0] == package
            and not is_kernel(name)
        ),
        "",
    )


def collect_citations(root: Path | None = None, packages=PACKAGES) -> list[Citation]:
    """Every equation citation in the code of ``packages``, sorted by file and line.

    Parameters
    ----------
    root : Path, optional
        The repository root (default: the one this module is in).
    packages : tuple of str
        Top-level packages to read.

    Returns
    -------
    list of Citation
        With ``author=None`` for an ``Eq. (N)`` that names no author.

    Examples
    --------
    >>> cites = collect_citations(packages=("phong_table",))
    >>> any(c.owner == "phong_table.placement.importance_ratio_Wang" and c.number == "14"
    ...     for c in cites)
    True
    """
    root = ROOT if root is None else Path(root)
    found = []
    for path in _sources(root, packages):
        found += _file_citations(path, root)
    found += _registry_citations(root, packages)[0]
    return sorted(set(found), key=lambda c: (c.path, c.line, c.owner, c.number))


def registry_entries(root: Path | None = None, packages=PACKAGES) -> dict[str, set[str]]:
    """``function -> {"NAME['key']"}``: the registry entries whose reference, class or kernel it is.

    Examples
    --------
    >>> sorted(registry_entries()["phong_table.placement.table_importance_Wang"])
    ["PLACEMENT_METHODS['importance']"]
    """
    return _registry_citations(ROOT if root is None else Path(root), tuple(packages))[1]


def registry_twins(root: Path | None = None, packages=PACKAGES) -> dict[str, set[str]]:
    """``function -> {twins}``: the kernel of a registry entry's reference, and the reverse.

    Examples
    --------
    >>> sorted(registry_twins()["phong_table.placement.table_error"])
    ['phong_table._kernels.table_error_kernel']
    """
    return _registry_citations(ROOT if root is None else Path(root), tuple(packages))[2]


# --- tests naming a function ------------------------------------------------------------------


def _names(node) -> set[str]:
    """The names and attribute names used anywhere in ``node``."""
    names = {n.id for n in ast.walk(node) if isinstance(n, ast.Name)}
    return names | {n.attr for n in ast.walk(node) if isinstance(n, ast.Attribute)}


@dataclass(frozen=True)
class _Test:
    """A test function: names its body and decorators use, its strings, its file's imports."""

    id: str
    names: frozenset
    decorators: frozenset
    strings: frozenset
    modules: frozenset  # modules the file imports (``import a.b``, ``from a import b`` if a module)
    imported: tuple  # ``(name, from module)`` of the file's ``from ... import`` statements


def read_tests(root: Path | None = None) -> list[_Test]:
    """Every test function under ``tests/``, with the names it uses and its file's imports.

    Examples
    --------
    >>> tests = read_tests()
    >>> any(t.id.endswith("test_citations.py::test_parse_expands_ranges") for t in tests)
    True
    """
    root = ROOT if root is None else Path(root)
    tests = []
    for path in sorted((root / "tests").rglob("test_*.py")):
        stat = path.stat()
        tests += _file_tests(path, root, stat.st_mtime_ns, stat.st_size)
    return tests


@functools.lru_cache(maxsize=4096)
def _file_tests(path: Path, root: Path, mtime_ns: int, size: int) -> tuple[_Test, ...]:
    """The test functions of one test file, read once per file version in a process."""
    tests = []
    tree = ast.parse(path.read_text(encoding="utf-8"))
    modules, imported = set(), set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            modules |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            modules.add(node.module)
            modules |= {f"{node.module}.{a.name}" for a in node.names}
            imported |= {(a.name, node.module) for a in node.names}
    functions = [(n, "") for n in tree.body if isinstance(n, ast.FunctionDef)]
    for cls in (n for n in tree.body if isinstance(n, ast.ClassDef)):
        functions += [(n, f"{cls.name}::") for n in cls.body if isinstance(n, ast.FunctionDef)]
    for node, prefix in functions:
        if node.name.startswith("test"):
            strings = {n.value for n in ast.walk(node) if isinstance(n, ast.Constant) and n.value}
            tests.append(
                _Test(
                    f"{path.relative_to(root).as_posix()}::{prefix}{node.name}",
                    frozenset(_names(node)),
                    frozenset().union(*(_names(d) for d in node.decorator_list)),
                    frozenset(v for v in strings if isinstance(v, str)),
                    frozenset(modules),
                    tuple(sorted(imported)),
                )
            )
    return tuple(tests)


def _split(name: str) -> tuple[str, str]:
    """``(module, qualname)`` of a dotted name: the longest prefix that is a module."""
    parts = name.split(".")
    for split in range(len(parts) - 1, 0, -1):
        module = ".".join(parts[:split])
        try:
            if importlib.util.find_spec(module) is not None:
                return module, ".".join(parts[split:])
        except (ImportError, ValueError):
            continue
    return "", name


def _names_function(test: _Test, module: str, qualname: str) -> bool:
    """Whether ``test`` names the function ``module.qualname`` and its file imports it."""
    first, short = qualname.split(".")[0], qualname.split(".")[-1]
    if short not in test.names:
        return False
    package = module.split(".")[0]
    return any(m in (module, package) for m in test.modules) or any(
        name == first and module.startswith(source) for name, source in test.imported
    )


def naming_tests(name: str, registries, tests: list[_Test]) -> tuple[str, ...]:
    """Tests naming the function (its module's test file first), then its registry entries' tests.

    An entry's tests are parametrized over the registry, or name the registry and the entry's key.

    Parameters
    ----------
    name : str
        ``package.module.Qual.name`` of the function or class.
    registries : iterable of str
        Its registry entries, ``"NAME['key']"``.
    tests : list
        From :func:`read_tests`.

    Examples
    --------
    >>> naming_tests("phong_table.placement.inverse_importance_ratio_Wang", (), read_tests())[0]
    'tests/phong_table/test_placement.py::test_ir_of_iir_is_identity'
    """
    module, qualname = _split(name)
    short = qualname.split(".")[-1]
    mirror = "tests/" + "/".join(module.split(".")[:-1]) + f"/test_{module.split('.')[-1]}.py::"
    mirror = mirror.replace("test__", "test_")
    direct = [t.id for t in tests if _names_function(t, module, qualname)]
    direct.sort(key=lambda t: (not t.startswith(mirror), short not in t, t))
    entries = [(r.split("[")[0], r.split("[")[1][1:-2]) for r in registries]
    via = [
        t.id
        for t in tests
        for registry, key in entries
        if registry in t.decorators or (registry in t.names and key in t.strings)
    ]
    return tuple(dict.fromkeys(direct + sorted(via)))


def resolve(name: str):
    """The object named ``package.module.Qual.name``, or None if it cannot be imported.

    Examples
    --------
    >>> resolve("phong_table.model.SpectralPhong").__name__, resolve("phong_table.model.nothing")
    ('SpectralPhong', None)
    """
    module, qualname = _split(name)
    try:
        obj = importlib.import_module(module)
        for attr in qualname.split("."):
            obj = getattr(obj, attr)
    except (ImportError, AttributeError, ValueError):
        return None
    return obj

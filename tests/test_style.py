"""STYLE.md's checkable rules, as tests (§11 "Style checked as tests")."""

import ast
import importlib
import inspect
import pkgutil
import re
import subprocess
import sys
from pathlib import Path

import pytest

from reference.registry import Method, Registry

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("reference", "phong_table", "shrm", "impastor", "validation")
#: What each package may import (STYLE.md §2): the papers import the shared core only, and
#: nothing imports ``validation``.
ALLOWED_IMPORTS = {
    "reference": {"reference"},
    "phong_table": {"reference", "phong_table"},
    "shrm": {"reference", "shrm"},
    "impastor": {"reference", "impastor"},
    "validation": set(PACKAGES),
}


def _modules():
    for package in PACKAGES:
        module = importlib.import_module(package)
        yield module
        for info in pkgutil.walk_packages(module.__path__, prefix=f"{package}."):
            if not info.name.endswith(".__main__"):  # runs the command when imported
                yield importlib.import_module(info.name)


MODULES = list(_modules())
SOURCES = [p for package in PACKAGES for p in (ROOT / package).rglob("*.py")]


def _registries():
    seen = {}
    for module in MODULES:
        for name, value in vars(module).items():
            if isinstance(value, Registry):
                seen[id(value)] = (f"{module.__name__}.{name}", value)
    return list(seen.values())


REGISTRIES = _registries()
METHODS = [
    (f"{where}:{key}", entry)
    for where, registry in REGISTRIES
    for key, entry in registry.items()
    if isinstance(entry, Method)
]


@pytest.mark.parametrize(("where", "method"), METHODS, ids=[w for w, _ in METHODS])
def test_registered_references_cite_their_equation_and_have_examples(where, method):
    doc = inspect.getdoc(method.reference) or ""
    assert "Examples" in doc, f"{where}: the reference's docstring has no Examples section"
    assert ">>>" in doc, f"{where}: the reference's docstring has no doctest"
    if "Eq. (" in method.cites:
        number = re.search(r"Eq\. \((\d+)\)", method.cites).group(1)
        assert f"Eq. ({number})" in doc, f"{where}: the docstring does not cite {method.cites}"


#: Registries whose entries are plain values rather than one class (their docstrings say why).
UNTYPED_REGISTRIES = {"target augmentation"}  # a function, or None for "no augmentation"


def test_registries_are_typed():
    # Family metadata lives in typed fields of the family's Method subclass, so a wrong key fails
    # where it is written; a registry refuses entries of another kind.
    import dataclasses

    assert "extra" not in {f.name for f in dataclasses.fields(Method)}
    for where, registry in REGISTRIES:
        if registry.family in UNTYPED_REGISTRIES:
            continue
        assert registry.kind is not object, f"{where}: Registry({registry.family!r}) has no kind"
        for key, entry in registry.items():
            assert isinstance(entry, registry.kind), f"{where}:{key}"


def _njit_functions():
    found = []
    for path in SOURCES:
        if not path.name.endswith("_kernels.py"):
            continue
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef):
                for deco in node.decorator_list:
                    text = ast.unparse(deco)
                    if "njit" in text or "numba.jit" in text:
                        found.append((path.relative_to(ROOT).as_posix(), node.name, text))
    return found


def test_every_njit_kernel_is_registered_exactly_once():
    kernels = {}
    for _, registry in REGISTRIES:
        for entry in registry.values():
            kernel = getattr(entry, "kernel", None)
            if kernel is not None:
                name = getattr(getattr(kernel, "py_func", kernel), "__name__", repr(kernel))
                kernels[name] = kernels.get(name, 0) + 1
    problems = [
        f"{path}:{name} is the kernel of {kernels.get(name, 0)} registry entries"
        for path, name, _ in _njit_functions()
        if kernels.get(name, 0) != 1 and not name.startswith("_")
    ]
    assert not problems, "; ".join(problems)


def test_no_kernel_sets_fastmath():
    offenders = [f"{p}:{n}" for p, n, text in _njit_functions() if "fastmath" in text]
    offenders += [
        str(p.relative_to(ROOT))
        for p in SOURCES
        if re.search(r"fastmath\s*=\s*True", p.read_text())
    ]
    assert not offenders


def test_print_only_in_cli_and_examples():
    offenders = []
    for path in SOURCES:
        if "cli" in path.relative_to(ROOT).parts[:2]:
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "print":
                offenders.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    assert not offenders


def _public_functions():
    for module in MODULES:
        for name in getattr(module, "__all__", []):
            obj = getattr(module, name, None)
            if inspect.isfunction(obj) and obj.__module__ == module.__name__:
                yield f"{module.__name__}.{name}", obj


PUBLIC = list(_public_functions())


@pytest.mark.parametrize(("name", "function"), PUBLIC, ids=[n for n, _ in PUBLIC])
def test_public_functions_have_doctests(name, function):
    doc = inspect.getdoc(function) or ""
    assert ">>>" in doc, f"{name} has no doctest"


def test_citations_use_the_fixed_format():
    # One grep finds each equation: "Eq. (11), Wang et al." -- never "Eq 11", "Equation (11)" or
    # "eq. (11)".
    pattern = re.compile(r"\b(Eq \(|Eqn\.? ?\(|Equation \(|eq\. \()")
    offenders = [
        f"{p.relative_to(ROOT)}:{i}"
        for p in SOURCES
        for i, line in enumerate(p.read_text().splitlines(), 1)
        if pattern.search(line)
    ]
    assert not offenders


def test_ruff_lint_and_format():
    ruff = Path(sys.executable).with_name("ruff")
    command = [str(ruff)] if ruff.exists() else [sys.executable, "-m", "ruff"]
    lint = subprocess.run(
        [*command, "check", "--no-cache", str(ROOT)], capture_output=True, text=True
    )
    assert lint.returncode == 0, lint.stdout[-3000:]
    fmt = subprocess.run(
        [*command, "format", "--check", "--no-cache", str(ROOT)], capture_output=True, text=True
    )
    assert fmt.returncode == 0, fmt.stdout[-3000:]


def _imported_packages(path: Path) -> set[str]:
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found.add(node.module.split(".")[0])
    return found & set(PACKAGES)


def test_imports_point_one_way():
    # reference imports no paper package; each paper package imports reference only; nothing
    # imports validation (function-level imports count too).
    offenders = []
    for package, allowed in ALLOWED_IMPORTS.items():
        for path in (ROOT / package).rglob("*.py"):
            for imported in sorted(_imported_packages(path) - allowed):
                offenders.append(f"{path.relative_to(ROOT)} imports {imported}")
    assert not offenders, "; ".join(offenders)


#: The shared core's sub-packages and the others each may import (the core modules of
#: ``reference/`` itself -- errors, registry, files, tasks, browser, data -- import no sub-package
#: and may be imported by all). The cut follows the imports; CONTRIBUTING.md's map shows it.
CORE_LAYERS = {
    "colour": set(),
    "geometry": set(),
    "display": set(),
    "materials": set(),
    "images": {"colour", "geometry", "display"},
    "scene": {"colour", "geometry", "display", "materials", "images"},
}


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imported_modules(path: Path) -> set[str]:
    """The specref modules a file imports, at module or function level (``from p import m`` too)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names if a.name.split(".")[0] in PACKAGES}
        elif (
            isinstance(node, ast.ImportFrom)
            and node.level == 0
            and node.module
            and node.module.split(".")[0] in PACKAGES
        ):
            found.add(node.module)
            found |= {f"{node.module}.{a.name}" for a in node.names}
    return found


def _core_part(module: str) -> str | None:
    """The sub-package of ``reference`` that ``module`` is in, ``""`` for the core, else None."""
    parts = module.split(".")
    if parts[0] != "reference":
        return None
    return parts[1] if len(parts) > 2 and parts[1] in CORE_LAYERS else ""


def test_shared_core_layers_point_one_way():
    assert set(CORE_LAYERS) == {
        p.name for p in (ROOT / "reference").iterdir() if (p / "__init__.py").is_file()
    } - {"data"}
    offenders = []
    for path in (ROOT / "reference").rglob("*.py"):
        here = _core_part(_module_name(path))
        if path.name == "__init__.py" and here in ("", None):
            continue  # the package __init__ re-exports the sub-packages
        allowed = CORE_LAYERS.get(here, set()) | {"", here}
        for imported in _imported_modules(path):
            part = _core_part(imported)
            if part is not None and part not in allowed:
                offenders.append(f"{path.relative_to(ROOT)} imports {imported}")
    assert not offenders, "; ".join(sorted(offenders))


def test_no_import_circles_between_modules():
    # Function-level imports count: two modules that import each other are one family of
    # equations cut in two, or a lower layer reaching up.
    modules = {_module_name(p): p for p in SOURCES if p.name != "__init__.py"}
    graph = {
        name: {m for m in _imported_modules(path) if m in modules and m != name}
        for name, path in modules.items()
    }
    circles, done = [], set()
    for start in sorted(graph):
        stack, seen = [(start, [start])], set()
        while stack:
            node, trail = stack.pop()
            for nxt in sorted(graph[node]):
                if nxt == start:
                    circles.append(" -> ".join([*trail, start]))
                elif nxt not in seen and nxt not in done:
                    seen.add(nxt)
                    stack.append((nxt, [*trail, nxt]))
        done.add(start)
    assert not circles, "; ".join(circles)


def _cli_actions(parser=None, prefix="specref"):
    import argparse

    from validation.cli import build_parser

    parser = parser or build_parser()
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, subparser in action.choices.items():
                yield from _cli_actions(subparser, f"{prefix} {name}")
        else:
            yield f"{prefix} {'/'.join(action.option_strings) or action.dest}", action


CLI_ACTIONS = list(_cli_actions())


def test_cli_registry_options_list_their_registry():
    # Every option that takes a registry key lists the keys from the registry itself.
    checked = 0
    for where, action in CLI_ACTIONS:
        registry = getattr(action, "registry", None)
        if registry is None:
            continue
        checked += 1
        assert set(action.registry_keys) <= set(registry), where
        listed = action.help.split(": ", 1)[1].split(" (default")[0].split(", ")
        assert [key.split("[:")[0] for key in listed] == action.registry_keys, where
    assert checked >= 10


def test_no_cli_option_spells_registry_keys_by_hand():
    # An option whose help or choices names two or more keys of one registry must read them from
    # that registry (validation.cli.parser.registry_option).
    offenders = []
    for where, action in CLI_ACTIONS:
        if getattr(action, "registry", None) is not None:
            continue
        words = set(re.findall(r"[A-Za-z0-9_]+", f"{action.help or ''} {action.choices or ''}"))
        for name, registry in REGISTRIES:
            spelled = words & set(registry)
            if len(spelled) >= 2:
                offenders.append(f"{where} spells {sorted(spelled)} of {name}")
    assert not offenders, "; ".join(offenders)


#: The longest function a reader is asked to follow (STYLE.md §2); numba kernels are exempt.
MAX_FUNCTION_LINES = 80


def test_functions_stay_short():
    # A function past 80 lines is several steps; name them. Counted from `def` to the last line,
    # docstring included, in every package (the report's sections read compute -> present ->
    # checks); numba kernels (`*_kernels.py`) keep their loops whole.
    assert len(SOURCES) > 100  # the packages were found
    long = []
    for path in SOURCES:
        if path.name.endswith("_kernels.py"):
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                lines = node.end_lineno - node.lineno + 1
                if lines > MAX_FUNCTION_LINES:
                    long.append(f"{path.relative_to(ROOT)}:{node.name} ({lines} lines)")
    assert not long, "; ".join(long)


def test_every_report_section_is_compute_present_checks():
    from validation.report.runner import SECTIONS

    for section in SECTIONS:
        assert callable(section.compute), section.name
        assert callable(section.present), section.name
        assert callable(section.checks), section.name

"""The CLI's shared pieces: the argument parser class and the JSON writer."""

from __future__ import annotations

import argparse
import json

from reference.registry import ParametricMethod

__all__ = [
    "InputPath",
    "OutputPath",
    "PaintingPath",
    "Parser",
    "TomlPath",
    "command_paths",
    "folder_name",
    "input_file",
    "key_or_input_file",
    "nonnegative_int",
    "number_in",
    "output_file",
    "output_file_or_stdout",
    "painting_input",
    "port_number",
    "registry_option",
    "toml_input",
    "toml_named_files",
    "write_json",
]


class _StoreOnce(argparse._StoreAction):
    """argparse's ``store``, refusing an option given twice (the last one silently won)."""

    def __call__(self, parser, namespace, values, option_string=None):
        given = namespace.__dict__.setdefault("_specref_given", set())
        if option_string is not None and self.dest in given:
            parser.error(f"argument {'/'.join(self.option_strings)}: given more than once")
        given.add(self.dest)
        super().__call__(parser, namespace, values, option_string)


class Parser(argparse.ArgumentParser):
    """argparse with one-line usage errors and exit code 2 (argparse's code for usage errors).

    An option that takes one value may be given once: ``-o a.png -o b.png`` is refused.

    Examples
    --------
    >>> p = Parser(prog="x")
    >>> _ = p.add_argument("-o", "--out")
    >>> p.parse_args(["-o", "a.png"]).out
    'a.png'
    """

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.register("action", None, _StoreOnce)
        self.register("action", "store", _StoreOnce)

    def error(self, message):
        """Print a one-line usage error naming the subcommand's help, and exit with code 2."""
        self.exit(2, f"specref: error: {message} (see {self.prog} --help)\n")


class InputPath(str):
    """An argument that names a file the command reads (:func:`input_file`)."""


class TomlPath(InputPath):
    """A TOML input (a scene, a sweep) whose strings may name other inputs (:func:`toml_input`)."""


class PaintingPath(str):
    """A painting folder (or its ``painting.toml``) the command reads (:func:`painting_input`)."""


class OutputPath(str):
    """An argument that names a file the command writes (:func:`output_file`)."""


class OutputStore(str):
    """An argument that names a file, or a Zarr store (``*.zarr``), the command writes."""


def input_file(value: str) -> InputPath:
    """An input file argument: ``data:<name>`` names a file shipped with specref, else the path.

    For argparse's ``type=``; an unknown ``data:`` name is a one-line usage error (exit code 2).
    The value is marked as an input, so that no output of the command may be the same file
    (:func:`command_paths`).

    Examples
    --------
    >>> input_file("data:environments/venice_sunset_1k.hdr").endswith("venice_sunset_1k.hdr")
    True
    >>> input_file("my/scene.toml")
    'my/scene.toml'
    """
    from reference.data import DATA_SCHEME, data_path
    from reference.errors import SpecrefError

    if not value.strip():  # Path("") is ".", which would be reported as "./: file not found"
        raise argparse.ArgumentTypeError("an empty file name")
    if not value.startswith(DATA_SCHEME):
        return InputPath(value)
    try:
        return InputPath(data_path(value))
    except SpecrefError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def toml_input(value: str) -> TomlPath:
    """A TOML input file argument; the files its strings name are inputs too.

    An environment map, a mesh, a material file of a sweep's grid (:func:`toml_named_files`).

    Examples
    --------
    >>> type(toml_input("scene.toml")).__name__
    'TomlPath'
    """
    return TomlPath(input_file(value))


def toml_named_files(path, limit: int = 10_000) -> list[str]:
    r"""The existing files that the strings of a TOML file name, relative to its folder.

    Unreadable or malformed files give none (the command says what is wrong with them).

    Examples
    --------
    >>> import tempfile, os
    >>> d = tempfile.mkdtemp(); _ = open(os.path.join(d, "env.exr"), "w").close()
    >>> _ = open(os.path.join(d, "s.toml"), "w").write('file = "env.exr"\nname = "x"\n')
    >>> [os.path.basename(p) for p in toml_named_files(os.path.join(d, "s.toml"))]
    ['env.exr']
    """
    import tomllib
    from pathlib import Path

    path = Path(path)
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError, RecursionError):
        return []
    strings, stack = [], [doc]
    while stack and len(strings) < limit:
        item = stack.pop()
        if isinstance(item, dict):
            stack.extend(item.values())
        elif isinstance(item, list):
            stack.extend(item)
        elif isinstance(item, str) and 0 < len(item) < 4096 and "\n" not in item:
            strings.append(item)
    found = []
    for text in strings:
        candidate = Path(text) if Path(text).is_absolute() else path.parent / text
        try:
            if candidate.is_file():
                found.append(str(candidate))
        except OSError:  # a name too long, a loop: not a file the command reads
            continue
    return found


def painting_input(value: str) -> PaintingPath:
    """A painting folder argument: its ``painting.toml`` and the files it names are inputs.

    Other files of the folder are not: a render may be written there, and written again.

    Examples
    --------
    >>> type(painting_input("my/painting")).__name__
    'PaintingPath'
    """
    return PaintingPath(input_file(value))


def key_or_input_file(value: str) -> str:
    """A name (an illuminant key) or, where it names a file, an input file (:func:`input_file`).

    A value with a folder separator, a suffix or an existing file of that name is a file, so the
    write policy keeps the command's outputs off it.

    Examples
    --------
    >>> type(key_or_input_file("D65")).__name__, type(key_or_input_file("lamp.csv")).__name__
    ('str', 'InputPath')
    """
    import os

    if os.sep in value or "." in value or value.startswith("data:") or os.path.exists(value):
        return input_file(value)
    return value


def folder_name(value: str) -> str:
    """A folder the command writes into, for argparse's ``type=``: not an empty name.

    Examples
    --------
    >>> folder_name("out")
    'out'
    >>> folder_name("")
    Traceback (most recent call last):
    ...
    argparse.ArgumentTypeError: an empty folder name
    """
    if not value.strip():  # Path("") is the current folder
        raise argparse.ArgumentTypeError("an empty folder name")
    return value


def nonnegative_int(value: str) -> int:
    """An integer >= 0 (a seed, a count), for argparse's ``type=``.

    Examples
    --------
    >>> nonnegative_int("7")
    7
    >>> nonnegative_int("-1")
    Traceback (most recent call last):
    ...
    argparse.ArgumentTypeError: must be an integer >= 0, got '-1'
    """
    try:
        number = int(value)
    except ValueError:
        number = -1
    if number < 0:
        raise argparse.ArgumentTypeError(f"must be an integer >= 0, got {value!r}")
    return number


def number_in(low: float, high: float, integer: bool = False):
    """An argparse ``type=`` for a finite number in [low, high] (a whole number with ``integer``).

    The message names the flag (argparse prefixes ``argument --FLAG:``), where the library's
    check, reached later, named only the quantity.

    Examples
    --------
    >>> number_in(1, 1 << 20, integer=True)("64")
    64
    >>> number_in(0, 1)("-1")
    Traceback (most recent call last):
    ...
    argparse.ArgumentTypeError: must be a number in [0, 1], got '-1'
    """
    what = "a whole number" if integer else "a number"
    bounds = f"[{low}, {high}]" if integer else f"[{low:g}, {high:g}]"

    def check(value: str):
        try:
            number = int(value) if integer else float(value)
        except ValueError:
            number = None
        if number is None or not low <= number <= high:  # NaN fails the comparison too
            raise argparse.ArgumentTypeError(f"must be {what} in {bounds}, got {value!r}")
        return number

    return check


def port_number(value: str) -> int:
    """A TCP port, 0 (any free port) to 65535, for argparse's ``type=``.

    Examples
    --------
    >>> port_number("5006")
    5006
    >>> port_number("70000")
    Traceback (most recent call last):
    ...
    argparse.ArgumentTypeError: a TCP port is 0 to 65535, got '70000'
    """
    try:
        number = int(value)
    except ValueError:
        number = -1
    if not 0 <= number <= 65535:
        raise argparse.ArgumentTypeError(f"a TCP port is 0 to 65535, got {value!r}")
    return number


def output_file(value: str) -> str:
    """An output file argument, for argparse's ``type=``: marked for the write policy.

    ``-`` is refused: a file of that name is not what a user means (the outputs that print
    instead take :func:`output_file_or_stdout`).

    Examples
    --------
    >>> type(output_file("out.exr")).__name__
    'OutputPath'
    >>> output_file("-")
    Traceback (most recent call last):
    ...
    argparse.ArgumentTypeError: '-' (standard output) is not offered here; give a file name
    """
    if value == "-":
        raise argparse.ArgumentTypeError(
            "'-' (standard output) is not offered here; give a file name"
        )
    if not value.strip():  # Path("") is the current folder: ".: cannot write (is a folder)"
        raise argparse.ArgumentTypeError("an empty file name")
    return (OutputStore if value.rstrip("/\\").endswith(".zarr") else OutputPath)(value)


def output_file_or_stdout(value: str) -> str:
    """:func:`output_file`, or ``-`` for standard output (where a command prints instead).

    Examples
    --------
    >>> output_file_or_stdout("-"), type(output_file_or_stdout("a.json")).__name__
    ('-', 'OutputPath')
    """
    return value if value == "-" else output_file(value)


def command_paths(args) -> tuple[list[str], list[str], list[str]]:
    """The files a parsed command writes and the files it reads, from its arguments.

    Its output files (with the sibling files the command derives from them,
    ``args.sibling_outputs``), its inputs and its output stores.

    ``validation.cli.main`` passes them to :func:`reference.files.check_outputs` before the
    command runs (the write policy, docs/bad-input.md).

    Examples
    --------
    >>> import argparse
    >>> args = argparse.Namespace(a=input_file("A.exr"), diff=output_file("A.exr"), n=3)
    >>> command_paths(args)
    (['A.exr'], ['A.exr'], [])
    """
    values = []
    for value in vars(args).values():
        values.extend(value if isinstance(value, list | tuple) else [value])
    outputs = [v for v in values if isinstance(v, OutputPath)]
    siblings = getattr(args, "sibling_outputs", None)
    if siblings is not None:
        outputs += [str(s) for s in siblings(args)]
    inputs = [v for v in values if isinstance(v, InputPath)]
    for toml in (v for v in values if isinstance(v, TomlPath)):
        inputs += toml_named_files(toml)
    sibling_inputs = getattr(args, "sibling_inputs", None)
    if sibling_inputs is not None:
        inputs += [str(s) for s in sibling_inputs(args)]
    for painting in (v for v in values if isinstance(v, PaintingPath)):
        from impastor.painting_files import painting_file_paths

        inputs += [str(p) for p in painting_file_paths(painting)]
    return outputs, inputs, [v for v in values if isinstance(v, OutputStore)]


def write_json(path, result) -> None:
    """Write ``result`` (NumPy values converted) as JSON to ``path``, atomically, and say so.

    Examples
    --------
    >>> import json, pathlib, tempfile
    >>> import numpy as np
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = pathlib.Path(folder) / "r.json"
    ...     write_json(path, {"rms": np.float64(0.5)})
    ...     json.loads(path.read_text())
    wrote .../r.json
    {'rms': 0.5}
    """
    from reference.files import write_text_atomic
    from validation.report import to_jsonable

    write_text_atomic(path, json.dumps(to_jsonable(result), indent=1))
    print(f"wrote {path}")


def registry_option(parser, flag: str, registry, help: str, where=None, **kwargs):
    """Add an option whose values are the keys of ``registry``; its help lists them from it.

    The CLI never spells a registry key by hand: the help text is built from ``registry`` (keys
    whose entry takes a parameter, a ``ParametricMethod``, are shown as ``key[:PARAM]``), and the
    library checks the value with ``registry.lookup``, so a wrong key gets the library's one-line
    error (exit 2).
    ``tests/test_style.py`` checks every such option against its registry.

    Parameters
    ----------
    parser : argparse.ArgumentParser
    flag : str
        The option, e.g. ``"--placement"``, or a positional name.
    registry : Registry or mapping
        Where the keys come from.
    help : str
        What the option chooses; the keys (and the default) are appended.
    where : callable, optional
        ``where(key, entry) -> bool``: the keys this option accepts, when it takes a subset.
    **kwargs
        Passed to ``add_argument`` (``default``, ``metavar``, ...).

    Returns
    -------
    argparse.Action
        With ``registry`` and ``registry_keys`` attributes.

    Examples
    --------
    >>> from reference.registry import Method, ParametricMethod, Registry
    >>> shapes = Registry("shape")
    >>> _ = shapes.register(Method("disc", abs, None, "Eq. (0), nobody"))
    >>> _ = shapes.register(ParametricMethod("lobe", abs, None, "Eq. (0), nobody", param="S"))
    >>> action = registry_option(Parser(prog="x"), "--shape", shapes, "the shape", default="disc")
    >>> action.help
    'the shape: disc, lobe[:S] (default disc)'
    >>> action.type("lobe:4"), action.type("disc")
    ('lobe:4', 'disc')
    >>> action.type("cube")
    Traceback (most recent call last):
    ...
    argparse.ArgumentTypeError: unknown value 'cube'; allowed: disc, lobe[:S]
    """
    keys = [key for key in registry if where is None or where(key, _entry(registry, key))]
    shown = []
    for key in keys:
        entry = _entry(registry, key)
        shown.append(f"{key}[:{entry.param}]" if isinstance(entry, ParametricMethod) else key)
    text = f"{help}: {', '.join(shown)}"
    if kwargs.get("default") is not None:
        text += f" (default {kwargs['default']})"

    def key(value: str) -> str:
        # checked while parsing, so that the message names the flag (the library's did not, and
        # an option no part of the input used, --texel-placement without an environment, was
        # never checked); a parameter is the library's to check
        base, colon, _ = value.partition(":")
        parametric = colon and base in keys and isinstance(_entry(registry, base), ParametricMethod)
        if value not in keys and not parametric:
            raise argparse.ArgumentTypeError(
                f"unknown value {value!r}; allowed: {', '.join(shown)}"
            )
        return value

    kwargs.setdefault("type", key)
    action = parser.add_argument(flag, help=text, **kwargs)
    action.registry = registry
    action.registry_keys = keys
    return action


def _entry(registry, key):
    return registry.lookup(key) if hasattr(registry, "lookup") else registry[key]

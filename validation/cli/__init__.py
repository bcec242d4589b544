"""The ``specref`` command: argument parsing and dispatch to library functions, nothing else.

One module per subcommand (:data:`COMMANDS`), each with ``add_parser(sub)``; every subcommand is a
small function that calls the library. Bad input raises :class:`~reference.errors.SpecrefError` in
the library; :func:`main` prints its one-line message to stderr and exits with code 2, without a
traceback.
"""

from __future__ import annotations

import argparse
import sys
import warnings

from reference.errors import SpecrefError, SpecrefWarning
from validation.cli import (
    brdf,
    cache,
    compare,
    conformance,
    crosscheck,
    display,
    env,
    equations,
    impastor,
    phong,
    polymer,
    render,
    report,
    sh,
    shrm,
    sweep,
)
from validation.cli.parser import Parser, command_paths

__all__ = ["COMMANDS", "build_parser", "main", "run"]

#: The subcommands, in the order ``specref --help`` lists them.
COMMANDS = (
    report,
    render,
    cache,
    brdf,
    shrm,
    sh,
    polymer,
    display,
    env,
    impastor,
    phong,
    sweep,
    equations,
    crosscheck,
    conformance,
    compare,
)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser for all subcommands.

    Examples
    --------
    >>> build_parser().parse_args(["report", "--quick"]).quick
    True
    """
    parser = Parser(prog="specref", description="specref: a spectral rendering reference.")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    for command in COMMANDS:
        command.add_parser(sub)
    return parser


def _warning_line(message, category, filename, lineno, line=None) -> str:
    """A specref warning as the command prints it: one line, no source file or code."""
    if issubclass(category, SpecrefWarning):
        return f"specref: warning: {message}\n"
    return _FORMAT_WARNING(message, category, filename, lineno, line)


_FORMAT_WARNING = warnings.formatwarning


def _terminated(signum, _frame):
    """SIGTERM or SIGHUP: unwind as an exception, so every output's temporary file is removed."""
    raise SystemExit(128 + signum)


def run() -> int:
    r"""The ``specref`` console command: :func:`main`, its warnings printed as one line each.

    A SIGTERM or SIGHUP (``kill``, a closed terminal, a CI timeout) ends the command as an
    exception does, so the temporary file of an output being written is removed (exit code
    128 + the signal's number), as after Ctrl-C; what a SIGKILL leaves, the next write to the same
    path removes (``reference.files.remove_stale_temporaries``).

    Examples
    --------
    >>> _warning_line("a.txt: ignored", SpecrefWarning, "cache.py", 3)
    'specref: warning: a.txt: ignored\n'
    """
    import signal

    warnings.formatwarning = _warning_line
    for name in ("SIGTERM", "SIGHUP"):
        if hasattr(signal, name):
            signal.signal(getattr(signal, name), _terminated)
    return main()


def main(argv: list[str] | None = None) -> int:
    """Run the ``specref`` command; return the exit code (2 for bad input).

    Examples
    --------
    >>> main(["report", "--only", "no-such-section", "--out", "/tmp/specref-doctest"])
    2
    """
    import shrm  # noqa: F401  (registers the environment-light shaders before any rendering)
    from reference.files import check_outputs
    from reference.tasks import set_malloc_trim

    parser = build_parser()
    args = parser.parse_args(argv)
    # glibc's default mmap threshold makes NumPy's large temporaries an mmap and a munmap each, in
    # system calls that slowed long sweeps (docs/scale-out.md); the workers set the same.
    # Streamed commands keep the default, which returns each chunk's memory to the system.
    if not getattr(args, "streamed", False):
        set_malloc_trim()
    try:
        # The write policy (docs/bad-input.md): every output checked before any work
        check_outputs(*command_paths(args))
        return int(args.func(args) or 0)
    except SpecrefError as error:
        print(f"specref: error: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("specref: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())

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

__all__ = ["COMMANDS", "build_parser", "main", "run", "run_command"]

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

    from reference.tasks import freeze_objects_for_exit

    warnings.formatwarning = _warning_line
    for name in ("SIGTERM", "SIGHUP"):
        if hasattr(signal, name):
            signal.signal(getattr(signal, name), _terminated)
    code = main()
    freeze_objects_for_exit()  # the command is done: exit without a last walk over every object
    return code


def main(argv: list[str] | None = None) -> int:
    """Run the ``specref`` command; return the exit code (2 for bad input).

    A usage error (an unknown flag, a value its flag refuses while parsing) exits from the
    parser with code 2, as argparse does.

    Examples
    --------
    >>> main(["sweep", "/nonexistent/sweep.toml"])
    2
    """
    import shrm  # noqa: F401  (registers the environment-light shaders before any rendering)
    from reference.files import check_outputs
    from reference.tasks import STREAMED_MMAP_BYTES, STREAMED_TRIM_BYTES, set_malloc_trim

    parser = build_parser()
    args = parser.parse_args(argv)
    vars(args).pop("_specref_given", None)  # the parser's record of the options given once
    # glibc's default mmap threshold makes NumPy's large temporaries an mmap and a munmap each, in
    # system calls that slowed long sweeps (docs/scale-out.md); the workers set the same.
    # Streamed commands map each chunk on its own and return it to the system when freed,
    # whatever thresholds the environment passed on.
    if getattr(args, "streamed", False):
        set_malloc_trim(STREAMED_TRIM_BYTES, STREAMED_MMAP_BYTES)
    else:
        set_malloc_trim()
    return run_command(args, lambda: check_outputs(*command_paths(args)))


class _HeldWarnings:
    """Warnings held until the command writes anything or ends (docs/bad-input.md).

    A command refused for bad input prints one line: a warning raised while it read its inputs
    (an unusable cache folder, say) would otherwise come first. The first line the command writes
    (a progress line, a result) releases what is held, in order; a refusal drops it.
    """

    def __init__(self, stream):
        self.stream, self.pending = stream, []

    def show(self, message, category, filename, lineno, file=None, line=None):
        self.pending.append(_warning_line(message, category, filename, lineno, line))

    def release(self):
        pending, self.pending = self.pending, []
        for text in pending:
            self.stream.write(text)


class _Releasing:
    """A stream that releases the held warnings before its first write (else as ``stream``)."""

    def __init__(self, stream, held: _HeldWarnings):
        self._stream, self._held = stream, held

    def write(self, text):
        if self._held.pending:
            self._held.release()
        return self._stream.write(text)

    def __getattr__(self, name):
        return getattr(self._stream, name)


def run_command(args, check=lambda: None) -> int:
    r"""``check()`` then ``args.func(args)``: the exit code, a refusal as one line on stderr.

    Warnings are held until the command writes its first line or ends (:class:`_HeldWarnings`),
    so bad input is one line, code 2, whatever was warned before it; Ctrl-C is code 130.

    Examples
    --------
    >>> import contextlib, io
    >>> from types import SimpleNamespace
    >>> def refused(args):
    ...     warnings.warn("cache.db: unusable", SpecrefWarning)
    ...     raise SpecrefError("scene.toml: width: must be > 0")
    >>> err = io.StringIO()
    >>> with contextlib.redirect_stderr(err):
    ...     code = run_command(SimpleNamespace(func=refused))
    >>> code, err.getvalue()
    (2, 'specref: error: scene.toml: width: must be > 0\n')
    """
    out, err = sys.stdout, sys.stderr
    held = _HeldWarnings(err)
    sys.stdout, sys.stderr = _Releasing(out, held), _Releasing(err, held)
    try:
        with warnings.catch_warnings():
            warnings.showwarning = held.show
            # The write policy (docs/bad-input.md): every output checked before any work
            check()
            code = int(args.func(args) or 0)
        held.release()
        return code
    except SpecrefError as error:
        held.pending.clear()  # a refusal is one line
        print(f"specref: error: {error}", file=err)
        return 2
    except KeyboardInterrupt:
        held.release()
        print("specref: interrupted", file=err)
        return 130
    finally:
        sys.stdout, sys.stderr = out, err


if __name__ == "__main__":
    sys.exit(main())

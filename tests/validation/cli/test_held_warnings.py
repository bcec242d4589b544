"""Warnings never precede a refusal's one line; else they come out in order (docs/bad-input.md)."""

import sys
import warnings
from types import SimpleNamespace

from reference.errors import SpecrefError, SpecrefWarning
from validation.cli import run_command


def _run(func, capsys):
    code = run_command(SimpleNamespace(func=func))
    out, err = capsys.readouterr()
    return code, out, err


def test_a_refusal_after_a_warning_is_one_line(capsys):
    def refused(_args):
        warnings.warn("/cache: cache folder unusable (read-only)", SpecrefWarning, stacklevel=2)
        raise SpecrefError("scene.toml: render.width: must be > 0")

    code, out, err = _run(refused, capsys)
    assert code == 2
    assert err == "specref: error: scene.toml: render.width: must be > 0\n"
    assert out == ""


def test_a_warning_comes_before_the_first_line_written_after_it(capsys):
    def works(_args):
        warnings.warn("/cache: cache folder unusable (read-only)", SpecrefWarning, stacklevel=2)
        sys.stderr.write("frame 1/2\n")
        sys.stdout.write("wrote out.png\n")
        return 0

    code, out, err = _run(works, capsys)
    assert code == 0
    assert err.splitlines() == [
        "specref: warning: /cache: cache folder unusable (read-only)",
        "frame 1/2",
    ]
    assert out == "wrote out.png\n"


def test_a_silent_command_shows_its_warnings_at_the_end_and_the_streams_come_back(capsys):
    before = sys.stdout, sys.stderr

    def silent(_args):
        warnings.warn("a.txt: ignored", SpecrefWarning, stacklevel=2)

    code, _out, err = _run(silent, capsys)
    assert code == 0
    assert err == "specref: warning: a.txt: ignored\n"
    assert (sys.stdout, sys.stderr) == before

import subprocess
import sys

from validation.cli import build_parser, main


def _run(*args):
    return subprocess.run(
        [sys.executable, "-m", "validation.cli", *args], capture_output=True, text=True, timeout=300
    )


def test_help_lists_subcommands():
    result = _run("--help")
    assert result.returncode == 0
    assert "report" in result.stdout


def test_bad_input_exits_2_with_one_line_and_no_traceback(tmp_path):
    result = _run("report", "--only", "nonexistent", "--out", str(tmp_path))
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1
    assert lines[0].startswith(
        "specref: error: argument --only: unknown value 'nonexistent'; allowed:"
    )


def test_usage_errors_exit_2_on_one_line():
    result = _run("report", "--no-such-flag")
    assert result.returncode == 2
    assert len(result.stderr.strip().splitlines()) == 1
    assert "unrecognized arguments: --no-such-flag" in result.stderr
    assert _run().returncode == 2


def test_report_via_main(tmp_path, capsys):
    assert main(["report", "--quick", "--only", "spectral-core", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "index.html").is_file()
    assert "index.html" in capsys.readouterr().out
    assert build_parser().parse_args(["report"]).out == "report"


#: Libraries that cost a command's start-up a tenth of a second or more each and that no command
#: needs before it runs: imported where they are used.
_HEAVY_AT_START = (
    "colour",
    "dask",
    "distributed",
    "imageio",
    "matplotlib",
    "OpenEXR",
    "scipy.interpolate",
    "scipy.optimize",
    "scipy.special",
    "tifffile",
    "zarr",
)


def test_the_command_line_starts_without_the_heavy_libraries():
    script = (
        "import sys, validation.cli; validation.cli.build_parser(); "
        "print(' '.join(sorted(sys.modules)))"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=True
    )
    loaded = set(done.stdout.split())
    assert {"validation.cli", "shrm", "impastor", "phong_table"} <= loaded
    assert sorted(set(_HEAVY_AT_START) & loaded) == []


def test_the_command_exits_without_a_last_collection(tmp_path):
    # the console command freezes its objects once its work is done, refused input included:
    # Python's exit then skips its last walk over them (reference.tasks.freeze_objects_for_exit)
    script = (
        "import gc, sys; from validation.cli import run; "
        f"sys.argv = ['specref', 'sweep', {str(tmp_path / 'none.toml')!r}]; "
        "code = run(); print(code, gc.get_freeze_count() > 0)"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=True
    )
    assert done.stdout.split() == ["2", "True"]
    assert done.stderr.count("\n") == 1  # the refusal's one line


def _documented_command_lines():
    """Every ``specref`` command line in the docs' code blocks (README, CONTRIBUTING, docs/)."""
    import re
    import shlex
    from pathlib import Path

    root = Path(__file__).resolve().parents[3]
    pages = [*sorted((root / "docs").glob("*.md")), root / "README.md", root / "CONTRIBUTING.md"]
    lines = []
    for page in pages:
        if page.name == "results.md":  # generated
            continue
        in_block = False
        for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
            if line.startswith("```"):
                in_block = not in_block
                continue
            text = re.sub(r"^\$ ", "", line.strip()).split(" # ")[0].split("  #")[0].strip()
            # a usage line with placeholders ([options], A|B, <...>) is not a command
            if (
                in_block
                and text.startswith("specref ")
                and not re.search(r"[][|<>\\]|\.\.\.", text)
            ):
                lines.append((f"{page.name}:{number}", shlex.split(text)[1:]))
    return lines


def test_every_documented_command_line_parses(capsys):
    # a documented command must be one a user can type: its options as the parser spells them
    # (docs/impastor.md once said `impastor render -o`, which the command did not take)
    lines = _documented_command_lines()
    assert len(lines) >= 25
    failed = []
    for where, argv in lines:
        try:
            build_parser().parse_args(argv)
        except SystemExit as exit_:
            if exit_.code != 0:
                failed.append(
                    f"{where}: specref {' '.join(argv)}: {capsys.readouterr().err.strip()}"
                )
    assert not failed, "\n".join(failed)

"""The wheel works anywhere: built, installed into a fresh virtual environment outside the
repository, and used from a folder that is neither the repository nor beside it.

Run by ``make test-wheel`` (``.ci/run`` runs it after the suite; the default suite deselects the
``wheel`` marker, since the install takes a few minutes). Inside the new environment nothing can
reach the source tree: the package is imported from the environment's ``site-packages``, so code
that found its data by a path relative to the repository (``../shared/data``, ``docs/``, ``tests/``)
fails here. Every shipped example scene renders, the example scripts of ``docs/examples`` run, and
``specref report --quick`` writes a complete page.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

pytestmark = pytest.mark.wheel

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "reference" / "data" / "examples").glob("*.toml"))
SCRIPTS = sorted((ROOT / "docs" / "examples").glob("*.py"))


def _run(command, cwd, timeout=3600, env=None):
    done = subprocess.run(
        [str(c) for c in command], cwd=cwd, capture_output=True, text=True, timeout=timeout, env=env
    )
    assert done.returncode == 0, f"{command}: exit {done.returncode}\n{done.stderr[-3000:]}"
    return done


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """``(bin folder, a working folder, the environment)`` of a fresh venv with the wheel in it."""
    work = tmp_path_factory.mktemp("specref-wheel")
    _run([sys.executable, "-m", "build", "--wheel", "--outdir", work / "dist", ROOT], work)
    (wheel,) = (work / "dist").glob("specref-*.whl")
    _run([sys.executable, "-m", "venv", work / "venv"], work)
    bin_ = work / "venv" / "bin"
    _run([bin_ / "python", "-m", "pip", "install", "--quiet", wheel], work)
    run = work / "run"
    run.mkdir()
    env = {k: v for k, v in os.environ.items() if not k.startswith(("SPECREF_", "PYTHON"))}
    env["MPLBACKEND"] = "Agg"
    return bin_, run, env, wheel


def test_the_package_comes_from_the_environment(installed):
    bin_, run, env, _ = installed
    code = "import reference, validation; print(reference.__file__, validation.__file__)"
    out = _run([bin_ / "python", "-c", code], run, env=env).stdout
    assert "site-packages" in out
    assert str(ROOT) not in out


@pytest.mark.parametrize("scene", EXAMPLES, ids=lambda p: p.name)
def test_shipped_example_renders_from_any_folder(installed, scene):
    bin_, run, env, _ = installed
    out = run / f"{scene.stem}.png"
    command = [bin_ / "specref", "render", f"data:examples/{scene.name}", "-o", out]
    _run([*command, "--width", 24, "--supersample", 1], run, env=env)
    assert out.stat().st_size > 0


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_docs_example_script_runs_from_any_folder(installed, script):
    bin_, run, env, _ = installed
    here = run / script.stem
    here.mkdir()
    shutil.copy(script, here / script.name)
    code = f"import {script.stem}; {script.stem}.main(quick=True)"
    _run([bin_ / "python", "-c", code], here, env={**env, "PYTHONPATH": str(here)})


def test_quick_report_is_complete(installed):
    bin_, run, env, _ = installed
    _run([bin_ / "specref", "report", "--quick", "--out", run / "report"], run, env=env)
    assert (run / "report" / "index.html").is_file()
    assert (run / "report" / "results.json").is_file()


def test_the_wheel_ships_every_data_file(installed):
    # setup.cfg's package-data patterns cover every file of the data folders.
    *_, wheel = installed
    with zipfile.ZipFile(wheel) as archive:
        shipped = set(archive.namelist())
    folders = ("reference/data", "shrm/polymer/data", "impastor/data", "validation/data")
    wanted = {
        path.relative_to(ROOT).as_posix()
        for folder in folders
        for path in (ROOT / folder).rglob("*")
        if path.is_file() and "__pycache__" not in path.parts
    }
    assert wanted, folders
    assert not wanted - shipped, sorted(wanted - shipped)


def test_the_conformance_suite_runs_from_an_installed_wheel(installed):
    # the scenes, maps and manifest ship in the wheel: references, export and a check from any
    # folder (the check of a reference against itself passes; exit 0)
    bin_, run, env, _ = installed
    refs, scenes = run / "conformance-refs", run / "conformance-scenes"
    specref = bin_ / "specref"
    _run([specref, "conformance", "references", "--out", refs, "--scene", "colorchecker-a"], run,
         env=env)  # fmt: skip
    _run([specref, "conformance", "export", scenes, "--format", "specref"], run, env=env)
    renders = run / "conformance-renders"
    renders.mkdir()
    code = (
        "import sys; from validation.conformance.references import load_reference; "
        "from reference.images.formats import write_exr; "
        f"r = load_reference('colorchecker-a', {str(refs)!r}); "
        f"write_exr({str(renders / 'colorchecker-a.exr')!r}, r.XYZ.astype('float32'), list('XYZ'))"
    )
    _run([bin_ / "python", "-c", code], run, env=env)
    _run([specref, "conformance", "check", renders, "--references", refs], run, env=env)
    assert (scenes / "lambert-env-venice.toml").is_file()

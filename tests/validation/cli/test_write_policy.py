"""The write policy: no command loses data, whatever output path it is given.

Each case is one a careless or hostile user tried (docs/bad-input.md, "The write policy"): an output
that is a device, a FIFO or an input of the same command (by name, hard link or symbolic link), a
sibling output that is an input, two outputs that are the same file, a name too long for the file
system, and a Zarr store over a folder of other files. Every one is refused in one line with exit
code 2 before any work, and the file that was there is unchanged.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import stat
from pathlib import Path

import numpy as np
import pytest

from reference.data import data_path
from reference.images.formats import write_exr
from validation.cli import build_parser, main
from validation.cli.parser import (
    OutputPath,
    OutputStore,
    input_file,
    output_file,
    output_file_or_stdout,
)

VENICE = str(data_path("environments/venice_sunset_1k.hdr"))
SCENE = str(data_path("examples/phong-sphere.toml"))


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _refused(argv, capsys, *needles) -> str:
    code = main([str(a) for a in argv])
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert len(err.splitlines()) == 1, err
    assert "Traceback" not in err
    for needle in needles:
        assert needle in err, err
    return err


@pytest.fixture
def files(tmp_path):
    """Inputs a user might point an output at: an EXR, a TOML, a CSV and a display JSON."""
    write_exr(tmp_path / "A.exr", np.full((4, 4, 3), 0.5))
    (tmp_path / "c.toml").write_text('name = "x"\n')
    (tmp_path / "t.csv").write_text("R,G,B\n0.1,0.2,0.3\n")
    (tmp_path / "s.toml").write_text('kind = "phong"\n')
    (tmp_path / "d.json").write_text("{}\n")
    (tmp_path / "e.toml").write_text('[[lights]]\ntype = "environment"\nfile = "A.exr"\n')
    (tmp_path / "g.toml").write_text('kind = "phong"\n[grid]\nmaterials = ["c.toml"]\n')
    return tmp_path


# (argv with {d} for the folder, the input that must survive)
SAME_AS_INPUT = [
    (["compare", "{d}/A.exr", "{d}/A.exr", "--diff", "{d}/A.exr"], "A.exr"),
    (["polymer", "characterize", "--constituents", "{d}/c.toml", "-o", "{d}/c.toml"], "c.toml"),
    (["env", "fit", "--target", "{d}/t.csv", "-o", "{d}/t.csv"], "t.csv"),
    (["sweep", "{d}/s.toml", "-o", "{d}/s.toml"], "s.toml"),
    # a sibling: calibrate -o d.cal also writes d.json, the display file here
    (["display", "calibrate", "--display", "{d}/d.json", "-o", "{d}/d.cal"], "d.json"),
    (["render", "{d}/c.toml", "-o", "{d}/c.toml"], "c.toml"),
    (["phong", "table1", "--material", "{d}/c.toml", "--json", "{d}/c.toml"], "c.toml"),
    # a lamp's spectrum file given where an illuminant key may go
    (["impastor", "render", "--size", "8", "--light", "{d}/t.csv", "--out", "{d}/t.csv"], "t.csv"),
    (["impastor", "path", "--size", "8", "--light", "{d}/t.csv", "-o", "{d}/t.csv"], "t.csv"),
    # a file a scene or a sweep names (its environment map; a material file of the grid), a
    # prefilter kernel's table
    (["render", "{d}/e.toml", "-o", "{d}/x.png", "--exr", "{d}/A.exr"], "A.exr"),
    (["sweep", "{d}/g.toml", "--scheduler", "serial", "-o", "{d}/c.toml"], "c.toml"),
    (["sh", "prefilter", VENICE, "--kernel", "table:{d}/t.csv", "-o", "{d}/t.csv"], "t.csv"),
    # a file of an input folder (crosscheck's data folder, a renders folder to check)
    (["crosscheck", "--quick", "--data", "{d}", "--json", "{d}/sub/../d.json"], "d.json"),
    (["conformance", "check", "{d}", "--json", "{d}/d.json"], "d.json"),
]


@pytest.mark.parametrize(("argv", "kept"), SAME_AS_INPUT, ids=lambda x: " ".join(x[:2]))
def test_an_output_that_is_an_input_is_refused(argv, kept, files, capsys):
    before = _digest(files / kept)
    _refused([a.format(d=files) for a in argv], capsys, "is also an input of this command")
    assert _digest(files / kept) == before


@pytest.mark.parametrize("link", ["hard", "symbolic", "dotdot"])
def test_links_to_an_input_are_the_input(link, files, capsys):
    out = files / "link.exr"
    if link == "hard":
        os.link(files / "A.exr", out)
    elif link == "symbolic":
        out.symlink_to(files / "A.exr")
    else:
        (files / "sub").mkdir()
        out = files / "sub" / ".." / "A.exr"
    before = _digest(files / "A.exr")
    _refused(["compare", files / "A.exr", files / "A.exr", "--diff", out], capsys, "input")
    assert _digest(files / "A.exr") == before


@pytest.mark.parametrize(
    "argv",
    [
        ["polymer", "characterize", "-o", "/dev/null"],
        ["env", "fit", "-o", "/dev/null"],
        ["sweep", "{d}/s.toml", "-o", "/dev/null"],
        ["equations", "-o", "/dev/null"],
        ["render", SCENE, "-o", "/dev/null"],
        ["compare", "{d}/A.exr", "{d}/A.exr", "--json", "/dev/full"],
    ],
    ids=lambda a: " ".join(a[:2]),
)
def test_device_nodes_are_never_replaced(argv, files, capsys):
    device = Path(argv[-1])
    before = device.stat()
    _refused([a.format(d=files) for a in argv], capsys, "a device or special file")
    after = device.stat()
    assert stat.S_ISCHR(after.st_mode)
    assert (after.st_ino, after.st_rdev) == (before.st_ino, before.st_rdev)


def test_a_fifo_is_refused(files, capsys):
    fifo = files / "out.csv"
    os.mkfifo(fifo)
    _refused(["sweep", files / "s.toml", "-o", fifo], capsys, "a device or special file")
    assert stat.S_ISFIFO(fifo.stat().st_mode)


def test_two_outputs_that_are_one_file_are_refused(files, capsys):
    _refused(
        ["compare", files / "A.exr", files / "A.exr", "--diff", files / "o.exr", "--json",
         files / "o.exr"], capsys, "would write it twice",
    )  # fmt: skip
    assert not (files / "o.exr").exists()


def test_a_name_too_long_for_the_file_system_is_refused(files, capsys):
    long = files / ("x" * 250 + ".exr")
    _refused(["compare", files / "A.exr", files / "A.exr", "--diff", long], capsys, "longer than")
    assert sorted(p.name for p in files.iterdir()) == ["A.exr", "c.toml", "d.json", "e.toml",
                                                       "g.toml", "s.toml", "t.csv"]  # fmt: skip


def test_a_zarr_store_never_replaces_a_folder_of_other_files(tmp_path, capsys):
    photos = tmp_path / "photos.zarr"
    photos.mkdir()
    (photos / "holiday.jpg").write_bytes(b"\xff\xd8 a photo")
    _refused(["env", "convert", VENICE, photos], capsys, "not a Zarr store")
    assert (photos / "holiday.jpg").read_bytes() == b"\xff\xd8 a photo"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["photos.zarr"]  # no temporary left


def test_a_zarr_store_replaces_an_earlier_store_and_not_its_own_input(tmp_path, capsys):
    store = tmp_path / "v.zarr"
    assert main(["env", "convert", VENICE, str(store), "--rows", "256"]) == 0
    assert main(["env", "convert", VENICE, str(store), "--rows", "128"]) == 0  # replaced
    capsys.readouterr()
    _refused(["env", "spectralize", store, "--model", "default", "-o", store], capsys, "input")


def test_profile_without_its_tools_writes_nothing(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("PATH", str(tmp_path / "empty"))
    _refused(["display", "calibrate", "--profile", "-o", tmp_path / "d.cal"], capsys, "colprof")
    assert list(tmp_path.iterdir()) == []


FOLDER_OUTPUTS = {("report", "out"), ("shrm orbit", "out"), ("conformance references", "out"),
                  ("conformance export", "out"), ("phong", "images"),
                  ("impastor painting", "out")}  # fmt: skip
OUTPUT_DESTS = {"out", "output", "json", "html", "diff", "exr", "counts", "screenshot", "markdown"}


def _actions(parser, prefix=""):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _actions(sub, f"{prefix} {name}".strip())
        else:
            yield prefix, action


def test_every_output_argument_is_under_the_policy():
    # a new command's output flag must be marked (type=output_file), so main() checks it
    found = 0
    for command, action in _actions(build_parser()):
        if action.dest in OUTPUT_DESTS and (command, action.dest) not in FOLDER_OUTPUTS:
            assert action.type in (output_file, output_file_or_stdout), (
                f"specref {command} {action.option_strings}"
            )
            found += 1
    assert found >= 20
    assert isinstance(output_file("x.exr"), OutputPath)
    assert isinstance(output_file("x.zarr"), OutputStore)
    assert type(input_file("x.exr")).__name__ == "InputPath"


@pytest.mark.parametrize(
    "argv",
    [
        ["conformance", "export", "{d}"],
        ["conformance", "export", "{d}", "--format", "mitsuba"],
        ["impastor", "painting", "{d}"],
        ["conformance", "references", "--out", "{d}", "--scene", "colorchecker-d65"],
    ],
    ids=lambda a: " ".join(a[:2]),
)
def test_a_folder_of_other_files_is_not_filled(argv, tmp_path, capsys):
    # The commands that fill a folder write files of their own names into it: a folder holding a
    # user's files (here one of the same name as the command's) is refused, nothing is written
    (tmp_path / "lambert-point-d65.toml").write_text("mine\n")
    (tmp_path / "holiday.jpg").write_bytes(b"jpeg")
    before = sorted(p.name for p in tmp_path.iterdir())
    _refused([a.format(d=tmp_path) for a in argv], capsys, "the folder holds other files")
    assert sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith(".")) == before
    assert (tmp_path / "lambert-point-d65.toml").read_text() == "mine\n"


def test_a_folder_the_command_filled_before_is_filled_again(tmp_path, capsys):
    assert main(["impastor", "painting", str(tmp_path / "p"), "--size", "16"]) == 0
    assert main(["impastor", "painting", str(tmp_path / "p"), "--size", "16", "--seed", "2"]) == 0
    assert "seed 2" in capsys.readouterr().out


@pytest.mark.parametrize(
    "argv",
    [
        ["impastor", "render", "--size", "8", "--out", "-"],
        ["conformance", "check", "{d}", "--json", "-"],
        ["sh", "project", VENICE, "-o", "-"],
    ],
    ids=lambda a: " ".join(a[:2]),
)
def test_a_dash_is_standard_output_only_where_offered(argv, files, capsys):
    # '-' prints where a command offers it (compare --json -, render --json -); elsewhere it was
    # written as a file named '-'
    with pytest.raises(SystemExit) as usage:
        main([a.format(d=files) for a in argv])
    assert usage.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "'-' (standard output) is not offered here" in err
    assert len(err.splitlines()) == 1
    assert not (Path.cwd() / "-").exists()


def test_a_paintings_files_are_inputs_and_its_folder_takes_renders(tmp_path, capsys):
    # painting.toml and the files it names are inputs; a render written into the painting's
    # folder is not one, so it may be written there again
    folder = tmp_path / "p"
    assert main(["impastor", "painting", str(folder), "--size", "16"]) == 0
    before = {name: _digest(folder / name) for name in ("painting.toml", "reflectance.tif")}
    render = ["impastor", "render", "--size", "8", "--method", "median_cut", "--painting"]
    for name in before:
        _refused([*render, folder, "--out", folder / name], capsys, "is also an input")
    path = ["impastor", "path", "--size", "8", "--frames", "2", "--method", "median_cut"]
    _refused([*path, "--painting", folder, "-o", folder / "sub" / ".." / "painting.toml"],
             capsys, "is also an input")  # fmt: skip
    assert {name: _digest(folder / name) for name in before} == before
    for _ in range(2):
        assert main([str(a) for a in (*render, folder, "--out", folder / "render.png")]) == 0


def test_a_store_never_takes_files_that_are_not_its_own(tmp_path, capsys):
    # an earlier store with a user's files in it, or an input inside the store, is not replaced
    store = tmp_path / "e.zarr"
    assert main(["env", "convert", VENICE, str(store), "--rows", "16"]) == 0
    (store / "notes.txt").write_text("mine\n")
    _refused(["env", "convert", VENICE, store, "--rows", "16"], capsys, "also holds other files")
    assert (store / "notes.txt").read_text() == "mine\n"
    (store / "notes.txt").unlink()
    inside = store / "precious.hdr"
    inside.write_bytes(Path(VENICE).read_bytes())
    _refused(["env", "convert", inside, store, "--rows", "16"], capsys, "precious.hdr")
    assert inside.is_file()


@pytest.mark.parametrize("kind", ["fifo", "device"])
def test_a_special_file_is_never_read(kind, tmp_path, capsys):
    # /dev/zero never ends (brdf check was killed at 24 GB); a FIFO waits for a writer
    path = tmp_path / "in.toml"
    if kind == "fifo":
        os.mkfifo(path)
    else:
        path = Path("/dev/zero")
    _refused(["brdf", "check", path], capsys, "a device or special file")

"""``specref render``: outputs, and exit code 2 with one line and no traceback for bad input."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from reference.data import data_path
from reference.images.formats import read_exr, read_png
from validation.cli import main

EXAMPLES = data_path("examples")

GOOD = """
[render]
width = 8
height = 6
[materials.m]
type = "lambert"
k_d = {k_d}
[[objects]]
type = "sphere"
material = "m"
[[lights]]
type = "point"
position = [0, 0, 5]
"""

#: name -> (scene text or None for no file, extra arguments, a piece of the expected message)
BAD_INPUT = {
    "empty scene": ("", [], "scene.toml: an empty scene file"),
    "malformed TOML": ("[camera\neye = [0, 0, 5]", [], "scene.toml: malformed TOML: Expected ']'"),
    "unknown key": ("[camera]\nfov = 30", [], "scene.toml: camera: unknown key 'fov'; allowed:"),
    "missing scene": (None, [], "scene.toml: file not found"),
    "missing CSV": (
        GOOD.replace("{k_d}", '{ csv = "nope.csv" }'),
        [],
        "scene.toml: materials.m.k_d.csv: file not found:",
    ),
    "unreadable image": (
        '[[lights]]\ntype = "environment"\nfile = "junk.hdr"',
        [],
        "junk.hdr: cannot read Radiance HDR image",
    ),
    "NaN spectrum": (
        GOOD.replace("{k_d}", "{ wavelengths = [380, 780], values = [nan, 1] }"),
        [],
        "scene.toml: materials.m.k_d: values must be finite, got nan at 380 nm",
    ),
    # huge values used to write infinities and NaN into the image, or end in OverflowError
    "huge k_d": (GOOD.replace("{k_d}", "1e200"), [], "materials.m.k_d: must be within ±1e+12"),
    "huge light position": (
        GOOD.replace("{k_d}", "0.5").replace("[0, 0, 5]\n", "[0, 0, 1e300]\n"),
        [],
        "must be within ±1e+12",
    ),
    "inf spectrum": (
        GOOD.replace("{k_d}", "inf"),
        [],
        "scene.toml: materials.m.k_d: must be finite",
    ),
    "negative spectrum": (
        GOOD.replace("{k_d}", "-0.5"),
        [],
        "scene.toml: materials.m.k_d: must be >= 0, got -0.5",
    ),
    "non-monotonic wavelengths": (
        GOOD.replace("{k_d}", "{ wavelengths = [380, 600, 500, 780], values = [1, 1, 1, 1] }"),
        [],
        "scene.toml: materials.m.k_d: wavelengths must increase strictly",
    ),
    "mesh with NaN vertices": (
        GOOD.replace('type = "sphere"', 'type = "mesh"\nfile = "nan.obj"').replace("{k_d}", "1"),
        [],
        "nan.obj: line 2: v 2: must be finite, got [nan, 0.0, 0.0]",
    ),
    "zero width": (
        GOOD.replace("{k_d}", "1"),
        ["--width", "0"],
        "render.width: must be an integer",
    ),
    "absurd resolution": (
        "[render]\nwidth = 100000",
        [],
        "scene.toml: render.width: must be an integer in [1, 16384], got 100000",
    ),
    "absurd supersampling": (
        "[render]\nwidth = 4096\nheight = 4096\nsupersample = 16",
        [],
        "samples is above the limit of 16777216 (MAX_RENDER_SAMPLES)",
    ),
    "wrong output type": (GOOD.replace("{k_d}", "1"), ["-o", "out.jpg"], "-o: the output must end"),
    "width not a number": (GOOD.replace("{k_d}", "1"), ["--width", "abc"], "argument --width"),
    "accuracy zero": (
        GOOD.replace("{k_d}", "1"),
        ["--accuracy", "0"],
        "--accuracy: must be a relative error in (0, 0.25], got 0",
    ),
    "unknown EXR output": (
        GOOD.replace("{k_d}", "1"),
        ["--exr", "out.exr", "--exr-output", "rgb"],
        "argument --exr-output: unknown value 'rgb'; allowed: display, xyz, spectral",
    ),
    "JSON suffix": (GOOD.replace("{k_d}", "1"), ["--json", "out.txt"], "--json: the output must"),
}


#: Cases also run as real processes (each costs a Python start-up and the colour-science import).
SUBPROCESS_CASES = ("malformed TOML", "mesh with NaN vertices", "width not a number")


def _prepare(folder: Path, name: str) -> list[str]:
    """Write the case's files into ``folder``; return the ``specref`` arguments."""
    text, extra, _ = BAD_INPUT[name]
    (folder / "junk.hdr").write_bytes(b"#?RADIANCE\nnot an image\n")
    (folder / "nan.obj").write_text("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n")
    if text is not None:
        (folder / "scene.toml").write_text(text, encoding="utf-8")
    output = [] if "-o" in extra else ["-o", "out.png"]
    return ["render", "scene.toml", *output, *extra]


def _check_one_line_exit_2(code: int, stderr: str, name: str, folder: Path) -> None:
    assert code == 2, stderr
    assert "Traceback" not in stderr
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, stderr
    assert lines[0].startswith("specref: error: ")
    assert BAD_INPUT[name][2] in lines[0]
    # Nothing (half-)written is left behind.
    assert not list(folder.glob("out*"))
    assert not list(folder.glob(".out*"))


@pytest.mark.parametrize("name", BAD_INPUT)
def test_bad_input_exits_2_with_one_line(name, tmp_path, monkeypatch, capsys):
    args = _prepare(tmp_path, name)
    monkeypatch.chdir(tmp_path)
    try:
        code = main(args)
    except SystemExit as exit_:  # argparse usage errors exit from the parser
        code = exit_.code
    _check_one_line_exit_2(code, capsys.readouterr().err, name, tmp_path)


def test_bad_input_in_a_subprocess(tmp_path):
    procs = {}
    for name in SUBPROCESS_CASES:
        folder = tmp_path / name.replace(" ", "-")
        folder.mkdir()
        command = [sys.executable, "-m", "validation.cli", *_prepare(folder, name)]
        procs[name] = (
            folder,
            subprocess.Popen(
                command, cwd=folder, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
            ),
        )
    for name, (folder, proc) in procs.items():
        _, stderr = proc.communicate(timeout=300)
        _check_one_line_exit_2(proc.returncode, stderr, name, folder)


def test_render_writes_png_and_exr(tmp_path, capsys):
    code = main(
        [
            "render",
            str(EXAMPLES / "phong-sphere.toml"),
            "-o",
            str(tmp_path / "s.png"),
            "--exr",
            str(tmp_path / "s.exr"),
            "--width",
            "24",
            "--supersample",
            "1",
        ]
    )
    assert code == 0
    assert "wrote" in capsys.readouterr().out
    png = read_png(tmp_path / "s.png")
    exr, names = read_exr(tmp_path / "s.exr")
    assert png.shape == (24, 24, 3)  # a lone --width keeps the scene's square aspect
    assert exr.shape == (24, 24, 3)
    assert names == ["R", "G", "B"]
    # The centre of the sphere is lit and the corners are the background.
    assert png[12, 12].sum() > png[0, 0].sum()
    assert np.isfinite(exr).all()


def test_oracle_flag_reaches_the_shading_options(tmp_path, monkeypatch):
    import reference.scene.render

    seen = {}
    original = reference.scene.render.render_scene

    def spy(scene, *args, **kwargs):
        seen.update(kwargs.get("options") or {})
        return original(scene, *args, **kwargs)

    monkeypatch.setattr(reference.scene.render, "render_scene", spy)
    scene = EXAMPLES / "colorchecker-d65.toml"
    assert (
        main(["render", str(scene), "-o", str(tmp_path / "c.png"), "--width", "12", "--oracle"])
        == 0
    )
    assert seen == {"environment": "bruteforce"}


ENV_SCENE = """
[render]
width = 6
height = 6
[camera]
eye = [0, 0, 4]
target = [0, 0, 0]
fov_deg = 20
[materials.m]
type = "lambert"
k_d = 0.5
[[objects]]
type = "sphere"
material = "m"
[[lights]]
type = "environment"
file = "sky.exr"
{placement}
"""


def test_texel_placement_scene_key_and_flag_agree(tmp_path):
    # The scene key and the CLI flag change the render the same way; the two placements differ
    # (a map with a bright top row: Mitsuba's rows put it on the pole, specref's half a row below).
    from reference.images.formats import write_exr

    sky = np.full((8, 16, 3), 0.1)
    sky[0] = 5.0
    write_exr(tmp_path / "sky.exr", sky)
    (tmp_path / "c.toml").write_text(ENV_SCENE.format(placement=""))
    (tmp_path / "m.toml").write_text(ENV_SCENE.format(placement='texel_placement = "mitsuba"'))
    runs = {
        "centred": ["c.toml"],
        "key": ["m.toml"],
        "flag": ["c.toml", "--texel-placement", "mitsuba"],
    }
    images = {}
    for name, (scene, *flags) in runs.items():
        exr = tmp_path / f"{name}.exr"
        args = ["render", str(tmp_path / scene), "-o", str(tmp_path / f"{name}.png")]
        assert main([*args, "--exr", str(exr), "--oracle", *flags]) == 0
        images[name] = read_exr(exr)[0]
    np.testing.assert_array_equal(images["key"], images["flag"])
    assert np.abs(images["key"] - images["centred"]).max() > 1e-3

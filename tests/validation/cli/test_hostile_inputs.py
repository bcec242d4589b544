"""Inputs that used to end in a traceback or a crash: each is now one line and exit code 2.

A binary target file, a model file that is a JSON list, a truncated Radiance file, an image of zero
rows (OpenEXR's writer aborted the process on it), a negative seed, a display file that is
``/dev/zero`` or nested 100,000 deep, a port above 65535, scheduler protocols specref does not
speak, and a sibling output that is a folder; and inputs that used to be accepted silently:
images with NaN or infinite pixels, reflectances of -0.5 or 5 (docs/bad-input.md).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from reference.data import data_path
from reference.images.formats import write_exr
from validation.cli import main

VENICE = data_path("environments/venice_sunset_1k.hdr")


def _make(tmp_path: Path, name: str) -> Path:
    path = tmp_path / name
    if name == "binary.csv":
        path.write_bytes(b"\x00\xff\xfe not text")
    elif name == "list.json":
        path.write_text("[1, 2]")
    elif name == "truncated.hdr":
        path.write_bytes(Path(VENICE).read_bytes()[:300])
    elif name == "zero.hdr":
        path.write_bytes(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 0 +X 16\n")
    elif name == "deep.json":
        path.write_text("[" * 100_000 + "]" * 100_000)
    elif name == "extra-key.toml":
        from shrm.polymer.kubelka_munk import DEFAULT_CONSTITUENTS

        path.write_text(Path(DEFAULT_CONSTITUENTS).read_text().replace("[base]", "[base]\nfoo = 1"))
    elif name == "steep.toml":  # scattering as λ^-1e308
        from shrm.polymer.kubelka_munk import DEFAULT_CONSTITUENTS

        text = Path(DEFAULT_CONSTITUENTS).read_text()
        path.write_text(text.replace("S_exponent = 2.0", "S_exponent = 1e308"))
    elif name.startswith("model-"):  # the shipped model file, one key spoilt
        import json

        doc = json.loads(Path(data_path("spectral_regression_sRGB.json")).read_text())
        if name == "model-x.json":
            doc["coefficients"][0][0] = "x"
        elif name == "model-ragged.json":
            doc["coefficients"][1].pop()
        elif name == "model-range.json":
            doc["wavelengths_nm"] = "380-780"
        else:
            del doc["coefficients"]
        path.write_text(json.dumps(doc))
    elif name == "mat.toml":
        path.write_text('name = "brick"\n[material]\nk_d = 0.4\nk_s = 0.4\nn = 50\n')
    elif name == "sweep.toml":
        path.write_text('kind = "phong"\n')
    elif name in ("d.cube", "empty"):
        path.mkdir()
    elif name == "square-data":  # a data folder whose map is square
        (path / "spectra").mkdir(parents=True)
        (path / "environments").mkdir()
        write_exr(path / "environments" / "square.exr", np.ones((8, 8, 3)))
    elif name in ("nan.exr", "inf.exr", "fine.exr"):
        image = np.full((4, 4, 3), 0.5)
        image[1, 2, 1] = {"nan.exr": np.nan, "inf.exr": np.inf, "fine.exr": 0.5}[name]
        write_exr(path, image, ["X", "Y", "Z"])
    elif name == "negative.exr":
        image = np.ones((8, 16, 3))
        image[3, 4, 1] = -1.0
        write_exr(path, image)
    elif name in ("nan-stderr.exr", "black.exr"):
        image = np.zeros((4, 4, 4)) if name == "black.exr" else np.full((4, 4, 4), 0.5)
        image[0, 0, 3] = np.nan if name == "nan-stderr.exr" else 0.0
        write_exr(path, image, ["X", "Y", "Z", "Y.stderr"])
    elif name in ("zero-mask.exr", "nan-mask.exr"):
        mask = np.zeros((4, 4, 1))
        mask[1, 1, 0] = np.nan if name == "nan-mask.exr" else 0.0
        write_exr(path, mask, ["Y"])
    elif name == "gamma0.json":
        path.write_text('{"gamma": [0, 0, 0]}')
    elif name == "bright.json":
        path.write_text('{"white_cd_m2": 1e308}')
    elif name in ("offset.json", "offset99.json", "shift.json"):
        key, value = {"offset.json": ("offset", 1e308), "offset99.json": ("offset", 0.99)}.get(
            name, ("shift_nm", 1e308)
        )
        path.write_text(f'{{"{key}": [{value}, 0, 0]}}')
    elif name == "no-blue.json":
        path.write_text('{"ramps": {"drive": [0, 1], "R": [0, 1], "G": [0, 1]}}')
    elif name == "huge-rgb.csv":
        path.write_text("R,G,B,380,780\n0.2,0.2,0.2,0.3,0.3\n0.5,0.4,1e308,0.3,0.3\n")
    elif name in ("negative.csv", "percent.csv"):
        value = -0.5 if name == "negative.csv" else 5.0
        path.write_text(f"R,G,B,380,780\n0.2,0.2,0.2,0.3,0.3\n0.5,0.4,0.3,{value},0.3\n")
    return path


CASES = [
    (["env", "fit", "--target", "{binary.csv}", "-o", "{out.json}"], "not a UTF-8 CSV text file"),
    (["env", "spectralize", VENICE, "--model", "{list.json}", "-o", "{out.exr}"],
     "not a specref-spectral-regression file"),
    # each was "malformed model file (ValueError)", "(KeyError)" or "(TypeError)"
    (["env", "spectralize", VENICE, "--model", "{model-x.json}", "-o", "{out.exr}"],
     "model-x.json: coefficients[0][0]: must be a finite number, got 'x'"),
    (["env", "spectralize", VENICE, "--model", "{model-ragged.json}", "-o", "{out.exr}"],
     "model-ragged.json: coefficients[1]: has 40 values, coefficients[0] has 41; rows are of one"),
    (["env", "spectralize", VENICE, "--model", "{model-range.json}", "-o", "{out.exr}"],
     "model-range.json: wavelengths_nm: must be a list of numbers, got '380-780'"),
    (["env", "spectralize", VENICE, "--model", "{model-none.json}", "-o", "{out.exr}"],
     "model-none.json: missing key 'coefficients'; a version 2 model file holds features, degree,"),
    (["env", "convert", "{truncated.hdr}", "{out.zarr}"], "truncated Radiance HDR image"),
    # flags named while parsing: the library's messages named no flag, and a texel placement was
    # not checked at all in a scene without an environment map
    (["render", "data:examples/phong-sphere.toml", "-o", "{out.png}", "--exr-output", "hdr"],
     "argument --exr-output: unknown value 'hdr'; allowed: display, xyz, spectral"),
    # what the EXR holds, without an EXR (it was ignored without a word)
    (["render", "data:examples/phong-sphere.toml", "-o", "{out.png}", "--exr-output", "xyz"],
     "--exr-output xyz: says what the EXR holds; give --exr OUT.exr too"),
    (["render", "data:examples/phong-sphere.toml", "-o", "{out.png}", "--texel-placement", "edge"],
     "argument --texel-placement: unknown value 'edge'; allowed: centred, mitsuba"),
    (["env", "convert", VENICE, "{out.zarr}", "--rows", "0"],
     "argument --rows: must be a whole number in [1, 1048576], got '0'"),
    (["env", "spectralize", VENICE, "--model", "default", "--rows", "0", "-o", "{out.exr}"],
     "argument --rows: must be a whole number in [1, 1048576], got '0'"),
    (["env", "fit", "--ridge", "-1", "-o", "{out.json}"],
     "argument --ridge: must be a number in [0, 1], got '-1'"),
    (["env", "convert", "{zero.hdr}", "{out.zarr}"], "an image of 0 × 16 pixels"),
    (["env", "spectralize", "{zero.hdr}", "--model", "default", "-o", "{out.exr}"],
     "an image of 0 × 16 pixels"),
    (["display", "calibrate", "--seed", "-1", "-o", "{d.cal}"], "--seed: must be an integer >= 0"),
    (["display", "calibrate", "--display", "/dev/zero", "-o", "{d.cal}"], "not a regular file"),
    (["display", "calibrate", "--display", "{deep.json}", "-o", "{d.cal}"], "nested too deeply"),
    (["display", "calibrate", "-o", "{d.cal}", "{d.cube}"], None),  # d.cube made a folder below
    (["phong", "edit", "--port", "70000"], "a TCP port is 0 to 65535"),
    (["sweep", "{sweep.toml}", "--scheduler", "ucx://127.0.0.1:8786"], "allowed: tcp://HOST:PORT"),
    (["sweep", "{sweep.toml}", "--scheduler", "tls://127.0.0.1:8786"], "allowed: tcp://HOST:PORT"),
    (["report", "--scheduler", "tcp://host:1/path"], "allowed: tcp://HOST:PORT"),
    # silent accepts: "mean nan" for a NaN pixel, "no lit pixels" for an infinity in B
    (["display", "calibrate", "--display", "{bright.json}", "-o", "{d.cal}"],
     "white_cd_m2: must be in (0, 10000] cd/m², got 1e+308"),
    # messages that name the cause (gamma 0 was "white outside the gamut", '' was ".: not found")
    (["display", "calibrate", "--display", "{gamma0.json}", "-o", "{d.cal}"],
     "gamma0.json: gamma: each channel's exponent must be in (0, 10], got [0.0, 0.0, 0.0]"),
    # NaN drives named no file; 0.99 was a LinAlgError traceback; shift_nm 1e308 was accepted
    (["display", "calibrate", "--display", "{offset.json}", "-o", "{d.cal}"],
     "offset.json: offset: each channel's offset o of ((1 - o) d + o)^gamma must be in [-0.5"),
    (["display", "calibrate", "--display", "{offset99.json}", "-o", "{d.cal}"],
     "offset99.json: offset: each channel's offset o"),
    (["display", "calibrate", "--display", "{shift.json}", "-o", "{d.cal}"],
     "shift.json: shift_nm: each channel's drift at zero drive must be in [-50, 50] nm"),
    (["display", "calibrate", "--display", "{no-blue.json}", "-o", "{d.cal}"],
     "no-blue.json: ramps: missing key 'B'"),  # was "ramps.B: must be finite, got nan"
    (["env", "spectralize", VENICE, "--model", "", "-o", "{out.exr}"],
     "argument --model: an empty file name"),
    (["compare", "{nan.exr}", "{fine.exr}"], "nan.exr: 1 pixels hold NaN or infinite values"),
    (["compare", "{fine.exr}", "{inf.exr}"], "inf.exr: 1 pixels hold NaN or infinite values"),
    (["env", "fit", "--target", "{negative.csv}", "-o", "{out.json}"],
     "patch 2: reflectances must be finite and in [-0.05, 1.5]"),
    (["env", "fit", "--target", "{percent.csv}", "-o", "{out.json}"],
     "patch 2: reflectances must be finite and in [-0.05, 1.5]"),
    (["env", "fit", "--target", "{huge-rgb.csv}", "-o", "{out.json}"],  # was fitted
     "huge-rgb.csv: patch 2: RGB must be finite and in [0, 10] (linear camera RGB, white"),
    # compare against nothing: a black reference or an empty mask was "no lit pixels", exit 0
    (["compare", "{fine.exr}", "{nan-stderr.exr}"], "Y.stderr: 1 pixels hold NaN, infinite or"),
    (["compare", "{fine.exr}", "{black.exr}"], "nothing to compare: no pixel of the reference"),
    (["compare", "{fine.exr}", "{fine.exr}", "--mask", "{zero-mask.exr}"], "within the mask is"),
    (["compare", "{fine.exr}", "{fine.exr}", "--mask", "{nan-mask.exr}"], "holds NaN or infin"),
    (["env", "preview", VENICE, "-o", "{out.exr}"], "the preview is an sRGB PNG"),
    (["env", "convert", "{negative.exr}", "{out.zarr}"], "radiance must be >= 0, found -1"),
    (["cache", "info", "--cache-dir", "{sweep.toml}"], "sweep.toml: not a folder"),
    (["cache", "info", "--cache-dir", ""], "an empty folder name"),
    (["report", "--out", "{sweep.toml}", "--only", "phong"], "sweep.toml: cannot write"),
    (["render", "{empty}", "-o", "{out.png}"], "empty: is a folder, not a TOML file"),
    (["polymer", "characterize", "-o", "{out.csv}", "--constituents", "{extra-key.toml}"],
     "extra-key.toml: base.foo: unknown key; allowed:"),
    (["polymer", "characterize", "-o", "{out.csv}", "--constituents", "{steep.toml}"],
     "steep.toml: base.S_exponent: must be a number in [0, 4]"),  # was "km_slab: S: ..."
    (["polymer", "characterize", "-o", "{out.csv}", "--thickness", "1,2", "--tio2", "0,101"],
     "--tio2: each TiO2 load must be in [0, 100] % by weight"),
    (["polymer", "characterize", "-o", "{out.csv}", "--thickness", "1,1e308", "--tio2", "0,1"],
     "--thickness: each thickness must be in [0, 1000] mm"),
    # sizes bounded by the memory they need (4096 ended in a MemoryError traceback under 8 GB)
    (["sh", "prefilter", VENICE, "--kernel", "lambert", "--size", "4096", "-o", "{out.exr}"],
     "--size: a cube face of 1 to 2048 texels, got 4096"),
    (["phong", "--material", "{mat.toml}", "--resolution", "4096", "--repeats", "1"],
     "resolution: must be an integer in [1, 2048], got 4096"),
    # crosscheck's data folder: a file or an empty folder was a traceback (Mitsuba 3 is a test
    # dependency: without it the line says how to install it)
    (["crosscheck", "--quick", "--data", "{sweep.toml}"], "not a folder laid out as specref's"),
    (["crosscheck", "--quick", "--data", "{empty}"], "(no environments/ folder)"),
    (["crosscheck", "--quick", "--data", "{square-data}"],
     "square.exr: a lat-long map (2:1) of at least"),  # the user's map named, before any case
]  # fmt: skip


@pytest.mark.parametrize(
    ("argv", "message"), CASES, ids=[" ".join(map(str, argv[:4])) for argv, _ in CASES]
)
def test_one_line_and_exit_2(argv, message, tmp_path, capsys):
    args = []
    for a in argv:
        if isinstance(a, str) and a.startswith("{"):
            args.append(str(_make(tmp_path, a.strip("{}"))))
        else:
            args.append(str(a))
    if message is None:  # the .cal's sibling .cube is a folder
        args, message = args[:-1], "d.cube: cannot write (is a folder"
    try:
        code = main(args)
    except SystemExit as usage_error:  # argparse's: refused while parsing
        code = usage_error.code
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert len(err.splitlines()) == 1, err
    assert message in err, err
    assert not (tmp_path / "out.zarr").exists()
    assert not (tmp_path / "out.exr").exists()
    assert not (tmp_path / "d.cal").exists()
    assert not (tmp_path / "out.png").exists()


def test_a_sweep_grid_beyond_its_bound_is_refused_before_any_cell(tmp_path, capsys):
    # a typing slip that makes a 24,000-cell grid asks for --yes; 2.4 million cells are refused
    # even with it; the message states the count and its factors, and nothing runs
    def grid(entries: int) -> Path:
        path = tmp_path / f"g{entries}.toml"
        path.write_text(
            'kind = "phong"\n[grid]\nmaterials = ["R1", "R2", "R3"]\nviews = ["near", "far"]\n'
            'placements = ["error", "uniform"]\ninterpolations = ["linear", "monotone"]\n'
            f"entries = {list(range(8, 8 + entries))}\nresolution = 4\n"
        )
        return path

    out = tmp_path / "out.csv"
    assert main(["sweep", str(grid(1000)), "--scheduler", "serial", "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "grid: 24,000 cells (3 materials × 2 views × 2 placements × 2 interpolations × " in err
    assert "at most 10,000 without --yes, 1,000,000 with it" in err
    big = ["sweep", str(grid(100_000)), "--scheduler", "serial", "--yes", "-o", str(out)]
    assert main(big) == 2
    assert "grid: 2,400,000 cells" in capsys.readouterr().err
    assert not out.exists()


def test_a_characterization_grid_beyond_its_bound_is_refused_before_any_chip(tmp_path, capsys):
    # 200 thicknesses × 60 loads asks for --yes; 1,000 × 1,001 is refused even with it; the
    # message gives the count, its factors and the file's size, and nothing is written
    def axis(n: int, start: float) -> str:
        return ",".join(f"{start + 0.001 * i:.3f}" for i in range(n))

    out = tmp_path / "c.csv"
    command = ["polymer", "characterize", "-o", str(out), "--thickness", axis(200, 0.1)]
    assert main([*command, "--tio2", axis(60, 0.0)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "grid: 12,000 chips (200 thicknesses × 60 TiO2 loads × 41 bands, about 21 MB" in err
    assert "at most 10,000 without --yes, 1,000,000 with it" in err
    command = ["polymer", "characterize", "-o", str(out), "--thickness", axis(1000, 0.1)]
    assert main([*command, "--tio2", axis(1001, 0.0), "--yes"]) == 2
    assert "grid: 1,001,000 chips" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("command", [["render", "{}.toml", "-o", "x.png"], ["sweep", "{}.toml"],
                                     ["compare", "{}.exr", "{}.exr"]])  # fmt: skip
def test_an_input_name_too_long_for_the_file_system_is_one_line(command, tmp_path, capsys):
    name = str(tmp_path / ("y" * 300))
    argv = [a.format(name) if "{}" in a else a for a in command]
    if "-o" in argv:  # the output beside it
        argv[-1] = str(tmp_path / argv[-1])
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith("cannot read (a name in the path is too long for the file system)"), err
    assert len(err.splitlines()) == 1


def test_a_loop_of_symbolic_links_is_one_line(tmp_path, capsys):
    (tmp_path / "a.toml").symlink_to(tmp_path / "b.toml")
    (tmp_path / "b.toml").symlink_to(tmp_path / "a.toml")
    assert main(["sweep", str(tmp_path / "a.toml")]) == 2
    assert "a.toml: cannot read (a loop of symbolic links)" in capsys.readouterr().err


def test_equations_check_outside_a_checkout_says_so(tmp_path, monkeypatch, capsys):
    # an installed wheel has no docs/equations.md: "not found", not "out of date"
    monkeypatch.chdir(tmp_path)
    assert main(["equations", "--check"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (
        "specref: error: docs/equations.md: not found; --check compares a checkout's "
        "docs/equations.md (run it in the repository, or give -o FILE)"
    )


@pytest.mark.parametrize(
    "argv",
    [
        ["render", "data:examples/phong-sphere.toml", "-o", "a.png", "-o", "b.png"],
        ["render", "data:examples/phong-sphere.toml", "-o", "a.png", "--width", "8",
         "--width", "4"],
        ["sh", "project", "data:environments/venice_sunset_1k.hdr", "--order", "2", "--order", "4",
         "-o", "x.npz"],
    ],
)  # fmt: skip
def test_an_option_given_twice_is_refused_in_one_line(argv, tmp_path, capsys, monkeypatch):
    """The last one silently won: `-o a.png -o b.png` wrote b.png alone."""
    from validation.cli import main

    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as refused:
        main(argv)
    assert refused.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "given more than once" in err
    assert not any(tmp_path.iterdir())

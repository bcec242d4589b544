"""Tests of validation.studies.impastor_commands and `specref impastor`: inputs, table, render."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.images.formats import read_png
from validation.cli import main
from validation.studies.impastor_commands import format_table1, render_for_cli, table1_for_cli


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"n_channels": 2}, "^--channels: channel count must be >= 3, got 2$"),
        ({"design": "gauss"}, "^unknown multispectral design 'gauss'; allowed: "),
        ({"display_file": "/no/such.json"}, "^/no/such.json: file not found"),
    ],
)
def test_table1_for_cli_bad_input(kwargs, match):
    args = {"design": "optimized", "n_channels": 6, "white_luminance": 200.0}
    args.update(kwargs)
    with pytest.raises(SpecrefError, match=match):
        table1_for_cli(**args)


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (("D65", 16, "nearest"), "^unknown lighting method 'nearest'; allowed: fis, hybrid"),
        (("D65", 0, "median_cut"), r"^--size: must be an integer in \[1, 4096\], got 0$"),
        (("D65", 5000, "median_cut"), r"^--size: must be an integer in \[1, 4096\], got 5000$"),
        (("D66", 16, "median_cut"), "unknown illuminant 'D66'"),
    ],
)
def test_render_for_cli_bad_input(args, match, tmp_path):
    with pytest.raises(SpecrefError, match=match):
        render_for_cli(*args, tmp_path / "p.png")
    assert not (tmp_path / "p.png").exists()


def test_format_table1_round_trips_the_figures():
    # Property: every figure of the result appears in its row, to the printed two decimals, and
    # the out-of-gamut lines name the patches; a light without screen output prints "—".
    rows = [
        {
            "label": "D65 (24)",
            "simulation": {"mean": 0.123, "std": 0.05, "p90": 0.2, "max": 0.456},
            "screen": {"mean": 1.5, "std": 0.25, "p90": 2.0, "max": 3.125},
        },
        {
            "label": "A (24)",
            "simulation": {"mean": 0.3, "std": 0.1, "p90": 0.4, "max": 0.9},
            "screen": {},
        },
    ]
    result = {
        "design": "optimized",
        "n_channels": 6,
        "rows": rows,
        "lights": {"D65": {"out_of_gamut": []}, "A": {"out_of_gamut": ["cyan", "blue"]}},
    }
    lines = format_table1(result).splitlines()
    assert len(lines) == 3 + len(rows) + len(result["lights"])
    assert "6-channel optimized design" in lines[0]
    for row, line in zip(rows, lines[3:5], strict=True):
        assert line.startswith(row["label"])
        numbers = [float(x) for x in re.findall(r"\d+\.\d\d", line[len(row["label"]) :])]
        expected = [row["simulation"][k] for k in ("mean", "std", "p90", "max")]
        expected += [row["screen"][k] for k in ("mean", "std", "p90", "max") if row["screen"]]
        np.testing.assert_allclose(numbers, expected, atol=0.005)
    assert lines[4].rstrip().endswith("—")
    assert lines[5] == "out of gamut under D65: 0 (none)"
    assert lines[6] == "out of gamut under A: 2 (cyan, blue)"


def test_cli_table1_writes_json(tmp_path, capsys):
    out = tmp_path / "t1.json"
    assert main(["impastor", "table1", "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "Table 1" in text
    assert "out of gamut under A" in text
    doc = json.loads(out.read_text())
    labels = [r["label"] for r in doc["rows"]]
    assert {"D65 (24)", "D50 (24)", "A (24)"} <= set(labels)
    assert doc["n_channels"] == 6


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["impastor", "table1", "--channels", "2"], "channel count must be >= 3"),
        (["impastor", "table1", "--design", "gauss"], "argument --design: unknown value"),
        (["impastor", "table1", "--white-luminance", "1e6"], "--white-luminance: the white"),
        (["impastor", "table1", "--white-luminance", "nan"], "must be in (0, 320"),
        (["impastor", "table1", "--display", "/no/such.json"], "file not found"),
        (["impastor", "render", "--method", "nearest"], "argument --method: unknown value"),
        (["impastor", "render", "--light", "D66"], "unknown illuminant 'D66'"),
        (["impastor", "render", "--tolerance", "0"], "--tolerance: must be a relative error in"),
        (["impastor", "render", "--tolerance", "1e6"], "--tolerance: must be a relative error in"),
        (["impastor", "render", "--tolerance", "loose"], "(0.02 is 2 %) or 'fixed', got 'loose'"),
        # the display's options are checked whether or not --counts uses them
        (["impastor", "render", "--screen-lux", "nan"], "--screen-lux: must be in [0, 200000]"),
        (["impastor", "render", "--screen-lux=-1000"], "--screen-lux: must be in"),
        (["impastor", "render", "--observer", "nan,0,0.6"], "--observer: must be x,y,z in metres"),
        (["impastor", "render", "--light-luminance", "1e308"], "--light-luminance: must be in"),
        (["impastor", "render", "--light-luminance", "nan"], "--light-luminance: must be in"),
        (["impastor", "render", "--light-position", "0,1e308,1e308"], "finite and within 100 m"),
        (["impastor", "path", "-o", "p.png", "--fps", "1e-5"], "--fps: must be in [0.1, 120]"),
        (
            ["impastor", "path", "-o", "p.png", "--size", "4096", "--frames", "600"],
            "the animation holds 28.1 GiB of frames, more than 2 GiB",
        ),
        (["impastor", "path", "-o", "p.png", "--from", "0,1e308,0.6"], "--from: must be x,y,z"),
    ],
)
def test_cli_bad_input_exits_2(argv, message, capsys):
    try:
        code = main(argv)
    except SystemExit as usage_error:  # a flag's value refused while parsing
        code = usage_error.code
    assert code == 2
    err = capsys.readouterr().err
    assert message in err
    assert "Traceback" not in err


def test_cli_render(tmp_path, capsys, monkeypatch):
    out = tmp_path / "p.png"
    assert (
        main(["impastor", "render", "--size", "24", "--method", "median_cut", "--out", str(out)])
        == 0
    )
    assert read_png(out).shape[:2] == (24, 24)


def test_cli_render_to_a_tolerance_records_its_settings(tmp_path, capsys):
    # the settings chosen and the promised bound: in the summary and in the PNG's text chunk
    import json

    import imageio.v3 as iio

    out = tmp_path / "p.png"
    argv = ["impastor", "render", "--size", "24", "--light", "A", "--tolerance", "0.05"]
    assert main([*argv, "-o", str(out)]) == 0  # -o, as every command that writes a file
    summary = capsys.readouterr().out
    assert "within the tolerance 5 %" in summary
    settings = json.loads(iio.immeta(out)["specref"])
    assert settings["tolerance"] == 0.05
    assert settings["met"]
    assert settings["pilot_error"] <= 0.05
    assert f"N={settings['n_lights']} K={settings['n_samples']}" in summary
    # the pixels' shares of the point lights, FIS and the hybrid, in the summary and the PNG
    shares = settings["shares"]
    assert sum(shares) == pytest.approx(1.0, abs=1e-3)
    assert (
        "pixels on point lights / FIS / hybrid {:.0f} / {:.0f} / {:.0f} %".format(
            *(100 * x for x in shares)
        )
        in summary
    )


def _tilted_booth():
    # The screen tilted 15° (its mirror of an on-axis view turns 30° up) and the booth light 3.5°
    # off that mirror direction: inside the specular lobe (§3.4.3, Ferwerda: 1.1 % at the
    # mirror angle, negligible beyond 10°).
    from reference.display.pipeline import ScreenGeometry

    geometry = ScreenGeometry(tilt=np.radians(15.0))
    flare = {"screen_lux": 1000.0, "position": (0.0, 0.5, 1.0), "luminance": 2000.0}
    return geometry, (0.0, 0.0, 0.6), flare


def test_specular_flare_is_subtracted():
    # Erratum E46: with the specular flare subtracted, what the observer sees (emission at their
    # angle plus the diffuse and the specular flare) is the intended painting; compensating the
    # diffuse flare alone (what the CLI did before) leaves the specular flare on the screen.
    from reference.display.model import screen_flare_XYZ, virtual_display
    from reference.display.pipeline import off_mirror_angle_deg
    from validation.studies.impastor_commands import painting_on_display

    geometry, eye, flare = _tilted_booth()
    white = virtual_display().white_XYZ / virtual_display().white_XYZ[1]
    XYZ = np.random.default_rng(16).uniform(20.0, 60.0, (12, 16, 1)) * white  # grays, cd/m²
    both = painting_on_display(XYZ, geometry, eye, flare)
    assert both["in_gamut"].all()
    assert np.abs(both["seen_XYZ"][..., 1] / XYZ[..., 1] - 1).max() < 5e-3
    diffuse_only = painting_on_display(XYZ, geometry, eye, {**flare, "luminance": 0.0})
    mirror = off_mirror_angle_deg(geometry, eye, flare["position"], 12, 16)
    specular = screen_flare_XYZ(virtual_display(), np.zeros(3), flare["luminance"] * white, mirror)
    seen = diffuse_only["seen_XYZ"] + specular  # the light is there all the same
    assert specular[..., 1].max() > 5.0  # cd/m²: a visible veil
    assert np.abs(seen[..., 1] / XYZ[..., 1] - 1).max() > 0.1
    assert (both["counts"] <= diffuse_only["counts"]).all()


def test_write_counts_reports_both_flares(tmp_path):
    from validation.studies.impastor_commands import _write_counts

    geometry, eye, flare = _tilted_booth()
    XYZ = np.full((8, 8, 3), 40.0)
    line = _write_counts(XYZ, tmp_path / "c.png", geometry, eye, flare)
    assert re.search(r"diffuse 0\.64 cd/m², specular up to \d+\.\d\d cd/m²", line)
    assert read_png(tmp_path / "c.png").shape[:2] == (8, 8)


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        ("--light-position", "0,0,-1", "--light-position: (0, 0, -1) m must be x,y,z in front"),
        ("--light-position", "0,1", "--light-position: must be x,y,z in metres, finite and"),
        ("--light-luminance", "-5", "--light-luminance: must be in [0, 2e+09] cd/m², got -5.0"),
    ],
)
def test_render_light_bad_input(tmp_path, capsys, option, value, message):
    argv = ["impastor", "render", "--size", "8", "--out", str(tmp_path / "p.png")]
    argv += ["--counts", str(tmp_path / "c.png"), option, value]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert message in err[0]
    assert not (tmp_path / "p.png").exists()


def test_render_light_options_reach_the_counts(tmp_path, capsys, monkeypatch):
    # --light-position and --light-luminance change the counts written, through the real CLI
    # (the painting replaced by a uniform gray, so the test does not render).
    import impastor.painting

    gray = {"XYZ": np.full((6, 6, 3), 40.0), "sRGB": np.full((6, 6, 3), 0.5), "seconds": {}}
    gray["settings"] = {"n_lights": 32, "n_samples": 32, "n_sectors": 36, "failsafe": True}
    monkeypatch.setattr(impastor.painting, "render_painting", lambda *a, **k: gray)
    counts = {}
    for luminance in ("0", "2000"):
        out = tmp_path / f"c{luminance}.png"
        argv = ["impastor", "render", "--size", "6", "--out", str(tmp_path / "p.png")]
        argv += ["--counts", str(out), "--tilt", "15", "--light-position", "0,0.5,1.0"]
        assert main([*argv, "--light-luminance", luminance]) == 0
        assert "specular up to" in capsys.readouterr().out
        counts[luminance] = read_png(out)
    assert (counts["2000"] <= counts["0"]).all()
    assert (counts["2000"] < counts["0"]).any()


def test_cli_render_no_worse_than_the_fixed_settings(tmp_path, capsys):
    # --tolerance fixed: the cheapest settings the pilot finds no worse than 32/32/36
    import json

    import imageio.v3 as iio

    out = tmp_path / "p.png"
    argv = ["impastor", "render", "--size", "24", "--light", "A", "--tolerance", "fixed"]
    assert main([*argv, "-o", str(out)]) == 0
    summary = capsys.readouterr().out
    assert "no worse than the fixed settings'" in summary
    settings = json.loads(iio.immeta(out)["specref"])
    assert settings["baseline"] == "fixed"
    assert settings["pilot_error"] <= settings["tolerance"]  # the fixed settings' pilot error


@pytest.mark.parametrize("value", ["nan", "-0.02", "inf", "0"])
def test_cli_render_refuses_a_bad_tolerance_before_any_work(value, tmp_path, capsys):
    out = tmp_path / "p.png"
    argv = ["impastor", "render", "--size", "24", "--tolerance", value, "--out", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "--tolerance: must be a relative error in (0, 1)" in err
    assert not out.exists()


@pytest.mark.parametrize("where", ["folder", "file in the path", "device", "read-only"])
def test_cli_render_refuses_an_unwritable_output_before_the_pilot(where, tmp_path, capsys, request):
    # the pilot of --tolerance takes seconds: an output that cannot be written is refused first,
    # in one line, and an earlier output is left as it was
    if where == "read-only":  # a read-only file system (a tmpfs as root, simulated otherwise)
        earlier = request.getfixturevalue("read_only_folder") / "earlier.png"
    else:
        earlier = tmp_path / "ro" / "p.png"
        earlier.parent.mkdir()
        earlier.write_bytes(b"earlier")
    out = {
        "folder": tmp_path,
        "file in the path": earlier / "p.png",  # its parent is a file
        "device": "/dev/null",  # a rename onto it would replace the device node
        "read-only": earlier,
    }
    argv = ["impastor", "render", "--size", "24", "--tolerance", "0.05", "--out", str(out[where])]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "Traceback" not in err
    assert "settings for a tolerance" not in err  # refused before the pilot started
    if where == "read-only":
        assert "read-only file system" in err
    assert earlier.read_bytes() == b"earlier"
    assert not Path("/dev/null").is_file()

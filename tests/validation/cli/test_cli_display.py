"""Tests of ``specref display calibrate``: outputs, and one-line errors with exit code 2."""

from __future__ import annotations

import json

import pytest

from validation.cli import main


def test_calibrate_writes_outputs(tmp_path, capsys):
    out = tmp_path / "d65.cal"
    assert (
        main(
            [
                "display",
                "calibrate",
                "--white",
                "D65",
                "--curve",
                "lstar",
                "--points",
                "10",
                "--instrument",
                "ideal",
                "-o",
                str(out),
            ]
        )
        == 0
    )
    printed = capsys.readouterr().out
    assert "max Δu′v′ above 5 % of white" in printed
    for suffix in (".cal", ".cube", ".ti3", ".json"):
        assert out.with_suffix(suffix).exists()
    # every file with an ordinary new file's permissions (the .cube had kept mkstemp's 0600)
    modes = {out.with_suffix(s).stat().st_mode & 0o777 for s in (".cal", ".cube", ".ti3", ".json")}
    assert len(modes) == 1, modes
    assert json.loads(out.with_suffix(".json").read_text())["curve"] == "lstar"


def test_instrument_option_changes_the_result(tmp_path):
    results = {}
    for instrument in ("ideal", "colorimeter"):
        out = tmp_path / f"{instrument}.cal"
        main(["display", "calibrate", "--instrument", instrument, "-o", str(out)])
        results[instrument] = json.loads(out.with_suffix(".json").read_text())
    assert results["colorimeter"]["instrument"] == "colorimeter"
    assert (
        results["colorimeter"]["verification"]["max_duv_above_5pct"]
        > 5 * results["ideal"]["verification"]["max_duv_above_5pct"]
    )


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--white", "0.7,0.29"], "outside the display's gamut by Δu'v' = 0.0"),
        (["--points", "1"], "points: must be an integer in 2..64, got 1"),
        (["--points", "65"], "points: must be an integer in 2..64, got 65"),
        (["--curve", "gamma2.4"], "argument --curve: unknown value 'gamma2.4'"),
        (["--display", "NOFILE"], "NOFILE: file not found"),
    ],
)
def test_bad_input_one_line_exit_2(tmp_path, capsys, args, message):
    try:
        code = main(["display", "calibrate", *args, "-o", str(tmp_path / "x.cal")])
    except SystemExit as usage_error:  # a flag's value refused while parsing
        code = usage_error.code
    err = capsys.readouterr().err
    assert code == 2
    assert message in err
    assert err.count("\n") == 1


def test_bad_display_file(tmp_path, capsys):
    path = tmp_path / "lcd.json"
    path.write_text(
        json.dumps(
            {
                "ramps": {
                    "drive": [0, 0.5, 1],
                    "R": [0, 0.6, 0.5],
                    "G": [0, 0.5, 1],
                    "B": [0, 0.5, 1],
                }
            }
        )
    )
    code = main(["display", "calibrate", "--display", str(path), "-o", str(tmp_path / "x.cal")])
    assert code == 2
    assert "ramps.R: must increase with the drive" in capsys.readouterr().err


def test_impastor_render_observer_behind_the_screen(tmp_path, capsys):
    code = main(
        [
            "impastor",
            "render",
            "--size",
            "8",
            "--out",
            str(tmp_path / "p.png"),
            "--counts",
            str(tmp_path / "c.png"),
            "--observer",
            "0,0,-1",
        ]
    )
    assert code == 2
    assert "is behind the screen" in capsys.readouterr().err


def test_impastor_render_bad_observer(tmp_path, capsys):
    code = main(["impastor", "render", "--out", str(tmp_path / "p.png"), "--observer", "1,2"])
    assert code == 2
    assert (
        "--observer: must be x,y,z in metres, finite and within 100 m, got '1,2'"
        in capsys.readouterr().err
    )

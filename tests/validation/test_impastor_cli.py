"""Tests of validation.impastor_cli and `specref impastor`: checked inputs, table, render."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.images import read_png
from validation.cli import main
from validation.impastor_cli import format_table1, render_for_cli, table1_for_cli


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
        (["impastor", "table1", "--design", "gauss"], "unknown multispectral design"),
        (["impastor", "table1", "--display", "/no/such.json"], "file not found"),
        (["impastor", "render", "--method", "nearest"], "unknown lighting method"),
        (["impastor", "render", "--light", "D66"], "unknown illuminant 'D66'"),
    ],
)
def test_cli_bad_input_exits_2(argv, message, capsys):
    assert main(argv) == 2
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

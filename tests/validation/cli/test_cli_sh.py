"""``specref sh project|prefilter`` (library side: shrm.files): outputs, bands, exit code 2."""

from __future__ import annotations

import numpy as np
import pytest

from reference.colour.spectra import GRID_41
from reference.images.formats import read_exr, spectral_channel_names, write_exr
from validation.cli import main


def test_cli_project_and_prefilter(tmp_path, package_data):
    env = package_data / "environments" / "studio_small_03_1k.hdr"
    assert (
        main(
            [
                "sh",
                "project",
                str(env),
                "--order",
                "8",
                "--window",
                "hanning",
                "-o",
                str(tmp_path / "c.npz"),
            ]
        )
        == 0
    )
    data = np.load(tmp_path / "c.npz")
    assert data["coeffs"].shape == (3, 81)
    assert (
        main(
            [
                "sh",
                "prefilter",
                str(env),
                "--kernel",
                "lambert",
                "--out",
                str(tmp_path / "cube.exr"),
                "--size",
                "8",
            ]
        )
        == 0
    )
    assert (tmp_path / "cube.exr").is_file()


@pytest.mark.parametrize(
    "argv",
    [
        ["sh", "project", "/nonexistent.hdr", "--order", "4", "-o", "x.npz"],
        ["sh", "project", "ENV", "--order", "-1", "-o", "x.npz"],
        ["sh", "project", "ENV", "--order", "4", "--window", "hamming", "-o", "x.npz"],
        ["sh", "prefilter", "ENV", "--kernel", "ward", "--out", "x.exr"],
        ["sh", "prefilter", "SQUARE", "--kernel", "lambert", "--out", "x.exr"],
        ["sh", "prefilter", "NEG", "--kernel", "lambert", "--out", "x.exr"],
        ["sh", "project", "NAN", "--order", "2", "-o", "x.npz"],
        ["sh", "project", "ENV", "--order", "5000", "-o", "x.npz"],
        ["sh", "project", "BROKEN", "--order", "2", "-o", "x.npz"],
        ["sh", "prefilter", "ENV", "--kernel", "table:BADTABLE", "--out", "x.exr"],
        ["sh", "prefilter", "ENV", "--kernel", "phong:-3", "--out", "x.exr"],
        ["sh", "prefilter", "ENV", "--kernel", "lambert", "--tol", "2", "--out", "x.exr"],
    ],
)
def test_cli_bad_input_exit_2(argv, tmp_path, package_data, capsys):
    write_exr(tmp_path / "square.exr", np.ones((8, 8, 3)))
    write_exr(tmp_path / "neg.exr", -np.ones((8, 16, 3)))
    write_exr(tmp_path / "nan.exr", np.full((8, 16, 3), np.nan))
    (tmp_path / "broken.hdr").write_bytes(b"#?RADIANCE\nnot really\n")
    (tmp_path / "bad.csv").write_text("angle_rad,value\n0,1\n5,1\n")
    mapping = {
        "ENV": str(package_data / "environments" / "studio_small_03_1k.hdr"),
        "SQUARE": str(tmp_path / "square.exr"),
        "NEG": str(tmp_path / "neg.exr"),
        "x.npz": str(tmp_path / "x.npz"),
        "x.exr": str(tmp_path / "x.exr"),
        "NAN": str(tmp_path / "nan.exr"),
        "BROKEN": str(tmp_path / "broken.hdr"),
        "table:BADTABLE": f"table:{tmp_path / 'bad.csv'}",
    }
    try:
        code = main([mapping.get(a, a) for a in argv])
    except SystemExit as usage_error:  # a flag's value refused while parsing
        code = usage_error.code
    assert code == 2
    err = capsys.readouterr().err
    assert err.startswith("specref: error:")
    assert err.count("\n") == 1
    assert "Traceback" not in err


def test_cli_bands_conversions(tmp_path, rng):
    # RGB -> 41 bands (Mallett 2019) and a spectral EXR (wavelength channel names) -> RGB.

    rgb = tmp_path / "rgb.exr"
    write_exr(rgb, rng.random((16, 32, 3)))
    assert (
        main(
            [
                "sh",
                "project",
                str(rgb),
                "--order",
                "4",
                "--bands",
                "spectral",
                "-o",
                str(tmp_path / "s.npz"),
            ]
        )
        == 0
    )
    data = np.load(tmp_path / "s.npz")
    assert data["coeffs"].shape == (41, 25)
    assert str(data["channels"][0]) == "S0.380,000000nm"
    spectral = tmp_path / "spectral.exr"
    write_exr(
        spectral, rng.random((16, 32, 41)), channels=spectral_channel_names(GRID_41.wavelengths_nm)
    )
    out = tmp_path / "cube.exr"
    assert (
        main(
            [
                "sh",
                "prefilter",
                str(spectral),
                "--kernel",
                "phong:8",
                "--bands",
                "rgb",
                "--size",
                "4",
                "--out",
                str(out),
            ]
        )
        == 0
    )

    image, names = read_exr(out)
    assert image.shape == (24, 4, 3)
    assert names == ["R", "G", "B"]

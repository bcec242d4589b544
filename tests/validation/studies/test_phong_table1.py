import pytest

from reference.errors import SpecrefError
from validation.cli import main
from validation.studies.phong_table1 import run_material


def _write(tmp_path, text):
    path = tmp_path / "m.toml"
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize(
    ("text", "args", "match"),
    [
        ("[material]\nk_d = 0.2\nk_s = 0.5\nn = -3\n", [], "material.n: must be >= 0"),
        ("[material]\nk_d = 0.2\nk_s = 0.5\nn = nan\n", [], "must be finite"),
        (
            "[material]\nk_d = { wavelengths = [400, 500, 600], values = [0.1, 0.2] }\n"
            "k_s = 0.5\nn = 3\n",
            [],
            "material.k_d: 3 wavelengths but 2 values",
        ),
        ("[material]\nk_d = [0.1, 0.2]\nk_s = 0.5\nn = 3\n", [], "must be a number or a spectrum"),
        (
            '[material]\nk_d = 0.2\nk_s = { illuminant = "D65", scale = -1 }\nn = 3\n',
            [],
            "material.k_s: unknown key 'scale'",
        ),
        ('[spectral]\ngrid = "40"\n[material]\nk_d = 0.2\nk_s = 0.5\nn = 3\n', [], "spectral.grid"),
        (
            "[material]\nk_d = 0.2\nk_s = 0.5\nn = 3\n",
            ["--interp", "parabolic", "--entries", "2"],
            "needs entries >= 3",
        ),
        (
            "[material]\nk_d = 0.2\nk_s = 0.5\nn = 3\n",
            ["--placement", "importance", "--segments", "3"],
            "must divide entries",
        ),
        (
            "[material]\nk_d = 0.2\nk_s = 0.5\nn = 3\n",
            ["--placement", "best"],
            "argument --placement: unknown value 'best'",
        ),
        (
            "[material]\nk_d = 0.2\nk_s = 0.5\nn = 3\n",
            ["--interp", "cubic"],
            "argument --interp: unknown value 'cubic'",
        ),
        ("[material]\nk_d = 0.2\nk_s = 0.5\n", [], "material: missing key 'n'"),
        ("[material]\nk_d = 0.2\nk_s = 0.5\nn = 3\ncolour = 1\n", [], "unknown key 'colour'"),
    ],
)
def test_bad_material_input_exits_2(tmp_path, capsys, text, args, match):
    path = _write(tmp_path, text)
    argv = ["phong", "--material", path, "--resolution", "8", "--repeats", "1", *args]
    try:
        code = main(argv)
    except SystemExit as usage_error:  # a flag's value refused while parsing
        code = usage_error.code
    assert code == 2
    err = capsys.readouterr().err
    assert match in err
    assert len(err.strip().splitlines()) == 1
    with pytest.raises(SpecrefError):
        run_material(path, resolution=8, repeats=1, **_kwargs(args))


def _kwargs(args):
    names = {
        "--interp": "interpolation",
        "--entries": "entries",
        "--placement": "placement",
        "--segments": "segments",
    }
    out = {}
    for flag, value in zip(args[::2], args[1::2], strict=True):
        out[names[flag]] = int(value) if flag in ("--entries", "--segments") else value
    return out


def test_material_command_writes_json(tmp_path):
    import json

    path = _write(tmp_path, "[material]\nk_d = 0.2\nk_s = 0.5\nn = 40\n")
    out = tmp_path / "out.json"
    argv = [
        "phong",
        "--material",
        path,
        "--view",
        "near",
        "--entries",
        "32",
        "--resolution",
        "16",
        "--repeats",
        "1",
        "--tolerance",
        "0.05",
        "--json",
        str(out),
    ]
    assert main(argv) == 0
    result = json.loads(out.read_text())
    keys = {
        "scene",
        "view",
        "placement",
        "interpolation",
        "entries",
        "segments",
        "rms_display",
        "rms_linear",
        "overshoot",
        "build_s",
        "shade_s",
        "exact_shade_s",
        "frame_s",
        "exact_frame_s",
    }
    assert all(keys <= set(r) for r in result["rows"])
    assert result["tolerance"]["verified"]


def test_phong_without_action_or_material_exits_2(capsys):
    assert main(["phong"]) == 2


def test_material_files_take_the_spectra_of_scenes(tmp_path):
    # the forms of reference.scene.values.SPECTRUM_FORMS and the [spectral] table, as in scenes
    from phong_table.materialfile import load_material_file
    from reference.scene.values import SceneReader

    text = (
        '[spectral]\ngrid = "31"\n'
        '[material]\nk_d = { colorchecker = "dark skin" }\nk_s = { constant = 0.3 }\n'
        "n = { wavelengths = [400, 700], values = [10, 2000] }\n"
        '[light]\nspectrum = { illuminant = "FL2" }\n'
    )
    model = load_material_file(_write(tmp_path, text))
    reader = SceneReader("s.toml", grid=model.grid)
    assert model.grid.n_bands == 31
    assert model.material.k_d == pytest.approx(
        reader.spectrum_on_grid({"colorchecker": "dark skin"}, "k_d")
    )
    assert model.material.n[0] == 10.0
    assert model.material.n[-1] == 2000.0
    assert model.light.spectrum.name == "illuminant:FL2"

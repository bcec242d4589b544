"""Scene files: every section, every spectrum form, and one-line errors for bad input."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from numpy.testing import assert_allclose

from reference.colour.spectra import GRID_31, GRID_41
from reference.errors import SpecrefError
from reference.geometry.shapes import Plane, Sphere
from reference.materials.types import MATERIAL_TYPES, LambertMaterial, MaterialType, PhongMaterial
from reference.scene.lights import AmbientLight, PointLight
from reference.scene.loader import (
    LIGHT_TYPES,
    MAX_RENDER_SAMPLES,
    OBJECT_TYPES,
    Scene,
    check_render_size,
    load_scene,
    loads_scene,
)
from reference.scene.values import SPECTRUM_FORMS

ROOT = Path(__file__).resolve().parents[3]

GREY = """
[materials.grey]
type = "lambert"
k_d = 0.5
[[objects]]
type = "sphere"
material = "grey"
"""


def scene_with(text: str, tmp_path=None) -> Scene:
    return loads_scene(text, "scene.toml", tmp_path or ".")


def raises(message: str):
    """``pytest.raises`` for a SpecrefError whose message starts with ``message`` (literal)."""
    return pytest.raises(SpecrefError, match="^" + re.escape(message))


# --- a full scene ---------------------------------------------------------------------------------


def test_load_scene_reads_every_section(tmp_path):
    (tmp_path / "r.csv").write_text("nm,R\n380,0.2\n780,0.6\n")
    scene = scene_with(
        """
        title = "all sections"
        [spectral]
        grid = "31"
        observer = "CIE 1964 10 Degree Standard Observer"
        weights = "point"
        [camera]
        eye = [1, 2, 3]
        target = [0, 0, 0]
        projection = "orthographic"
        extent = 4.0
        [render]
        width = 40
        height = 30
        supersample = 3
        background = [0.1, 0.2, 0.3]
        [render.options]
        environment = "bruteforce"
        [display]
        colourspace = "Display P3"
        encoding = "gamma_2.2"
        exposure = 2.0
        chromatic_adaptation = "CAT02"
        [materials.red]
        type = "lambert"
        k_d = { csv = "r.csv" }
        [materials.gold]
        type = "phong"
        k_d = 0.1
        k_s = { constant = 0.8 }
        n = { wavelengths = [400, 700], values = [10, 100] }
        [[objects]]
        type = "sphere"
        center = [0, 1, 0]
        radius = 0.5
        material = "gold"
        [[objects]]
        type = "rectangle"
        size = [2, 1]
        normal = [0, 0, 1]
        material = "red"
        [[objects]]
        type = "plane"
        material = "red"
        [[lights]]
        type = "point"
        position = [0, 5, 5]
        spectrum = { illuminant = "A" }
        intensity = 2.0
        attenuation = [1, 0.1, 0.01]
        [[lights]]
        type = "ambient"
        intensity = 0.1
        """,
        tmp_path,
    )
    assert scene.title == "all sections"
    assert scene.grid == GRID_31
    assert scene.observer == "CIE 1964 10 Degree Standard Observer"
    assert scene.weights_method == "point"
    assert scene.camera.projection == "orthographic"
    assert scene.camera.eye == (1.0, 2.0, 3.0)
    assert (scene.render.width, scene.render.height, scene.render.supersample) == (40, 30, 3)
    assert scene.render.background == (0.1, 0.2, 0.3)
    assert dict(scene.shading_context().options) == {"environment": "bruteforce"}
    assert scene.display.colourspace == "Display P3"
    assert scene.display.encoding == "gamma_2.2"
    assert scene.display.exposure == 2.0
    assert scene.display.chromatic_adaptation == "CAT02"
    # The adaptation white defaults to the first light's spectrum.
    assert scene.display.white is scene.lights[0].spectrum
    assert scene.material_names == ("red", "gold")
    red, gold = scene.materials
    assert isinstance(red, LambertMaterial)
    assert isinstance(gold, PhongMaterial)
    # Source: linear interpolation of the CSV's two samples, (0.2 + (wl - 380)/400 * 0.4).
    assert_allclose(red.k_d, 0.2 + (GRID_31.wavelengths_nm - 380) / 400 * 0.4, rtol=1e-12)
    assert_allclose(gold.n, 10 + (GRID_31.wavelengths_nm - 400) / 300 * 90, rtol=1e-12)
    assert_allclose(gold.k_a, 0.0)
    sphere, rectangle, plane = scene.objects
    assert isinstance(sphere, Sphere)
    assert (sphere.center, sphere.radius, sphere.material) == ((0.0, 1.0, 0.0), 0.5, 1)
    assert isinstance(rectangle, Plane)
    assert (rectangle.size, rectangle.normal, rectangle.material) == ((2.0, 1.0), (0, 0, 1), 0)
    assert plane.size is None
    point, ambient = scene.lights
    assert isinstance(point, PointLight)
    assert point.attenuation == (1.0, 0.1, 0.01)
    assert point.intensity == 2.0
    assert point.spectrum.name == "illuminant:A"
    assert isinstance(ambient, AmbientLight)
    assert ambient.spectrum.name == "illuminant:D65"  # the documented default


def test_load_scene_defaults():
    scene = scene_with("")
    assert scene.grid == GRID_41
    assert (scene.objects, scene.lights, scene.materials) == ((), (), ())
    assert (scene.render.width, scene.render.height, scene.render.supersample) == (256, 256, 1)
    assert scene.render.background == (0.0, 0.0, 0.0)
    assert (scene.display.colourspace, scene.display.encoding) == ("sRGB", "srgb")
    assert scene.display.chromatic_adaptation is None
    assert scene.camera.eye == (0.0, 0.0, 5.0)


def test_load_scene_relative_paths_are_relative_to_the_scene_file(tmp_path):
    folder = tmp_path / "scenes" / "sub"
    folder.mkdir(parents=True)
    (folder / "k.csv").write_text("nm,R\n380,0.25\n780,0.25\n")
    (folder / "s.toml").write_text(
        '[materials.m]\ntype = "lambert"\nk_d = { csv = "k.csv" }\n', encoding="utf-8"
    )
    scene = load_scene(folder / "s.toml")
    assert_allclose(scene.materials[0].k_d, 0.25)
    assert scene.path == folder / "s.toml"


def test_with_render_keeps_the_aspect_ratio():
    scene = scene_with("[render]\nwidth = 300\nheight = 200\nsupersample = 2")
    r = scene.with_render(height=50).render
    assert (r.width, r.height, r.supersample) == (75, 50, 2)
    r = scene.with_render(width=10, height=10, supersample=1).render
    assert (r.width, r.height, r.supersample) == (10, 10, 1)


# --- spectrum forms: tests/reference/scene/test_values.py -----------------------------------------


def test_every_spectrum_form_key_is_documented():
    text = (ROOT / "docs" / "scene-format.md").read_text(encoding="utf-8")
    for form in SPECTRUM_FORMS.values():
        assert f"`{form.name}`" in text
        for key in form.keys:
            assert f"`{key}`" in text
    for registry in (OBJECT_TYPES, LIGHT_TYPES, MATERIAL_TYPES):
        for name in registry:
            assert f'`"{name}"`' in text or f"`{name}`" in text, name


# --- registries drive the loader ------------------------------------------------------------------


def test_a_registered_material_type_loads_without_editing_the_loader(monkeypatch):
    kind = MaterialType("tinted", LambertMaterial, ("k_d",), (), "Eq. (2), Wang et al.")
    monkeypatch.setitem(MATERIAL_TYPES._entries, "tinted", kind)
    scene = scene_with('[materials.t]\ntype = "tinted"\nk_d = 0.3')
    assert_allclose(scene.materials[0].k_d, 0.3)
    with raises("scene.toml: materials.t: unknown key 'k_s'; allowed: k_d, type"):
        scene_with('[materials.t]\ntype = "tinted"\nk_d = 0.3\nk_s = 1')


# --- bad input: one line naming the file, the key, what is allowed, what was given ---------------


def test_bad_material_value_message_has_the_documented_form():
    with raises("scene.toml: materials.gold.n: must be >= 0, got -3"):
        scene_with('[materials.gold]\ntype = "phong"\nk_d = 0.5\nk_s = 0.5\nn = -3')


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            "[camera]\nfov = 30",
            "scene.toml: camera: unknown key 'fov'; allowed: extent, eye, fov_deg,",
        ),
        (
            "colour = 1",
            "scene.toml: top level: unknown key 'colour'; allowed: camera, description,",
        ),
        (
            '[materials.m]\ntype = "lambert"\nkd = 0.5',
            "scene.toml: materials.m: unknown key 'kd'; allowed: k_d, type",
        ),
        (
            '[materials.m]\ntype = "lambert"\nk_d = { constant = 0.5, scale = 2 }',
            "scene.toml: materials.m.k_d: unknown key 'scale'; allowed: constant, extrapolation,",
        ),
        (
            GREY + "radius = 1\nradus = 2",
            "scene.toml: objects[0]: unknown key 'radus'; allowed: center, material, radius, type",
        ),
        (
            '[[lights]]\ntype = "point"\nposition = [0, 0, 1]\npower = 3',
            "scene.toml: lights[0]: unknown key 'power'; allowed: attenuation, intensity,",
        ),
        ("[render]\nwidht = 3", "scene.toml: render: unknown key 'widht'; allowed: background,"),
        ("[display]\ngamma = 2", "scene.toml: display: unknown key 'gamma'; allowed:"),
        ("[spectral]\nbands = 41", "scene.toml: spectral: unknown key 'bands'; allowed: end_nm,"),
        (
            '[materials.m]\ntype = "lamberd"',
            "scene.toml: materials.m.type: unknown value 'lamberd'; allowed:",
        ),
        (
            '[[objects]]\ntype = "cube"',
            "scene.toml: objects[0].type: unknown value 'cube'; allowed:",
        ),
        ('[[lights]]\ntype = "spot"', "scene.toml: lights[0].type: unknown value 'spot'; allowed:"),
        (
            '[materials.m]\ntype = "lambert"\nk_d = { illuminant = "D66" }',
            "scene.toml: materials.m.k_d.illuminant: unknown illuminant 'D66'; allowed: A,",
        ),
        (
            '[materials.m]\ntype = "lambert"\nk_d = { ilumninant = "D65" }',
            "scene.toml: materials.m.k_d: a spectrum table needs exactly one of colorchecker,",
        ),
        (
            '[display]\nencoding = "sRGB"',
            "scene.toml: display.encoding: unknown value 'sRGB'; allowed:",
        ),
        (
            '[display]\nchromatic_adaptation = "bradford"',
            "scene.toml: display.chromatic_adaptation: unknown value 'bradford'; allowed:",
        ),
        (
            '[display]\nchromatic_adaptation = "Bradford"',
            "scene.toml: display.chromatic_adaptation: needs display.white",
        ),
        (
            '[spectral]\ngrid = "40"',
            "scene.toml: spectral.grid: unknown value '40'; allowed: 31, 41",
        ),
        (
            "[spectral]\nstart_nm = 300\nend_nm = 700\nstep_nm = 10",
            "scene.toml: spectral: band weights: grid 300-700/10 must lie within",
        ),
        ("[spectral]\nstart_nm = 400", "scene.toml: spectral: start_nm, end_nm and step_nm go"),
        (
            GREY.replace('material = "grey"', 'material = "gray"'),
            "scene.toml: objects[0].material: unknown material",
        ),
        (
            '[materials.m]\ntype = "phong"\nk_d = 0.5\nk_s = 0.5',
            "scene.toml: materials.m: missing key 'n'",
        ),
        ("[camera]\nfov_deg = 180", "scene.toml: camera.fov_deg: must be < 180, got 180"),
        (
            "[camera]\neye = [0, 0]",
            "scene.toml: camera.eye: must be a list of 3 numbers, got [0, 0]",
        ),
        ("[camera]\neye = [0, 0, 0]", "scene.toml: camera.target: must differ from eye"),
        (
            '[camera]\nprojection = "fisheye"',
            "scene.toml: camera.projection: unknown value 'fisheye'",
        ),
        (GREY + "radius = -1", "scene.toml: objects[0].radius: must be > 0, got -1"),
        (
            GREY + 'center = [0, "a", 0]',
            "scene.toml: objects[0].center[1]: must be a number, got 'a'",
        ),
        (
            GREY.replace("sphere", "rectangle"),
            "scene.toml: objects[0]: missing key 'size'",
        ),
        (
            GREY.replace("sphere", "plane") + "normal = [0, 1, 0]\nu_axis = [0, 2, 0]",
            "scene.toml: objects[0].u_axis: must not be parallel to the normal",
        ),
        (
            '[[lights]]\ntype = "point"\nposition = [0, 0, 1]\nattenuation = [0, 0, 0]',
            "scene.toml: lights[0].attenuation: c1, c2, c3 must not all be 0",
        ),
        (
            '[[lights]]\ntype = "point"\nposition = [0, 0, 1]\nintensity = -1',
            "scene.toml: lights[0].intensity: must be >= 0, got -1",
        ),
        ('[[lights]]\ntype = "point"', "scene.toml: lights[0]: missing key 'position'"),
        ('[render]\nbackground = "sky"', "scene.toml: render.background: must be a number, a list"),
        (
            '[render]\nbackground = "environment"',
            'scene.toml: render.background: "environment" needs an environment light',
        ),
        ("objects = 3", "scene.toml: objects: must be an array of tables ([[objects]]), got 3"),
        ("materials = 3", "scene.toml: materials: must be a table, got 3"),
        ("[materials]\nm = 3", "scene.toml: materials.m: must be a table, got 3"),
        ("[render]\nexposure = 1", "scene.toml: render: unknown key 'exposure'"),
        ("[display]\nexposure = 0", "scene.toml: display.exposure: must be > 0, got 0"),
    ],
)
def test_bad_scene_values_are_refused_with_file_and_key(text, message):
    with raises(message):
        scene_with(text)


def test_resolution_limits():
    with raises("scene.toml: render.width: must be an integer in [1, 16384], got 0"):
        scene_with("[render]\nwidth = 0")
    with raises("scene.toml: render.height: must be an integer in [1, 16384], got -5"):
        scene_with("[render]\nheight = -5")
    with raises("scene.toml: render.width: must be an integer in [1, 16384], got 100000"):
        scene_with("[render]\nwidth = 100000")
    with raises("scene.toml: render.width: must be an integer in [1, 16384], got 2.5"):
        scene_with("[render]\nwidth = 2.5")
    with raises("scene.toml: render.supersample: must be an integer in [1, 16], got 17"):
        scene_with("[render]\nsupersample = 17")
    with raises("scene.toml: render: width × height × supersample² = 67108864 samples is above"):
        scene_with("[render]\nwidth = 4096\nheight = 4096\nsupersample = 2")
    # The limit itself is allowed.
    assert check_render_size(4096, 4096, 1) == (4096, 4096, 1)
    assert check_render_size(2048, 2048, 2)[2] == 2
    assert MAX_RENDER_SAMPLES == 4096 * 4096
    scene = scene_with("")
    with raises("command line: render.width: must be an integer in [1, 16384], got 0"):
        scene.with_render(width=0, where="command line: render")
    # a lone --height is named as such, with the value given (it was reported as the width from it)
    for height, shown in ((0, "0"), (-5, "-5"), (20000, "20000")):
        with raises(f"command line: render.height: must be an integer in [1, 16384], got {shown}"):
            scene.with_render(height=height, where="command line: render")


def test_malformed_and_missing_scene_files(tmp_path):
    with raises("scene.toml: malformed TOML: "):
        scene_with("[camera\neye = [0, 0, 5]")
    with raises("scene.toml: malformed TOML: "):
        scene_with("[camera]\neye = [0, 0, 5]\neye = [0, 0, 6]")
    missing = tmp_path / "missing.toml"
    with raises(f"{missing}: file not found"):
        load_scene(missing)
    binary = tmp_path / "binary.toml"
    binary.write_bytes(b"\xff\xfe\x00[camera]")
    with raises(f"{binary}: not UTF-8 text"):
        load_scene(binary)
    with raises(f"{tmp_path}: is a folder, not a TOML file"):
        load_scene(tmp_path)


@pytest.mark.parametrize(
    "text",
    [
        "a = " + "[" * 100_000 + "]" * 100_000,  # deeper than tomllib's recursion can parse
        "a = " + "[" * 100 + "]" * 100,  # parses, but deeper than any scene
        "x = " + "{a = " * 50_000 + "1" + "}" * 50_000,
    ],
    ids=["arrays-100000", "arrays-100", "tables-50000"],
)
def test_deeply_nested_scenes_are_refused_in_one_line(text, tmp_path, capsys):
    # Source: docs/bad-input.md (a RecursionError with 3,000 lines of traceback before).
    from reference.scene.loader import MAX_NESTING
    from validation.cli import main

    with pytest.raises(SpecrefError, match=f"deep.toml: .*nested deeper than {MAX_NESTING}"):
        loads_scene(text, "deep.toml")
    path = tmp_path / "deep.toml"
    path.write_text(text)
    assert main(["render", str(path), "-o", str(tmp_path / "x.png")]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert "Traceback" not in err


@pytest.mark.parametrize(
    "command",
    [
        ["phong", "--material", "{path}", "--json", "{out}"],
        ["sweep", "{path}", "-o", "{out}"],
    ],
    ids=["phong-material", "sweep"],
)
def test_every_toml_input_refuses_deep_nesting_in_one_line(command, tmp_path, capsys):
    # Material and sweep files go through the scene's reader
    # (reference.scene.loader.read_toml_file):
    # before it, they raised a RecursionError with a traceback.
    from validation.cli import main

    path = tmp_path / "deep.toml"
    path.write_text("a = " + "[" * 100_000 + "]" * 100_000)
    args = [a.format(path=path, out=tmp_path / "out") for a in command]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err
    assert "deep.toml" in err
    assert "nested deeper than" in err

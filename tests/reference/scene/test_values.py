"""Tests of reference.scene.values: typed scene-file values (SceneReader) and the spectrum forms
(SPECTRUM_FORMS), read directly and through the scene loader."""

from __future__ import annotations

import re

import colour
import numpy as np
import pytest
from numpy.testing import assert_allclose

from reference.colour.spectra import GRID_41
from reference.errors import SpecrefError
from reference.scene.loader import loads_scene
from reference.scene.values import SceneReader


def scene_with(text: str, tmp_path=None):
    return loads_scene(text, "scene.toml", tmp_path or ".")


def raises(message: str):
    """``pytest.raises`` for a SpecrefError whose message starts with ``message`` (literal)."""
    return pytest.raises(SpecrefError, match="^" + re.escape(message))


# --- SceneReader, directly ------------------------------------------------------------------------


def test_scene_reader_scalars_accept_valid_values():
    r = SceneReader("s.toml")
    assert r.number(3, "k") == 3.0
    assert r.number(0.5, "k", minimum=0, maximum=1) == 0.5
    assert r.integer(4.0, "k", 1, 8) == 4  # a float with an integer value is accepted
    assert r.vector([1, 2], "k", n=2) == (1.0, 2.0)
    assert r.boolean(False, "k") is False
    assert r.choice("b", "k", ["a", "b"]) == "b"
    assert r.string("x", "k") == "x"


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda r: r.number(True, "a.b"), "s.toml: a.b: must be a number, got True"),
        (lambda r: r.number(1e400, "a.b"), "s.toml: a.b: must be finite, got inf"),
        (lambda r: r.number(2, "a.b", maximum=1), "s.toml: a.b: must be <= 1, got 2"),
        (
            lambda r: r.number(1, "a.b", maximum=1, exclusive_maximum=True),
            "s.toml: a.b: must be < 1",
        ),
        (
            lambda r: r.integer(2.5, "a.b", 1, 4),
            "s.toml: a.b: must be an integer in [1, 4], got 2.5",
        ),
        (lambda r: r.vector([1, 2], "a.b"), "s.toml: a.b: must be a list of 3 numbers, got [1, 2]"),
        (lambda r: r.vector([1, "x", 3], "a.b"), "s.toml: a.b[1]: must be a number, got 'x'"),
        (lambda r: r.boolean(1, "a.b"), "s.toml: a.b: must be true or false, got 1"),
        (lambda r: r.string("", "a.b"), "s.toml: a.b: must be a non-empty string"),
        (
            lambda r: r.choice("c", "a.b", ["b", "a"]),
            "s.toml: a.b: unknown value 'c'; allowed: a, b",
        ),
        (lambda r: r.file_path("nope.csv", "a.b"), "s.toml: a.b: file not found: "),
    ],
)
def test_scene_reader_bad_values_name_the_file_and_key(call, message):
    with raises(message):
        call(SceneReader("s.toml"))


# --- spectrum forms through the loader ------------------------------------------------------------


def _k_d(spectrum: str, tmp_path=None, grid: str = "41") -> np.ndarray:
    text = f'[spectral]\ngrid = "{grid}"\n[materials.m]\ntype = "lambert"\nk_d = {spectrum}\n'
    return scene_with(text, tmp_path).materials[0].k_d


def test_spectrum_forms_number_and_constant():
    assert_allclose(_k_d("0.25"), np.full(41, 0.25))
    assert_allclose(_k_d("{ constant = 0.75 }"), np.full(41, 0.75))
    assert_allclose(_k_d("1"), np.full(41, 1.0))


def test_spectrum_form_colorchecker_matches_colour_science():
    values = _k_d('{ colorchecker = "dark skin" }')
    # Source: colour-science's N Ohta data (5 nm), read at the 10 nm grid nodes.
    sd = colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"]["dark skin"]
    assert_allclose(values, sd[GRID_41.wavelengths_nm], rtol=1e-12)
    # BabelColor Average stops at 730 nm: the 41-band grid needs an extrapolation.
    with raises("scene.toml: materials.m.k_d: covers 380-730 nm but the grid needs 380-780 nm"):
        _k_d('{ colorchecker = "dark skin", set = "BabelColor Average" }')
    held = _k_d(
        '{ colorchecker = "dark skin", set = "BabelColor Average", extrapolation = "constant" }'
    )
    babel = colour.SDS_COLOURCHECKERS["BabelColor Average"]["dark skin"]
    assert_allclose(held[-5:], babel.values[-1], rtol=1e-12)


def test_spectrum_form_illuminant_and_light_source():
    values = _k_d('{ illuminant = "D65" }')
    # Source: colour-science's CIE D65 table at the grid nodes.
    assert_allclose(values, colour.SDS_ILLUMINANTS["D65"][GRID_41.wavelengths_nm], rtol=1e-12)
    values = _k_d('{ light_source = "Natural", extrapolation = "zero" }')
    natural = colour.SDS_LIGHT_SOURCES["Natural"]
    inside = (GRID_41.wavelengths_nm >= natural.wavelengths[0]) & (
        GRID_41.wavelengths_nm <= natural.wavelengths[-1]
    )
    assert_allclose(values[inside], natural[GRID_41.wavelengths_nm[inside]], rtol=1e-9)
    assert_allclose(values[~inside], 0.0)


def test_spectrum_form_csv_options(tmp_path):
    (tmp_path / "long.csv").write_text("nm,a,b\n380,0.1,10\n780,0.3,30\n")
    assert_allclose(
        _k_d('{ csv = "long.csv", column = "b", scale = 0.01 }', tmp_path)[[0, -1]], [0.1, 0.3]
    )
    assert_allclose(_k_d('{ csv = "long.csv", column = 1 }', tmp_path)[[0, -1]], [0.1, 0.3])
    (tmp_path / "wide.csv").write_text("380,580,780\n0.1,0.2,0.3\n0.4,0.5,0.6\n")
    assert_allclose(_k_d('{ csv = "wide.csv", row = 1 }', tmp_path)[[0, 20, 40]], [0.4, 0.5, 0.6])
    with raises("scene.toml: materials.m.k_d.column: must be a header name"):
        _k_d('{ csv = "long.csv", column = 1.5 }', tmp_path)


def test_spectrum_form_csv_reads_the_shared_measurements(package_data):
    path = package_data / "spectra" / "physicallybased" / "lemon__nix_export.csv"
    with raises("scene.toml: materials.m.k_d: covers 400-700 nm but the grid needs 380-780 nm"):
        _k_d(f'{{ csv = "{path}" }}')
    values = _k_d(f'{{ csv = "{path}", extrapolation = "constant" }}')
    # Source: the file's own R400 nm ... R700 nm cells, on the 31-band grid.
    on_31 = _k_d(f'{{ csv = "{path}" }}', grid="31")
    assert_allclose(values[2:33], on_31, rtol=1e-12)
    assert_allclose(values[:2], on_31[0])
    assert_allclose(values[33:], on_31[-1])


def test_spectrum_form_inline_arrays_and_interpolation():
    linear = _k_d("{ wavelengths = [380, 480, 580, 680, 780], values = [0, 1, 0, 1, 0] }")
    # Source: linear interpolation between the samples (closed form).
    assert_allclose(linear[:11], np.linspace(0, 1, 11), atol=1e-15)
    x, y = [380.0, 460, 540, 620, 700, 780], [1.0, 2, 4, 3, 2, 1]
    sprague = _k_d(f'{{ wavelengths = {x}, values = {y}, interpolation = "sprague" }}')
    # Source: colour-science's Sprague interpolator on the same samples.
    from colour.algebra import SpragueInterpolator

    expected = SpragueInterpolator(np.array(x), np.array(y))(GRID_41.wavelengths_nm)
    assert_allclose(sprague, expected, rtol=1e-12)
    assert not np.allclose(sprague, np.interp(GRID_41.wavelengths_nm, x, y))


@pytest.mark.parametrize(
    ("spectrum", "message"),
    [
        ("nan", "scene.toml: materials.m.k_d: must be finite, got nan"),
        ("inf", "scene.toml: materials.m.k_d: must be finite, got inf"),
        ("-0.5", "scene.toml: materials.m.k_d: must be >= 0, got -0.5"),
        ("{ constant = -1 }", "scene.toml: materials.m.k_d.constant: must be >= 0, got -1"),
        (
            "{ wavelengths = [380, 780], values = [0.5, nan] }",
            "scene.toml: materials.m.k_d: values must be finite, got nan at 780 nm",
        ),
        (
            "{ wavelengths = [380, 780], values = [0.5, inf] }",
            "scene.toml: materials.m.k_d: values must be finite, got inf at 780 nm",
        ),
        (
            "{ wavelengths = [380, 780], values = [-0.5, 0.5] }",
            "scene.toml: materials.m.k_d: values must be >= 0, got -0.5 at 380 nm",
        ),
        (
            "{ wavelengths = [380, 580, 500, 780], values = [1, 1, 1, 1] }",
            "scene.toml: materials.m.k_d: wavelengths must increase strictly, got 580.0 then 500.0",
        ),
        (
            "{ wavelengths = [380, 380, 780], values = [1, 1, 1] }",
            "scene.toml: materials.m.k_d: wavelengths must increase strictly, got 380.0 then 380.0",
        ),
        (
            "{ wavelengths = [380, 780], values = [1, 1, 1] }",
            "scene.toml: materials.m.k_d: 2 wavelengths but 3 values",
        ),
        (
            "{ wavelengths = [380, 780] }",
            "scene.toml: materials.m.k_d: inline spectrum needs 'values'",
        ),
        (
            '{ wavelengths = [380, "x"], values = [1, 1] }',
            "scene.toml: materials.m.k_d.wavelengths[1]: must be a number, got 'x'",
        ),
        (
            '{ constant = 1, extrapolation = "mirror" }',
            "scene.toml: materials.m.k_d.extrapolation: unknown value 'mirror'; allowed: constant,",
        ),
        ('"red"', "scene.toml: materials.m.k_d: must be a number or a spectrum table"),
    ],
)
def test_bad_spectra_are_refused(spectrum, message):
    with raises(message):
        _k_d(spectrum)


def test_bad_csv_spectra_are_refused(tmp_path):
    (tmp_path / "nan.csv").write_text("nm,R\n380,0.5\n780,nan\n")
    (tmp_path / "neg.csv").write_text("nm,R\n380,0.5\n780,-0.1\n")
    (tmp_path / "back.csv").write_text("nm,R\n380,0.5\n370,0.5\n780,0.5\n")
    with raises("scene.toml: materials.m.k_d.csv: file not found: "):
        _k_d('{ csv = "missing.csv" }', tmp_path)
    with raises(f"scene.toml: materials.m.k_d: {tmp_path / 'nan.csv'}: values must be finite"):
        _k_d('{ csv = "nan.csv" }', tmp_path)
    with raises(f"scene.toml: materials.m.k_d: {tmp_path / 'neg.csv'}: values must be >= 0"):
        _k_d('{ csv = "neg.csv" }', tmp_path)
    with raises(f"scene.toml: materials.m.k_d: {tmp_path / 'back.csv'}: wavelengths must increase"):
        _k_d('{ csv = "back.csv" }', tmp_path)


def test_bad_light_spectra_are_refused(tmp_path):
    light = '[[lights]]\ntype = "ambient"\nspectrum = '
    with raises("scene.toml: lights[0].spectrum: covers 400-700 nm but the grid needs 380-780 nm"):
        scene_with(light + "{ wavelengths = [400, 700], values = [1, 1] }")
    with raises("scene.toml: lights[0].spectrum: values must be finite, got nan at 700 nm"):
        scene_with(light + "{ wavelengths = [400, 700], values = [1, nan] }")
    # With an extrapolation the light is resampled at 1 nm over the grid, as the scene asked.
    scene = scene_with(
        light + '{ wavelengths = [400, 700], values = [1, 1], extrapolation = "zero" }'
    )
    spectrum = scene.lights[0].spectrum
    assert (spectrum.wavelengths_nm[0], spectrum.wavelengths_nm[-1]) == (380.0, 780.0)
    inside = (spectrum.wavelengths_nm >= 400) & (spectrum.wavelengths_nm <= 700)
    assert_allclose(spectrum.values[inside], 1.0)
    assert_allclose(spectrum.values[~inside], 0.0)

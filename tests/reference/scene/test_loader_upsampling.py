"""Scenes choose the RGB upsampling of environment maps: ``upsampling`` and ``upsampling_model``.

``[render.options] upsampling = "regression"`` with ``upsampling_model = "FILE"`` (a model of
``specref env fit``, Herbert et al. §4) reaches the environment shaders on the real render path
(the brute-force integration, which reads the same spectral radiance as the SH path, is quicker
on a tiny map).
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reference.colour.spectral_regression import SpectralRegression, save_regression
from reference.colour.upsampling import default_regression
from reference.errors import SpecrefError
from reference.images.formats import write_exr
from reference.scene.loader import loads_scene
from reference.scene.render import render_scene

SCENE = """
[spectral]
grid = "31"
[camera]
eye = [0.0, 0.0, 6.0]
target = [0.0, 0.0, 0.0]
fov_deg = 24.0
[render]
width = 4
height = 4
[render.options]
environment = "bruteforce"
{options}
[materials.white]
type = "lambert"
k_d = 0.8
[[objects]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "white"
[[lights]]
type = "environment"
file = "sky.exr"
"""


def _scene(tmp_path, options: str):
    return loads_scene(SCENE.format(options=options), "s.toml", tmp_path)


@pytest.fixture
def sky(tmp_path):
    # a smooth coloured sky: RGB varying with the row, all positive
    rows = np.linspace(0.2, 1.0, 8)[:, None, None]
    write_exr(tmp_path / "sky.exr", np.broadcast_to(rows * [0.9, 0.6, 0.3], (8, 16, 3)).copy())
    return tmp_path / "sky.exr"


def test_scene_model_file_reaches_the_environment_shader(tmp_path, sky):
    # Property: shading is linear in the environment's radiance and the regression is linear in
    # its coefficients, so a model of half the shipped coefficients renders exactly half.
    shipped = default_regression()
    half = SpectralRegression(
        shipped.kind, shipped.degree, 0.5 * shipped.coefficients, shipped.wavelengths_nm
    )
    save_regression(half, tmp_path / "half.json")
    full = render_scene(_scene(tmp_path, 'upsampling = "regression"')).XYZ
    scene = _scene(tmp_path, 'upsampling = "regression"\nupsampling_model = "half.json"')
    assert scene.render.options["upsampling_model"] == str((tmp_path / "half.json").resolve())
    halved = render_scene(scene).XYZ
    assert full[2, 2, 1] > 0.1
    assert_allclose(halved, 0.5 * full, rtol=1e-9, atol=1e-12)
    # and the method itself is honoured: Mallett 2019 gives another spectrum, other XYZ
    mallett = render_scene(_scene(tmp_path, 'upsampling = "mallett2019"')).XYZ
    assert np.abs(mallett - full).max() > 1e-4


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ('upsampling = "smits1999"', "render.options.upsampling: unknown value 'smits1999'"),
        (
            'upsampling_model = "other.json"',
            'render.options.upsampling_model: needs upsampling = "regression"',
        ),
        (
            'upsampling = "regression"\nupsampling_model = "none.json"',
            "render.options.upsampling_model: file not found",
        ),
        (
            'upsampling = "regression"\nupsampling_model = "other.json"',
            "render.options.upsampling_model: .*other.json: model grid 450-650 nm, 3 bands; "
            "does not cover the scene grid 400-700 nm",
        ),
        (
            'upsampling = "regression"\nupsampling_model = "sky.exr"',
            "render.options.upsampling_model: .*sky.exr: malformed model file",
        ),
    ],
)
def test_bad_upsampling_options_one_line(tmp_path, sky, options, message):
    save_regression(
        SpectralRegression("polynomial", 1, np.eye(3), [450.0, 550.0, 650.0]),
        tmp_path / "other.json",
    )
    with pytest.raises(SpecrefError, match=message) as error:
        _scene(tmp_path, options)
    assert "\n" not in str(error.value)
    assert str(error.value).startswith("s.toml: ")

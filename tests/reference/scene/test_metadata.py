"""Render outputs (display, XYZ, spectral EXR) and the metadata every render states.

See docs/render-outputs.md.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import shrm  # noqa: F401  (registers the environment shaders)
from reference.colour.colorimetry import band_weights
from reference.errors import SpecrefError
from reference.images.formats import channel_wavelengths_nm, read_exr, write_exr
from reference.scene.loader import loads_scene
from reference.scene.metadata import (
    DEFAULT_ACCURACY,
    MAX_FACTOR,
    RENDER_OUTPUTS,
    check_accuracy,
    read_exr_metadata,
)
from reference.scene.render import render_scene, render_scene_file

POINT = """
[render]
width = 9
height = 9
[materials.white]
type = "lambert"
k_d = 1.0
[[objects]]
type = "sphere"
material = "white"
[[lights]]
type = "point"
position = [0, 0, 5]
spectrum = { illuminant = "D65" }
"""


def _env_scene(folder, size=6):
    rng = np.random.default_rng(17)
    sky = 0.2 + rng.random((16, 32, 3))
    sky[4, 9] = 400.0  # a bright texel: lit exactly beside the SH residual
    path = write_exr(folder / "sky.exr", sky)
    text = "\n".join(
        [
            "[render]",
            f"width = {size}",
            f"height = {size}",
            'background = "environment"',
            "[materials.m]",
            'type = "lambert"',
            "k_d = 0.5",
            "[[objects]]",
            'type = "sphere"',
            'material = "m"',
            "[[lights]]",
            'type = "environment"',
            f'file = "{path}"',
        ]
    )
    (folder / "env.toml").write_text(text)
    return folder / "env.toml"


def test_outputs_registry_has_the_three_kinds():
    assert RENDER_OUTPUTS.names() == ["display", "xyz", "spectral"]


def test_xyz_exr_holds_the_render_xyz_and_metadata(tmp_path):
    # Source: the render's own XYZ (float32 storage: rtol 1e-6) and a JSON round trip.
    scene = tmp_path / "s.toml"
    scene.write_text(POINT)
    result = render_scene_file(scene, exr=tmp_path / "x.exr", exr_output="xyz")
    image, names = read_exr(tmp_path / "x.exr")
    assert names == ["X", "Y", "Z"]
    np.testing.assert_allclose(image, result.XYZ, rtol=1e-6, atol=1e-7)
    # The white diffuser facing the light has Y = 1 (docs/conventions.md)
    assert image[4, 4, 1] == pytest.approx(1.0, rel=1e-6)
    meta = read_exr_metadata(tmp_path / "x.exr")
    assert meta == result.metadata
    assert meta["output"] == "xyz"
    assert meta["normalisation"] == "Y = 1 for a perfect white diffuser under the light"


def test_spectral_exr_of_a_white_diffuser_is_the_light_spectrum(tmp_path):
    # Source: colour-science's D65 (reference.colour.spectra dataset): the reflected spectrum of a
    # white diffuser facing a D65 point light is D65 itself, scaled so the equal-energy weights give
    # Y=1.
    from reference.colour.spectra import GRID_41, resample_spectrum, spectrum_from_dataset

    scene = tmp_path / "s.toml"
    scene.write_text(POINT)
    render_scene_file(scene, exr=tmp_path / "s.exr", exr_output="spectral")
    image, names = read_exr(tmp_path / "s.exr")
    assert names[0] == "S0.380,000000nm"
    np.testing.assert_array_equal(channel_wavelengths_nm(names), GRID_41.wavelengths_nm)
    D65 = resample_spectrum(spectrum_from_dataset("illuminant", "D65"), GRID_41, "constant")
    W_E = band_weights(GRID_41, None)
    np.testing.assert_allclose(image[4, 4], D65 / (D65 @ W_E[:, 1]), rtol=1e-6)
    meta = read_exr_metadata(tmp_path / "s.exr")
    assert meta["spectral"]["wavelengths_nm"] == GRID_41.wavelengths_nm.tolist()
    assert meta["spectral"]["band_weights"]["method"] == "astm_e308"


def test_spectral_render_integrates_to_the_xyz_render(tmp_path):
    # Source: linearity. Under an environment (radiance, equal-energy weights) the spectral image
    # through the band weights is exactly the XYZ path's image on the sphere. The background is
    # the map's RGB in the XYZ path and its upsampled spectrum here (Mallett 2019, within 1 %).
    scene = loads_scene(_env_scene(tmp_path).read_text())
    xyz = render_scene(scene)
    spectral = render_scene(scene, spectral=True)
    W_E = band_weights(scene.grid, None)
    sphere = xyz.gbuffer.mask
    np.testing.assert_allclose(spectral.XYZ, spectral.spectral @ W_E, rtol=1e-12)
    np.testing.assert_allclose(spectral.XYZ[sphere], xyz.XYZ[sphere], rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(spectral.XYZ[~sphere], xyz.XYZ[~sphere], rtol=1e-2)


def test_render_states_the_order_and_bound_it_used(tmp_path, capsys):
    # The metadata names the order the accuracy rule chose and the bound it promises; --accuracy
    # changes both (a looser tolerance never needs a higher order).
    from validation.cli import main

    scene = _env_scene(tmp_path)
    orders = {}
    for tol in (None, "0.05"):
        args = ["render", str(scene), "-o", str(tmp_path / "a.png"), "--json", "-"]
        args += [] if tol is None else ["--accuracy", tol]
        assert main(args) == 0
        meta = json.loads(capsys.readouterr().out)
        (choice,) = meta["methods"]["environment"].values()
        expected = DEFAULT_ACCURACY if tol is None else float(tol)
        assert choice["tol_mean"] == expected
        assert choice["tol_max"] == MAX_FACTOR * expected
        assert choice["exact_texels"] >= 1
        orders[tol] = choice["order"]
    assert orders["0.05"] <= orders[None]
    assert meta["environment"][0]["upsampling"] == "mallett2019"


@pytest.mark.parametrize("bad", [0, -1, 0.5, float("nan"), "abc"])
def test_check_accuracy_refuses(bad):
    with pytest.raises(SpecrefError, match="--accuracy: must be a relative error in"):
        check_accuracy(bad)


def test_spectral_output_of_an_rgb_shader_is_refused():
    # The Phong-table shader works in RGB (Wang et al.); it cannot give a spectrum per pixel.
    import phong_table  # noqa: F401

    text = POINT.replace(
        'type = "lambert"\nk_d = 1.0', 'type = "phong"\nk_d = 0.5\nk_s = 0.5\nn = 10'
    )
    options = {"phong": {"method": "table", "entries": 64}}
    with pytest.raises(SpecrefError, match="render it as display or xyz"):
        render_scene(loads_scene(text), options=options, spectral=True)

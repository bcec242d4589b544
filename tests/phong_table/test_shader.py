"""Tests of phong_table.shader: the "table" Phong shader that scenes select by options["phong"]."""

from __future__ import annotations

import numpy as np
import pytest

from phong_table import INTERPOLATION_METHODS, PLACEMENT_METHODS
from phong_table.shader import OPTION_KEYS, shade_phong_point_table
from reference.colour.spectra import spectrum_from_dataset
from reference.errors import SpecrefError
from reference.geometry.camera import Camera
from reference.geometry.gbuffer import render_gbuffer
from reference.geometry.shapes import Sphere
from reference.materials.types import PhongMaterial
from reference.scene.lights import PointLight
from reference.scene.shading import PHONG_POINT_METHODS, ShadingContext, shade_gbuffer


@pytest.fixture(scope="module")
def sphere_scene():
    material = PhongMaterial(np.full(41, 0.3), np.full(41, 0.4), np.linspace(10.0, 300.0, 41))
    light = PointLight((2.0, 3.0, 4.0), spectrum_from_dataset("illuminant", "D65"))
    g = render_gbuffer([Sphere()], Camera(eye=(0, 0, 4)), 24, 24)
    # Source: the exact spectral Phong shader (Eq. (2), Wang et al.; tests/phong_table/
    # test_render.py checks it against colour.sd_to_XYZ per pixel).
    return g, material, light, shade_gbuffer(g, [material], [light])


def _table(sphere_scene, **phong):
    g, material, light, _ = sphere_scene
    ctx = ShadingContext(options={"phong": {"method": "table", **phong}})
    return shade_gbuffer(g, [material], [light], ctx)


def test_table_shader_through_scene_options_matches_exact(sphere_scene):
    g, material, light, exact = sphere_scene
    table = _table(sphere_scene, entries=200)
    assert table.shape == exact.shape
    assert np.abs(table - exact).max() < 1e-6
    # the default stays the exact shader
    assert np.array_equal(shade_gbuffer(g, [material], [light], ShadingContext()), exact)
    assert PHONG_POINT_METHODS.lookup("table").reference is shade_phong_point_table


@pytest.mark.parametrize("placement", PLACEMENT_METHODS.names())
@pytest.mark.parametrize("interpolation", INTERPOLATION_METHODS.names())
def test_every_placement_and_interpolation_converges(sphere_scene, placement, interpolation):
    # Property: the table's error against the exact shader falls as the table grows (m = 16 → 128).
    exact = sphere_scene[3]
    errors = [
        np.abs(
            _table(sphere_scene, entries=m, placement=placement, interpolation=interpolation)
            - exact
        ).max()
        for m in (16, 128)
    ]
    assert errors[1] < errors[0]


@pytest.mark.parametrize(
    ("phong", "match"),
    [
        (
            {"entrys": 10},
            "options.phong: unknown key 'entrys'; allowed: " + ", ".join(sorted(OPTION_KEYS)),
        ),
        ({"placement": "random"}, "unknown placement 'random'"),
        ({"interpolation": "cubic"}, "unknown interpolation 'cubic'"),
        (
            {"interpolation": "parabolic", "entries": 2},
            "parabolic interpolation needs entries >= 3",
        ),
    ],
)
def test_table_shader_bad_options(sphere_scene, phong, match):
    with pytest.raises(SpecrefError, match=match):
        _table(sphere_scene, **phong)

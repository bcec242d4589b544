"""The ColorChecker material: layout, data, shaders, and a render checked against colour-science."""

from __future__ import annotations

import colour
import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from reference.colour.spectra import GRID_31, GRID_41
from reference.errors import SpecrefError
from reference.geometry.camera import Camera
from reference.geometry.shapes import Plane
from reference.scene.colorchecker import (
    ColorCheckerMaterial,
    colorchecker_material,
    colorchecker_patch_centres_uv,
    colorchecker_patch_index,
    colorchecker_patch_pixels,
    shade_colorchecker_ambient,
    shade_colorchecker_point,
)
from reference.scene.lights import AmbientLight, PointLight, attenuation_Wang
from reference.scene.loader import loads_scene
from reference.scene.render import render_scene
from reference.scene.shading import ShadingContext, Surface

# colour.sd_to_XYZ warns that it aligns the illuminant to the CMFs, which is what E308 does.
pytestmark = pytest.mark.filterwarnings("ignore::colour.utilities.ColourRuntimeWarning")

CMFS = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
OHTA = colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"]


def E308_XYZ(sd, illuminant: str, grid=GRID_41) -> np.ndarray:
    """colour-science's ASTM E308 XYZ of a patch sampled at the grid's 10 nm nodes, Y = 1 scale."""
    wl = grid.wavelengths_nm
    sd_10 = colour.SpectralDistribution(sd[wl], wl)
    return (
        colour.sd_to_XYZ(sd_10, CMFS, colour.SDS_ILLUMINANTS[illuminant], method="ASTM E308") / 100
    )


def test_patch_index_layout():
    centres = colorchecker_patch_centres_uv()
    assert_array_equal(colorchecker_patch_index(centres, 0.1), np.arange(24))
    # Row by row from the top left: patch 6 (orange) starts the second row.
    assert_array_equal(colorchecker_patch_index([[0.01 + 0.05, 0.25 + 0.05]], 0.1), [6])
    # The gap: within gap_width/2 of a cell edge, and outside the chart.
    cell = 1 / 6
    assert_array_equal(
        colorchecker_patch_index(
            [[cell - 0.004, 0.1], [cell + 0.004, 0.1], [cell + 0.1 * cell, 0.1], [-0.1, 0.5]], 0.1
        ),
        [24, 24, 1, 24],
    )
    assert_array_equal(colorchecker_patch_index([[np.nan, 0.5], [0.5, 1.2]], 0.1), [24, 24])
    # Without a gap every point of the chart shows a patch.
    uv = np.random.default_rng(5).uniform(0, 1, (1000, 2))
    assert (colorchecker_patch_index(uv, 0.0) < 24).all()
    # The gap's share of the chart is 1 - (1 - g)^2 (closed form), within Monte Carlo error.
    g = 0.2
    share = (colorchecker_patch_index(uv, g) == 24).mean()
    expected = 1 - (1 - g) ** 2
    assert abs(share - expected) < 5 * np.sqrt(expected * (1 - expected) / uv.shape[0])


def test_material_holds_colour_science_data():
    m = colorchecker_material(GRID_41)
    assert m.patch_names == tuple(OHTA)
    for i, name in enumerate(OHTA):
        # Source: colour-science's N Ohta table at the grid nodes.
        assert_allclose(m.patches[i], OHTA[name][GRID_41.wavelengths_nm], rtol=1e-12)
    assert_allclose(m.gap, m.patches[23])
    assert m.reflectances.shape == (25, 41)
    assert colorchecker_material(GRID_31).n_bands == 31


def test_material_refuses_bad_sets_and_values():
    with pytest.raises(
        SpecrefError, match="colorchecker set 'PMC' has 30 patches; a chart needs 24"
    ):
        colorchecker_material(set_name="PMC")
    with pytest.raises(SpecrefError, match="unknown colorchecker set 'Ohta'"):
        colorchecker_material(set_name="Ohta")
    with pytest.raises(SpecrefError, match="covers 380-730 nm but the grid needs 380-780 nm"):
        colorchecker_material(set_name="BabelColor Average")
    assert colorchecker_material(set_name="BabelColor Average", extrapolation="constant").n_bands
    with pytest.raises(SpecrefError, match=r"chart\.gap_width: must be in \[0, 1\), got 1"):
        ColorCheckerMaterial(np.ones((24, 3)), np.ones(3), 1.0, "chart")
    with pytest.raises(SpecrefError, match=r"chart\.patches: must have shape \(24, n_bands\)"):
        ColorCheckerMaterial(np.ones((23, 3)), np.ones(3), 0.1, "chart")
    with pytest.raises(SpecrefError, match=r"chart\.patches: must be >= 0"):
        ColorCheckerMaterial(-np.ones((24, 3)), np.ones(3), 0.1, "chart")


def test_scene_material_keys_and_errors():
    chart = '[materials.chart]\ntype = "colorchecker"\n'
    m = loads_scene(chart + "gap = 0.02\ngap_width = 0.25").materials[0]
    assert isinstance(m, ColorCheckerMaterial)
    assert (m.gap_width, m.name) == (0.25, "chart")
    assert_allclose(m.gap, 0.02)
    with pytest.raises(SpecrefError, match=r"^s\.toml: materials\.chart\.gap_width: must be < 1"):
        loads_scene(chart + "gap_width = 1", "s.toml")
    with pytest.raises(SpecrefError, match=r"^s\.toml: materials\.chart: unknown key 'patches'"):
        loads_scene(chart + "patches = 1", "s.toml")
    with pytest.raises(SpecrefError, match=r"^s\.toml: materials\.chart\.set: unknown value 'X'"):
        loads_scene(chart + 'set = "X"', "s.toml")
    with pytest.raises(
        SpecrefError, match=r"^s\.toml: materials\.chart: colorchecker:dark skin: covers 380-730 nm"
    ):
        loads_scene(chart + 'set = "BabelColor Average"', "s.toml")


def test_point_shader_is_the_ambient_value_times_f_att_cos_theta(rng):
    m = colorchecker_material(GRID_41)
    n = 50
    normal = rng.normal(size=(n, 3))
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    position = rng.uniform(-1, 1, (n, 3))
    surface = Surface(position, normal, normal, rng.uniform(-0.1, 1.1, (n, 2)))
    light = PointLight((0.5, 2.0, 3.0), intensity=1.7, attenuation=(0.3, 0.2, 0.1))
    ctx = ShadingContext()
    XYZ = shade_colorchecker_point(surface, m, light, ctx)
    flat = shade_colorchecker_ambient(surface, m, AmbientLight(light.spectrum, 1.7), ctx)
    # Closed form: f_att · max(N·L, 0) with L the unit vector to the light.
    to_light = np.asarray(light.position) - position
    d = np.linalg.norm(to_light, axis=-1)
    cos_theta = np.maximum((normal * to_light).sum(-1) / d, 0.0)
    expected = flat * (attenuation_Wang(d, 0.3, 0.2, 0.1) * cos_theta)[:, None]
    assert_allclose(XYZ, expected, rtol=1e-12, atol=1e-15)


def test_shaders_refuse_a_material_on_another_grid():
    m = colorchecker_material(GRID_31)
    s = Surface(np.zeros((1, 3)), np.zeros((1, 3)), np.zeros((1, 3)), np.zeros((1, 2)))
    with pytest.raises(SpecrefError, match="has 31 bands but the grid 380-780/10 has 41"):
        shade_colorchecker_ambient(s, m, AmbientLight(), ShadingContext())


@pytest.mark.parametrize("illuminant", ["D65", "A", "FL2"])
def test_rendered_chart_reproduces_colour_science_E308(illuminant):
    scene = loads_scene(
        f"""
        [camera]
        projection = "orthographic"
        extent = 0.44
        [render]
        width = 66
        height = 44
        [materials.chart]
        type = "colorchecker"
        [[objects]]
        type = "rectangle"
        normal = [0, 0, 1]
        size = [0.6, 0.4]
        material = "chart"
        [[lights]]
        type = "ambient"
        spectrum = {{ illuminant = "{illuminant}" }}
        """
    )
    result = render_scene(scene)
    rows, columns = colorchecker_patch_pixels(scene.camera, scene.objects[0], 66, 44).T
    rendered = result.XYZ[rows, columns]
    # Source: colour.sd_to_XYZ(method="ASTM E308") on the same 10 nm data, to rounding.
    expected = np.stack([E308_XYZ(OHTA[name], illuminant) for name in OHTA])
    assert np.abs(rendered - expected).max() * 100 <= 1e-9


def test_patch_pixels_fall_on_their_patches():
    cam = Camera(eye=(0.3, 0.2, 3.0), target=(0, 0, 0), fov_deg=20)
    chart = Plane((0, 0, 0), (0, 0, 1), (1, 0, 0), size=(0.6, 0.4))
    scene_uv = colorchecker_patch_centres_uv()
    pixels = colorchecker_patch_pixels(cam, chart, 200, 150)
    from reference.geometry.gbuffer import render_gbuffer

    g = render_gbuffer([chart], cam, 200, 150)
    uv = g.uv[pixels[:, 0], pixels[:, 1]]
    # Each pixel's own uv lies within a pixel's footprint of its patch centre, on that patch.
    assert_array_equal(colorchecker_patch_index(uv, 0.1), np.arange(24))
    assert np.abs(uv - scene_uv).max() < 0.02
    behind = Camera(eye=(0, 0, 3), target=(0, 0, 6))
    outside = colorchecker_patch_pixels(behind, chart, 20, 20)
    assert (outside == -1).all()

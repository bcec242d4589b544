"""The render pipeline: closed-form images, supersampling, re-shading, display, outputs."""

from __future__ import annotations

import dataclasses

import colour
import numpy as np
import pytest
from numpy.testing import assert_allclose

import reference.images.formats
import reference.scene.render
from reference.colour.spectra import GRID_41
from reference.data import data_path
from reference.errors import SpecrefError
from reference.geometry.camera import downsample_box
from reference.images.formats import read_exr, read_png, spectral_channel_names, write_exr
from reference.materials.types import LambertMaterial
from reference.scene.loader import load_scene, loads_scene
from reference.scene.render import (
    check_shaders,
    render_scene,
    render_scene_file,
    scene_gbuffer,
    write_render,
)

pytestmark = pytest.mark.filterwarnings("ignore::colour.utilities.ColourRuntimeWarning")

EXAMPLES = data_path("examples")
CMFS = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]


def white_XYZ_E308(illuminant: str) -> np.ndarray:
    """XYZ of the perfect white diffuser, colour-science ASTM E308 at 10 nm, Y = 1 scale."""
    ones = colour.SpectralDistribution(np.ones(41), GRID_41.wavelengths_nm)
    return (
        colour.sd_to_XYZ(ones, CMFS, colour.SDS_ILLUMINANTS[illuminant], method="ASTM E308") / 100
    )


LAMBERT_SPHERE = """
[camera]
projection = "orthographic"
eye = [0, 0, 5]
extent = 2.4
[render]
width = 41
height = 41
background = [0.25, 0.5, 0.75]
[materials.white]
type = "lambert"
k_d = 1
[[objects]]
type = "sphere"
material = "white"
[[lights]]
type = "point"
position = [2, 3, 4]
spectrum = { illuminant = "A" }
intensity = 1.5
attenuation = [0.5, 0.1, 0.02]
"""


def test_lambert_sphere_matches_the_closed_form():
    result = render_scene(loads_scene(LAMBERT_SPHERE))
    # Closed form: orthographic rays through pixel centres hit the unit sphere at
    # (x, y, sqrt(1 - x² - y²)); there N = P and Y = I f_att(d) max(N·L, 0).
    centres = (np.arange(41) + 0.5) / 41 * 2.4 - 1.2
    x, y = np.meshgrid(centres, -centres)
    r2 = x**2 + y**2
    hit = r2 < 1
    P = np.stack([x, y, np.sqrt(np.where(hit, 1 - r2, 0))], axis=-1)
    to_light = np.array([2.0, 3.0, 4.0]) - P
    d = np.linalg.norm(to_light, axis=-1)
    cos_theta = np.maximum((P * to_light).sum(-1) / d, 0)
    f_att = np.minimum(1 / (0.5 + 0.1 * d + 0.02 * d**2), 1)
    expected = 1.5 * (f_att * cos_theta)[..., None] * white_XYZ_E308("A")
    assert_allclose(result.XYZ[hit], expected[hit], rtol=1e-10, atol=1e-14)
    # Off the sphere: the background, given in linear display RGB, comes back exactly.
    assert_allclose(
        result.RGB_linear[~hit], np.broadcast_to([0.25, 0.5, 0.75], (int((~hit).sum()), 3))
    )


def test_phong_example_pixels_match_a_colour_science_evaluation():
    scene = load_scene(EXAMPLES / "phong-sphere.toml").with_render(33, 33, 1)
    result = render_scene(scene)
    g, material = result.gbuffer, scene.materials[0]
    point, ambient = scene.lights
    for row, column in [(16, 16), (12, 19), (20, 10)]:
        P, N, V = g.position[row, column], g.normal[row, column], g.view[row, column]
        to_light = np.asarray(point.position) - P
        d = np.linalg.norm(to_light)
        L = to_light / d
        R = 2 * (N @ L) * N - L
        t = np.clip(R @ V, 0, 1) if N @ L > 0 else 0.0
        f_att = min(1 / (0.5 + 0.02 * d**2), 1)
        # Eq. (2), Wang et al. per band, then colour-science's E308 integration under each light.
        ratio = f_att * (material.k_d * max(N @ L, 0) + material.k_s * t**material.n)
        expected = 0
        for spectrum_ratio, light in ((ratio, point), (material.k_a, ambient)):
            sd = colour.SpectralDistribution(spectrum_ratio, GRID_41.wavelengths_nm)
            XYZ = colour.sd_to_XYZ(sd, CMFS, colour.SDS_ILLUMINANTS["D65"], method="ASTM E308")
            expected = expected + light.intensity * XYZ / 100
        assert_allclose(result.XYZ[row, column], expected, rtol=1e-9)


def test_supersampling_is_the_box_average_of_the_finer_render():
    scene = loads_scene(LAMBERT_SPHERE)
    coarse = render_scene(scene, width=12, height=8, supersample=3)
    fine = render_scene(scene, width=36, height=24, supersample=1)
    assert coarse.gbuffer.shape == (24, 36)
    assert_allclose(coarse.XYZ, downsample_box(fine.XYZ, 3), rtol=1e-13, atol=1e-15)


def test_cached_gbuffer_reshades_without_rasterizing(monkeypatch):
    scene = loads_scene(LAMBERT_SPHERE)
    first = render_scene(scene, width=20, height=20)
    red = LambertMaterial(np.linspace(0.1, 0.9, 41), "white")
    edited = dataclasses.replace(scene, materials=(red,))
    fresh = render_scene(edited, width=20, height=20)

    def no_raster(*args, **kwargs):
        raise AssertionError("render_gbuffer called although a G-buffer was given")

    monkeypatch.setattr(reference.scene.render, "render_gbuffer", no_raster)
    reshaded = render_scene(edited, width=20, height=20, gbuffer=first.gbuffer)
    assert_allclose(reshaded.XYZ, fresh.XYZ, rtol=0, atol=0)
    assert not np.allclose(reshaded.XYZ, first.XYZ)
    with pytest.raises(
        SpecrefError, match=r"the G-buffer has shape \(20, 20\) but the render needs"
    ):
        render_scene(edited, width=10, height=10, gbuffer=first.gbuffer)


def test_shading_in_tiles_changes_nothing(monkeypatch):
    scene = loads_scene(LAMBERT_SPHERE)
    whole = render_scene(scene, width=30, height=20)
    monkeypatch.setattr(reference.scene.render, "SHADING_TILE_SAMPLES", 7)
    tiled = render_scene(scene, width=30, height=20)
    # The same sums; only BLAS blocking may change the last bit.
    assert_allclose(tiled.XYZ, whole.XYZ, rtol=1e-14, atol=1e-16)


def test_display_conversion_and_encoding_match_colour_science():
    scene = loads_scene(
        LAMBERT_SPHERE.replace("[materials", "[display]\nexposure = 0.5\n[materials")
    )
    result = render_scene(scene, width=15, height=15)
    # Source: colour-science's XYZ -> sRGB (no adaptation) and its sRGB encoding (CCTF).
    RGB = colour.XYZ_to_RGB(result.XYZ, "sRGB", apply_cctf_encoding=False)
    assert_allclose(result.RGB_linear, RGB, rtol=1e-9, atol=1e-12)
    encoded = colour.cctf_encoding(np.clip(RGB * 0.5, 0, 1), "sRGB")
    assert_allclose(result.encoded, encoded, rtol=1e-9, atol=1e-12)
    gamma = loads_scene(
        LAMBERT_SPHERE.replace("[materials", '[display]\nencoding = "gamma_2.2"\n[materials')
    )
    encoded = render_scene(gamma, width=15, height=15).encoded
    # Closed form: Eq. (6), Herbert et al. inverted, G/255 = Y^(1/2.2).
    assert_allclose(encoded, np.clip(result.RGB_linear, 0, 1) ** (1 / 2.2), rtol=1e-12)


def test_bradford_adaptation_maps_the_light_white_to_display_white():
    scene = loads_scene(
        """
        [camera]
        projection = "orthographic"
        [render]
        width = 3
        height = 3
        [display]
        chromatic_adaptation = "Bradford"
        [materials.white]
        type = "lambert"
        k_d = 1
        [[objects]]
        type = "plane"
        normal = [0, 0, 1]
        material = "white"
        [[lights]]
        type = "ambient"
        spectrum = { illuminant = "A" }
        """
    )
    result = render_scene(scene)
    # A white diffuser under A, adapted A -> D65 (the sRGB white), is display white, to the 4
    # decimals of the IEC 61966-2-1 matrix that colour-science uses (errors up to ~2e-4).
    assert_allclose(result.RGB_linear, 1.0, atol=5e-4)
    # Source: colour-science's Bradford adaptation, then XYZ -> sRGB.
    grey = white_XYZ_E308("A") * 0.3
    adapted = colour.chromatic_adaptation(
        grey,
        white_XYZ_E308("A"),
        colour.xy_to_XYZ(colour.RGB_COLOURSPACES["sRGB"].whitepoint),
        method="Von Kries",
        transform="Bradford",
    )
    RGB, _ = reference.scene.render.XYZ_to_display(scene, grey)
    assert_allclose(RGB, colour.XYZ_to_RGB(adapted, "sRGB", apply_cctf_encoding=False), rtol=1e-9)


def test_environment_background(tmp_path):
    H, W = 8, 16
    image = np.broadcast_to(np.arange(H, dtype=float)[:, None, None], (H, W, 3)).copy()
    image[..., 1] *= 2
    write_exr(tmp_path / "rows.exr", image)
    scene = loads_scene(
        """
        [camera]
        projection = "orthographic"
        [render]
        width = 4
        height = 3
        background = "environment"
        [display]
        encoding = "linear"
        [[lights]]
        type = "environment"
        file = "rows.exr"
        intensity = 0.5
        """,
        base_dir=tmp_path,
    )
    result = render_scene(scene)
    # Every ray points down -z: u = 0 (the seam), v = 1/2, halfway between rows H/2 - 1 and H/2
    # (Mitsuba 3 axes, pixel-centred rows; docs/conventions.md), so bilinear gives (H - 1)/2.
    expected = 0.5 * np.array([1.0, 2.0, 1.0]) * (H - 1) / 2
    assert_allclose(result.RGB_linear, np.broadcast_to(expected, (3, 4, 3)), rtol=1e-12)

    # A spectral map of constant radiance 1 is the equal-energy white, weighted as radiance.
    wl = np.array([380.0, 580.0, 780.0])
    write_exr(tmp_path / "flat.exr", np.ones((H, W, 3)), spectral_channel_names(wl))
    spectral = loads_scene(
        '[render]\nwidth = 2\nheight = 2\nbackground = "environment"\n'
        '[[lights]]\ntype = "environment"\nfile = "flat.exr"',
        base_dir=tmp_path,
    )
    XYZ = render_scene(spectral).XYZ
    assert_allclose(XYZ, np.broadcast_to(white_XYZ_E308("E"), (2, 2, 3)), rtol=1e-9)


def test_missing_shader_is_refused_before_rasterizing(monkeypatch):
    class Torch:
        spectrum = None

    scene = dataclasses.replace(loads_scene(LAMBERT_SPHERE, "s.toml"), lights=(Torch(),))
    monkeypatch.setattr(reference.scene.render, "render_gbuffer", None)  # would fail if reached
    with pytest.raises(
        SpecrefError,
        match=r"^s\.toml: no shader for materials\.white \(LambertMaterial\) under lights\[0\] "
        r"\(Torch\); registered: .*LambertMaterial/PointLight",
    ):
        render_scene(scene)
    # A scene without objects needs no shaders.
    check_shaders(dataclasses.replace(scene, objects=()))


def test_size_overrides_are_checked():
    scene = loads_scene(LAMBERT_SPHERE)
    with pytest.raises(
        SpecrefError, match=r"render\.width: must be an integer in \[1, 16384\], got 0"
    ):
        render_scene(scene, width=0)
    with pytest.raises(SpecrefError, match=r"render\.supersample: must be an integer in \[1, 16\]"):
        render_scene(scene, supersample=17)
    with pytest.raises(SpecrefError, match="samples is above the limit of 16777216"):
        render_scene(scene, width=16384, height=16384)
    assert scene_gbuffer(scene.with_render(5, 4, 2)).shape == (8, 10)


# --- outputs --------------------------------------------------------------------------------------


def test_outputs_png_and_exr(tmp_path):
    result = render_scene(loads_scene(LAMBERT_SPHERE), width=21, height=21)
    written = write_render(result, png=tmp_path / "a.png", exr=tmp_path / "a.exr")
    assert sorted(p.name for p in written) == ["a.exr", "a.png"]
    png = read_png(tmp_path / "a.png")
    # Source: round-half-up 8-bit quantisation of the encoded values (closed form).
    assert_allclose(png, np.floor(result.encoded * 255 + 0.5) / 255, atol=1e-12)
    exr, names = read_exr(tmp_path / "a.exr")
    assert names == ["R", "G", "B"]
    assert_allclose(exr, result.RGB_linear, rtol=2**-23)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.exr", "a.png"]


def test_bad_output_paths(tmp_path):
    result = render_scene(loads_scene(LAMBERT_SPHERE), width=4, height=4)
    with pytest.raises(SpecrefError, match=r"-o: the output must end in \.png, got '.*a\.jpg'"):
        write_render(result, png=tmp_path / "a.jpg")
    with pytest.raises(SpecrefError, match=r"--exr: the output must end in \.exr"):
        write_render(result, exr=tmp_path / "a.png")
    (tmp_path / "file").write_text("x")
    with pytest.raises(SpecrefError, match=r"file/a\.png: cannot write \("):
        write_render(result, png=tmp_path / "file" / "a.png")
    (tmp_path / "dir.png").mkdir()
    with pytest.raises(SpecrefError, match=r"dir\.png is a folder"):
        write_render(result, png=tmp_path / "dir.png")


def test_failure_during_rendering_leaves_no_output(tmp_path, monkeypatch):
    out = tmp_path / "out"
    out.mkdir()
    (out / "old.png").write_bytes(b"previous render")

    def crash(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(reference.scene.render, "shade_gbuffer", crash)
    with pytest.raises(KeyboardInterrupt):
        render_scene_file(EXAMPLES / "phong-sphere.toml", out / "new.png", out / "new.exr", 8, 8)
    with pytest.raises(KeyboardInterrupt):
        render_scene_file(EXAMPLES / "phong-sphere.toml", out / "old.png", None, 8, 8)
    assert sorted(p.name for p in out.iterdir()) == ["old.png"]
    assert (out / "old.png").read_bytes() == b"previous render"


def test_interrupted_write_leaves_no_file(tmp_path, monkeypatch):
    result = render_scene(loads_scene(LAMBERT_SPHERE), width=8, height=8)

    def interrupted(src, dst):
        raise KeyboardInterrupt

    monkeypatch.setattr(reference.images.formats.os, "replace", interrupted)
    for kwargs in ({"png": tmp_path / "a.png"}, {"exr": tmp_path / "a.exr"}):
        with pytest.raises(KeyboardInterrupt):
            write_render(result, **kwargs)
    assert list(tmp_path.iterdir()) == []


def test_render_scene_file_checks_outputs_before_rendering(tmp_path, monkeypatch):
    monkeypatch.setattr(reference.scene.render, "load_scene", None)  # would fail if reached
    with pytest.raises(SpecrefError, match=r"-o: the output must end in \.png"):
        render_scene_file(EXAMPLES / "phong-sphere.toml", tmp_path / "x.tif")


def test_rasterized_mesh_quad_matches_the_ray_cast_rectangle(tmp_path):
    (tmp_path / "quad.obj").write_text(
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n"
    )
    common = """
        [camera]
        eye = [0.3, 0.2, 4]
        fov_deg = 40
        [render]
        width = 40
        height = 30
        [materials.m]
        type = "phong"
        k_d = 0.4
        k_s = 0.5
        n = { wavelengths = [380, 780], values = [5, 200] }
        [[lights]]
        type = "point"
        position = [1, 1, 3]
        [[objects]]
        material = "m"
        """
    mesh = loads_scene(common + 'type = "mesh"\nfile = "quad.obj"', base_dir=tmp_path)
    rectangle = loads_scene(common + 'type = "rectangle"\nsize = [2, 2]\nnormal = [0, 0, 1]')
    a, b = render_scene(mesh), render_scene(rectangle)
    both = a.gbuffer.mask & b.gbuffer.mask
    # Rasterizer (top-left rule) and ray cast (closed edges) may differ only on the outline.
    assert (a.gbuffer.mask != b.gbuffer.mask).sum() <= 2 * (40 + 30)
    assert both.sum() > 0.5 * b.gbuffer.mask.sum()
    # Same surface, same shading: perspective-correct interpolation of a plane is exact.
    assert_allclose(a.XYZ[both], b.XYZ[both], rtol=1e-9, atol=1e-12)


def test_environment_background_needs_a_map_that_covers_the_grid(tmp_path):
    wl = np.array([400.0, 550.0, 700.0])
    write_exr(tmp_path / "narrow.exr", np.ones((4, 8, 3)), spectral_channel_names(wl))
    scene = loads_scene(
        '[render]\nwidth = 2\nheight = 2\nbackground = "environment"\n'
        '[[lights]]\ntype = "environment"\nfile = "narrow.exr"',
        "s.toml",
        tmp_path,
    )
    with pytest.raises(
        SpecrefError,
        match=r"^s\.toml: render\.background: the spectral environment .*narrow\.exr covers "
        r"400-700 nm but the grid needs 380-780 nm",
    ):
        render_scene(scene)


def test_spectral_output_with_an_ambient_light_is_the_XYZ_render():
    # The ambient shader returns one value per output (3 for XYZ, n_bands for spectral), so a scene
    # with an ambient light renders spectrally; on the sphere XYZ is then spectral @ W_E
    # (docs/render-outputs.md; a constant background has no spectrum, erratum E77).
    from reference.colour.colorimetry import band_weights

    scene = load_scene(EXAMPLES / "phong-sphere.toml")
    assert any(type(light).__name__ == "AmbientLight" for light in scene.lights)
    result = render_scene(scene, 8, 8, supersample=1, spectral=True)
    W_E = band_weights(scene.grid, None, scene.weights_method, scene.observer)
    assert result.spectral.shape == (8, 8, scene.grid.n_bands)
    on = result.gbuffer.mask
    assert on.any()
    np.testing.assert_allclose((result.spectral @ W_E)[on], result.XYZ[on], rtol=1e-10, atol=1e-14)

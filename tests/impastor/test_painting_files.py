"""Painting files (Ferwerda §3): the demo painting written and read renders the same; bad ones."""

import numpy as np
import pytest

from impastor.painting import impasto_painting, render_painting
from impastor.painting_files import painting_reflectance, read_painting, write_painting
from reference.errors import SpecrefError
from validation.cli import main


@pytest.fixture(scope="module")
def demo_folder(tmp_path_factory):
    folder = tmp_path_factory.mktemp("demo")
    write_painting(folder, impasto_painting(32, seed=3), "demo")
    return folder


def test_the_demo_painting_read_back_renders_the_same(demo_folder):
    demo = impasto_painting(32, seed=3)
    back = read_painting(demo_folder)
    assert back["name"] == "demo"
    assert back["pixel_size"] == demo["pixel_size"]
    for key in ("height", "rho_s", "alpha"):
        assert np.array_equal(back[key], demo[key]), key
    # the reflectance per texel is the paint spectra the indices name (stored as float32)
    np.testing.assert_allclose(back["reflectance"], painting_reflectance(demo), rtol=0, atol=1e-7)
    options = {"light_resolution": (16, 8), "backend": "numpy"}
    a = render_painting("D65", 16, "median_cut", demo, **options)["XYZ"]
    b = render_painting("D65", 16, "median_cut", back, **options)["XYZ"]
    np.testing.assert_allclose(b, a, rtol=1e-6, atol=1e-9)


def test_an_rgb_photograph_becomes_reflectance(tmp_path):
    import imageio.v3 as iio

    from reference.colour.colorimetry import band_weights, spectra_to_XYZ
    from reference.colour.spectra import spectrum_from_dataset
    from reference.display.encodings import display_to_linear

    rgb = np.zeros((8, 8, 3), dtype=np.uint8)
    rgb[:4] = (200, 40, 30)  # a red half
    rgb[4:] = (230, 230, 230)  # a white half
    iio.imwrite(tmp_path / "photo.png", rgb)
    height = np.zeros((8, 8), dtype=np.uint16)
    height[2:6, 2:6] = 65535
    iio.imwrite(tmp_path / "relief.png", height)
    (tmp_path / "painting.toml").write_text(
        'name = "photo"\nwidth_m = 0.1\n[colour]\nfile = "photo.png"\n'
        '[height]\nfile = "relief.png"\nscale_m = 0.002\n[gloss]\nrho_s = 0.05\nalpha = 0.3\n'
    )
    p = read_painting(tmp_path)
    assert p["height"].max() == pytest.approx(0.002)
    assert p["rho_s"].shape == (8, 8)
    # the red texels' reflectance is red, with the photo's colour: its XYZ back to linear sRGB
    from impastor.multispectral import MS_GRID
    from reference.colour.colorimetry import XYZ_to_display_RGB

    D65 = spectrum_from_dataset("illuminant", "D65")
    XYZ = spectra_to_XYZ(p["reflectance"][0, 0], band_weights(MS_GRID, D65))
    back = XYZ_to_display_RGB(XYZ)
    np.testing.assert_allclose(back, display_to_linear(rgb[0, 0] / 255.0, "srgb"), atol=0.01)


def _edit(folder, tmp_path, text_change=None, files=None):
    import shutil

    copy = tmp_path / "copy"
    shutil.copytree(folder, copy)
    toml = copy / "painting.toml"
    if text_change:
        toml.write_text(text_change(toml.read_text()))
    for name, writer in (files or {}).items():
        writer(copy / name)
    return copy


@pytest.mark.parametrize(("old", "new", "message"), [
    ("[gloss]", "frame = 1\n[gloss]", "height: unknown key 'frame'"),
    ("[colour]", "frame = 1\n[colour]", "unknown key 'frame'"),
    ("width_m = 0.3", "width_m = -1", "width_m: must be a width in metres"),
    ('file = "height.tif"', 'file = "missing.tif"', "missing.tif: file not found"),
    ('rho_s = { file = "rho_s.tif" }', "rho_s = 2", "gloss.rho_s: must be in [0, 1]"),
    ('alpha = { file = "alpha.tif" }', "alpha = 0", "gloss.alpha: Ward–Dür's roughness must be"),
    ('alpha = { file = "alpha.tif" }', "alpha = 1e308", "gloss.alpha: Ward–Dür's roughness must"),
    ("scale_m = 1.0", "scale_m = 1e300", "height.scale_m: the relief of a height of 1"),
    ("width_m = 0.3", "width_m = 1e-6", "height: a relief of"),  # taller than the canvas is wide
    ("[height]", "[heigh]", "unknown key 'heigh'"),
    ("width_m = 0.3", "width_m = 0.3\nx = " + "[" * 100_000, "nested deeper than"),
])  # fmt: skip
def test_bad_painting_files_are_one_line(demo_folder, tmp_path, old, new, message):
    with pytest.raises(SpecrefError) as error:
        read_painting(_edit(demo_folder, tmp_path, lambda text: text.replace(old, new)))
    assert message in str(error.value)
    assert "painting.toml" in str(error.value)
    assert "\n" not in str(error.value)


def test_maps_of_another_size_or_with_nan_are_refused(demo_folder, tmp_path):
    import tifffile

    small = _edit(demo_folder, tmp_path, files={
        "height.tif": lambda p: tifffile.imwrite(p, np.zeros((16, 16))),
    })  # fmt: skip
    with pytest.raises(
        SpecrefError, match=r"height: height.tif: 16×16 pixels, the colour is 32×32"
    ):
        read_painting(small)
    nan = np.zeros((32, 32))
    nan[3, 4] = np.nan
    broken = tmp_path / "broken"
    _edit(demo_folder, tmp_path / "x", files={"alpha.tif": lambda p: tifffile.imwrite(p, nan)})
    (tmp_path / "x" / "copy").rename(broken)
    with pytest.raises(SpecrefError, match=r"gloss.alpha: .*NaN or infinite values"):
        read_painting(broken)


def test_an_image_larger_than_a_painting_is_refused_before_it_is_converted(demo_folder, tmp_path):
    import imageio.v3 as iio

    from impastor.painting_files import MAX_PAINTING_SIDE

    side = MAX_PAINTING_SIDE + 1
    image = np.zeros((side, 8, 3), np.uint8)
    big = _edit(demo_folder, tmp_path, lambda t: t.replace("reflectance.tif", "big.png"),
                files={"big.png": lambda p: iio.imwrite(p, image)})  # fmt: skip
    with pytest.raises(SpecrefError, match=f"{side} × 8 pixels; a painting is at most"):
        read_painting(big)


def test_the_commands_write_and_render_a_painting(tmp_path, capsys):
    folder = tmp_path / "demo"
    assert main(["impastor", "painting", str(folder), "--size", "32", "--seed", "3"]) == 0
    assert (folder / "painting.toml").is_file()
    out = tmp_path / "demo.png"
    command = ["impastor", "render", "--painting", str(folder), "--size", "16", "--out", str(out)]
    assert main([*command, "--method", "median_cut"]) == 0
    assert out.is_file()
    capsys.readouterr()
    (folder / "painting.toml").write_text("width_m = 0.3\n")
    assert main([*command, "--method", "median_cut"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "missing key 'colour'" in err


def test_the_painting_command_refuses_bad_numbers_and_outputs(tmp_path, capsys):
    (tmp_path / "file").write_text("not a folder")
    for argv, message in (
        (["--seed", "-1"], "--seed: must be an integer >= 0"),
        (["--size", "0"], "--size"),
        (["--size", "100000"], "--size"),
    ):
        assert main(["impastor", "painting", str(tmp_path / "p"), *argv]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1
        assert message in err
    assert main(["impastor", "painting", str(tmp_path / "file"), "--size", "8"]) == 2
    assert "cannot write" in capsys.readouterr().err
    assert (tmp_path / "file").read_text() == "not a folder"
    assert not (tmp_path / "p").exists()

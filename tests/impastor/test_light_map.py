"""A captured room as the booth's light (erratum E113): an HDR panorama seen through the ceiling."""

import re

import numpy as np
import pytest

from impastor import painting as imp
from impastor.arealights import plane_image_from_latlong
from reference.errors import SpecrefError
from reference.geometry.envmap import latlong_pixel_directions
from reference.images.formats import spectral_channel_names, write_exr
from validation.cli import main


def _corner_form_factor(a, b, h):
    # Source: the closed form of the view factor from a point to a parallel rectangle a × b with one
    # corner above it at height h (e.g. Howell's catalogue of configuration factors, B-3)
    X, Y = a / h, b / h
    return (
        X / np.sqrt(1 + X**2) * np.arctan(Y / np.sqrt(1 + X**2))
        + Y / np.sqrt(1 + Y**2) * np.arctan(X / np.sqrt(1 + Y**2))
    ) / (2 * np.pi)


def test_a_uniform_room_gives_the_ceilings_view_factor():
    # the booth's ceiling spans x in [-0.6, 0.6], z in [-1.0, -0.2] at 0.6 m: by superposition of
    # corner rectangles its view factor from the canvas's centre is 2 (F(0.6, 1.0) - F(0.6, 0.2)),
    # and a uniform room of radiance 1 gives E = π F
    plane = imp.booth_plane_light("fluorescent", 128, 64)
    uniform = imp.replace(plane, image=plane_image_from_latlong(np.ones((32, 64)), plane))
    F = 2 * (_corner_form_factor(0.6, 1.0, 0.6) - _corner_form_factor(0.6, 0.2, 0.6))
    assert imp.centre_illuminance(uniform) == pytest.approx(np.pi * F, rel=2e-4)


def test_a_bright_spot_lands_where_its_direction_meets_the_ceiling():
    d0 = np.array([0.3, 0.6, -0.5]) / np.linalg.norm([0.3, 0.6, -0.5])
    d = latlong_pixel_directions(256, 512)
    room = 0.01 + np.exp(-((1 - d @ d0) / 2e-4))
    plane = imp.booth_plane_light("fluorescent", 120, 80)
    image = plane_image_from_latlong(room, plane)
    row, col = np.unravel_index(np.argmax(image), image.shape)
    # the ray from the canvas's centre meets y = 0.6 at (0.3, 0.6, -0.5)
    assert abs((col + 0.5) / 120 * 1.2 - 0.6 - 0.3) < 0.015
    assert abs((row + 0.5) / 80 * 0.8 - 1.0 + 0.5) < 0.015


def test_the_room_is_scaled_to_the_booths_illuminance(tmp_path):
    rng = np.random.default_rng(3)
    path = write_exr(tmp_path / "room.exr", rng.uniform(0.5, 2.0, (32, 64, 3)))
    booth = imp.centre_illuminance(imp.booth_plane_light("fluorescent", 32, 16))
    default = imp.booth_plane_light_from_map(path, 32, 16)
    assert imp.centre_illuminance(default) == pytest.approx(booth, rel=1e-12)
    chosen = imp.booth_plane_light_from_map(path, 32, 16, lux=1234.0)
    assert imp.centre_illuminance(chosen) == pytest.approx(1234.0, rel=1e-12)
    # the painting renders under it, and the tolerance path takes it too
    painting = imp.impasto_painting(32, seed=5)
    options = {"light_resolution": (16, 8), "backend": "numpy"}
    out = imp.render_painting("D65", 16, "median_cut", painting, light_map=path, **options)
    assert np.isfinite(out["XYZ"]).all()
    assert out["XYZ"][..., 1].max() > 0


def test_bad_light_maps_are_one_line(tmp_path, capsys):
    dark_above = np.zeros((16, 32, 3))
    dark_above[8:] = 1.0  # only the lower hemisphere: nothing behind the ceiling
    spectral = np.ones((8, 16, 4))
    cases = {
        "dark.exr": (dark_above, None, "no light in the directions the booth's ceiling covers"),
        "spectral.exr": (
            spectral, spectral_channel_names([450.0, 500.0, 550.0, 600.0]), "must be RGB"
        ),
        "negative.exr": (-np.ones((8, 16, 3)), None, "must be finite and >= 0"),
        "square.exr": (np.ones((16, 16, 3)), None, "must be a lat-long panorama \\(2:1\\)"),
    }  # fmt: skip
    for name, (image, channels, message) in cases.items():
        path = write_exr(tmp_path / name, image, channels)
        with pytest.raises(SpecrefError, match=message):
            imp.booth_plane_light_from_map(path, 16, 8)
        out = tmp_path / f"{name}.png"
        command = ["impastor", "render", "--size", "16", "--method", "median_cut"]
        assert main([*command, "--light-map", str(path), "--out", str(out)]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1
        assert re.search(message, err), err
        assert not out.exists()
    missing = ["impastor", "render", "--size", "16", "--light-map", str(tmp_path / "none.hdr")]
    assert main([*missing, "--out", str(tmp_path / "m.png")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "none.hdr" in err
    assert not (tmp_path / "m.png").exists()
    good = write_exr(tmp_path / "room.exr", np.ones((16, 32, 3)))
    out = tmp_path / "path.png"
    path_command = ["impastor", "path", "--frames", "2", "--size", "16", "--method", "median_cut"]
    assert main([*path_command, "--light-map", str(good), "-o", str(out)]) == 0
    assert out.is_file()

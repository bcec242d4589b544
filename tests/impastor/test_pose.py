"""The painting follows the viewer (Ferwerda §3.4): pose as an input of the render, and paths."""

import imageio.v3 as iio
import numpy as np
import pytest

from impastor import painting as imp
from validation.cli import main

OPTIONS = {"light_resolution": (16, 8), "backend": "numpy", "method": "median_cut"}


def _render(eye, painting, size=16):
    return imp.render_painting("D65", size, painting=painting, eye=eye, **OPTIONS)


def test_the_default_pose_is_the_booth_viewer():
    painting = imp.impasto_painting(32, seed=5)
    a = imp.render_painting("D65", 16, painting=painting, **OPTIONS)
    b = _render(imp.EYE, painting)
    assert np.array_equal(a["XYZ"], b["XYZ"])


def test_a_mirrored_viewer_sees_the_mirrored_canvas():
    # the canvas outline is symmetric about x = 0: from (x, y, z) and (−x, y, z) the visible pixels
    # are each other's mirror image
    x, y, z = 0.2, 0.45, 0.6
    left = imp.canvas_pixels(imp.impasto_painting(16), 24, (x, y, z)).gbuffer.mask
    right = imp.canvas_pixels(imp.impasto_painting(16), 24, (-x, y, z)).gbuffer.mask
    assert left.any()
    assert np.array_equal(left, right[:, ::-1])


def test_a_path_shares_its_horizon_map_and_moves_the_highlight(monkeypatch):
    painting = imp.impasto_painting(32, seed=6)
    calls = []
    original = imp.horizon_map

    def counted(*args, **kwargs):
        calls.append(1)
        return original(*args, **kwargs)

    monkeypatch.setattr(imp, "horizon_map", counted)
    imp._HORIZON_CACHE.clear()
    frames = [_render((x, 0.45, 0.6), painting)["XYZ"] for x in (-0.2, 0.0, 0.2)]
    assert len(calls) == 1  # pose-independent: built once for the whole path
    assert not np.array_equal(frames[0], frames[2])


def test_the_path_command_writes_an_animation(tmp_path, capsys):
    out = tmp_path / "path.png"
    base = ["impastor", "path", "--size", "16", "--method", "median_cut"]
    command = [*base, "--frames", "3"]
    assert main([*command, "-o", str(out)]) == 0
    frames = iio.imread(out, index=None)
    assert frames.shape[:3] == (3, 16, 16)
    assert "3 frames of 16×16" in capsys.readouterr().out
    for bad, message in (
        (["--from", "0,-0.2,0.6"], "--from: (0, -0.2, 0.6) m is behind the canvas"),
        (["--frames", "0"], "--frames"),
        (["--frames", "601"], "--frames"),
        (["--fps", "0"], "--fps: must be in [0.1, 120]"),
        (["--to", "1,2"], "--to: must be x,y,z in metres"),
    ):
        given = [*base, *bad] if bad[0] == "--frames" else [*command, *bad]  # each option once
        assert main([*given, "-o", str(tmp_path / "bad.png")]) == 2, bad
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1
        assert message in err
    assert not (tmp_path / "bad.png").exists()


# --- the display's tilt turns the painting under the booth's light --------------------------------


def _flat_matte(size=32):
    painting = imp.impasto_painting(size, seed=5)
    for key in ("height", "rho_s", "material"):
        painting[key] = np.zeros_like(painting[key])
    return painting


def _booth_illuminance(tilt, resolution):
    # Independent of the render's frame change: every pixel of the booth's ceiling, in the booth's
    # own frame, seen from the canvas centre whose normal is turned instead, R_x(−tilt) (0, 1, 0)
    plane = imp.booth_plane_light("fluorescent", *resolution)
    x, L = plane.pixel_positions().reshape(-1, 3), plane.image.reshape(-1)
    n = np.array([0.0, np.cos(tilt), -np.sin(tilt)])
    r2 = (x * x).sum(axis=1)
    w = x / np.sqrt(r2)[:, None]
    cos_s, cos_l = np.maximum(w @ n, 0.0), np.maximum(-(w @ plane.n_light), 0.0)
    return float((L * cos_s * cos_l * plane.pixel_area / r2).sum())


def test_a_tilted_flat_canvas_follows_lamberts_law_under_the_booth_light():
    # a flat matte canvas lit by every light pixel (N = the light's 128 pixels): the centre pixel's
    # luminance over its value at rest is the booth's illuminance ratio for the turned normal
    resolution, painting = (16, 8), _flat_matte()
    options = {"light_resolution": resolution, "n_lights": 128, "backend": "numpy"}

    def centre_Y(tilt):
        out = imp.render_painting("D65", 33, "median_cut", painting, tilt=tilt, **options)
        return out["XYZ"][16, 16, 1]

    rest, rest_E = centre_Y(0.0), _booth_illuminance(0.0, resolution)
    for degrees in (-40.0, -20.0, 20.0, 35.0):
        t = np.radians(degrees)
        ratio = centre_Y(t) / rest
        assert abs(ratio / (_booth_illuminance(t, resolution) / rest_E) - 1) < 1e-4, degrees
    # towards the light it brightens, away from it it darkens
    assert centre_Y(np.radians(20.0)) > rest > centre_Y(np.radians(-20.0))


def test_a_canvas_turned_from_the_whole_light_is_black_and_keeps_its_exposure():
    painting = imp.impasto_painting(32, seed=5)
    away = imp.render_painting("D65", 16, painting=painting, tilt=np.radians(-75.0), **OPTIONS)
    assert away["pose"]["tilt_deg"] == -75.0
    assert np.all(away["XYZ"] == 0)  # every light pixel is behind the canvas's plane
    # the sRGB keeps the exposure of the canvas at rest: turned from the light, it darkens
    rest = imp.render_painting("D65", 16, painting=painting, **OPTIONS)
    less = imp.render_painting("D65", 16, painting=painting, tilt=np.radians(-30.0), **OPTIONS)
    seen = lambda out: out["sRGB"][out["XYZ"][..., 1] > 0].mean()  # noqa: E731
    assert seen(less) < seen(rest)


def test_the_pose_is_checked_and_the_pilot_sees_the_tilted_canvas():
    from impastor.settings import render_painting_to_tolerance
    from reference.errors import SpecrefError

    painting = imp.impasto_painting(32, seed=5)
    out = render_painting_to_tolerance(
        "A", 16, 0.05, painting=painting, light_resolution=(16, 8), backend="numpy",
        tilt=np.radians(20.0),
    )  # fmt: skip
    assert out["pose"]["tilt_deg"] == 20.0
    assert out["settings"]["met"]
    assert out["settings"]["pilot_error"] <= 0.05
    for tilt, message in ((np.radians(45.0), "faces away from the viewer"),
                          (np.radians(95.0), "within ±90°"), (np.nan, "within ±90°")):  # fmt: skip
        with pytest.raises(SpecrefError, match=message):
            imp.render_painting("D65", 8, painting=painting, tilt=tilt, **OPTIONS)


def test_the_commands_take_the_tilt(tmp_path, capsys):
    out = tmp_path / "tilt.png"
    command = ["impastor", "path", "--frames", "3", "--size", "16", "--method", "median_cut"]
    assert main([*command, "--tilt-from", "-20", "--tilt-to", "20", "-o", str(out)]) == 0
    frames = iio.imread(out, index=None)
    assert frames.shape[:3] == (3, 16, 16)
    assert not np.array_equal(frames[0], frames[2])
    assert "tilt 20.0°" in capsys.readouterr().err
    bad = ["--tilt-to", "60", "-o", str(tmp_path / "bad.png")]
    assert main([*command, *bad]) == 2
    err = capsys.readouterr().err.strip()
    assert "frame 3 of the path: tilt: at 60° the canvas faces away" in err
    assert len(err.splitlines()) == 1
    assert not (tmp_path / "bad.png").exists()
    render = ["impastor", "render", "--size", "16", "--method", "median_cut", "--tilt", "50"]
    assert main([*render, "--out", str(tmp_path / "r.png")]) == 2
    assert "faces away from the viewer" in capsys.readouterr().err
    assert not (tmp_path / "r.png").exists()


def test_non_finite_and_huge_tilts_are_one_line(tmp_path, capsys):
    render = ["impastor", "render", "--size", "16", "--method", "median_cut"]
    path = ["impastor", "path", "--frames", "2", "--size", "16", "--method", "median_cut"]
    for command, bad in (
        (render, ["--tilt", "nan"]),
        (render, ["--tilt=-1e300"]),
        (path, ["--tilt-from", "inf"]),  # "--tilt-from: must be a finite angle"
        (path, ["--tilt-to=-95"]),
    ):
        out = tmp_path / "bad.png"
        flag = "--out" if command is render else "-o"
        assert main([*command, *bad, flag, str(out)]) == 2, bad
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1, err
        assert "tilt" in err
        assert not out.exists()

"""The painting follows the viewer (Ferwerda §3.4): pose as an input of the render, and paths."""

import imageio.v3 as iio
import numpy as np

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
    command = ["impastor", "path", "--frames", "3", "--size", "16", "--method", "median_cut"]
    assert main([*command, "-o", str(out)]) == 0
    frames = iio.imread(out, index=None)
    assert frames.shape[:3] == (3, 16, 16)
    assert "3 frames of 16×16" in capsys.readouterr().out
    for bad, message in (
        (["--from", "0,-0.2,0.6"], "--from: (0, -0.2, 0.6) m is behind the canvas"),
        (["--frames", "0"], "--frames"),
        (["--frames", "601"], "--frames"),
        (["--fps", "0"], "--fps: must be in (0, 120]"),
        (["--to", "1,2"], "--to: must be x,y,z in metres"),
    ):
        assert main([*command, *bad, "-o", str(tmp_path / "bad.png")]) == 2, bad
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1
        assert message in err
    assert not (tmp_path / "bad.png").exists()

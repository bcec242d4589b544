"""The material editor's Python side, without a browser (errata E28, E29; §1, §5, Wang et al.)."""

import socket
import threading
from types import SimpleNamespace

import numpy as np
import pytest

from phong_table.editor.state import (
    EditorState,
    LatestWorker,
    render_exact_frame,
    render_table_frame,
)
from phong_table.materialfile import load_material_file
from phong_table.render import shade_pixels, shading_buffer, sphere_gbuffer
from phong_table.table import build_table
from validation.cli import main

RES = 32


def test_an_edit_moves_the_curve_between_its_control_points():
    state = EditorState.default()
    before = state.model()
    state.set_point("k_s", 3, 0.8)  # 500 nm
    state.set_point("n", 5, 400.0)  # 580 nm; neighbours stay
    wl = state.grid.wavelengths_nm
    k_s, n = state.model().material.k_s, state.model().material.n
    # Linear in λ between 460 nm (0.5) and 500 nm (0.8); flat far away.
    assert k_s[wl.tolist().index(490.0)] == pytest.approx(0.5 + 0.3 * 0.75)
    assert k_s[wl.tolist().index(600.0)] == before.material.k_s[wl.tolist().index(600.0)]
    # n: linear in log n, so the midpoint is the geometric mean of its neighbours.
    n_540 = state.points["n"][4]
    assert n[wl.tolist().index(560.0)] == pytest.approx(np.sqrt(n_540 * 400.0))
    # Bounds of the curve editor: k_s in [0, 1].
    state.set_point("k_s", 0, 7.0)
    assert state.points["k_s"][0] == 1.0


def test_an_edit_gives_the_table_and_image_of_a_direct_build():
    state = EditorState.default()
    old = render_table_frame(state.model(), resolution=RES, entries=64)
    state.set_point("k_s", 3, 0.9)
    model = state.model()
    frame = render_table_frame(model, resolution=RES, entries=64, placement="uniform")
    buffer = shading_buffer(sphere_gbuffer("far", RES), model)
    table = build_table(model, 64, "uniform", None, True, buffer.t_range, buffer.t_density)
    assert np.array_equal(frame.info["nodes"], table.nodes)
    assert np.array_equal(frame.info["values"], table.values)
    # The table's values are f_sp at the nodes, Eq. (11), Wang et al.
    assert np.allclose(table.values, model.specular(table.nodes), rtol=0, atol=1e-12)
    pixels = shade_pixels(buffer, model, "table", table, "monotone")
    assert np.array_equal(frame.linear, pixels)
    assert not np.array_equal(frame.rgba, old.rgba)  # the highlight changed colour
    # Against the exact render of the same edit: a small but non-zero RMS.
    exact = render_exact_frame(model, resolution=RES)
    rms = render_table_frame(model, resolution=RES, entries=64, exact=exact.linear).info["rms"]
    assert 0 < rms < 5


def test_save_and_open_round_trip(tmp_path):
    state = EditorState.default()
    state.set_point("k_d", 2, 0.7)
    state.set_point("light", 8, 2.0)
    state.name = 'blue "plastic"'
    path = state.save(tmp_path / "m.toml")
    model = load_material_file(path)
    mine = state.model()
    for key in ("k_d", "k_s", "n"):
        np.testing.assert_allclose(getattr(model.material, key), state.curve(key), rtol=1e-8)
    assert model.material.name == 'blue "plastic"'
    assert model.light.intensity == pytest.approx(state.intensity, rel=1e-11)
    t = np.linspace(0.9, 1.0, 7)
    np.testing.assert_allclose(model.specular(t), mine.specular(t), rtol=1e-8)
    np.testing.assert_allclose(model.diffuse_RGB, mine.diffuse_RGB, rtol=1e-8)
    again = EditorState.open(path)
    for key, values in state.points.items():
        np.testing.assert_allclose(again.points[key], values, rtol=1e-8)


def test_a_file_that_fails_to_open_is_shown_and_never_overwritten(tmp_path):
    from phong_table.editor.app import EditorPage

    bad = tmp_path / "bad.toml"
    bad.write_text("[material]\nk_d = 0.2\nk_s = -1\nn = 10\n")
    page = EditorPage(bad, resolution=RES)
    assert "\n" not in page.error
    assert "bad.toml" in page.error
    assert "k_s" in page.error
    page.path_input = SimpleNamespace(value=str(bad))
    page.error_div = SimpleNamespace(text="")
    page._on_save()
    assert "not overwritten" in page.error_div.text
    assert bad.read_text() == "[material]\nk_d = 0.2\nk_s = -1\nn = 10\n"
    page.path_input.value = str(tmp_path / "good.toml")
    page._on_save()
    assert load_material_file(tmp_path / "good.toml").material.k_s.shape == (41,)


def test_the_worker_drops_stale_requests():
    started, release, got = threading.Event(), threading.Event(), []
    worker = LatestWorker(lambda result, _seq: got.append(result))
    worker.submit(lambda: started.set() or (release.wait(5.0) and "first"))
    assert started.wait(5.0)
    for k in range(4):
        worker.submit(lambda k=k: k)
    release.set()
    assert worker.wait_idle(5.0)
    worker.stop()
    assert got == ["first", 3]
    assert worker.dropped >= 3


def test_a_port_in_use_is_one_line_and_exit_2(capsys):
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        assert main(["phong", "edit", "--port", str(port)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert f"127.0.0.1:{port}" in err
    assert "--port" in err

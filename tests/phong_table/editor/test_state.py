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
from phong_table.model import SpectralPhong
from phong_table.render import shade_pixels, shading_buffer, sphere_gbuffer
from phong_table.scenes import LIGHT_POSITION
from phong_table.table import build_table
from reference.colour.spectra import Spectrum
from reference.scene.lights import PointLight
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


def _chromaticity(rgb):
    return np.asarray(rgb) / np.sum(rgb)


def test_a_preset_light_keeps_its_lines(tmp_path):
    """FL2 in the editor is FL2 (its 5 nm samples), not the 11-point bump it was once cut to."""
    from phong_table.editor.state import illuminant_presets

    state = EditorState.default()
    wl, values = illuminant_presets(("FL2",))["FL2"]
    state.set_curve("light", values, wl)
    mine = state.model()
    assert np.array_equal(mine.light.spectrum.wavelengths_nm, wl)
    assert np.array_equal(mine.light.spectrum.values, values)
    # The same material under FL2 as a material file names it: the same colour of the diffuse.
    text = (
        state.material_text().split("[light]")[0] + '[light]\nspectrum = { illuminant = "FL2" }\n'
    )
    (tmp_path / "fl2.toml").write_text(text)
    named = load_material_file(tmp_path / "fl2.toml")
    np.testing.assert_allclose(
        _chromaticity(mine.diffuse_RGB), _chromaticity(named.diffuse_RGB), rtol=0, atol=1e-12
    )
    # The 11 control points alone (what the editor kept before) give another colour.
    smoothed = Spectrum(wl, np.interp(wl, state.control_nm, state.points["light"]))
    coarse = SpectralPhong(mine.material, PointLight(LIGHT_POSITION, smoothed, 1.0))
    shift = np.abs(_chromaticity(coarse.diffuse_RGB) - _chromaticity(mine.diffuse_RGB)).max()
    assert shift > 1e-3


def _jagged_material(path):
    """A material file whose curves vary between the control points, lit by FL11 (5 nm)."""
    wl = np.arange(380.0, 781.0, 10.0)
    rng = np.random.default_rng(7)
    k_d = 0.2 + 0.6 * rng.random(wl.size)
    k_s = 0.1 + 0.3 * rng.random(wl.size)
    n = 10.0 ** (1.0 + 2.0 * rng.random(wl.size))

    def spectrum(values):
        return "{{ wavelengths = [{}], values = [{}] }}".format(
            ", ".join(repr(float(w)) for w in wl),
            ", ".join(repr(float(v)) for v in values),
        )

    text = f'name = "jagged"\n[material]\nk_d = {spectrum(k_d)}\nk_s = {spectrum(k_s)}\n'
    text += f'n = {spectrum(n)}\n[light]\nspectrum = {{ illuminant = "FL11" }}\nintensity = 0.7\n'
    path.write_text(text)
    return path


def test_open_then_save_writes_what_was_opened(tmp_path):
    original = load_material_file(_jagged_material(tmp_path / "jagged.toml"))
    saved = EditorState.open(tmp_path / "jagged.toml").save(tmp_path / "again.toml")
    again = load_material_file(saved)
    for key in ("k_d", "k_s", "n"):
        assert np.array_equal(getattr(again.material, key), getattr(original.material, key))
    assert np.array_equal(
        again.light.spectrum.wavelengths_nm, original.light.spectrum.wavelengths_nm
    )
    assert np.array_equal(again.light.spectrum.values, original.light.spectrum.values)
    assert again.light.intensity == original.light.intensity
    assert np.array_equal(again.diffuse_RGB, original.diffuse_RGB)
    assert np.array_equal(again.specular_weights, original.specular_weights)


def test_an_edit_changes_the_curve_between_the_neighbours_only(tmp_path):
    state = EditorState.open(_jagged_material(tmp_path / "jagged.toml"))
    before = {key: state.curve(key).copy() for key in ("k_d", "n", "light")}
    state.set_point("k_d", 5, 0.05)  # 580 nm: 540-620 nm move
    state.set_point("n", 0, 2000.0)  # 380 nm: 380-420 nm move
    state.set_point("light", 5, 3.0)  # 580 nm on the light's 5 nm samples
    wl = state.grid.wavelengths_nm
    changed = wl[state.curve("k_d") != before["k_d"]]
    assert changed.min() > 540.0
    assert changed.max() < 620.0
    assert 580.0 in changed
    assert state.curve("k_d")[wl.tolist().index(580.0)] == pytest.approx(0.05)
    changed = wl[state.curve("n") != before["n"]]
    assert changed.min() == 380.0
    assert changed.max() < 420.0
    light_wl = state.curve_wavelengths("light")
    changed = light_wl[state.curve("light") != before["light"]]
    assert changed.min() > 540.0
    assert changed.max() < 620.0
    assert changed.size == 15
    # The displacement is linear in λ between the neighbours: half-way, half the change.
    i = wl.tolist().index(560.0)
    half = before["k_d"][i] + 0.5 * (0.05 - np.interp(580.0, wl, before["k_d"]))
    assert state.curve("k_d")[i] == pytest.approx(float(np.clip(half, 0.0, 1.0)))

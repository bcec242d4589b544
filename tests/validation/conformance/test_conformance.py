"""Tests of the conformance suite: scenes, references, the check and its diagnoses, the export.

The references of every scene are rendered once (about a minute) into the session's folder
(conftest.py), which the Mitsuba 3 proof (test_mitsuba_proof.py) shares when it runs in the same
process.
"""

from __future__ import annotations

import json
import os
import tomllib
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from reference.data import data_path
from reference.errors import SpecrefError
from reference.images.formats import read_exr, write_exr, write_png
from reference.scene.loader import load_scene
from reference.scene.render import render_scene
from validation.cli import main
from validation.conformance.check import check_folder, check_render
from validation.conformance.diagnose import DIAGNOSES, DiagnosisContext, diagnosis_variants
from validation.conformance.display import scene_display
from validation.conformance.export import TEXEL_REPEAT, export_scenes, mitsuba_xml
from validation.conformance.references import (
    REFERENCE_OPTIONS,
    ensure_references,
    load_reference,
    render_reference,
    shipped_manifest,
)
from validation.conformance.scenes import (
    CONFORMANCE_SCENES,
    ENVIRONMENT_MAPS,
    scene_path,
    scene_text,
)
from validation.precompute.conformance import small_map

NAMES = CONFORMANCE_SCENES.names()
DISPLAY = "colorchecker-d65-calibrated-display"


@pytest.fixture(scope="module")
def references(conformance_references):
    ensure_references(folder=conformance_references)
    return conformance_references


def _write(path, XYZ):
    return write_exr(path, np.asarray(XYZ, dtype=np.float32), ["X", "Y", "Z"])


def _render(folder, name, XYZ):
    """``XYZ`` as a renderer writes it for the scene: device values in an 8-bit PNG for a
    calibrated display (what ``specref render`` writes), else an XYZ EXR."""
    display = scene_display(name)
    if display is None:
        return _write(folder / f"{name}.exr", XYZ)
    return write_png(folder / f"{name}.png", display.values(XYZ))


def test_the_shipped_scene_files_are_what_the_registry_writes():
    for name in NAMES:
        assert scene_path(name).read_text(encoding="utf-8") == scene_text(name), name
    assert len(NAMES) >= 18


def test_every_scene_is_small_loads_and_lists_known_mistakes():
    for name in NAMES:
        scene = load_scene(scene_path(name))
        r = scene.render
        assert r.width * r.height <= 256 * 256, name
        assert set(CONFORMANCE_SCENES.lookup(name).catches) <= set(DIAGNOSES.names()), name
        assert scene.title == name
        assert scene_text(name).count("Tests ") == 1


def test_the_shipped_maps_are_box_averages_of_the_shipped_environments():
    for key, file in ENVIRONMENT_MAPS.items():
        shipped = read_exr(data_path(f"conformance/maps/{key}.exr"))[0][..., :3]
        np.testing.assert_allclose(shipped, small_map(file), rtol=1e-6, atol=1e-30)


@pytest.mark.parametrize("name", ["colorchecker-fl2", "lambert-point-orange-a"])
def test_a_reference_is_the_box_filtered_render_with_its_standard_error(name):
    # Source: render_scene's own box resolve at the scene's supersampling (an independent path
    # through specref: XYZ shading instead of spectral output integrated here).
    ref = render_reference(name)
    scene = load_scene(scene_path(name))
    np.testing.assert_allclose(ref.XYZ, render_scene(scene, options=REFERENCE_OPTIONS).XYZ,
                               rtol=1e-12, atol=1e-14)  # fmt: skip
    # the spectral image integrates to XYZ up to the light's folding into the band weights (E7)
    from validation.conformance.references import _equal_energy_weights

    np.testing.assert_allclose(ref.spectral @ _equal_energy_weights(ref), ref.XYZ, rtol=1e-4,
                               atol=1e-9)  # fmt: skip
    assert (ref.stderr >= 0).all()
    full = ref.coverage == 1.0
    # inside a flat patch or on a smooth sphere the sub-samples barely differ; at edges they do
    assert np.median(ref.stderr[full][:, 1] / np.maximum(ref.XYZ[full][:, 1], 1e-12)) < 0.01
    assert ref.stderr[..., 1].max() > 10 * np.median(ref.stderr[full][:, 1])


def test_references_agree_with_the_shipped_manifest_within_their_uncertainty(references):
    shipped = shipped_manifest()["scenes"]
    made = json.loads((references / "manifest.json").read_text())["scenes"]
    assert set(shipped) == set(made) == set(NAMES)
    for name in NAMES:
        a, b = np.array(made[name]["mean_XYZ"]), np.array(shipped[name]["mean_XYZ"])
        se = np.array(shipped[name]["stderr_mean_XYZ"])
        assert (np.abs(a - b) <= 4 * se + 1e-6 * np.abs(b)).all(), name


def test_a_changed_reference_file_is_refused_in_one_line(references, tmp_path):
    import shutil

    folder = tmp_path / "refs"
    shutil.copytree(references, folder)
    path = folder / "colorchecker-a.xyz.exr"
    data = bytearray(path.read_bytes())
    data[-5] ^= 0xFF
    path.write_bytes(bytes(data))
    with pytest.raises(SpecrefError, match="SHA-256 differs") as error:
        load_reference("colorchecker-a", folder)
    assert "\n" not in str(error.value)
    manifest = json.loads((folder / "manifest.json").read_text())
    manifest["version"] = 0
    (folder / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(SpecrefError, match="version"):
        load_reference("colorchecker-a", folder)


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        ("files", {"../lamp.csv": "0" * 64}, "must name .exr files of the manifest's own folder"),
        ("width", 10**9, "width: must be a size in pixels"),
        ("height", float("nan"), "height: must be a size in pixels"),
        ("mean_XYZ", [float("nan"), 1.0, 1.0], "mean_XYZ: must be three finite values"),
    ],
)
def test_a_tampered_manifest_entry_is_refused_in_one_line(
    references, tmp_path, key, value, message
):
    # a manifest is read only as write_reference makes it: nothing outside its folder is read
    import shutil

    folder = tmp_path / "refs"
    shutil.copytree(references, folder)
    manifest = json.loads((folder / "manifest.json").read_text())
    manifest["scenes"]["colorchecker-a"][key] = value
    (folder / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(SpecrefError, match=message) as error:
        load_reference("colorchecker-a", folder)
    assert "\n" not in str(error.value)


def test_an_unknown_scene_is_refused_before_the_folder_is_made(tmp_path, capsys):
    code = main(["conformance", "references", "--out", str(tmp_path / "new"), "--scene", "nope"])
    assert code == 2
    assert not (tmp_path / "new").exists()


def test_every_reference_passes_its_own_check_from_the_command_line(references, tmp_path, capsys):
    renders = tmp_path / "renders"
    renders.mkdir()
    for name in NAMES:
        _render(renders, name, load_reference(name, references).XYZ)
    out = tmp_path / "check.json"
    code = main(["conformance", "check", str(renders), "--references", str(references),
                 "--json", str(out), "--html", str(tmp_path / "check.html")])  # fmt: skip
    assert code == 0, capsys.readouterr().out
    result = json.loads(out.read_text())
    assert result["passed"] == len(NAMES)
    assert result["missing"] == []
    assert "<img" in (tmp_path / "check.html").read_text()


def _catches(name):
    return [(name, key) for key in CONFORMANCE_SCENES.lookup(name).catches]


# Every scene's list, the glossy environment spheres' too (their brute-force variants take about
# five seconds a scene since the oracle sums only the pairs above the horizon)
CASES = [c for n in NAMES for c in _catches(n)]


@pytest.mark.parametrize(("name", "key"), CASES)
def test_each_mistake_a_scene_lists_fails_and_is_named(references, tmp_path, name, key):
    # Every scene is held to its list: each mistake it lists, made on purpose, fails the check
    # and is the diagnosis among all the scene's mistakes (the variants are cached beside the
    # references, so each is rendered once for the module).
    ref = load_reference(name, references)
    if key == "Y_scaled":
        broken, label = ref.XYZ * 1.2, "by 1.2"
    else:
        ctx = DiagnosisContext(name, ref, ref.XYZ)
        label, broken = diagnosis_variants(DIAGNOSES.lookup(key), ctx, references)[-1]
    found = check_render(name, _render(tmp_path, name, broken), references)
    assert not found["passed"], (name, label)
    diagnosis = found["diagnosis"]
    assert diagnosis["mistake"] == key, diagnosis
    assert diagnosis["certain"], diagnosis
    assert diagnosis["detail"].startswith(label)


def test_a_render_no_mistake_explains_is_said_to_be_so(references, tmp_path):
    ref = load_reference("lambert-point-d65", references)
    rng = np.random.default_rng(7)
    noisy = ref.XYZ * rng.uniform(0.5, 1.5, ref.XYZ.shape[:2])[..., None]
    found = check_render("lambert-point-d65", _write(tmp_path / "x.exr", noisy), references)
    assert not found["passed"]
    assert found["diagnosis"]["mistake"] is None


def test_monte_carlo_noise_passes_and_bias_fails(references, tmp_path):
    # a renderer's per-pixel noise (5 % per pixel) averages out over the blocks; 3 % bias does not
    ref = load_reference("lambert-env-studio", references)
    rng = np.random.default_rng(11)
    noisy = ref.XYZ * (1 + 0.05 * rng.standard_normal(ref.XYZ.shape[:2]))[..., None]
    assert check_render("lambert-env-studio", _write(tmp_path / "a.exr", noisy), references)[
        "passed"
    ]
    biased = _write(tmp_path / "b.exr", ref.XYZ * 1.03)
    assert not check_render("lambert-env-studio", biased, references, diagnose=False)["passed"]


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda d, ref: _write(d / "colorchecker-a.exr", ref.XYZ[:-1]), "width × height"),
        (lambda d, ref: _write(d / "colorchecker-a.exr", np.where(ref.XYZ > 0.5, np.nan, ref.XYZ)),
         "NaN or infinite"),
        (lambda d, ref: (d / "colorchecker-a.exr").write_bytes(b"not an exr"),
         "colorchecker-a.exr"),
        (lambda d, ref: _write(d / "colourchecker-a.exr", ref.XYZ), "no conformance scene named"),
        (lambda d, ref: None, "no renders"),
        (lambda d, ref: os.mkfifo(d / "colorchecker-a.exr"), "not a regular file"),
        (lambda d, ref: (d / "colorchecker-a.exr").mkdir(), "cannot read (a folder, not a file)"),
        (lambda d, ref: (os.symlink(d / "colorchecker-a.exr", d / "loop"),
                         os.symlink(d / "loop", d / "colorchecker-a.exr")),
         "a loop of symbolic links"),
        (lambda d, ref: write_exr(d / "colorchecker-a.exr", ref.XYZ[..., :2].astype(np.float32),
                                  ["U", "V"]), "no X, Y, Z"),
        # the frame for a calibrated display (as large as colorchecker-a) takes device values
        (lambda d, ref: _write(d / f"{DISPLAY}.exr", ref.XYZ),
         "its render is the device values sent to it"),
        (lambda d, ref: (d / f"{DISPLAY}.hdr").write_bytes(b"#?RADIANCE\n"), f"as {DISPLAY}.png"),
        (lambda d, ref: write_png(d / f"{DISPLAY}.png", ref.XYZ[:, 1:]), "width × height"),
        (lambda d, ref: write_png(d / f"{DISPLAY}.png", ref.XYZ[..., 1]), "1 channels"),
        (lambda d, ref: (d / f"{DISPLAY}.png").write_bytes(b"not a png"), "cannot read image"),
        (lambda d, ref: write_png(d / "colorchecker-a.png", ref.XYZ), "no renders"),
    ],
)  # fmt: skip
def test_bad_renders_are_refused_in_one_line_and_nothing_is_written(
    references, tmp_path, capsys, make, message
):
    renders = tmp_path / "renders"
    renders.mkdir()
    make(renders, load_reference("colorchecker-a", references))
    out = tmp_path / "out.json"
    code = main(["conformance", "check", str(renders), "--references", str(references),
                 "--json", str(out)])  # fmt: skip
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert message in err, err
    assert len(err.splitlines()) == 1, err
    assert not out.exists()


def test_the_mitsuba_export_is_well_formed_and_lists_what_it_cannot_express(tmp_path):
    index = export_scenes(tmp_path, "mitsuba", spp=16)
    assert set(index["scenes"]) | set(index["cannot_express"]) == set(NAMES)
    assert {"phong-point-r1", "ward-env-stage"} <= set(index["cannot_express"])
    for name in index["scenes"]:
        root = ET.fromstring((tmp_path / f"{name}.xml").read_text())
        assert root.tag == "scene"
        assert root.find("sensor/film/integer[@name='width']") is not None
    # the maps' texels are repeated 8 × 8 (docs/conformance.md)
    big = read_exr(tmp_path / "maps" / "venice.exr")[0]
    small = read_exr(data_path("conformance/maps/venice.exr"))[0]
    k = TEXEL_REPEAT
    assert big.shape[:2] == (k * small.shape[0], k * small.shape[1])
    _is_the_map_as_mitsuba_reads_it(big[..., :3].astype(np.float64), small[..., :3], k)


def _is_the_map_as_mitsuba_reads_it(big, small, k):
    """Columns repeated k times; Mitsuba's rows (at v = r/(R − 1), interpolated linearly) keep
    each texel row's integral and, wherever a sample's span lies in one texel row, its value."""
    H, R = small.shape[0], big.shape[0]
    for c in range(k):
        np.testing.assert_array_equal(big[:, c::k], big[:, ::k])
    # the integral over v of the linear interpolation: trapezoid weights of the samples
    weights = np.full(R, 1.0 / (R - 1))
    weights[[0, -1]] *= 0.5
    np.testing.assert_allclose(np.einsum("r,rwc->wc", weights, big[:, ::k]),
                               small.mean(axis=0), rtol=1e-5)  # fmt: skip
    v = np.arange(R) / (R - 1)
    half = 0.5 / (R - 1)
    inside = np.floor((v - half) * H) == np.floor(np.minimum(v + half, 1 - 1e-12) * H)
    rows = np.minimum((v * H).astype(int), H - 1)
    np.testing.assert_allclose(big[inside, ::k], small[rows[inside]], rtol=1e-6)
    # and a texel row's edges where they are: the half-way point between a dark and a bright
    # row falls on the edge j/H (the ring map's second row) within 1 % of a texel (rows merely
    # repeated 8 times put it 6 % of a texel towards the pole)
    from validation.conformance.export import texels_for_mitsuba
    from validation.conformance.scenes import ring_map

    ring = texels_for_mitsuba(ring_map())[:, 0, 0].astype(np.float64)
    level = 0.5 * (ring.min() + ring.max())
    r = np.nonzero(ring > level)[0][0]  # the first sample above half way, and the one before
    v_edge = (r - 1 + (level - ring[r - 1]) / (ring[r] - ring[r - 1])) / (R - 1)
    assert abs(v_edge - 1 / H) < 0.01 / H
    with pytest.raises(SpecrefError, match="no Phong BSDF"):
        mitsuba_xml("phong-point-r2")


def test_the_mitsuba_units_are_specrefs(tmp_path):
    # Source: closed form. A point light of specref intensity I at distance d facing a white
    # diffuser gives Y = I/d²; in Mitsuba radiance = (1/π) · Φ/d² with Φ = π I S/Y_S.
    xml = mitsuba_xml("lambert-point-d65")
    light = ET.fromstring(xml).find("emitter[@type='point']/spectrum")
    pairs = [tuple(map(float, p.split(":"))) for p in light.get("value").split(",")]
    wl, values = np.array(pairs).T
    import colour

    ybar = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(
        colour.SpectralShape(wl[0], wl[-1], 1)).values[:, 1]  # fmt: skip
    Y = (values * ybar).sum() / ybar.sum()
    assert pytest.approx(np.pi * 25, rel=1e-6) == Y
    # A sphere light of specref intensity L: Mitsuba's area emitter of radiance L S / Y_S on a
    # sphere of the same centre and radius (a white diffuser facing it has Y = L r²/d² in both).
    root = ET.fromstring(mitsuba_xml("lambert-sphere-light-d65"))
    shape = root.find("shape/emitter[@type='area']/..")
    assert shape.get("type") == "sphere"
    assert float(shape.find("float[@name='radius']").get("value")) == 1.5
    assert shape.find("point[@name='center']").get("value") == "3,2,4"
    pairs = [tuple(map(float, p.split(":"))) for p in
             shape.find("emitter/spectrum").get("value").split(",")]  # fmt: skip
    wl, values = np.array(pairs).T
    Y = (values * ybar).sum() / ybar.sum()
    assert pytest.approx(25 / 1.5**2, rel=1e-6) == Y


def test_the_specref_export_is_self_contained_and_renders_the_same(tmp_path):
    index = export_scenes(tmp_path / "out", "specref")
    assert set(index["scenes"]) == set(NAMES)
    assert not index["cannot_express"]
    text = (tmp_path / "out" / "lambert-point-orange-a.toml").read_text()
    assert "data:" not in tomllib.loads(text)["materials"]["m"]["k_d"]["csv"]
    for name in ("lambert-point-orange-a", "lambert-env-venice",
                 "colorchecker-d65-calibrated-display"):  # fmt: skip
        exported = render_scene(load_scene(tmp_path / "out" / f"{name}.toml"), width=16,
                                options=REFERENCE_OPTIONS)  # fmt: skip
        shipped = render_scene(load_scene(scene_path(name)), width=16, options=REFERENCE_OPTIONS)
        np.testing.assert_array_equal(exported.XYZ, shipped.XYZ)
        # the PNG: device values for the calibrated display the folder carries beside the scene
        np.testing.assert_array_equal(exported.encoded, shipped.encoded)
    assert index["scenes"]["colorchecker-d65-calibrated-display"]["render"].startswith("device")


def test_list_and_export_from_the_command_line(tmp_path, capsys):
    assert main(["conformance", "list"]) == 0
    out = capsys.readouterr().out
    assert all(name in out for name in NAMES)
    assert "catches:" in out
    assert main(["conformance", "export", str(tmp_path), "--format", "mitsuba"]) == 0
    assert "not exported: phong-point-r1" in capsys.readouterr().out
    with pytest.raises(SystemExit) as error:  # argparse's usage error: one line, exit 2
        main(["conformance", "export", str(tmp_path), "--format", "pbrt"])
    assert error.value.code == 2
    assert "invalid choice: 'pbrt'" in capsys.readouterr().err


def test_check_folder_reports_missing_scenes(references, tmp_path):
    _write(tmp_path / "colorchecker-d65.exr", load_reference("colorchecker-d65", references).XYZ)
    result = check_folder(tmp_path, references)
    assert result["passed"] == 1
    assert len(result["missing"]) == len(NAMES) - 1


@pytest.mark.parametrize(
    ("command", "message"),
    [
        (["check", "{renders}", "--json", "{renders}/colorchecker-a.exr"], "an input"),
        (["check", "{renders}", "--html", "{refs}/manifest.json"], "an input"),
        (["check", "{renders}", "--json", "{tmp}"], "is a folder"),
        (["check", "{renders}", "--json", "/dev/null"], "a device"),
        (["check", "{renders}", "--json", "{tmp}/afile/out.json"], "a part of the path is a file"),
        (["references", "--out", "{tmp}/afile", "--scene", "colorchecker-a"], "is a file"),
        (["references", "--out", "/dev/null"], "cannot write"),
        (["references", "--scene", "nope", "--out", "{tmp}/r"], "unknown conformance scene"),
        (["export", "{tmp}/afile"], "cannot write"),
        (["export", "{tmp}/afile/x"], "cannot write"),
        (["export", "{tmp}/e", "--format", "mitsuba", "--spp", "-3"], "must be an integer in"),
        (["export", "{tmp}/e", "--format", "mitsuba", "--spp", "0"], "must be an integer in"),
        (["export", "{tmp}/e", "--format", "mitsuba", "--spp", "99999999999999"], "integer in"),
    ],
)
def test_bad_outputs_and_settings_are_refused_and_the_inputs_stay_intact(
    references, tmp_path, capsys, command, message
):
    renders = tmp_path / "renders"
    renders.mkdir()
    render = _write(
        renders / "colorchecker-a.exr", load_reference("colorchecker-a", references).XYZ
    )
    (tmp_path / "afile").write_text("x")
    before = render.read_bytes(), (references / "manifest.json").read_bytes()
    fill = {"renders": renders, "refs": references, "tmp": tmp_path}
    argv = [a.format(**fill) for a in command]
    if argv[0] == "check":
        argv += ["--references", str(references)]
    code = main(["conformance", *argv])
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert message in err, err
    assert len(err.splitlines()) == 1, err
    assert (render.read_bytes(), (references / "manifest.json").read_bytes()) == before
    assert (tmp_path / "afile").read_text() == "x"


def _ensure_and_report(folder, names, queue):
    from validation.conformance.references import ensure_references

    lines = []
    ensure_references(names, folder, progress=lines.append)
    queue.put(sum("rendering the reference" in line for line in lines))


def test_processes_filling_one_folder_render_each_reference_once(tmp_path):
    # two commands (or the suite's workers) at once on one cache: each scene's lock lets one of
    # them render it and the other find it, and no scene is lost from the manifest
    import multiprocessing

    from validation.conformance.references import _read_manifest

    names = ["colorchecker-d65", "lambert-point-d65"]
    context = multiprocessing.get_context("spawn")
    queue = context.Queue()
    procs = [
        context.Process(target=_ensure_and_report, args=(tmp_path, names, queue)) for _ in range(2)
    ]
    for p in procs:
        p.start()
    for p in procs:
        p.join(timeout=300)
    assert [p.exitcode for p in procs] == [0, 0]
    assert queue.get(timeout=5) + queue.get(timeout=5) == len(names)
    assert sorted(_read_manifest(tmp_path)["scenes"]) == names


def test_a_scene_another_process_holds_is_passed_over_then_done_if_it_stops(tmp_path):
    # This process holds colorchecker-d65's lock, as another command rendering it would: the child
    # renders colorchecker-a meanwhile (its manifest entry appears while the lock is held), then
    # waits, and renders colorchecker-d65 itself once the lock goes without the scene being done
    import multiprocessing
    import time

    from reference.files import folder_lock
    from validation.conformance.references import _read_manifest

    names = ["colorchecker-d65", "colorchecker-a"]
    context = multiprocessing.get_context("spawn")
    queue = context.Queue()
    child = context.Process(target=_ensure_and_report, args=(tmp_path, names, queue))
    with folder_lock(tmp_path, "colorchecker-d65"):
        child.start()
        deadline = time.monotonic() + 120
        while "colorchecker-a" not in _read_manifest(tmp_path)["scenes"]:
            assert child.is_alive(), "the child stopped before rendering colorchecker-a"
            assert time.monotonic() < deadline, "the child did not pass over colorchecker-d65"
            time.sleep(0.1)
        assert "colorchecker-d65" not in _read_manifest(tmp_path)["scenes"]
        assert child.is_alive()  # waiting for the scene this process holds
    child.join(timeout=120)
    assert child.exitcode == 0
    assert queue.get(timeout=5) == 2
    assert sorted(_read_manifest(tmp_path)["scenes"]) == sorted(names)

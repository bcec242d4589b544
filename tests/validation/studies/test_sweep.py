"""``specref sweep``: sweep files, their one-line errors, and serial = distributed."""

import pytest

from reference.errors import SpecrefError
from validation.cli import main
from validation.studies.sweep import load_sweep, run_sweep, sweep_csv

GRID = """kind = "phong"
[grid]
materials = ["R1", "R3"]
views = ["near"]
placements = ["uniform", "error"]
interpolations = ["linear", "parabolic"]
entries = [25, 50]
resolution = 16
"""


def test_cells_are_the_grid_in_file_order(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(GRID)
    kind, cells = load_sweep(path)
    assert kind.name == "phong"
    assert len(cells) == 2 * 1 * 2 * 2 * 2
    assert cells[0] == {
        "materials": "R1",
        "views": "near",
        "placements": "uniform",
        "interpolations": "linear",
        "entries": 25,
        "resolution": 16,
    }
    assert cells[-1]["materials"] == "R3"
    assert cells[-1]["entries"] == 50


def test_serial_sweep_matches_the_direct_computation(tmp_path):
    from phong_table.scenes import SCENES
    from validation.studies.phong import table_error_row, view_state

    path = tmp_path / "s.toml"
    path.write_text(GRID.replace('"R1", "R3"', '"R1"'))
    rows = run_sweep(path, scheduler="serial", progress=False)
    state = view_state(SCENES.lookup("R1").build(), "near", 16)
    direct = table_error_row(state, "error", "parabolic", 50)
    row = next(
        r
        for r in rows
        if (r["placements"], r["interpolations"], r["entries"]) == ("error", "parabolic", 50)
    )
    assert row["rms"] == direct["rms"]
    text = sweep_csv(rows, tmp_path / "out.csv")
    assert (tmp_path / "out.csv").read_text() == text
    assert text.splitlines()[0].startswith("materials,views,placements,interpolations,entries")
    assert len(text.splitlines()) == 1 + len(rows)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            ('kind = "phong"', 'kind = "fong"'),
            r"unknown 'fong'; allowed: impastor, phong, shrm",
        ),
        (("entries = [25, 50]", "entries = []"), r"grid.entries: must be a non-empty list"),
        (("entries = [25, 50]", "entries = [25, 0]"), r"grid.entries: must be an integer"),
        (('views = ["near"]', 'views = ["nearby"]'), r"grid.views: unknown 'nearby'"),
        (("resolution = 16", "resolution = 16\ncolour = 1"), r"grid: unknown keys \['colour'\]"),
        (("resolution = 16", ""), r"grid: missing keys \['resolution'\]"),
        (("[grid]", "[grids]"), r"unknown keys \['grids'\]"),
        (("materials = [", "materials = "), r"malformed TOML"),
        # a missing or bad material was refused by the first cell, naming only the material
        (('"R1", "R3"', '"R1", "R99"'), r"s.toml: grid.materials\[1\]: 'R99': neither a Phong"),
        (
            ('"R1", "R3"', '"bad.toml"'),
            r"s.toml: grid.materials\[0\]: .*bad.toml: material.n: must",
        ),
    ],
)
def test_bad_sweep_files_are_one_line(tmp_path, edit, message):
    (tmp_path / "bad.toml").write_text('name = "b"\n[material]\nk_d = 0.4\nk_s = 0.4\nn = -5\n')
    path = tmp_path / "s.toml"
    path.write_text(GRID.replace(*edit))
    with pytest.raises(SpecrefError, match=message):
        load_sweep(path)


def test_cli_exit_code_two_without_traceback(tmp_path, capsys):
    path = tmp_path / "s.toml"
    path.write_text(GRID.replace("entries = [25, 50]", "entries = []"))
    assert main(["sweep", str(path), "--scheduler", "serial"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert str(path) in err
    assert "Traceback" not in err
    assert main(["sweep", str(tmp_path / "missing.toml")]) == 2
    assert "file not found" in capsys.readouterr().err


def test_local_cluster_sweep_is_identical_to_serial(tmp_path, dask_local_client):
    path = tmp_path / "s.toml"
    path.write_text(GRID.replace('"R1", "R3"', '"R3"'))
    serial = sweep_csv(run_sweep(path, scheduler="serial", progress=False))
    painting = tmp_path / "p.toml"
    painting.write_text(PAINTING_GRID)
    serial_painting = sweep_csv(run_sweep(painting, scheduler="serial", progress=False))
    client = dask_local_client
    distributed = sweep_csv(run_sweep(path, client=client, progress=False))
    distributed_painting = sweep_csv(run_sweep(painting, client=client, progress=False))
    assert distributed == serial
    assert distributed_painting == serial_painting


PAINTING_GRID = """kind = "impastor"
[grid]
seeds = [301]
lights = ["fluorescent", "lamp_panel:4"]
n_lights = [8]
n_samples = [8]
alphas = [0.05, 0.2]
points = 2
painting_size = 16
"""


def test_impastor_sweep_matches_the_direct_computation(tmp_path, monkeypatch):
    # the brute force of a painting, light and α does not depend on N and K: cells of every N
    # share it (reference.tasks.Shared), rendered once per (light, α)
    import validation.studies.impastor_hybrid as hybrid

    path = tmp_path / "p.toml"
    path.write_text(PAINTING_GRID.replace("n_lights = [8]", "n_lights = [8, 4]"))
    calls, brute_force = [], hybrid.specular_brute_force

    def counted(*args):
        calls.append(args[5])  # the supersampling
        return brute_force(*args)

    monkeypatch.setattr(hybrid, "specular_brute_force", counted)
    rows = run_sweep(path, scheduler="serial", progress=False)
    assert len(rows) == 1 * 2 * 2 * 1 * 2
    assert sorted(calls) == [8] * 4 + [16] * 4  # 2 lights × 2 α, the reference and its check
    monkeypatch.setattr(hybrid, "specular_brute_force", brute_force)
    for n_lights in (8, 4):
        case = hybrid.HybridCase(301, "lamp_panel:4", n_lights, 8)
        direct = hybrid.hybrid_case_ratios(case, (0.05, 0.2), 2, 16)
        got = [r for r in rows if (r["lights"], r["n_lights"]) == ("lamp_panel:4", n_lights)]
        assert [r["ratio"] for r in got] == direct["ratio"]
        assert [r["fis"] for r in got] == direct["fis"]


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            ('"lamp_panel:4"', '"lamp"'),
            r"grid.lights\[1\]: unknown light 'lamp'; allowed: fluoresc",
        ),
        (('"lamp_panel:4"', '"env:nosuch.hdr:0"'), r"grid.lights\[1\]: unknown light 'env:nosuch"),
        # a NaN azimuth was refused by the first cell as "plane light: image: must be finite"
        (
            ('"lamp_panel:4"', '"env:studio_small_03_1k.hdr:nan"'),
            r"p.toml: grid.lights\[1\]: .*AZIMUTH_DEG must be a number of degrees in \[-360, 360\]",
        ),
        (("alphas = [0.05, 0.2]", "alphas = [0.05, 2]"), r"grid.alphas: must be numbers in"),
        (("alphas = [0.05, 0.2]", "alphas = []"), r"grid.alphas: must be a non-empty list"),
    ],
)
def test_bad_impastor_sweeps_are_one_line(tmp_path, edit, message):
    path = tmp_path / "p.toml"
    path.write_text(PAINTING_GRID.replace(*edit))
    with pytest.raises(SpecrefError, match=message):
        load_sweep(path)


SHRM_GRID = """kind = "shrm"
[grid]
environments = ["sky.exr"]
materials = [{brdf = "ggx", alpha = 0.3, F_0 = 1.0, rho_d = 0.0}]
tolerances = [0.01]
size = 6
"""


def _sky(tmp_path):
    import numpy as np

    from reference.images.formats import write_exr

    rows = np.linspace(0.0, np.pi, 16, endpoint=False)[:, None, None]
    sky = np.broadcast_to(1.0 + 4.0 * np.cos(rows) ** 2, (16, 32, 3))
    return write_exr(tmp_path / "sky.exr", np.ascontiguousarray(sky))


def test_shrm_sweep_matches_the_direct_computation(tmp_path):
    from reference.scene.loader import loads_scene
    from validation.studies.env_accuracy import render_against_oracle, sphere_scene_toml
    from validation.studies.sweep import SWEEP_KINDS

    sky = _sky(tmp_path)
    path = tmp_path / "s.toml"
    path.write_text(SHRM_GRID)  # the map relative to the sweep file's folder
    (row,) = run_sweep(path, scheduler="serial", progress=False)
    # the brute-force render does not depend on the tolerance: cells of other tolerances share
    # it (reference.tasks.Shared builds a key once; tests/reference/test_tasks.py)
    _, cells = load_sweep(path)
    key = SWEEP_KINDS.lookup("shrm").shared.key
    assert key(cells[0]) == key({**cells[0], "tolerances": 0.5})
    assert key(cells[0]) != key({**cells[0], "size": 7})
    material = 'type = "isotropic_brdf"\nbrdf = "ggx"\nalpha = 0.3\nF_0 = 1.0\nrho_d = 0.0'
    direct = render_against_oracle(
        loads_scene(sphere_scene_toml(sky, material, 6)), {"shrm_tol": 0.01}
    )
    assert (row["mean"], row["max"]) == (direct["mean"], direct["max"])
    # a 16-row map cannot carry 1 % at this size: the row says so, from the promised bound and
    # the spot check against brute force
    assert row["meets_tolerance"] == (
        row["promised_of_peak"] <= 0.01 and row["check_of_peak"] <= 0.01
    )
    assert row["environments"] == str(sky)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (('brdf = "ggx"', 'brdf = "gx"'), r"s.toml: grid.materials.*'gx'"),
        (("alpha = 0.3", "alpha = -1"), r"s.toml: grid.materials\[0\]: alpha: must be >= 0"),
        (('["sky.exr"]', '["none.exr"]'), r"grid.environments\[0\]: none.exr: file not found"),
        # maps the cells' scenes refuse were refused by the first cell, naming "<string>"
        (('["sky.exr"]', '["square.exr"]'), r"s.toml: grid.environments\[0\]: .*must be 2:1"),
        (('["sky.exr"]', '["nan.exr"]'), r"s.toml: grid.environments\[0\]: .*must be finite"),
        (("tolerances = [0.01]", "tolerances = [0]"), r"grid.tolerances: must be numbers in"),
        # NaN has no JSON spelling: it was "malformed TOML" at a line the sweep file lacks
        (("alpha = 0.3", "alpha = nan"), r"s.toml: grid.materials\[0\].alpha: must be finite"),
        (("alpha = 0.3", "alpha = -inf"), r"s.toml: grid.materials\[0\].alpha: must be finite"),
        (("alpha = 0.3", "alpha = 1e308"), r"s.toml: grid.materials\[0\].alpha: must be within"),
        (
            ("materials = [{", "materials = [3, {"),
            r"grid.materials\[0\]: each material is an inline",
        ),
    ],
)
def test_bad_shrm_sweeps_are_one_line(tmp_path, edit, message):
    import numpy as np

    from reference.images.formats import write_exr

    _sky(tmp_path)
    write_exr(tmp_path / "square.exr", np.ones((8, 8, 3)))
    write_exr(tmp_path / "nan.exr", np.where(np.eye(8, 16)[..., None] > 0, np.nan, np.ones(3)))
    path = tmp_path / "s.toml"
    path.write_text(SHRM_GRID.replace(*edit))
    with pytest.raises(SpecrefError, match=message):
        load_sweep(path)

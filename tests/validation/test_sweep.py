"""``specref sweep``: sweep files, their one-line errors, and serial = distributed."""

import pytest

from reference.errors import SpecrefError
from validation.cli import main
from validation.sweep import load_sweep, run_sweep, sweep_csv

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
    from validation.phong import table_error_row, view_state

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
        (('kind = "phong"', 'kind = "fong"'), r"kind: unknown 'fong'; allowed: phong"),
        (("entries = [25, 50]", "entries = []"), r"grid.entries: must be a non-empty list"),
        (("entries = [25, 50]", "entries = [25, 0]"), r"grid.entries: must be an integer"),
        (('views = ["near"]', 'views = ["nearby"]'), r"grid.views: unknown 'nearby'"),
        (("resolution = 16", "resolution = 16\ncolour = 1"), r"grid: unknown keys \['colour'\]"),
        (("resolution = 16", ""), r"grid: missing keys \['resolution'\]"),
        (("[grid]", "[grids]"), r"unknown keys \['grids'\]"),
        (("materials = [", "materials = "), r"malformed TOML"),
    ],
)
def test_bad_sweep_files_are_one_line(tmp_path, edit, message):
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


def test_local_cluster_sweep_is_identical_to_serial(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(GRID.replace('"R1", "R3"', '"R3"'))
    serial = sweep_csv(run_sweep(path, scheduler="serial", progress=False))
    from reference.tasks import dask_client

    with dask_client(n_workers=2) as client:
        distributed = sweep_csv(run_sweep(path, client=client, progress=False))
    assert distributed == serial

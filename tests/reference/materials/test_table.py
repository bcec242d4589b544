import subprocess
import sys
from operator import attrgetter
from pathlib import Path

import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.materials.brdf import BRDF_METHODS
from reference.materials.isotropic import brdf_lafortune, isotropic_directions
from reference.materials.table import (
    BRDFTable,
    brdf_tabulated,
    read_brdf_table,
    tabulate_brdf,
    tabulate_registered_brdf,
    write_brdf_table,
)

Z = np.array([0.0, 0.0, 1.0])
ROOT = Path(__file__).resolve().parents[3]
ANALYTIC = [m for m in BRDF_METHODS.values() if m.isotropic and m.name != "table"]


def _bands(method, params):
    probe = method.reference(Z, Z, Z, **params)
    return params.get("wavelengths_nm", np.arange(probe.shape[-1]) * 10.0 + 400.0)


@pytest.mark.parametrize("method", ANALYTIC, ids=attrgetter("name"))
def test_tabulated_equals_analytic_at_the_grid_nodes(method, rng):
    params = method.example_inputs(rng)
    theta = np.array([0.0, 10.0, 25.0, 40.0, 60.0, 75.0, 89.0])
    phi = np.linspace(0.0, 180.0, 7)
    table = tabulate_brdf(method.reference, params, theta, phi, _bands(method, params))
    ti, to, pd = np.meshgrid(*(np.radians(a) for a in (theta, theta, phi)), indexing="ij")
    wi, wo = isotropic_directions(ti, to, pd)
    expected = method.reference(wi, wo, Z, **params)
    # Source: the analytic model. At a node the interpolation weights are 0 or 1 up to the
    # round-off of recovering the angles from directions (<= 1e-13 rad), times the lobe's slope.
    np.testing.assert_allclose(brdf_tabulated(wi, wo, Z, table), expected, rtol=1e-9, atol=1e-12)
    # The interpolant of a reciprocal table on shared nodes is reciprocal.
    np.testing.assert_allclose(
        brdf_tabulated(wo, wi, Z, table), brdf_tabulated(wi, wo, Z, table), rtol=1e-12
    )


def test_trilinear_interpolation_converges_at_second_order(rng):
    params = {"rho_d": 0.1, "rho_s": 0.5, "C_xy": -1.0, "C_z": 1.0, "n": 4.0}
    ti, to = rng.uniform(5, 70, 400), rng.uniform(5, 70, 400)
    pd = rng.uniform(0, 180, 400)
    wi, wo = isotropic_directions(*(np.radians(a) for a in (ti, to, pd)))
    exact = brdf_lafortune(wi, wo, Z, **params)
    errors = []
    for step in (6.0, 3.0, 1.5):
        table = tabulate_brdf(
            brdf_lafortune,
            params,
            np.arange(0.0, 90.0 + step / 2, step),
            np.arange(0.0, 180.0 + step / 2, step),
            [550.0],
        )
        errors.append(np.abs(brdf_tabulated(wi, wo, Z, table) - exact).max())
    rates = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    # Linear interpolation of a smooth function: error ∝ h² (observed rates 2.15 and 2.19).
    assert np.all(rates > 1.7), rates


def test_file_round_trip_is_exact(tmp_path, rng):
    theta = np.array([0.0, 15.0, 45.0, 80.0])
    table = BRDFTable(
        theta,
        theta,
        np.array([0.0, 60.0, 150.0, 180.0]),
        np.array([450.0, 550.0, 650.0]),
        rng.uniform(0, 3, (4, 4, 4, 3)),
        name="random",
    )
    path = write_brdf_table(tmp_path / "t.txt", table, {"sample": "random numbers"})
    back = read_brdf_table(path)
    for key in ("theta_i_deg", "theta_o_deg", "phi_d_deg", "wavelengths_nm", "values"):
        np.testing.assert_array_equal(getattr(back, key), getattr(table, key))
    assert back.name == "random"
    # The file's φ_s runs from the specular side: the row (0, 15, 0) holds Δφ = 180°.
    rows = [line.split() for line in path.read_text().splitlines() if line[0].isdigit()]
    row = next(r for r in rows if r[:3] == ["0", "15", "0"])
    assert float(row[3]) == table.values[0, 1, 3, 0]
    assert not list(tmp_path.glob(".*.tmp"))


def _write(tmp_path, body, header="theta_i theta_s phi_s 500 600"):
    path = tmp_path / "bad.txt"
    path.write_text("# a comment\n" + header + "\n" + body)
    return path


GOOD_ROWS = ["0 0 0 1 1", "0 0 180 1 1", "0 30 0 1 1", "0 30 180 1 1"]


@pytest.mark.parametrize(
    ("rows", "match"),
    [
        (GOOD_ROWS[:3], r"bad\.txt: missing angles theta_i=0 theta_s=30 phi_s=180"),
        ([*GOOD_ROWS, "0 30 0 2 2"], r"bad\.txt:7: duplicated angles .*first at line 5"),
        (["0 0 0 1 -0.5", *GOOD_ROWS[1:]], r"bad\.txt:3: BRDF at 600 nm: must be >= 0"),
        (["0 0 0 nan 1", *GOOD_ROWS[1:]], r"bad\.txt:3: BRDF at 500 nm: must be finite"),
        ([*GOOD_ROWS[:3], "0 95 180 1 1"], r"bad\.txt:6: theta_s: must be in \[0, 90\]"),
        ([*GOOD_ROWS[:3], "0 30 200 1 1"], r"bad\.txt:6: phi_s: must be in \[0, 180\]"),
        (["-1 0 0 1 1"], r"bad\.txt:3: theta_i: must be in \[0, 90\]"),
        (["0 0 0 1"], r"bad\.txt:3: expected 5 columns"),
        (["0 0 zero 1 1"], r"bad\.txt:3: not a number"),
        ([], r"bad\.txt: no data rows"),
    ],
)
def test_bad_files_name_file_and_line(tmp_path, rows, match):
    path = _write(tmp_path, "\n".join(rows) + "\n")
    with pytest.raises(SpecrefError, match=match):
        read_brdf_table(path)


def test_bad_headers_and_unreadable_files(tmp_path):
    with pytest.raises(SpecrefError, match=r"bad\.txt:2: header: must start with"):
        read_brdf_table(_write(tmp_path, "0 0 0 1 1\n", header="theta phi 500"))
    with pytest.raises(SpecrefError, match=r"bad\.txt:2: header: wavelength columns"):
        read_brdf_table(_write(tmp_path, "0 0 0 1\n", header="theta_i theta_s phi_s red"))
    with pytest.raises(SpecrefError, match="file not found"):
        read_brdf_table(tmp_path / "none.txt")
    with pytest.raises(SpecrefError, match="unreadable BRDF table"):
        read_brdf_table(tmp_path)
    (tmp_path / "binary.txt").write_bytes(b"\xff\xfe\x00")
    with pytest.raises(SpecrefError, match="unreadable BRDF table"):
        read_brdf_table(tmp_path / "binary.txt")


def test_table_constructor_refuses_bad_grids():
    ok = dict(theta_i_deg=[0, 45], theta_o_deg=[0, 45], phi_d_deg=[0, 180], wavelengths_nm=[550])
    with pytest.raises(SpecrefError, match=r"theta_i: angles must be strictly increasing"):
        BRDFTable(**(ok | {"theta_i_deg": [45, 0]}), values=np.ones((2, 2, 2, 1)))
    with pytest.raises(SpecrefError, match=r"phi_d: angles must be in \[0, 180\]"):
        BRDFTable(**(ok | {"phi_d_deg": [0, 270]}), values=np.ones((2, 2, 2, 1)))
    with pytest.raises(SpecrefError, match=r"values: must have shape \(2, 2, 2, 1\)"):
        BRDFTable(**ok, values=np.ones((2, 2, 2)))
    with pytest.raises(SpecrefError, match="values: must be finite"):
        BRDFTable(**ok, values=np.full((2, 2, 2, 1), np.nan))
    with pytest.raises(SpecrefError, match="theta step: must divide 90"):
        tabulate_registered_brdf("ggx", 7.0)
    with pytest.raises(SpecrefError, match="not an isotropic 3-D BRDF"):
        tabulate_registered_brdf("ward_duer")


def _cli(*args):
    return subprocess.run(
        [sys.executable, "-m", "validation.cli", *args], capture_output=True, text=True, cwd=ROOT
    )


def test_cli_tabulate_check_and_bad_input(tmp_path):
    out = tmp_path / "ggx.txt"
    result = _cli(
        "brdf", "tabulate", "ggx", "-o", str(out), "--theta-step", "30", "--phi-step", "90"
    )
    assert result.returncode == 0, result.stderr
    table = read_brdf_table(out)
    assert table.values.shape == (4, 4, 3, 3)
    result = _cli("brdf", "check", str(out))
    assert result.returncode == 0
    assert "4 theta_i x 4 theta_s x 3 phi_s" in result.stdout
    bad = _write(tmp_path, "0 0 0 1 -1\n")
    result = _cli("brdf", "check", str(bad))
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1
    assert "bad.txt:3: BRDF at 600 nm: must be >= 0" in result.stderr
    assert "Traceback" not in result.stderr

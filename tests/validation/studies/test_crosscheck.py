"""Tests of validation.studies.crosscheck, ``specref crosscheck`` and its section (Mitsuba 3)."""

from __future__ import annotations

import json
import sys

import pytest

from reference.errors import SpecrefError
from validation.cli import main
from validation.report.sections.crosscheck import MEAN_REL_Y_TARGET, RMS_Z_FACTOR, SECTION
from validation.studies.crosscheck import QUICK, crosscheck_summary, mitsuba_missing, run_crosscheck

needs_mitsuba = pytest.mark.skipif(
    mitsuba_missing() is not None, reason=str(mitsuba_missing()) + " (pip install '.[mitsuba]')"
)


@needs_mitsuba
@pytest.mark.parametrize("case", ["ColorChecker D65", "ColorChecker A"])
def test_colorchecker_agrees_with_mitsuba(package_data, case):
    # Source: Mitsuba 3 (scalar_spectral), an independent spectral path tracer: with the
    # standard error estimated from QUICK.seeds seeds, z ~ Student's t; the RMS z must be near
    # its expectation and Y within 2 % (the 41-band grid against Mitsuba's continuous one).
    row = crosscheck_summary(run_crosscheck(package_data, QUICK, only=case))[0]
    assert row["values"] == 24 * 3
    assert row["rms_z"] <= RMS_Z_FACTOR * row["expected_rms_z"]
    assert abs(row["mean_rel_Y"]) <= MEAN_REL_Y_TARGET


@needs_mitsuba
@pytest.mark.slow
def test_sphere_under_an_environment_agrees_with_mitsuba(package_data):
    # Source: Mitsuba 3 as above; the map is read as Mitsuba reads it (texel_placement "mitsuba",
    # jakob2019 scaled by 2 max), integrated by brute force on both sides.
    row = crosscheck_summary(run_crosscheck(package_data, QUICK, only="venice"))[0]
    assert row["rms_z"] <= RMS_Z_FACTOR * row["expected_rms_z"]
    assert abs(row["mean_rel_Y"]) <= MEAN_REL_Y_TARGET


@needs_mitsuba
def test_cli_writes_the_summary(package_data, tmp_path, capsys):
    out = tmp_path / "cc.json"
    args = ["crosscheck", "--quick", "--case", "ColorChecker A", "--data", str(package_data)]
    assert main([*args, "--json", str(out)]) == 0
    assert "ColorChecker A" in capsys.readouterr().out
    assert [c["name"] for c in json.loads(out.read_text())["cases"]] == ["ColorChecker A"]


def test_unknown_case_is_refused(package_data, capsys):
    if mitsuba_missing() is None:
        code = main(["crosscheck", "--case", "nothing", "--data", str(package_data)])
        assert code == 2
        assert "no case matches 'nothing'; cases: sphere" in capsys.readouterr().err
    else:
        with pytest.raises(SpecrefError, match="pip install"):
            run_crosscheck(package_data, QUICK, only="nothing")


def test_without_mitsuba_the_section_and_cli_say_how_to_install(monkeypatch, tmp_path, capsys):
    monkeypatch.setitem(sys.modules, "mitsuba", None)  # import mitsuba now raises ImportError
    reason = mitsuba_missing()
    assert "pip install '.[mitsuba]'" in reason
    data = SECTION.compute(None)
    assert data.results == {"available": False, "reason": reason}
    assert "pip install" in SECTION.present(None, data)[0].text
    assert SECTION.checks(data) == []
    assert main(["crosscheck", "--quick"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert "pip install" in err[0]


def test_json_output_into_a_folder_is_refused_before_rendering(tmp_path, capsys):
    code = main(["crosscheck", "--quick", "--json", str(tmp_path)])
    assert code == 2
    err = capsys.readouterr().err
    assert "is a folder" in err or "pip install" in err


def test_the_plastic_check_reads_the_full_reports_figures():
    # the polymer's opaque smooth limit against Mitsuba's plastic: a check in full reports, a
    # pointer to --full in quick ones (its four renders at 16,384 spp take minutes)
    from validation.report.sections.crosscheck import PLASTIC_TARGET, SECTION
    from validation.report.types import SectionData, Table, Text

    case = {"name": "sphere", "rms_z": 1.0, "expected_rms_z": 1.0, "mean_rel_Y": 0.0}
    plastic = {"spp": 16384, "layered": 0.21, "oracle": 0.21, "lambert": 0.24, "seeds": 0.17,
               "lambert_seeds": 0.16, "worst_block": 1.2, "sum_Y_ratio": 0.995}  # fmt: skip
    results = {"available": True, "cases": [case], "plastic": plastic}
    found = [c for c in SECTION.checks(SectionData(results)) if "plastic" in c.name]
    assert [c.passed for c in found] == [True]
    plastic["layered"] = PLASTIC_TARGET + 0.06
    assert [c.passed for c in SECTION.checks(SectionData(results)) if "plastic" in c.name] == [
        False
    ]
    from validation.report.sections.crosscheck import _plastic_blocks

    assert isinstance(_plastic_blocks(plastic)[1], Table)
    quick = _plastic_blocks(None)
    assert isinstance(quick[0], Text)
    assert "--full" in quick[0].text
    results["plastic"] = None
    assert not [c for c in SECTION.checks(SectionData(results)) if "plastic" in c.name]

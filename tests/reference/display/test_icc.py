"""Tests of reference.display.icc: a colprof profile from the .ti3, checked by littlecms."""

from __future__ import annotations

import pytest

from reference.display.calibration import calibrate_display
from reference.display.calibration_files import write_calibration
from reference.display.icc import (
    INSTALL_HINT,
    build_icc_profile,
    check_icc_profile,
    icc_tools_missing,
)
from reference.display.spectral import spectral_display
from reference.errors import SpecrefError

needs_tools = pytest.mark.skipif(
    bool(icc_tools_missing()), reason=f"missing {icc_tools_missing()}; {INSTALL_HINT}"
)


@needs_tools
@pytest.mark.slow
def test_profile_built_and_checked(tmp_path):
    d = spectral_display()
    cal = calibrate_display(d, "D65", "gamma2.2", points=15, instrument="ideal")
    summary = write_calibration(tmp_path / "d65.cal", d, cal)
    icc = build_icc_profile(summary["files"][".ti3"])
    assert icc.read_bytes()[36:40] == b"acsp"  # Source: ICC.1:2010 §7.2.5, the file signature
    check = check_icc_profile(icc, summary["files"][".ti3"])
    # a shaper/matrix profile of a display with channel drift: colprof reports about 1 ΔE
    assert check["mean"] < 1.5
    assert check["max"] < 4.0


def test_missing_ti3():
    with pytest.raises(SpecrefError, match=r"nowhere.ti3: file not found"):
        build_icc_profile("/nowhere.ti3")


def test_missing_tool_message(monkeypatch, tmp_path):
    import shutil

    monkeypatch.setattr(shutil, "which", lambda tool: None)
    path = tmp_path / "x.ti3"
    path.write_text("CTI3\n")
    with pytest.raises(SpecrefError, match="colprof: not found on PATH; install them with: apt"):
        build_icc_profile(path)

"""The "Display calibration" report section: targets, figures and the instrument comparison."""

from validation.report.runner import run_report


def test_report_display_section(tmp_path):
    results = run_report(tmp_path / "r", quick=True, only=["display-calibration"], progress=False)
    section = results["sections"]["display-calibration"]
    # 4 whites x 5 curves x 2 targets, the instrument comparison, 3 compensated observers
    assert len(results["checks"]) == 44
    assert all(c["passed"] for c in results["checks"])
    assert set(section["whites"]) == {"D65", "F2", "A", "D50"}
    instruments = section["instruments"]
    assert instruments["colorimeter"]["bands"]["5-12.5 %"] > 0.004
    assert instruments["spectro"]["bands"]["5-12.5 %"] < 0.002
    screen = section["screen"]
    assert screen["30° to the side, not compensated"]["max_abs_Y_error"] > 0.1
    html = (tmp_path / "r" / "index.html").read_text()
    assert "<h2>Display calibration</h2>" in html
    for name in ("fig6", "fig7"):
        assert (tmp_path / "r" / "images" / f"display-calibration-{name}.png").exists()

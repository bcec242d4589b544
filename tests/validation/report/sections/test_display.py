"""The "Display calibration" report section: targets, figures and the instrument comparison."""

from validation.report.runner import run_report


def test_report_display_section(tmp_path):
    results = run_report(
        tmp_path / "r", effort="quick", only=["display-calibration"], progress=False
    )
    section = results["sections"]["display-calibration"]
    # 4 whites x 5 curves x 2 targets, the instrument comparison, 3 compensated observers (a
    # gray and the painting), the scene on its calibrated display (above 5 % of white and all in
    # gamut); the default instrument on four
    # displays x 2 targets
    assert len(results["checks"]) == 49 + 8
    # every target holds, the laser-like display's luminance too where two channels are at zero
    # (erratum E105: the luminance is held where the white's chromaticity is out of reach)
    failed = [c["name"] for c in results["checks"] if not c["passed"]]
    assert failed == []
    held_out = section["default_instrument"]
    assert {r["role"] for r in held_out.values()} == {"designed on", "held out"}
    assert max(r["max_duv_above_5pct"] for r in held_out.values()) <= 0.001
    assert set(section["whites"]) == {"D65", "F2", "A", "D50"}
    instruments = section["instruments"]
    assert instruments["colorimeter"]["bands"]["5-12.5 %"] > 0.004
    assert instruments["spectro"]["bands"]["5-12.5 %"] < 0.002
    screen = section["screen"]
    assert screen["30° to the side, not compensated"]["max_abs_Y_error"] > 0.1
    # docs/display.md, "ImpastoR's display per pixel": the painting off axis, uncompensated, is
    # visibly wrong; compensated it is not
    painting = section["painting"]
    assert painting["30° to the side, not compensated"]["dE00_mean"] > 2.0
    assert painting["30° to the side, compensated"]["dE00_max"] < 1.0
    # a scene with [display] calibration: every pixel compared; the black frame is out of gamut
    scene = section["scene"]
    assert scene["pixels"] == 90 * 60
    assert 0 < scene["out_of_gamut"] < scene["pixels"] - scene["pixels_above_5pct"]
    html = (tmp_path / "r" / "index.html").read_text()
    assert "<h2>Display calibration</h2>" in html
    for name in ("fig6", "fig7", "scene", "painting"):
        assert (tmp_path / "r" / "images" / f"display-calibration-{name}.png").exists()

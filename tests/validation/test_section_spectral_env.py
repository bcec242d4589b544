"""The "Spectral environments" report section, quick mode, through the runner."""

import pytest

from validation.report.runner import run_report


@pytest.mark.slow
def test_report_spectral_env_section_quick(tmp_path, shared_data, monkeypatch):
    monkeypatch.setenv("SPECREF_SHARED_DATA", str(shared_data))
    results = run_report(tmp_path / "r", quick=True, only=["spectral-env"], progress=False)
    section = results["sections"]["spectral-env"]
    rows = section["regression"]
    assert len(rows) == 2 * (5 + 4)  # every degree of both families, with and without noise
    assert set(section["recovery"]) == {"Mallett 2019", "Otsu 2018", "Smits 1999"}
    assert set(section["losses"]) == {"colorimetric", "spectral"}  # erratum E44
    names = [c["name"] for c in results["checks"] if c["section"] == "spectral-env"]
    assert len(names) == 4
    images = sorted(p.name for p in (tmp_path / "r" / "images").iterdir())
    assert images == [
        "spectral-env-degree.png",
        "spectral-env-panorama.png",
        "spectral-env-picks.png",
    ]

"""The "Spectral environments" report section, quick mode, through the runner."""

import pytest

from validation.report.runner import run_report


@pytest.mark.slow
def test_report_spectral_env_section_quick(tmp_path):
    results = run_report(tmp_path / "r", effort="quick", only=["spectral-env"], progress=False)
    section = results["sections"]["spectral-env"]
    rows = section["regression"]
    # every degree of both families but polynomial 4 and 5 (quick mode), with and without noise
    assert len(rows) == 2 * (3 + 4)
    assert section["left_out"] == [["polynomial", 4], ["polynomial", 5]]
    assert set(section["recovery"]) == {"Mallett 2019", "Otsu 2018", "Smits 1999"}
    # erratum E44: each loss with and without the products; the shipped row is the table's row
    fits = {(f["loss"], f["augmentation"]): f for f in section["losses"]}
    assert set(fits) == {(a, b) for a in ("colorimetric", "spectral") for b in ("products", "none")}
    assert fits["colorimetric", "none"]["augment_weight"] == 0.0
    shipped = next(
        r for r in rows if (r["features"], r["degree"], r["noise"]) == ("root_polynomial", 4, False)
    )
    assert shipped["augment_weight"] == fits["colorimetric", "products"]["augment_weight"] > 0
    names = [c["name"] for c in results["checks"] if c["section"] == "spectral-env"]
    assert len(names) == 4
    images = sorted(p.name for p in (tmp_path / "r" / "images").iterdir())
    assert images == [
        "spectral-env-degree.png",
        "spectral-env-panorama.png",
        "spectral-env-picks.png",
    ]

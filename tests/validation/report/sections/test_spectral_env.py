"""The "Spectral environments" report section: every figure, table and check on tiny settings.

The targets themselves are the report's (``specref report``, root-polynomial 4); the suite checks
the section's machinery here and the regression's figures in tests/validation/studies.
"""

import json

import pytest

from reference.colour.spectral_target import EVALUATION_SETS
from validation.report import ReportContext, to_jsonable
from validation.report.sections.spectral_env import (
    SETTINGS,
    checks,
    headlines,
    present,
    spectral_environments,
)


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    folder = tmp_path_factory.mktemp("spectral-env")
    ctx = ReportContext(folder, quick=True, section="spectral-env")
    data = spectral_environments(ctx, SETTINGS["tiny"])
    return ctx, data, folder


def test_tiny_settings_give_every_table_row_and_fit(tiny):
    _, data, _ = tiny
    section = data.results
    rows = section["regression"]
    # the one degree tiny keeps, with and without noise; the rest named as left out
    assert [(r["features"], r["degree"], r["noise"]) for r in rows] == [
        ("root_polynomial", 1, False),
        ("root_polynomial", 1, True),
    ]
    assert ["root_polynomial", 2] in section["left_out"]
    assert ["polynomial", 1] in section["left_out"]
    assert set(section["recovery"]) == {"Mallett 2019", "Otsu 2018", "Smits 1999"}
    # erratum E44: each loss with and without the products; the shipped row is the table's row
    fits = {(f["loss"], f["augmentation"]): f for f in section["losses"]}
    assert set(fits) == {(a, b) for a in ("colorimetric", "spectral") for b in ("products", "none")}
    assert fits["colorimetric", "none"]["augment_weight"] == 0.0
    shipped = rows[0]
    assert shipped["augment_weight"] == fits["colorimetric", "products"]["augment_weight"] > 0
    # the same fit: the losses table adds the set measured after the choices
    loss_fit = fits["colorimetric", "products"]["held_out"]
    assert {name: loss_fit[name] for name in shipped["held_out"]} == shipped["held_out"]
    json.dumps(to_jsonable(section))


def test_checks_and_headlines_name_the_features_they_gate(tiny):
    _, data, _ = tiny
    found = checks(data)
    # the four targets of the fit, the panorama's projection (erratum E106), then mean and max
    # on every reflectance set, noise-free and noisy, against the camera's floor (erratum E107)
    every = [c for c in found if "camera's" in c.name]
    assert len(every) == 2 * 3 * len(EVALUATION_SETS)
    assert {c.basis for c in every} == {"held out"}
    found = [c for c in found if c not in every]
    assert len(found) == 5
    projection = found.pop()
    assert "negative band values projected" in projection.name
    assert projection.passed
    assert data.results["nonnegative"]["values"] == 29
    assert all("root-polynomial 1, " in c.name for c in found)
    assert all(c.name.endswith(", root-polynomial 1") for c in every)
    cc = data.results["regression"][0]["held_out"]["ColorChecker N Ohta"]
    measured = {c.name.split(" ΔE94")[0]: c.measured for c in found}
    assert measured["D65 mean"] == cc["D65 mean"]
    assert measured["A mean"] == cc["A mean"]
    assert all(c.passed == (c.measured <= float(c.target[3:])) for c in found)
    assert "root-polynomial 1" in headlines(data)[0].text


def test_present_writes_every_image_and_table(tiny):
    ctx, data, folder = tiny
    blocks = present(ctx, data)
    images = sorted(p.name for p in (folder / "images").iterdir())
    assert images == [
        "spectral-env-degree.png",
        "spectral-env-panorama.png",
        "spectral-env-picks.png",
        "spectral-env-upsamplers.png",
    ]
    captions = " ".join(getattr(b, "caption", "") for b in blocks)
    # the upsamplers' chart states its conclusion from the run
    timed = data.results["upsamplers"]["mallett2019"]
    assert timed["seconds"] > 0
    assert timed["A mean"] > 0
    assert f"mallett2019 is the fastest ({timed['seconds']:.2g} s" in captions
    assert "Root-polynomial 1 fitted with each loss" in captions
    assert "root_polynomial 2" in captions  # the left-out rows are named


def test_speed_is_checked_on_the_real_panorama_and_the_worst_case_shown():
    from validation.report import SectionData
    from validation.report.sections.spectral_env import _speed_figures, speed_checks

    def record(role, source, seconds):
        extra = {"role": role, "input": source}
        return {"group": "spectral-env-2k", "stats": {"median": seconds}, "extra_info": extra}

    bench = {"benchmarks": [record("baseline", "panorama", 1.0),
                            record("spectralize", "panorama", 1.6),
                            record("spectralize", "random", 5.0)]}  # fmt: skip
    figures = _speed_figures(ReportContext(out_dir=".", bench=bench))
    speed = figures["speed"]
    assert speed["panorama"]["throughput_ratio"] == pytest.approx(0.625)
    assert speed["random"]["throughput_ratio"] == pytest.approx(0.2)
    found = speed_checks(SectionData(figures))
    assert len(found) == 1
    assert found[0].passed
    assert found[0].basis == "held out"
    assert "venice_sunset_1k" in found[0].name
    bench["benchmarks"][1]["stats"]["median"] = 2.5  # 0.4 of the product: fails
    found = speed_checks(SectionData(_speed_figures(ReportContext(".", bench=bench))))
    assert [c.passed for c in found] == [False]
    assert _speed_figures(ReportContext(out_dir=".")) == {}

"""Report section "SHRMs on full-resolution maps" and validation.studies.shrm_fullres."""

import copy

import numpy as np
import pytest

from reference.images.formats import write_exr
from validation.report import ReportContext
from validation.report.sections.shrm_fullres import SECTION, checks, fullres_study, present
from validation.studies.shrm_fullres import sphere_points


@pytest.fixture(scope="module")
def sun_map(tmp_path_factory):
    # a dim sky and a compact sun: what the SH series alone cannot carry
    sky = np.full((24, 48, 3), 0.5)
    sky[:, :, 2] += np.linspace(0.0, 0.5, 24)[:, None]
    sky[5:7, 30:32] = 800.0
    return write_exr(tmp_path_factory.mktemp("env") / "sun.exr", sky)


@pytest.fixture(scope="module")
def study(sun_map, tmp_path_factory):
    # The section's study on the sun map: GGX alpha 0.2 and the tabulated GGX alpha 0.3
    folder = tmp_path_factory.mktemp("fullres")
    settings = {
        "rows": None,
        "pixels": 8,
        "brdfs": (("ggx", 0.2), ("table", 0.3)),
        "label": "test",
        "targets": True,
    }
    ctx = ReportContext(folder, section=SECTION.name)
    return ctx, fullres_study(ctx, settings, [sun_map]), folder


def test_the_split_beats_the_shrm_alone_under_a_sun(study):
    row = study[1].results["cases"][0]
    assert (row["brdf"], row["alpha"]) == ("ggx", 0.2)
    assert row["residual_texels"] > 0
    # the sun goes to the residual and is summed exactly: far closer than the SHRM alone
    assert row["split"]["pct_of_peak"] < 0.2 * row["shrm"]["pct_of_peak"]
    assert row["split"]["pct_of_peak"] <= 1.0
    # what the split promised holds (an upper bound of its error)
    assert row["split"]["pct_of_peak"] <= row["promised_pct_of_peak"]
    assert row["pixels"] == len(sphere_points(8)[0])
    # the Monte Carlo estimator of equal time: at least one sample, an error that is measured
    assert row["mc"]["samples"] >= 1
    assert np.isfinite(row["mc"]["pct_of_peak"])


def test_checks_follow_the_targets_and_quick_mode_has_none(study):
    ctx, data, folder = study
    data = copy.deepcopy(data)
    found = checks(data)
    assert len(found) == 2
    for check, row in zip(found, data.results["cases"], strict=True):
        split = row["split"]
        assert check.passed == (split["pct_of_peak"] <= 1.0 and split["mean_rel_pct"] <= 1.0)
    # a case that misses shows as a failed check
    data.results["cases"][0]["split"]["pct_of_peak"] = 2.0
    assert not checks(data)[0].passed
    data.results["targets"] = False
    assert checks(data) == []
    blocks = present(ctx, data)
    assert (folder / "images" / "shrm-fullres-time-error.png").exists()
    assert len(blocks[-1].rows) == 2


def test_a_tabulated_brdf_goes_through_the_same_path(study):
    # erratum E94: a BRDF table (GGX alpha 0.3 tabulated) renders through the split like an
    # analytic BRDF, against a brute force over the same table
    table = study[1].results["cases"][1]
    assert table["brdf"] == "table"
    assert table["residual_texels"] > 0
    assert table["split"]["pct_of_peak"] <= 1.0
    assert table["split"]["pct_of_peak"] < 0.5 * table["shrm"]["pct_of_peak"]

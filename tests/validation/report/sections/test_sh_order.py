import copy

import pytest

from validation.report import ReportContext
from validation.report.sections.sh_order import SETTINGS, checks, present, sh_order_study


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    ctx = ReportContext(tmp_path_factory.mktemp("sh-order"))
    return ctx, sh_order_study(ctx, SETTINGS["tiny"])


def test_sh_order_study_tiny_meets_the_bound_and_draws(tiny):
    # Source: brute force (validation.studies.env_accuracy.render_against_oracle), on the worst
    # cases.
    ctx, data = tiny
    assert all(c.passed for c in checks(data))
    for per in data.results["by_order"].values():
        curve = per["lambert"]
        # SH alone: the error falls with the order
        assert curve["max"][-1] < curve["max"][0]
    images = [b.path for b in present(ctx, data) if hasattr(b, "path")]
    assert len(images) == 1
    assert (ctx.out_dir / images[0]).is_file()


def test_sh_order_checks_fail_when_the_bound_is_broken(tiny):
    broken = copy.deepcopy(tiny[1])
    broken.results["renders"]["sun disc"]["new"]["max"] = 0.5
    assert sum(not c.passed for c in checks(broken)) == 1

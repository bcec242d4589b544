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
    assert len(images) == 2
    assert all((ctx.out_dir / image).is_file() for image in images)


def test_speed_against_accuracy_times_each_setting_and_names_the_faster_path(tiny):
    # Property: a tighter tolerance never picks a lower order; every render and the oracle
    # are timed; the caption's crossover is the oracle's time scaled to the frequency path's.
    from validation.report.sections.sh_order import _speed_caption

    speed = tiny[1].results["speed"]
    for found in speed.values():
        orders = [p["order"] for p in found["points"]]  # accuracies from loose to tight
        assert orders == sorted(orders)
        assert found["oracle_s"] > 0
        assert all(p["seconds"] > 0 for p in found["points"])
    made = {
        "m": {
            "oracle_s": 2.0,
            "covered": 100,
            "points": [{"accuracy": 0.005, "seconds": 0.5, "mean": 1e-3, "max": 2e-3}],
        }
    }
    assert "from about 25 pixels" in _speed_caption(made)


def test_sh_order_checks_fail_when_the_bound_is_broken(tiny):
    broken = copy.deepcopy(tiny[1])
    broken.results["renders"]["sun disc"]["new"]["max"] = 0.5
    assert sum(not c.passed for c in checks(broken)) == 1

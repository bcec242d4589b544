import numpy as np

from validation.report.sections.shrm_speed import bench_ratio, speed_checks


def _record(name, median, **info):
    return {"name": f"bench_shrm.py::{name}", "stats": {"median": median}, "extra_info": info}


IN_RUN = {
    "creation": {"ratio": 500.0, "frequency_error": 0.001, "angular_error": 0.002, "brdf": "ggx"},
    "extraction": {"ratio": 900.0},
    "cache": {"ratio": 300.0},
}


def test_speed_checks_prefer_bench_and_show_failures():
    # A bench run that misses every target: the in-run figures (which pass) must not hide it.
    groups = {
        "shrm-create-ggx": [
            _record("angular", 1.0, role="baseline", texels=10, error=0.002),
            _record("frequency", 0.5, texels=400, error=0.001),  # 80× per texel
        ],
        "shrm-create-ward_isotropic": [
            _record("angular", 1.0, role="baseline", texels=10, error=0.001),
            _record("frequency", 0.1, texels=400, error=0.05),  # 400× but a larger error
        ],
        "shrm-extract": [_record("create", 1.0, role="baseline"), _record("extract", 0.04)],
        "shrm-cache": [_record("rebuild", 1.0, role="baseline"), _record("hit", 0.1)],
    }
    checks = speed_checks(groups, IN_RUN)
    assert [c.name.split(":")[0] for c in checks] == ["make bench"] * 4
    assert [c.passed for c in checks] == [False, False, False, False]
    assert [round(c.measured, 6) for c in checks] == [80.0, 400.0, 25.0, 10.0]
    passing = {**groups, "shrm-cache": [_record("r", 1.0, role="baseline"), _record("h", 0.01)]}
    assert speed_checks(passing, IN_RUN)[-1].passed


def test_speed_checks_fall_back_to_the_in_run_measurement():
    checks = speed_checks({}, IN_RUN, "quick: ")
    assert all(c.name.startswith("quick: in-run:") for c in checks)
    assert [c.passed for c in checks] == [True, True, True]
    slow = {**IN_RUN, "extraction": {"ratio": 12.0}}
    assert speed_checks({}, slow)[1].passed is False
    assert speed_checks({}, slow)[1].measured == 12.0


def test_bench_ratio_is_per_texel():
    base = _record("a", 2.0, role="baseline", texels=4)
    assert bench_ratio([base, _record("f", 0.5, texels=100)])[0] == 100.0
    assert np.isnan(bench_ratio([base])[0])  # no method to compare

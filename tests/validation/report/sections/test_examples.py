"""Report section "Examples": the renders, their times and the ColorChecker check."""

from __future__ import annotations

import copy

import pytest

import validation.report.sections.examples as examples
from validation.report import Image, ReportContext, Table


@pytest.fixture(scope="module")
def small_renders():
    # every example at 48 pixels wide (supersample 1), the environment scene at 12
    return examples.example_renders(width=48, env_width=12)


def test_example_renders_present_and_check(tmp_path, small_renders):
    ctx = ReportContext(out_dir=tmp_path, quick=True, section="examples")
    blocks = examples.present(ctx, small_renders)
    images = [b for b in blocks if isinstance(b, Image)]
    assert {i.path for i in images} == {
        "images/examples-colorchecker-d65-a.png",
        "images/examples-phong-sphere.png",
        "images/examples-env-lambert-sphere.png",
    }
    for image in images:
        assert (tmp_path / image.path).is_file()
    assert any(isinstance(b, Table) for b in blocks)
    scenes = small_renders.results["scenes"]
    assert set(scenes) == {
        "colorchecker-d65.toml",
        "colorchecker-a.toml",
        "phong-sphere.toml",
        "env-lambert-sphere.toml",
    }
    assert all(scenes[name]["width"] == 48 for name, _ in examples.SCENES)
    assert all(c.passed for c in examples.checks(small_renders))
    for entry in (scenes[name] for name, _ in examples.SCENES):
        assert entry["seconds"]["total"] > 0
    # The rendered charts reproduce colour-science's E308 XYZ (Y = 1 scale), as the band weights
    # of erratum E7 do: |ΔXYZ| <= 1e-9 on the Y = 100 scale.
    for name in ("colorchecker-d65.toml", "colorchecker-a.toml"):
        assert scenes[name]["accuracy"]["max_abs_dXYZ"] * 100 <= 1e-9


def test_example_checks_are_a_pure_function_of_the_data(small_renders):
    before = examples.checks(small_renders)
    assert [c.passed for c in before] == [True, True, True]
    changed = copy.deepcopy(small_renders)
    changed.results["scenes"]["colorchecker-a.toml"]["accuracy"]["max_abs_dXYZ"] = 1e-6
    env = changed.results["scenes"][examples.ENV_SCENE]
    env["max_error_of_peak"] = 2 * env["tolerance"]
    after = examples.checks(changed)
    assert [c.passed for c in after] == [True, False, False]
    assert after[1].measured == pytest.approx(1e-4)  # Y = 100 scale
    assert after[2].measured == 2 * env["tolerance"]
    assert [c.name for c in examples.checks(small_renders)] == [c.name for c in before]


def test_environment_example_frequency_path_agrees_with_the_oracle():
    # Source: the brute-force oracle (every environment pixel integrated per shading point).
    from validation.report.sections.examples import (
        ENV_SCENE,
        EXAMPLES_DIR,
        environment_oracle_error,
    )

    env = environment_oracle_error(EXAMPLES_DIR / ENV_SCENE, 12)
    fast, _ = env["renders"]
    assert fast.gbuffer.mask.any()
    assert env["max_error_of_peak"] <= env["tolerance"]
    assert env["max_error_of_peak"] > 0  # two different computations, not one twice


def _startup_record(cache, process_s, **seconds):
    return {"stats": {"min": process_s}, "extra_info": {"cache": cache, **seconds}}


def test_startup_figures_take_numbas_own_start_up_out_of_the_warm_ratio():
    group = [
        _startup_record(
            "cold",
            9.0,
            import_s=1.5,
            first_s=6.0,
            second_s=0.25,
            numba_s=0.4,
            first_after_numba_s=5.0,
        ),
        _startup_record(
            "warm",
            2.5,
            import_s=1.5,
            first_s=0.6,
            second_s=0.25,
            numba_s=0.2,
            first_after_numba_s=0.3,
        ),
    ]
    found = examples.startup_figures({"startup-render": group})
    assert found["warm_ratio"] == pytest.approx(2.4)
    assert found["warm_ratio_past_numba"] == pytest.approx(1.2)
    table = examples._startup_blocks(found)[0]
    assert table.rows[1] == ["warm", 2.5, 1.5, 0.6, 0.25, 0.2, 0.3]
    assert "2.40× the second, 1.20× without numba's start-up" in table.caption
    # a benchmark file written before numba's start-up was measured still reads
    for record in group:
        del record["extra_info"]["numba_s"], record["extra_info"]["first_after_numba_s"]
    older = examples.startup_figures({"startup-render": group})
    assert "warm_ratio_past_numba" not in older
    assert "without numba" not in examples._startup_blocks(older)[0].caption

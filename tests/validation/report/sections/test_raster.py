import json

import numpy as np

from validation.report.runner import run_report


def test_report_rasterizer_section_quick(tmp_path):
    # A pytest-benchmark file with one group: the section shows each record's ratio to the
    # group's baseline. Source: the records below (0.2 s / 0.1 s = 2).
    bench = {
        "benchmarks": [
            {
                "group": "raster-gbuffer-512",
                "name": "test_baseline_analytic_sphere",
                "extra_info": {"role": "baseline", "triangles": 0},
                "stats": {"median": 0.1},
            },
            {
                "group": "raster-gbuffer-512",
                "name": "test_mesh_gbuffer_100k[edge_function]",
                "extra_info": {"role": "mesh", "triangles": 100488},
                "stats": {"median": 0.2},
            },
        ]
    }
    bench_json = tmp_path / "bench.json"
    bench_json.write_text(json.dumps(bench))
    results = run_report(
        tmp_path / "r", effort="quick", only=["rasterizer"], bench_json=bench_json, progress=False
    )
    section = results["sections"]["rasterizer"]
    assert [c["passed"] for c in results["checks"]] == [True] * len(results["checks"])
    assert len(results["checks"]) == 8
    mesh = section["benchmarks"]["raster-gbuffer-512 test_mesh_gbuffer_100k[edge_function]"]
    assert mesh["ratio_to_baseline"] == 2.0
    assert section["tessellation"]["32x64"]["triangles"] == 3968
    assert section["closed_mesh"]["front_back_mismatch"] == 0
    html = (tmp_path / "r" / "index.html").read_text()
    assert "<h2>Rasterizer</h2>" in html
    assert "Benchmarks (make bench)" in html
    for name in ("convergence", "normals"):
        assert (tmp_path / "r" / "images" / f"rasterizer-{name}.png").stat().st_size > 1000


def test_rasterizer_checks_are_a_pure_function_of_the_data():
    import copy

    from validation.report.sections.raster import checks, rasterizer_figures

    data = rasterizer_figures(size=32, levels=(4, 8), normals_size=(16, 8))
    before = checks(data)
    assert [c.passed for c in before] == [True] * len(before)
    assert [c.name for c in checks(data)] == [c.name for c in before]  # same data, same checks
    # a modified figure flips exactly its own check, and shows the modified value
    changed = copy.deepcopy(data)
    e = changed.results["tessellation"]["8x16"]
    e["max"] = 2 * e["bound"]
    changed.results["closed_mesh"]["front_back_mismatch"] = 3
    twin = next(iter(changed.results["twin"].values()))
    twin["max_abs_difference"] = 1e-6
    after = checks(changed)
    flipped = [c.name for c, d in zip(before, after, strict=True) if c.passed != d.passed]
    assert flipped == [
        "normal error, 224 triangles",
        "pixel centres with front ≠ back coverage (cracks)",
        before[-len(changed.results["twin"])].name,
    ]
    assert after[1].measured == np.degrees(2 * e["bound"])
    assert after[4].measured == 3

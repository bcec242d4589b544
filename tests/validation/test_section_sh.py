import json

import pytest

from validation.report.runner import run_report


def _record(group, name, role, median, **extra):
    return {
        "group": group,
        "name": name,
        "extra_info": {"role": role, **extra},
        "stats": {"median": median},
    }


@pytest.mark.slow
def test_report_sh_section_quick(tmp_path):
    # A pytest-benchmark file with every sh-* group; expected ratios and shares follow from the
    # records below (e.g. brute force 10 s / frequency 5 ms = 2000×; cube map (1.5e8 B / 0.06 s) /
    # (1.7e8 B / 0.024 s) ≈ 0.353).
    bench = {
        "benchmarks": [
            _record("sh-project-L100", "ducc0", "baseline", 0.0024, order=100),
            _record("sh-project-L100", "numpy", "numpy", 0.0072, order=100),
            _record("sh-project-41band", "ducc0-41", "baseline", 0.18),
            _record("sh-project-order", "numpy-25", "numpy", 0.002, order=25),
            _record("sh-project-order", "ducc0-25", "ducc0", 0.0019, order=25),
            _record("sh-prefilter-cube64", "brute", "baseline", 10.0),
            _record("sh-prefilter-cube64", "f-ducc0", "frequency-ducc0", 0.005),
            _record("sh-prefilter-cube64", "f-numpy", "frequency-numpy", 2.0),
            _record("sh-bandwidth", "copy", "baseline", 0.024, bytes=1.7e8),
            _record("sh-bandwidth", "cube", "latlong_to_cubemap", 0.06, bytes=1.5e8),
            _record("sh-bandwidth", "xyz", "spectra_to_XYZ", 0.5, bytes=9e7),
        ]
    }
    bench_json = tmp_path / "bench.json"
    bench_json.write_text(json.dumps(bench))
    results = run_report(
        tmp_path / "r", quick=True, only=["sh"], bench_json=bench_json, progress=False
    )
    checks = {c["name"]: c for c in results["checks"]}
    speedup = checks["prefilter speed-up over brute force"]
    assert speedup["measured"] == 2000.0
    assert speedup["passed"]
    assert not checks["prefilter 64²×6, frequency-numpy"]["passed"]  # 2 s > 1.5 s
    cube = checks["latlong_to_cubemap bandwidth / np.copyto"]
    assert abs(cube["measured"] - (1.5e8 / 0.06) / (1.7e8 / 0.024)) < 1e-12
    assert not checks["spectra_to_XYZ bandwidth / np.copyto"]["passed"]
    # The accuracy checks computed in the section itself hold.
    for name in (
        "basis vs mpmath, l <= 101",
        "basis vs mpmath, l <= 1000",
        "prefilter phong:32 vs brute force, L=100",
        "gaussian σ=π/L, L=100: negative pixels",
    ):
        assert checks[name]["passed"], name
    section = results["sections"]["sh"]
    assert section["ringing"]["none"]["100"]["negative_share"] > 0.01
    html = (tmp_path / "r" / "index.html").read_text()
    assert "<h2>Spherical harmonics</h2>" in html
    for name in (
        "basis-error",
        "ringing",
        "prefilter",
        "phong-lambda",
        "projection-time",
        "irradiance",
    ):
        assert (tmp_path / "r" / "images" / f"sh-{name}.png").is_file()

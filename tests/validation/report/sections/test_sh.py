import copy
import json

import pytest

from reference.errors import SpecrefError
from shrm.lobes import PREFILTER_KERNELS
from shrm.windows import WINDOWS
from validation.report import ReportContext, SectionData
from validation.report.runner import run_report
from validation.report.sections.sh import (
    SETTINGS,
    checks,
    kernel_specs,
    sh_accuracy_and_speed,
)
from validation.report.sections.sh_speed import benchmark_checks, benchmark_figures


def _record(group, name, role, median, **extra):
    return {
        "group": group,
        "name": name,
        "extra_info": {"role": role, **extra},
        "stats": {"median": median},
    }


#: A pytest-benchmark file with every sh-* group; expected ratios and shares follow from the
#: records (e.g. brute force 10 s / frequency 5 ms = 2000×; cube map (1.5e8 B / 0.06 s) /
#: (1.7e8 B / 0.024 s) ≈ 0.353).
BENCH = {
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


def test_benchmark_checks_read_the_sh_groups():
    groups = ReportContext(".", bench=BENCH).bench_groups("sh-")
    results, records = benchmark_figures(groups)
    found = {c.name: c for c in benchmark_checks(records)}
    speedup = found["prefilter speed-up over brute force"]
    assert speedup.measured == 2000.0
    assert speedup.passed
    assert not found["prefilter 64²×6, frequency-numpy"].passed  # 2 s > 1.5 s
    cube = found["latlong_to_cubemap bandwidth / np.copyto"]
    assert abs(cube.measured - (1.5e8 / 0.06) / (1.7e8 / 0.024)) < 1e-12
    assert results["sh-bandwidth cube"]["share_of_copy_bandwidth"] == cube.measured
    assert not found["spectra_to_XYZ bandwidth / np.copyto"].passed
    assert results["sh-project-L100 numpy"]["ratio_to_baseline"] == pytest.approx(3.0)
    # every record of the groups is in the results, and no benchmarks give no speed checks
    assert len(results) == len(BENCH["benchmarks"])
    assert benchmark_checks(benchmark_figures({})[1]) == []


def test_kernel_specs_cover_every_registered_kernel():
    specs = kernel_specs({"phong": (32,), "table": ("lobe.csv",)})
    assert {s.partition(":")[0] for s in specs} == set(PREFILTER_KERNELS.names())
    with pytest.raises(SpecrefError, match="kernel 'phong' takes S"):
        kernel_specs({"table": ("lobe.csv",)})


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    # Every figure of the section on small inputs (venice_sunset subsampled; basis to l = 10)
    folder = tmp_path_factory.mktemp("sh-tiny")
    ctx = ReportContext(folder, bench=BENCH)
    return sh_accuracy_and_speed(ctx, SETTINGS["tiny"])


def test_compute_on_tiny_settings(tiny):
    results = tiny.results
    assert list(results["ringing"]) == WINDOWS.names()
    assert list(tiny.arrays["windows"]) == WINDOWS.names()
    # the plain reconstruction rings (negative pixels); the Gaussian window does not
    assert results["ringing"]["none"][100]["negative_share"] > 0.01
    assert results["ringing"]["gaussian"][100]["negative_share"] == 0.0
    prefilter = list(results["prefilter"])
    assert prefilter == ["lambert", "phong:32", "phong:256", "table:sh-gaussian-lobe.csv"]
    assert all(c.passed for c in checks(tiny)[:7])
    json.dumps(results)


def test_checks_are_a_pure_function_of_the_data(tiny):
    before = checks(tiny)
    assert [c.name for c in before][:4] == [
        "basis vs mpmath, l <= 101",
        "basis vs mpmath, l <= 1000",
        "basis vs mpmath, all l (scaled)",
        "gaussian σ=π/L, L=100: negative pixels",
    ]
    assert checks(tiny) == before  # same data, same checks
    changed = SectionData(copy.deepcopy(tiny.results), tiny.arrays)
    changed.results["prefilter"]["phong:32"]["relative_error"] = 1e-3
    changed.results["ringing"]["gaussian"][100]["negative_share"] = 0.2
    after = {c.name: c for c in checks(changed)}
    assert not after["prefilter phong:32 vs brute force, L=100"].passed
    assert after["prefilter phong:32 vs brute force, L=100"].measured == 1e-3
    assert not after["gaussian σ=π/L, L=100: negative pixels"].passed
    assert [c for c in checks(changed) if c.name.startswith("basis")] == before[:3]


@pytest.mark.slow
def test_report_sh_section_quick(tmp_path):
    # The section through the report (quick): its checks and images.
    bench_json = tmp_path / "bench.json"
    bench_json.write_text(json.dumps(BENCH))
    results = run_report(
        tmp_path / "r", effort="quick", only=["sh"], bench_json=bench_json, progress=False
    )
    checks_by_name = {c["name"]: c for c in results["checks"]}
    assert checks_by_name["prefilter speed-up over brute force"]["measured"] == 2000.0
    # The accuracy checks computed in the section itself hold.
    for name in (
        "basis vs mpmath, l <= 101",
        "basis vs mpmath, l <= 1000",
        "prefilter phong:32 vs brute force, L=100",
        "gaussian σ=π/L, L=100: negative pixels",
    ):
        assert checks_by_name[name]["passed"], name
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
        *(f"window-{w}" for w in WINDOWS.names()),
    ):
        assert (tmp_path / "r" / "images" / f"sh-{name}.png").is_file()

"""SH engine speed against same-run baselines (read by the report's "Spherical harmonics").

BLAS runs single-threaded (``threadpoolctl.threadpool_limits(1)``): multithreaded BLAS collapses on
the shared 2-core machines (docs/dependencies.md). Groups:

- ``sh-project-L100``: one 512×1024 channel of ``venice_sunset_1k.hdr`` to L = 100 by each path of
  ``shrm.transform.SH_BACKENDS`` (ducc0 is the baseline); targets ducc0 ≤ 5 ms, NumPy ≤ 25 ms.
- ``sh-project-41band``: the same map upsampled to 41 bands, ducc0 (target ≤ 0.25 s).
- ``sh-project-order``: projection time against order, per path (the report's chart).
- ``sh-prefilter-cube64``: a 64²×6 cube map of the map prefiltered with ``phong:32`` at L = 100 from
  a 256×512 channel: frequency path with ducc0 and with NumPy, and the numba brute force (the
  baseline) on the same input and texels; targets ≤ 20 ms, ≤ 1.5 s, ≥ 500× faster than brute force.
- ``sh-bandwidth``: ``np.copyto`` of a 41-band float32 1024×512 map (the baseline),
  ``latlong_to_cubemap`` to 6×256² into a reused buffer (target ≥ 25 % of the copy bandwidth) and
  ``reference.colour.colorimetry.spectra_to_XYZ`` of the map in float32 (band weights,
  ``(..., 41) @ (41, 3)`` on its two row blocks; target ≥ 50 %); ``latlong_to_cubemap`` runs on
  one thread. ``extra_info``
  records the bytes each moves (input + output).
"""

import numpy as np
import pytest
from threadpoolctl import threadpool_limits

from reference.colour.colorimetry import band_weights, spectra_to_XYZ
from reference.colour.spectra import GRID_41
from reference.colour.upsampling import RGB_to_spectra
from reference.geometry.cubemap import cubemap_texel_directions, latlong_to_cubemap
from reference.images.formats import read_hdr
from shrm.lobes import parse_kernel
from shrm.prefilter import prefilter_bruteforce, prefilter_coefficients
from shrm.sh import sh_evaluate
from shrm.transform import SH_BACKENDS, project_latlong


@pytest.fixture(scope="module", autouse=True)
def _one_blas_thread():
    with threadpool_limits(1):
        yield


@pytest.fixture(scope="module")
def venice(package_data):
    return read_hdr(package_data / "environments" / "venice_sunset_1k.hdr")


@pytest.fixture(scope="module")
def venice_41(venice):
    return RGB_to_spectra(venice, GRID_41)


def _info(benchmark, role, **extra):
    benchmark.extra_info.update({"role": role, **extra})


@pytest.mark.parametrize("backend", SH_BACKENDS.names())
@pytest.mark.benchmark(group="sh-project-L100")
def test_project_one_channel_L100(benchmark, venice, backend):
    channel = np.ascontiguousarray(venice[..., :1])
    project_latlong(channel, 100, backend=backend)  # warm-up: JIT and the ring-table cache
    _info(benchmark, "baseline" if backend == "ducc0" else backend, order=100, channels=1)
    benchmark(project_latlong, channel, 100, backend=backend)


@pytest.mark.benchmark(group="sh-project-41band")
def test_project_41_bands_ducc0(benchmark, venice_41):
    _info(benchmark, "baseline", order=100, channels=41)
    coeffs = benchmark(project_latlong, venice_41, 100, backend="ducc0")
    assert coeffs.shape == (41, 101**2)


@pytest.mark.parametrize("order", [25, 50, 100, 200])
@pytest.mark.parametrize("backend", SH_BACKENDS.names())
@pytest.mark.benchmark(group="sh-project-order")
def test_project_against_order(benchmark, venice, backend, order):
    channel = np.ascontiguousarray(venice[..., :1])
    project_latlong(channel, order, backend=backend)
    _info(benchmark, backend, order=order, channels=1)
    benchmark(project_latlong, channel, order, backend=backend)


def _frequency_prefilter(image, kernel, directions, backend):
    coeffs = project_latlong(image, 100, backend=backend)
    return sh_evaluate(
        prefilter_coefficients(coeffs, kernel.Lambda(100)), directions, backend=backend
    )


@pytest.fixture(scope="module")
def prefilter_input(venice):
    image = np.ascontiguousarray(venice[::2, ::2, :1])
    kernel = parse_kernel("phong:32")
    kernel.Lambda(100)
    return image, kernel, cubemap_texel_directions(64)


@pytest.mark.parametrize("backend", ["ducc0", "numpy"])
@pytest.mark.benchmark(group="sh-prefilter-cube64")
def test_prefilter_frequency(benchmark, prefilter_input, backend):
    image, kernel, d = prefilter_input
    _frequency_prefilter(image, kernel, d[:1, :1, :1], backend)
    _info(benchmark, f"frequency-{backend}", order=100, kernel=kernel.name)
    benchmark(_frequency_prefilter, image, kernel, d, backend)


@pytest.mark.benchmark(group="sh-prefilter-cube64")
def test_prefilter_bruteforce(benchmark, prefilter_input):
    image, kernel, d = prefilter_input
    prefilter_bruteforce(image[:2, :4], kernel, d[:1, :1, :1])  # JIT warm-up
    _info(benchmark, "baseline", kernel=kernel.name)
    benchmark.pedantic(prefilter_bruteforce, (image, kernel, d), rounds=1, iterations=1)


@pytest.fixture(scope="module")
def spectral_float32(venice_41):
    return np.ascontiguousarray(venice_41, dtype=np.float32)


@pytest.mark.benchmark(group="sh-bandwidth")
def test_bandwidth_copyto(benchmark, spectral_float32):
    target = np.empty_like(spectral_float32)
    _info(benchmark, "baseline", bytes=2 * spectral_float32.nbytes)
    benchmark(np.copyto, target, spectral_float32)


@pytest.mark.benchmark(group="sh-bandwidth")
def test_bandwidth_latlong_to_cubemap(benchmark, spectral_float32):
    out = latlong_to_cubemap(spectral_float32, 256)
    _info(benchmark, "latlong_to_cubemap", bytes=spectral_float32.nbytes + out.nbytes)
    benchmark(latlong_to_cubemap, spectral_float32, 256, out=out)


@pytest.mark.benchmark(group="sh-bandwidth")
def test_bandwidth_spectra_to_XYZ(benchmark, spectral_float32):
    W = band_weights(GRID_41, None).astype(np.float32)
    XYZ = np.empty((*spectral_float32.shape[:2], 3), dtype=np.float32)
    _info(benchmark, "spectra_to_XYZ", bytes=spectral_float32.nbytes + XYZ.nbytes)
    benchmark(spectra_to_XYZ, spectral_float32, W, out=XYZ)

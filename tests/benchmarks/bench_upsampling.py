"""RGB → spectrum upsampling of a real 1k environment map, every method against Mallett's, same run.

Group ``upsampling-1k`` (target: a 1k map upsamples in seconds): ``studio_small_03_1k.hdr``
(1024×512, shipped in ``data:environments``) to 41 bands by each ``UPSAMPLING_METHODS`` entry
through :func:`reference.colour.upsampling.RGB_to_radiance_spectra`, what rendering a scene runs.
The baseline is ``mallett2019`` (one matrix product). ``jakob2019`` looks its coefficients up in the
cached 64³ table (generated before timing, as a user's second render would find it); the per-colour
fit it replaced took 0.5-2 s per distinct colour, thousands of them on this map.
"""

from operator import attrgetter

import numpy as np
import pytest

from reference.colour.jakob2019 import DEFAULT_TABLE_SIZE, table_Jakob2019
from reference.colour.spectra import GRID_41
from reference.colour.upsampling import (
    DEFAULT_UPSAMPLING,
    UPSAMPLING_METHODS,
    RGB_to_radiance_spectra,
)
from reference.images.formats import read_hdr


@pytest.fixture(scope="module")
def panorama(package_data):
    table_Jakob2019(DEFAULT_TABLE_SIZE)  # the cached table, as after a first run
    return read_hdr(package_data / "environments" / "studio_small_03_1k.hdr")


@pytest.mark.benchmark(group="upsampling-1k")
@pytest.mark.parametrize("method", UPSAMPLING_METHODS.values(), ids=attrgetter("name"))
def test_upsample_1k_map(benchmark, panorama, method):
    role = "baseline" if method.name == DEFAULT_UPSAMPLING else method.name
    benchmark.extra_info.update({"role": role, "pixels": panorama.shape[0] * panorama.shape[1]})
    out = benchmark.pedantic(
        RGB_to_radiance_spectra, (panorama, GRID_41, method.name), rounds=2, iterations=1
    )
    assert out.shape == (*panorama.shape[:2], 41)
    assert np.isfinite(out).all()

"""Spectralizing speed: a 2048×1024 panorama to 41 bands, against a bare matrix product, same run.

Group ``spectral-env-2k`` (target: spectralize throughput >= 50 % of the baseline; erratum E45):

- ``baseline``: ``np.matmul`` of the panorama's precomputed feature matrix (shipped model:
  root-polynomial degree 4, 22 features, float64) by the coefficients, into a preallocated output;
- ``spectralize``: :func:`reference.colour.spectral_regression.spectralize_blocks` (RGB checks,
  feature
  expansion and product in float32, erratum E45) by its default blocks (2^17 pixels, 64 rows) into
  a preallocated float32 panorama.
"""

import numpy as np
import pytest

from reference.colour.spectral_regression import features_RGB, spectralize_blocks
from reference.colour.upsampling import default_regression

HEIGHT, WIDTH = 1024, 2048


@pytest.fixture(scope="module")
def panorama():
    return np.random.default_rng(15).uniform(0.0, 4.0, (HEIGHT, WIDTH, 3))


def _info(benchmark, role):
    benchmark.extra_info.update({"role": role, "pixels": HEIGHT * WIDTH, "bands": 41})


@pytest.mark.benchmark(group="spectral-env-2k")
def test_baseline_matmul(benchmark, panorama):
    model = default_regression()
    X = features_RGB(panorama.reshape(-1, 3), model.kind, model.degree)
    out = np.empty((X.shape[0], model.n_bands))
    _info(benchmark, "baseline")
    benchmark(np.matmul, X, model.coefficients, out=out)


@pytest.mark.benchmark(group="spectral-env-2k")
def test_spectralize_blocks(benchmark, panorama):
    model = default_regression()
    out = np.empty((HEIGHT, WIDTH, model.n_bands), np.float32)

    def run():
        for row0, block in spectralize_blocks(model, panorama):
            out[row0 : row0 + block.shape[0]] = block

    _info(benchmark, "spectralize")
    benchmark(run)
    assert np.isfinite(out).all()

"""Spectralizing speed: a 2048×1024 panorama to 41 bands, against a bare matrix product, same run.

Group ``spectral-env-2k`` (target: spectralize throughput >= 50 % of the baseline on a real
panorama; erratum E45):

- ``baseline``: ``np.matmul`` of the panorama's precomputed feature matrix (shipped model:
  root-polynomial degree 4, 22 features, float64) by the coefficients, into a preallocated output
  (its time does not depend on the pixels);
- ``spectralize``: :func:`reference.colour.spectral_regression.spectralize_blocks` (RGB checks,
  feature expansion and product in float32, erratum E45; spectra with a negative value projected,
  erratum E106) by its default blocks (2^17 pixels, 64 rows) into a preallocated float32 panorama,
  on two inputs: ``panorama``, the shipped ``venice_sunset_1k.hdr`` with each pixel repeated 2 × 2
  (a real capture's colours, where few spectra need the projection), and ``random``, RGB drawn
  uniformly in [0, 4] (saturated colours no capture gives, where most do: the worst case).
"""

import numpy as np
import pytest

from reference.colour.spectral_regression import features_RGB, spectralize_blocks
from reference.colour.upsampling import default_regression
from reference.data import data_path
from reference.images.formats import read_image

HEIGHT, WIDTH = 1024, 2048


@pytest.fixture(scope="module")
def inputs():
    venice = read_image(data_path("environments/venice_sunset_1k.hdr"))[..., :3]
    panorama = np.repeat(np.repeat(venice.astype(np.float64), 2, axis=0), 2, axis=1)
    assert panorama.shape == (HEIGHT, WIDTH, 3)
    random = np.random.default_rng(15).uniform(0.0, 4.0, (HEIGHT, WIDTH, 3))
    return {"panorama": panorama, "random": random}


def _info(benchmark, role, source):
    benchmark.extra_info.update(
        {"role": role, "input": source, "pixels": HEIGHT * WIDTH, "bands": 41}
    )


@pytest.mark.benchmark(group="spectral-env-2k")
def test_baseline_matmul(benchmark, inputs):
    model = default_regression()
    X = features_RGB(inputs["panorama"].reshape(-1, 3), model.kind, model.degree)
    out = np.empty((X.shape[0], model.n_bands))
    _info(benchmark, "baseline", "panorama")
    benchmark(np.matmul, X, model.coefficients, out=out)


@pytest.mark.benchmark(group="spectral-env-2k")
@pytest.mark.parametrize("source", ["panorama", "random"])
def test_spectralize_blocks(benchmark, inputs, source):
    model = default_regression()
    out = np.empty((HEIGHT, WIDTH, model.n_bands), np.float32)

    def run():
        for row0, block in spectralize_blocks(model, inputs[source]):
            out[row0 : row0 + block.shape[0]] = block

    _info(benchmark, "spectralize", source)
    benchmark(run)
    assert np.isfinite(out).all()
    assert (out >= 0).all()

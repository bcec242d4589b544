import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.geometry.cubemap import cubemap_texel_directions
from reference.images.formats import read_hdr
from shrm.lobes import kernel_table, parse_kernel
from shrm.prefilter import (
    BRUTEFORCE_METHODS,
    prefilter_bruteforce,
    prefilter_coefficients,
    prefilter_environment,
)
from shrm.sh import sh_evaluate
from shrm.transform import project_latlong


@pytest.mark.slow
@pytest.mark.parametrize(
    ("kernel", "bound"), [("phong:32", 1e-11), ("phong:256", 2e-9), ("lambert", 5e-4)]
)
def test_frequency_matches_bruteforce_at_L100(kernel, bound, package_data):
    # Same Fejér-1 weights: the two differ only by the kernel's truncation at L = 100 (addition
    # theorem). Bounds are the targets of docs/sh.md, on venice_sunset (downsampled 4×, one
    # channel).
    image = read_hdr(package_data / "environments" / "venice_sunset_1k.hdr")[::4, ::4, :1].copy()
    d = cubemap_texel_directions(8)
    coeffs = prefilter_coefficients(project_latlong(image, 100), parse_kernel(kernel).Lambda(100))
    frequency = sh_evaluate(coeffs, d, backend="numba")
    brute = prefilter_bruteforce(image, kernel, d)
    assert np.abs(frequency - brute).max() / np.abs(brute).max() <= bound


@pytest.mark.parametrize("method", BRUTEFORCE_METHODS.values(), ids=lambda m: m.name)
def test_bruteforce_twins(method, rng, tmp_path):
    if method.example_inputs is None:
        path = tmp_path / "lobe.csv"
        path.write_text("angle_rad,value\n0,1\n0.5,0.6\n1.2,0.0\n")
        d = rng.normal(size=(5, 3))
        args = (
            rng.random((8, 16, 2)),
            kernel_table(path),
            d / np.linalg.norm(d, axis=-1, keepdims=True),
        )
    else:
        args = method.example_inputs(rng)
    np.testing.assert_allclose(
        prefilter_bruteforce(*args, backend="numba"),
        prefilter_bruteforce(*args, backend="numpy"),
        rtol=1e-12,
        atol=1e-14,
    )


def test_prefilter_environment_white_furnace():
    # Uniform radiance 1: irradiance π everywhere, Phong map 1 (Λ_0 = 1).
    image = np.ones((32, 64, 2))
    assert np.allclose(prefilter_environment(image, "lambert", size=4).values, np.pi, atol=1e-12)
    assert np.allclose(prefilter_environment(image, "phong:10", size=4).values, 1.0, atol=1e-12)
    with pytest.raises(SpecrefError, match=">= 0"):
        prefilter_environment(-image, "lambert")

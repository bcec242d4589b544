"""The polymer oracle's smooth opaque limit against an independent renderer (Mitsuba 3 ``plastic``).

Optional: Mitsuba is not a dependency of specref. Install it with ``.venv/bin/pip install mitsuba``.
"""

import numpy as np
import pytest

from shrm.polymer.layered import layered_maps, layered_terms
from shrm.polymer.oracle import polymer_oracle

mi = pytest.importorskip(
    "mitsuba", reason="optional independent renderer: install with .venv/bin/pip install mitsuba"
)

SIZE, RHO, N_INDEX, SUB = 16, 0.5, 1.54, 6


def _mitsuba_sphere(seed: int) -> np.ndarray:
    """Y of an orthographic unit sphere, Mitsuba 3 plastic (nonlinear), constant sky, over sky Y."""
    mi.set_variant("scalar_spectral")
    camera = mi.ScalarTransform4f().look_at(origin=[0, 0, 5], target=[0, 0, 0], up=[0, 1, 0])
    scene = mi.load_dict(
        {
            "type": "scene",
            "integrator": {"type": "path", "max_depth": 3},
            "sensor": {
                "type": "orthographic",
                "to_world": camera,
                "film": {
                    "type": "hdrfilm",
                    "width": SIZE,
                    "height": SIZE,
                    "rfilter": {"type": "box"},
                    "pixel_format": "xyz",
                },
                "sampler": {"type": "independent", "sample_count": 1024},
            },
            "emitter": {"type": "constant", "radiance": {"type": "spectrum", "value": 1.0}},
            "sphere": {
                "type": "sphere",
                "radius": 1.0,
                "bsdf": {
                    "type": "plastic",
                    "int_ior": N_INDEX,
                    "ext_ior": 1.0,
                    "nonlinear": True,
                    "diffuse_reflectance": {"type": "spectrum", "value": RHO},
                },
            },
        }
    )
    image = np.array(mi.render(scene, seed=seed))
    return image[..., 1] / image[0, 0, 1]  # the corner pixel sees the sky only


@pytest.fixture(scope="module")
def renders():
    return _mitsuba_sphere(1), _mitsuba_sphere(2)


def _oracle_sphere(model: str = "oracle") -> np.ndarray:
    """The oracle (or the layered model) on the same sphere, box-filtered from SUB x SUB samples
    per pixel (sky = 1)."""
    x = (np.arange(SIZE * SUB) + 0.5) / (SIZE * SUB) * 2 - 1
    X, Y = np.meshgrid(x, -x)
    inside = X**2 + Y**2 < 1
    N = np.stack([X[inside], Y[inside], np.sqrt(1 - X[inside] ** 2 - Y[inside] ** 2)], -1)
    V = np.tile([0.0, 0.0, 1.0], (N.shape[0], 1))
    # an opaque KM body with R_inf = RHO: K/S = (1 - R)^2 / (2R)
    S = 1e3
    K = S * (1 - RHO) ** 2 / (2 * RHO)
    sky = np.ones((64, 128, 1))
    if model == "oracle":
        result = polymer_oracle(N, V, sky, [K], [S], 100.0, N_INDEX, gloss=1.0).result
    else:
        result = layered_terms(N, V, layered_maps(sky, N_INDEX, 1.0), [K], [S], 100.0)["result"]
    full = np.ones(X.shape)
    full[inside] = result[:, 0]
    return full.reshape(SIZE, SUB, SIZE, SUB).mean(axis=(1, 3))


@pytest.mark.slow
@pytest.mark.parametrize("model", ["oracle", "layered"])
def test_smooth_opaque_limit_matches_mitsuba_plastic(model, renders):
    # Source: Mitsuba 3 (independent renderer), path tracing, 1024 spp, two seeds. The noise sigma
    # per pixel comes from the two renders' difference; every pixel agrees within 5 sigma of the
    # mean image (observed ~3.5 sigma max, mean difference ~7e-4).
    # The layered model from prefiltered maps (shrm.polymer.layered) is held to the same bound.
    first, second = renders
    sigma = np.std(first - second) / np.sqrt(2)
    mean_render = 0.5 * (first + second)
    difference = mean_render - _oracle_sphere(model)
    assert np.abs(difference).max() <= 5 * sigma / np.sqrt(2)
    assert abs(difference.mean()) <= 5 * sigma / np.sqrt(2 * difference.size)


@pytest.mark.slow
def test_the_layered_model_under_a_real_map_is_mitsuba_plastic_to_its_noise():
    # Source: Mitsuba 3 (independent renderer), smooth plastic (nonlinear) on the conformance
    # suite's studio sphere (its exported scene, the map's conventions solved there), two seeds,
    # against specref's layered model in its opaque smooth limit on the same scene's G-buffer and
    # map (studio_small_03: small bright lamps, the hard case), the map read constant over each
    # texel as the scene defines it (validation.studies.polymer_mitsuba). At 1024 spp the model
    # is within Mitsuba's noise (its two seeds 0.69 ΔE00 apart), as it is with a bilinear look-up
    # of the map itself: this test cannot see a lamp's reflection moved by a look-up. The 0.3
    # target at 16,384 spp is the report's (section "Cross-check against Mitsuba 3", --full).
    from validation.studies.polymer_mitsuba import plastic_against_mitsuba

    found = plastic_against_mitsuba(1024, oracle=False, control=False)
    assert found["layered"] <= 1.5 * found["seeds"] + 0.1, found
    assert abs(found["sum_Y_ratio"] - 1.0) < 0.04, found  # ΣY: 3 % at 1024 spp (lamps' noise)

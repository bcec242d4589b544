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


def _blocks(X, size=4):
    h, w = X.shape[0] // size, X.shape[1] // size
    return X[: h * size, : w * size].reshape(h, size, w, size, -1).mean(axis=(1, 3))


@pytest.mark.slow
def test_the_layered_model_under_a_real_map_is_mitsuba_plastic_to_its_noise(tmp_path):
    # Source: Mitsuba 3 (independent renderer), smooth plastic (nonlinear) on the conformance
    # suite's studio sphere (its exported scene, the map's conventions solved there), two seeds.
    # specref's layered model in its opaque smooth limit on the same scene's G-buffer and map
    # (studio_small_03: small bright lamps, the hard case). Measured (4 × 4-pixel blocks, L*a*b*
    # against a white Lambertian facing the camera): at 1024 spp the model is 0.65 ΔE00 from
    # Mitsuba where Mitsuba's two seeds are 0.69 apart; at 2048 spp 0.55 against 0.41 (the
    # oracle 0.52): the gap is Mitsuba's noise. ΣY within 1.7 %. At 16,384 spp (by hand, 53 s)
    # the seeds are 0.17 apart and the model is 0.36 from their mean, ΣY within 0.2 %: about 0.33
    # once the mean's own noise is taken out in quadrature, against the 0.3 a real-time model
    # should reach in this limit.
    import re

    import phong_table  # noqa: F401  (registers the scene shaders the loader needs)
    import shrm  # noqa: F401
    from reference.colour.colorimetry import XYZ_to_Lab, band_weights, delta_E_00
    from reference.geometry.envmap import latlong_pixel_directions, latlong_pixel_solid_angles
    from reference.images.formats import read_exr
    from reference.scene.loader import load_scene
    from reference.scene.render import scene_gbuffer
    from reference.scene.shading import ShadingContext
    from shrm.environment import cached_spectral_radiance
    from validation.conformance.export import export_scenes
    from validation.conformance.mitsuba import render_mitsuba
    from validation.conformance.scenes import scene_path

    scene = load_scene(scene_path("lambert-env-studio"))
    g, S = scene_gbuffer(scene), scene.render.supersample
    env = cached_spectral_radiance(scene.lights[0], ShadingContext(scene.grid))
    bands = env.shape[-1]
    K = 1e3 * (1 - RHO) ** 2 / (2 * RHO)  # opaque KM body with R_inf = RHO
    maps = layered_maps(env, N_INDEX, 1.0)
    spectra = layered_terms(
        g.normal[g.mask], g.view[g.mask], maps, np.full(bands, K), np.full(bands, 1e3), 100.0
    )["result"]
    W = band_weights(scene.grid, None, scene.weights_method, scene.observer)
    full = np.zeros((*g.mask.shape, 3))
    full[g.mask] = spectra @ W
    H, Wd = full.shape[0] // S, full.shape[1] // S
    ours = full.reshape(H, S, Wd, S, 3).mean(axis=(1, 3))
    covered = g.mask.reshape(H, S, Wd, S).all(axis=(1, 3))

    export_scenes(tmp_path, "mitsuba", spp=1024)
    xml = (tmp_path / "lambert-env-studio.xml").read_text()
    plastic = (
        f'<bsdf type="plastic"><float name="int_ior" value="{N_INDEX}"/>'
        f'<boolean name="nonlinear" value="true"/>'
        f'<spectrum name="diffuse_reflectance" value="{RHO}"/></bsdf>'
    )
    (tmp_path / "p.xml").write_text(
        re.sub(r'<bsdf type="diffuse">.*?</bsdf>', plastic, xml, flags=re.S)
    )
    first, second = (
        read_exr(render_mitsuba(tmp_path / "p.xml", tmp_path / f"{s}.exr", seed=s))[0][..., :3]
        for s in (1, 2)
    )
    Hm, Wm = env.shape[:2]
    cos = latlong_pixel_directions(Hm, Wm)[..., 2]
    omega = latlong_pixel_solid_angles(Hm, Wm)
    white = (np.einsum("hw,hwb->b", np.maximum(cos, 0.0) * omega, env) / np.pi) @ W
    inside = _blocks(covered[..., None].astype(float))[..., 0] == 1.0

    def block_dE(a, b):
        lab = [XYZ_to_Lab(_blocks(np.asarray(x, float))[inside], white) for x in (a, b)]
        return float(delta_E_00(*lab).mean())

    noise = block_dE(second, first)
    assert block_dE(ours, first) <= 1.5 * noise + 0.1, (block_dE(ours, first), noise)
    ratio = ours[covered][:, 1].sum() / np.asarray(first, float)[covered][:, 1].sum()
    assert abs(ratio - 1.0) < 0.03, ratio

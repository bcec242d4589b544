"""The layered polymer model in its opaque smooth limit against Mitsuba 3's ``plastic``.

:func:`plastic_against_mitsuba` renders the conformance suite's studio sphere
(``lambert-env-studio``: a 48² sphere under ``studio_small_03``, small bright lamps) with its
material swapped for a smooth, opaque polymer: in specref by the layered model
(:mod:`shrm.polymer.layered`) and by the oracle (:func:`shrm.polymer.oracle.polymer_oracle`), in
Mitsuba 3 as ``plastic`` (``nonlinear``, Weidlich & Wilkie 2007, the limit both specref models
reach), at two seeds. The exported scene carries the map's conventions, which the suite solved on
its Lambertian spheres (``validation.conformance.export.texels_for_mitsuba``); specref reads the
map with each texel repeated 8 × 8 (:data:`MIRROR_REPEAT`): the scene's map is constant over each
texel and the model's mirror look-up is bilinear (docs/herbert-polymer.md). The same scene
with its own grey Lambertian material, rendered by both, is the control: the pipeline's floor.

Differences are mean ΔE00 over 4 × 4-pixel blocks inside the sphere, L*a*b* against a white
Lambertian facing the camera under the same map.
"""

from __future__ import annotations

import re
import tempfile
import time
from pathlib import Path

import numpy as np

__all__ = [
    "MIRROR_REPEAT",
    "PLASTIC_INDEX",
    "PLASTIC_RHO",
    "block_delta_E",
    "plastic_against_mitsuba",
]

#: The polymer's refractive index and its Kubelka–Munk body's reflectance R_∞.
PLASTIC_INDEX, PLASTIC_RHO = 1.54, 0.5
#: Each texel repeated this many × this many times for the models' bilinear mirror look-up, so
#: that it reads the map as constant over each texel but for a border of 1/16 texel.
MIRROR_REPEAT = 8
#: The conformance scene the study swaps the material of.
SCENE = "lambert-env-studio"
BLOCK = 4


def _blocks(X: np.ndarray, size: int = BLOCK) -> np.ndarray:
    h, w = X.shape[0] // size, X.shape[1] // size
    return X[: h * size, : w * size].reshape(h, size, w, size, -1).mean(axis=(1, 3))


def block_delta_E(a, b, covered, white) -> np.ndarray:
    """ΔE00 per 4 × 4-pixel block wholly inside ``covered``, L*a*b* against ``white`` (XYZ).

    Examples
    --------
    >>> a = np.ones((8, 8, 3)); b = a.copy(); b[:4, :4] *= 1.1
    >>> block_delta_E(a, b, np.ones((8, 8), bool), np.ones(3)).round(2).tolist()
    [2.11, 0.0, 0.0, 0.0]
    """
    from reference.colour.colorimetry import XYZ_to_Lab, delta_E_00

    inside = _blocks(np.asarray(covered, float)[..., None])[..., 0] == 1.0
    lab = [XYZ_to_Lab(_blocks(np.asarray(x, float))[inside], white) for x in (a, b)]
    return delta_E_00(*lab)


def _specref_sphere(scene, model: str) -> tuple:
    """The layered model's or the oracle's XYZ per pixel, the covered pixels and the white."""
    from reference.colour.colorimetry import band_weights
    from reference.geometry.envmap import latlong_pixel_directions, latlong_pixel_solid_angles
    from reference.scene.render import scene_gbuffer
    from reference.scene.shading import ShadingContext
    from shrm.environment import cached_spectral_radiance
    from shrm.polymer.layered import layered_maps, layered_terms
    from shrm.polymer.oracle import polymer_oracle

    g, S = scene_gbuffer(scene), scene.render.supersample
    env = cached_spectral_radiance(scene.lights[0], ShadingContext(scene.grid))
    repeated = np.repeat(np.repeat(env, MIRROR_REPEAT, axis=0), MIRROR_REPEAT, axis=1)
    bands = env.shape[-1]
    # an opaque Kubelka–Munk body with R_∞ = ρ: K/S = (1 − ρ)² / (2ρ)
    S_km = np.full(bands, 1e3)
    K_km = S_km * (1 - PLASTIC_RHO) ** 2 / (2 * PLASTIC_RHO)
    N, V = g.normal[g.mask], g.view[g.mask]
    if model == "layered":
        maps = layered_maps(repeated, PLASTIC_INDEX, 1.0)
        spectra = layered_terms(N, V, maps, K_km, S_km, 100.0)["result"]
    else:
        spectra = polymer_oracle(N, V, repeated, K_km, S_km, 100.0, PLASTIC_INDEX, gloss=1.0).result
    W = band_weights(scene.grid, None, scene.weights_method, scene.observer)
    full = np.zeros((*g.mask.shape, 3))
    full[g.mask] = spectra @ W
    H, Wd = full.shape[0] // S, full.shape[1] // S
    XYZ = full.reshape(H, S, Wd, S, 3).mean(axis=(1, 3))
    covered = g.mask.reshape(H, S, Wd, S).all(axis=(1, 3))
    cos = latlong_pixel_directions(*env.shape[:2])[..., 2]
    omega = latlong_pixel_solid_angles(*env.shape[:2])
    white = (np.einsum("hw,hwb->b", np.maximum(cos, 0.0) * omega, env) / np.pi) @ W
    return XYZ, covered, white


def _mitsuba_pair(folder: Path, xml_text: str, name: str, spp: int) -> list:
    """Mitsuba 3's XYZ image of a scene file at seeds 1 and 2."""
    from reference.images.formats import read_exr
    from validation.conformance.mitsuba import render_mitsuba

    (folder / f"{name}.xml").write_text(xml_text)
    return [
        read_exr(render_mitsuba(folder / f"{name}.xml", folder / f"{name}-{seed}.exr", seed, spp))[
            0
        ][..., :3].astype(np.float64)
        for seed in (1, 2)
    ]


def plastic_against_mitsuba(
    spp: int = 16384, progress=None, oracle: bool = True, control: bool = True
) -> dict:
    """The layered model, the oracle and a Lambertian control against Mitsuba 3 on one sphere.

    Parameters
    ----------
    spp : int
        Mitsuba's samples per pixel per seed (16,384: about a minute a render on two cores).
    progress : callable, optional
        ``progress(text)`` before each Mitsuba render.
    oracle, control : bool
        Also the oracle (about 20 s), and the Lambertian control (two more renders); their
        entries are None otherwise.

    Returns
    -------
    dict
        ``spp``; mean block ΔE00 from the mean of Mitsuba's two seeds: ``layered``, ``oracle``,
        ``lambert`` (the control: specref's render of the Lambertian scene against Mitsuba's);
        ``seeds`` and ``lambert_seeds`` (Mitsuba's two seeds against each other);
        ``worst_block`` (the layered model's); ``sum_Y_ratio`` (the layered model's ΣY over
        Mitsuba's mean's, covered pixels); ``mitsuba_seconds``.

    Examples
    --------
    >>> from validation.studies.crosscheck import mitsuba_missing
    >>> if mitsuba_missing() is None:  # Mitsuba 3 is optional
    ...     found = plastic_against_mitsuba(16, oracle=False, control=False)
    ...     print(found["spp"], found["oracle"], found["layered"] > 0)
    ... else:
    ...     print(16, None, True)
    16 None True
    """
    import phong_table  # noqa: F401  (registers the scene shaders the loader needs)
    import shrm  # noqa: F401
    from reference.scene.loader import load_scene
    from reference.scene.render import render_scene
    from validation.conformance.export import export_scenes
    from validation.conformance.scenes import scene_path

    scene = load_scene(scene_path(SCENE))
    layered, covered, white = _specref_sphere(scene, "layered")
    oracle = _specref_sphere(scene, "oracle")[0] if oracle else None
    lambert = render_scene(scene).XYZ if control else None
    plastic = (
        f'<bsdf type="plastic"><float name="int_ior" value="{PLASTIC_INDEX}"/>'
        f'<boolean name="nonlinear" value="true"/>'
        f'<spectrum name="diffuse_reflectance" value="{PLASTIC_RHO}"/></bsdf>'
    )
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        export_scenes(folder, "mitsuba", spp=spp)
        xml = (folder / f"{SCENE}.xml").read_text()
        pairs = {}
        scenes = [("plastic", re.sub(r'<bsdf type="diffuse">.*?</bsdf>', plastic, xml, flags=re.S))]
        for name, text in scenes + ([("lambert", xml)] if control else []):
            if progress is not None:
                progress(f"Mitsuba 3: {name} sphere, 2 seeds × {spp} spp")
            pairs[name] = _mitsuba_pair(folder, text, name, spp)
    seconds = time.perf_counter() - start
    mean = {k: 0.5 * (a + b) for k, (a, b) in pairs.items()}

    def dE(a, b) -> float | None:
        return None if a is None else float(block_delta_E(a, b, covered, white).mean())

    worst = block_delta_E(layered, mean["plastic"], covered, white)
    return {
        "spp": int(spp),
        "layered": float(worst.mean()),
        "oracle": dE(oracle, mean["plastic"]),
        "lambert": dE(lambert, mean.get("lambert")),
        "seeds": dE(*pairs["plastic"]),
        "lambert_seeds": dE(*pairs["lambert"]) if control else None,
        "worst_block": float(worst.max()),
        "sum_Y_ratio": float(layered[covered][:, 1].sum() / mean["plastic"][covered][:, 1].sum()),
        "mitsuba_seconds": seconds,
    }

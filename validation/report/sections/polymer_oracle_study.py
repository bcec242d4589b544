"""The hybrid polymer model of Eq. (1), Herbert et al. against the layered oracle (report).

Eq. (1), Herbert et al.: the hybrid's sum, measured against ``shrm.polymer.oracle``.

For the section "Herbert hybrid model" (``validation.report.sections.polymer``): on an orthographic
sphere under the section's synthetic spectral environment, the hybrid (``shrm.polymer.hybrid``) and
the brute-force layered model (``shrm.polymer.oracle``) shade the same chip; ΔE00 between them per
pixel, swept over gloss, thickness and TiO2 load one at a time around a base chip, for every M_s of
``MIRROR_FACTORS``; and time per frame of both (the hybrid from maps built beforehand, the oracle at
several sample counts) for a speed–accuracy chart.

The two models share the chip (the KM constituents), the index and the gloss; the hybrid's Phong
exponent is ``gloss_phong_exponent(gloss)`` and its gloss factor the gloss itself (erratum E65).
Colour: CIE 1931 XYZ of the radiance spectra (equal-energy band weights), L*a*b* relative to the
radiance of a white Lambertian surface facing the camera under the same environment.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from reference.colour.colorimetry import XYZ_to_Lab, band_weights, delta_E_00, spectra_to_XYZ
from reference.colour.spectra import DEFAULT_GRID
from reference.geometry.envmap import latlong_pixel_directions, latlong_pixel_solid_angles
from shrm.polymer.characterization import characterize_model
from shrm.polymer.hybrid import MIRROR_FACTORS, PolymerMaps, polymer_look, polymer_terms
from shrm.polymer.kubelka_munk import km_R_infinity, polymer_constituents, polymer_K_S
from shrm.polymer.layered import (
    layered_maps,
    layered_pixel_parts,
    layered_shade_parts,
    layered_terms,
)
from shrm.polymer.oracle import (
    gloss_alpha,
    gloss_phong_exponent,
    interface_coupling,
    oracle_diffuse,
    polymer_oracle,
    smooth_plastic_albedo,
)
from shrm.prefilter import prefilter_environment

#: The base chip of the sweeps (each sweep varies one of these).
BASE = {"gloss": 0.8, "thickness_mm": 1.524, "tio2_pct": 0.2}
#: Above this mean ΔE00 the report says the heuristic fails (about two just-noticeable differences).
FAIL_DELTA_E = 2.0


@dataclass(frozen=True)
class OracleStudy:
    """Sizes of the comparison.

    Parameters
    ----------
    size : int
        Sphere image size, pixels.
    env_height : int
        Height of the synthetic environment.
    gloss, thickness_mm, tio2_pct : tuple of float
        Sweep values.
    samples : tuple of int
        Fixed sample counts of the oracle for the speed–accuracy chart.
    tol : float
        Convergence target of the reference oracle (``polymer_oracle(tol=...)``).
    """

    size: int
    env_height: int
    gloss: tuple
    thickness_mm: tuple
    tio2_pct: tuple
    samples: tuple
    tol: float


SETTINGS = {
    "tiny": OracleStudy(10, 16, (1.0, 0.6), (0.762, 3.048), (0.0, 1.0), (4, 16), 0.02),
    "quick": OracleStudy(
        48,
        32,
        (1.0, 0.8, 0.6, 0.4),
        (0.381, 0.762, 1.524, 3.048, 4.572),
        (0.0, 0.05, 0.2, 0.5, 1.0, 2.0),
        (4, 16, 64, 256),
        0.01,
    ),
    "full": OracleStudy(
        64,
        32,
        (1.0, 0.95, 0.9, 0.8, 0.7, 0.6, 0.5, 0.4),
        (0.381, 0.762, 1.143, 1.524, 2.286, 3.048, 4.572),
        (0.0, 0.02, 0.05, 0.1, 0.2, 0.35, 0.5, 1.0, 2.0),
        (4, 16, 64, 256, 1024),
        0.005,
    ),
}


def orthographic_sphere(size: int):
    """Mask, normals and views of an orthographic unit sphere seen along −z.

    Returns
    -------
    mask : ndarray of bool, shape (size, size)
        The pixels whose centres fall on the sphere.
    normals, views : ndarray, shape (P, 3)
        Unit normals at those pixels (row-major) and the direction towards the camera, +z.

    Examples
    --------
    >>> mask, N, V = orthographic_sphere(4)
    >>> int(mask.sum()), N.shape, bool(np.allclose(np.linalg.norm(N, axis=1), 1.0)), V[0].tolist()
    (12, (12, 3), True, [0.0, 0.0, 1.0])
    """
    x = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    X, Y = np.meshgrid(x, -x)
    mask = X**2 + Y**2 < 1.0
    N = np.stack([X[mask], Y[mask], np.sqrt(1.0 - X[mask] ** 2 - Y[mask] ** 2)], axis=-1)
    return mask, N, np.tile([0.0, 0.0, 1.0], (N.shape[0], 1))


class Colour:
    """L*a*b* of radiance spectra relative to a white Lambertian surface facing the camera.

    Examples
    --------
    >>> colour = Colour(np.ones((8, 16, 41)))
    >>> colour.lab(np.ones((1, 41)) / 1.0).round(3)
    array([[100.,   0.,   0.]])
    """

    def __init__(self, env: np.ndarray):
        H, W = env.shape[:2]
        cos = latlong_pixel_directions(H, W)[..., 2]
        omega = latlong_pixel_solid_angles(H, W)
        white = np.einsum("hw,hwb->b", np.maximum(cos, 0.0) * omega, env) / np.pi
        self.W = band_weights(DEFAULT_GRID, None)
        self.white = spectra_to_XYZ(white, self.W)

    def lab(self, spectra) -> np.ndarray:
        """L*a*b*, shape (..., 3)."""
        return XYZ_to_Lab(spectra_to_XYZ(spectra, self.W), self.white)

    def delta_E(self, a, b) -> np.ndarray:
        """ΔE00 between two radiance spectra arrays, shape (...,)."""
        return delta_E_00(self.lab(a), self.lab(b))


def hybrid_maps(env, gloss_values, size: int = 32) -> tuple[dict, float]:
    """The hybrid's maps per gloss (the Lambert map once, a Phong map per exponent), and seconds.

    Examples
    --------
    >>> maps, seconds = hybrid_maps(np.ones((8, 16, 2)), (1.0, 0.6), size=4)
    >>> sorted(maps), round(maps[0.6].phong_exponent, 6)
    ([0.6, 1.0], 48.0)
    """
    t0 = time.perf_counter()
    E = prefilter_environment(env, "lambert", tol=1e-2, size=size, where="polymer study").values
    out = {}
    for g in gloss_values:
        s = gloss_phong_exponent(g)
        E_s = prefilter_environment(env, f"phong:{s:g}", tol=1e-2, size=size, where="polymer study")
        out[g] = PolymerMaps(E, E_s.values, env, s)
    return out, time.perf_counter() - t0


def chip_oracle(N, V, env, chip: dict, settings: OracleStudy, **kwargs):
    """The layered oracle (``shrm.polymer.oracle.polymer_oracle``) for one chip.

    The chip's K and S from its TiO2 load (``shrm.polymer.kubelka_munk``) with its ``tint`` (a
    spot colour's name) as a dye (erratum E115), its thickness, index (the constituents' when the
    chip has none) and gloss; the study's tolerance, seed 0;
    ``kwargs`` override the oracle's keywords.

    Examples
    --------
    >>> _, N, V = orthographic_sphere(4)
    >>> run = chip_oracle(N[:2], V[:2], np.ones((8, 16, 41)), {**BASE, "gloss": 1.0},
    ...                   SETTINGS["tiny"])
    >>> run.result.shape, bool((run.result > 0).all())
    ((2, 41), True)
    """
    constituents = polymer_constituents()
    K, S = polymer_K_S(constituents, chip["tio2_pct"])
    if "tint" in chip and chip["tint"] != "none":  # a dye in the slab (erratum E115)
        from shrm.polymer.kubelka_munk import km_tinted_K
        from shrm.polymer.oracle import interface_coupling
        from shrm.polymer.tint import read_tint_library

        n = chip.get("index", constituents.index)
        r_t = interface_coupling(n, gloss_alpha(chip["gloss"])).r_i
        K = km_tinted_K(K, S, read_tint_library(None).tint(chip["tint"]), r_t)
    options = {"tol": settings.tol, "seed": 0, **kwargs}
    return polymer_oracle(
        N,
        V,
        env,
        K,
        S,
        chip["thickness_mm"],
        chip.get("index", constituents.index),
        chip["gloss"],
        **options,
    )


def _oracle_result(N, V, env, chip: dict, specular: dict) -> np.ndarray:
    """The oracle for a chip from the converged specular term of its gloss (the slab re-summed)."""
    constituents = polymer_constituents()
    K, S = polymer_K_S(constituents, chip["tio2_pct"])
    body, trans = oracle_diffuse(
        N, V, env, K, S, chip["thickness_mm"], constituents.index, chip["gloss"]
    )
    return specular[chip["gloss"]].specular + body + trans


def oracle_references(env, settings: OracleStudy) -> dict:
    """The converged oracle of the base chip at every gloss of the sweep (seed 0).

    Examples
    --------
    >>> refs = oracle_references(np.ones((8, 16, 41)), SETTINGS["tiny"])
    >>> sorted(refs), refs[1.0].samples
    ([0.6, 0.8, 1.0], 0)
    """
    _, N, V = orthographic_sphere(settings.size)
    values = sorted({*settings.gloss, BASE["gloss"]})
    return {g: chip_oracle(N, V, env, {**BASE, "gloss": g}, settings) for g in values}


def chip_hybrid(N, V, maps, chips, chip: dict, mirror: str) -> dict:
    """Herbert's hybrid (Eq. (1), Herbert et al.) for one chip: its terms per pixel.

    The chip's look from the characterized model ``chips`` (``shrm.polymer.characterization``)
    at its thickness, TiO2 load, tint (a spot colour's name, Eq. (2), Herbert et al.), gloss
    and index, shaded with the maps of its gloss (:func:`hybrid_maps`); ``mirror`` is the
    specular map's Fresnel treatment.

    Examples
    --------
    >>> from shrm.polymer.characterization import characterize_model
    >>> _, N, V = orthographic_sphere(4)
    >>> maps, _ = hybrid_maps(np.ones((8, 16, 41)), (1.0,), size=4)
    >>> terms = chip_hybrid(N[:2], V[:2], maps, characterize_model(), {**BASE, "gloss": 1.0},
    ...                     "fresnel")
    >>> terms["I_result"].shape
    (2, 41)
    """
    d, c = chip["thickness_mm"], chip["tio2_pct"]
    tint = 1.0 if chip.get("tint", "none") == "none" else chip["tint"]  # a spot colour's name
    look = polymer_look(chips, d, c, tint=tint, gloss=chip["gloss"], mirror=mirror,
                        index=chip.get("index"))  # fmt: skip
    return polymer_terms(N, V, look, maps[chip["gloss"]])


def object_delta_E_stats(dE, cos_view) -> dict:
    """Mean, p95, max of ΔE00 over the object; means at the centre and the rim.

    The centre is where the view is within about 45° of the normal (``cos_view > 0.7``), the rim
    where it is beyond about 73° (``cos_view < 0.3``).

    Examples
    --------
    >>> s = object_delta_E_stats([1.0, 2.0, 3.0, 4.0], np.array([0.9, 0.8, 0.2, 0.1]))
    >>> s["mean"], s["max"], s["centre"], s["rim"]
    (2.5, 4.0, 1.5, 3.5)
    """
    d = np.asarray(dE).ravel()
    return {
        "mean": float(d.mean()),
        "p95": float(np.percentile(d, 95)),
        "max": float(d.max()),
        "centre": float(d[cos_view > 0.7].mean()),
        "rim": float(d[cos_view < 0.3].mean()),
    }


def sweeps(env, settings: OracleStudy, maps: dict, references: dict) -> dict:
    """ΔE00 of the hybrid against the oracle, per sweep, value and M_s.

    Returns
    -------
    dict
        ``{axis: {"values": [...], mirror: [stats per value]}}`` with ``axis`` in gloss,
        thickness_mm, tio2_pct and stats ``mean``, ``p95``, ``max`` over the sphere's pixels and
        the means at the centre (cos θ_v > 0.7) and the rim (cos θ_v < 0.3).
    """
    _, N, V = orthographic_sphere(settings.size)
    chips, colour = characterize_model(), Colour(env)
    out = {}
    for axis in ("gloss", "thickness_mm", "tio2_pct"):
        row: dict = {"values": list(getattr(settings, axis))}
        for value in row["values"]:
            chip = {**BASE, axis: value}
            oracle = _oracle_result(N, V, env, chip, references)
            for mirror in MIRROR_FACTORS.names():
                terms = chip_hybrid(N, V, maps, chips, chip, mirror)
                dE = colour.delta_E(terms["I_result"], oracle)
                row.setdefault(mirror, []).append(object_delta_E_stats(dE, N[:, 2]))
        out[axis] = row
    return out


def _seconds(function, repeat: int = 3) -> float:
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        function()
        best = min(best, time.perf_counter() - t0)
    return float(best)


def speed_accuracy(env, settings: OracleStudy, maps: dict, references: dict) -> dict:
    """Seconds per frame and ΔE00 against the converged oracle, at the base chip.

    The hybrid per M_s (from maps built beforehand: look-up and shading only); the layered model
    (``shrm.polymer.layered``: its maps' time, a frame from them, and a re-shade from its pixel
    parts after a change of the slab); the oracle at fixed sample counts with another seed than
    the reference.
    """
    _, N, V = orthographic_sphere(settings.size)
    chips, colour = characterize_model(), Colour(env)
    reference = references[BASE["gloss"]]
    out: dict = {
        "reference": {
            "seconds": reference.seconds,
            "samples": reference.samples,
            "relative_error": reference.relative_error,
        },
        "hybrid": {},
        "oracle": [],
    }
    for mirror in MIRROR_FACTORS.names():
        terms = chip_hybrid(N, V, maps, chips, BASE, mirror)
        seconds = _seconds(lambda m=mirror: chip_hybrid(N, V, maps, chips, BASE, m))
        dE = colour.delta_E(terms["I_result"], reference.result)
        out["hybrid"][mirror] = {"seconds": seconds, **object_delta_E_stats(dE, N[:, 2])}
    out["layered"] = _layered_speed(N, V, env, colour, reference.result)
    out["layered_split_sum"] = _layered_speed(
        N, V, env, colour, reference.result, "split_sum_Karis"
    )
    for m in settings.samples:
        run = chip_oracle(N, V, env, BASE, settings, tol=0.0, samples=m, max_samples=m, seed=1)
        dE = colour.delta_E(run.result, reference.result)
        out["oracle"].append(
            {"samples": m, "seconds": run.seconds, **object_delta_E_stats(dE, N[:, 2])}
        )
    return out


def _layered_speed(
    N, V, env, colour: Colour, reference: np.ndarray, specular: str = "fis_Colbert"
) -> dict:
    """The layered model on the base chip: seconds for its maps, a frame and a re-shade; ΔE00.

    ``specular``: the interface's reflection (``shrm.polymer.layered.LAYERED_SPECULAR``).

    The maps' time includes the interface's coupling tables, built uncached as a cold process
    builds them, and the pilot that chooses filtered importance sampling's ``samples`` (erratum
    E118; 0 for the split sum).
    """
    constituents = polymer_constituents()
    K, S = polymer_K_S(constituents, BASE["tio2_pct"])
    d = BASE["thickness_mm"]
    # a cold frame pays the coat's coupling tables too: built here uncached, then the maps
    t0 = time.perf_counter()
    for alpha in (gloss_alpha(BASE["gloss"]), 0.0):
        interface_coupling.__wrapped__(float(constituents.index), alpha)
    maps = layered_maps(env, constituents.index, BASE["gloss"], specular)
    maps_seconds = time.perf_counter() - t0
    result = layered_terms(N, V, maps, K, S, d)["result"]
    parts = layered_pixel_parts(N, V, maps)
    return {
        "maps_seconds": maps_seconds,
        "samples": maps.samples,
        "seconds": _seconds(lambda: layered_terms(N, V, maps, K, S, d)),
        "reshade_seconds": _seconds(lambda: layered_shade_parts(parts, K, S, 2.0 * d, maps)),
        **object_delta_E_stats(colour.delta_E(result, reference), N[:, 2]),
    }


def demo_images(env, settings: OracleStudy, maps: dict, references: dict) -> dict:
    """The base chip's hybrid terms (M_s = fresnel), their sum, the oracle and the ΔE00 map.

    Returns
    -------
    dict
        (size, size, n_bands) spectra ``I_d``, ``I_s F_r``, ``I_trans (1 - F_r)``, ``I_effect``,
        ``hybrid``, ``oracle`` and the oracle's terms (``oracle specular``, ``oracle body``,
        ``oracle transmission``); (size, size) ``delta_E``; ``mask``.
    """
    mask, N, V = orthographic_sphere(settings.size)
    terms = chip_hybrid(N, V, maps, characterize_model(), BASE, "fresnel")
    reference = references[BASE["gloss"]]
    oracle = reference.result
    pieces = {
        "I_d": terms["I_d"],
        "I_s F_r": terms["I_s"] * terms["F_r"],
        "I_trans (1 - F_r)": terms["I_trans"] * (1.0 - terms["F_r"]),
        "I_effect": terms["I_effect"],
        "hybrid": terms["I_result"],
        "oracle": oracle,
        "oracle specular": reference.specular,
        "oracle body": reference.body,
        "oracle transmission": reference.transmission,
    }
    out: dict = {"mask": mask}
    for name, values in pieces.items():
        image = np.zeros((*mask.shape, values.shape[-1]))
        image[mask] = values
        out[name] = image
    out["delta_E"] = np.zeros(mask.shape)
    out["delta_E"][mask] = Colour(env).delta_E(terms["I_result"], oracle)
    return out


def failures(sweep: dict, threshold: float = FAIL_DELTA_E) -> list[str]:
    """Sentences: per sweep and M_s, where the mean ΔE00 (object, rim) exceeds ``threshold``.

    Examples
    --------
    >>> stats = {"mean": 3.0, "p95": 7.0, "max": 9.0, "centre": 1.0, "rim": 6.0}
    >>> print(failures({"gloss": {"values": [0.5], "fresnel": [stats]}})[0])
    gloss, M_s = fresnel: object mean > 2 at 0.5, rim mean > 2 at 0.5; worst at 0.5: mean 3.00,
    p95 7.0, max 9.0, rim 6.00, centre 1.00
    """
    sentences = []
    for axis, row in sweep.items():
        for mirror in (k for k in row if k != "values"):
            stats = row[mirror]
            worst = int(np.argmax([s["mean"] for s in stats]))
            where = {
                part: [
                    f"{v:g}"
                    for v, s in zip(row["values"], stats, strict=True)
                    if s[key] > threshold
                ]
                for part, key in (("object", "mean"), ("rim", "rim"))
            }
            w = stats[worst]
            said = ", ".join(
                f"{part} mean > {threshold:g} at {', '.join(v) if v else 'no value'}"
                for part, v in where.items()
            )
            sentences.append(
                f"{axis}, M_s = {mirror}: {said}; worst at {row['values'][worst]:g}: "
                f"mean {w['mean']:.2f}, p95 {w['p95']:.1f}, max {w['max']:.1f}, "
                f"rim {w['rim']:.2f}, centre {w['centre']:.2f}"
            )
    return sentences


def furnace_error(n: float = 1.54, height: int = 64) -> float:
    """Max relative difference of the oracle's opaque smooth limit from the closed form.

    Under radiance 1 (white furnace), a 1 % TiO2 slab 100 mm thick, five views.

    Examples
    --------
    >>> furnace_error(height=32) < 1e-3
    True
    """
    K, S = polymer_K_S(polymer_constituents(), 1.0)
    cos = np.linspace(1.0, 0.1, 5)
    V = np.stack([np.sqrt(1.0 - cos**2), cos, np.zeros(5)], axis=-1)
    N = np.tile([0.0, 1.0, 0.0], (5, 1))
    out = polymer_oracle(N, V, np.ones((height, 2 * height, K.size)), K, S, 100.0, n)
    expected = smooth_plastic_albedo(cos, n, km_R_infinity(K, S))
    return float(np.abs(out.result / expected - 1.0).max())


#: The hybrid's terms and the oracle's that play the same part.
COUNTERPARTS = (
    ("I_s F_r", "oracle specular"),
    ("I_d", "oracle body"),
    ("I_trans (1 - F_r)", "oracle transmission"),
)


def term_balance(images: dict) -> dict:
    """Band-mean radiance of matching terms at the rim and the centre of the sphere.

    Examples
    --------
    >>> images = {name: np.ones((8, 8, 3)) for pair in COUNTERPARTS for name in pair}
    >>> images["mask"] = np.ones((8, 8), bool)
    >>> term_balance(images)["I_d"]["rim"]
    {'hybrid': 1.0, 'oracle': 1.0}
    """
    mask = images["mask"]
    size = mask.shape[0]
    x = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    X, Y = np.meshgrid(x, -x)
    cos = np.sqrt(np.clip(1.0 - X**2 - Y**2, 0.0, 1.0))
    parts = {"rim": mask & (cos < 0.3), "centre": mask & (cos > 0.7)}
    return {
        hybrid: {
            part: {
                "hybrid": float(images[hybrid][where].mean()),
                "oracle": float(images[oracle][where].mean()),
            }
            for part, where in parts.items()
        }
        for hybrid, oracle in COUNTERPARTS
    }


def oracle_study(env, name: str) -> tuple[dict, dict]:
    """Everything the section shows of the oracle comparison: (results, arrays).

    Examples
    --------
    >>> results, arrays = oracle_study(np.ones((16, 32, 41)), "tiny")
    >>> sorted(results)
    ['balance', 'failures', 'furnace_error', 'maps_seconds', 'settings', 'speed', 'sweeps']
    >>> arrays["delta_E"].shape
    (10, 10)
    """
    settings = SETTINGS[name]
    maps, seconds = hybrid_maps(env, sorted({*settings.gloss, BASE["gloss"]}))
    references = oracle_references(env, settings)
    sweep = sweeps(env, settings, maps, references)
    results = {
        "settings": {"name": name, "size": settings.size, "tol": settings.tol},
        "maps_seconds": seconds,
        "sweeps": sweep,
        "speed": speed_accuracy(env, settings, maps, references),
        "failures": failures(sweep),
        "furnace_error": furnace_error(),
    }
    images = demo_images(env, settings, maps, references)
    results["balance"] = term_balance(images)
    return results, images

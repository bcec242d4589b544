"""The real-time polymer models against the layered oracle where their design never looked.

The hybrid's sweeps in ``polymer_oracle_study`` (the design cases) vary one parameter at a time
around one chip under one synthetic environment. Here every chip is held out: drawn by a seeded
generator (:data:`HELD_OUT_SEED`) from the ranges the sweeps span (thickness log-uniform, TiO2 and
gloss uniform; the index and a spot-colour tint, which the sweeps never vary, from generators of
their own), none equal to a sweep value, and each is shaded under every environment map
specref ships (real captures: :data:`MAPS`). The measure is the one the sweeps use: ΔE00 of the
hybrid (Eqs. (1)-(5), Herbert et al.; M_s = fresnel) against the oracle (``polymer_oracle``),
relative to a white Lambertian surface facing the camera, over the sphere (mean, p95, max) and at
its rim (cos θ_v < 0.3). The real-time models are measured: Herbert's hybrid and the layered model
from prefiltered maps (``shrm.polymer.layered``), with its filtered importance sampling of the
interface's lobe and with Karis's split sum in its place; its terms were designed on the oracle's,
its sampling's settings on earlier draws of chips (:data:`HELD_OUT_SEED`) and its sampling's
tolerance on the design sweeps (erratum E118), never on these.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.colour.spectra import DEFAULT_GRID
from reference.data import data_path
from shrm.polymer.characterization import characterize_model
from shrm.polymer.kubelka_munk import polymer_constituents, polymer_K_S
from shrm.polymer.layered import layered_maps, layered_terms
from validation.report.sections.polymer_oracle_study import SETTINGS as SWEEPS
from validation.report.sections.polymer_oracle_study import (
    Colour,
    OracleStudy,
    chip_hybrid,
    chip_oracle,
    hybrid_maps,
    object_delta_E_stats,
    orthographic_sphere,
)
from validation.report.types import Check, Table

__all__ = [
    "HELD_OUT",
    "MAPS",
    "MODELS",
    "NOISE_LIMIT",
    "TARGETS",
    "held_out_checks",
    "held_out_chips",
    "held_out_study",
    "held_out_table",
    "map_environment",
    "tint_spectrum",
]

#: The environment maps specref ships (``reference/data/environments``), every one.
MAPS = (
    "venice_sunset_1k.hdr",
    "studio_small_03_1k.hdr",
    "st_fagans_interior_1k.hdr",
    "StageEnvLatLong.exr",
)
#: ΔE00 to the oracle that a real-time polymer model should hold on held-out chips and maps: the
#: worst chip's object mean and rim mean (cos θ_v < 0.3) per map. Herbert's hybrid is measured
#: against them; a model beyond it is to meet them (docs/herbert-polymer.md).
TARGETS = {"mean": 1.0, "rim": 2.0}
#: The judge's own noise that the study allows, ΔE00 between two seeds of the oracle (object mean,
#: worst chip per map): a quarter of the models' target, so a miss is the model's (erratum E117).
NOISE_LIMIT = TARGETS["mean"] / 4
#: The real-time models measured, by key: their names in the checks and tables.
MODELS = {
    "hybrid": "Herbert's hybrid",
    "layered": "the layered model",
    "layered_split_sum": "the layered model with the split sum",
}
#: Seed of the held-out chips. The first draw (seed 20261128) showed where the split sum fails and
#: chose the samples and bias of the layered model's filtered importance sampling (erratum E108);
#: the second (seed 20261129) was looked at while diagnosing why its fixed sample count missed
#: under studio_small_03 on a near-black chip, which led to the count from a tolerance (erratum
#: E118). Neither is held out any longer; this is a third draw.
HELD_OUT_SEED = 20261201
#: The ranges the chips are drawn from: those the design sweeps span (``SWEEPS["full"]``).
RANGES = {"thickness_mm": (0.381, 4.572), "tio2_pct": (0.0, 2.0), "gloss": (0.4, 1.0)}
#: The polymer's index, which the design never varies (the constituents' 1.54): drawn uniformly
#: over common plastics (polypropylene 1.49 to polycarbonate 1.585 and polystyrene 1.59), from
#: a generator of its own (seed + 1), so the other axes draw as before.
INDEX_RANGE = (1.45, 1.65)
#: The chance that a chip is tinted; its tint is a spot colour of the shipped library
#: (``shrm.polymer.tint``) drawn uniformly, from a generator of its own (seed + 2). Herbert's hybrid
#: multiplies its diffuse term by the tint (Eq. (2), Herbert et al.); the oracle and the layered
#: model take it as a dye in the slab (erratum E115).
TINT_CHANCE = 0.5


@dataclass(frozen=True)
class HeldOut:
    """Sizes of the held-out study: chips, sphere pixels, map rows, the oracle's tolerance and cap.

    The cap is in pairs per pixel: the oracle's rounds stop there if the tolerance is not met first.
    """

    chips: int
    size: int
    env_height: int
    tol: float
    max_pairs: int = 4096


#: The full study's oracle may take 16,384 pairs: at the oracle's default cap of 4,096 the rounds
#: stopped short of the tolerance on most chips under studio_small_03 and st_fagans and on every
#: map's near-black chip, and its two seeds differed by up to the noise limit (erratum E117).
HELD_OUT = {
    "tiny": HeldOut(1, 10, 8, 0.05),
    "quick": HeldOut(3, 24, 32, 0.02),
    "full": HeldOut(8, 48, 32, 0.01, 16384),
}


def held_out_chips(count: int, seed: int = HELD_OUT_SEED) -> list[dict]:
    """``count`` chips from :data:`RANGES`, none equal to a value of the design sweeps.

    Thickness is drawn log-uniform (mm), TiO2 (%), gloss and index (:data:`INDEX_RANGE`)
    uniform; values rounded to 3 digits; ``tint`` is a spot colour's name or ``"none"``
    (:data:`TINT_CHANCE`).

    Examples
    --------
    >>> chips = held_out_chips(3)
    >>> len(chips), sorted(chips[0])
    (3, ['gloss', 'index', 'thickness_mm', 'tint', 'tio2_pct'])
    >>> all(0.4 <= c["gloss"] <= 1.0 for c in chips)
    True
    """
    from shrm.polymer.tint import read_tint_library

    rng, rng_index = np.random.default_rng(seed), np.random.default_rng(seed + 1)
    rng_tint, names = np.random.default_rng(seed + 2), read_tint_library(None).names
    design = {
        axis: {round(v, 3) for s in SWEEPS.values() for v in getattr(s, axis)} for axis in RANGES
    }
    (t0, t1), tio2, gloss = RANGES["thickness_mm"], RANGES["tio2_pct"], RANGES["gloss"]
    chips: list[dict] = []
    while len(chips) < count:
        chip = {
            "thickness_mm": round(float(np.exp(rng.uniform(np.log(t0), np.log(t1)))), 3),
            "tio2_pct": round(float(rng.uniform(*tio2)), 3),
            "gloss": round(float(rng.uniform(*gloss)), 3),
        }
        if all(chip[axis] not in design[axis] for axis in RANGES):
            index = round(float(rng_index.uniform(*INDEX_RANGE)), 3)
            tinted = rng_tint.uniform() < TINT_CHANCE
            tint = str(names[rng_tint.integers(len(names))]) if tinted else "none"
            chips.append(chip | {"index": index, "tint": tint})
    return chips


def map_environment(name: str, rows: int) -> np.ndarray:
    """A shipped map, box-filtered to ``rows`` rows, as spectral radiance on the 41-band grid.

    Examples
    --------
    >>> map_environment("venice_sunset_1k.hdr", 8).shape
    (8, 16, 41)
    """
    from validation.studies.shrm_fullres import environment_radiance

    return environment_radiance(data_path(f"environments/{name}"), rows, DEFAULT_GRID)


def tint_spectrum(chip: dict):
    """The chip's tint on the 41-band grid: a spot colour's reflectance, or 1 for ``"none"``.

    Examples
    --------
    >>> tint_spectrum({"tint": "none"}), tint_spectrum({"tint": "cc-cyan"}).shape
    (1.0, (41,))
    """
    from shrm.polymer.tint import read_tint_library

    name = chip.get("tint", "none")
    return 1.0 if name == "none" else read_tint_library(None).tint(name)


def _layered(N, V, env, chip: dict, specular: str = "fis_Colbert") -> dict:
    """The layered model's terms for a chip (maps made per chip's gloss), and its sample count."""
    from shrm.polymer.kubelka_munk import km_tinted_K
    from shrm.polymer.oracle import interface_coupling

    constituents = polymer_constituents()
    K, S = polymer_K_S(constituents, chip["tio2_pct"])
    maps = layered_maps(env, chip.get("index", constituents.index), chip["gloss"], specular)
    K = km_tinted_K(K, S, tint_spectrum(chip), interface_coupling(maps.n, maps.alpha).r_i)
    return layered_terms(N, V, maps, K, S, chip["thickness_mm"]) | {"samples": maps.samples}


def _chip_rows(N, V, env, chip: dict, maps: dict, colour: Colour, s: HeldOut) -> list[dict]:
    """One row per model of :data:`MODELS` for a chip under a map (:func:`held_out_study`)."""
    model = characterize_model()
    settings = OracleStudy(s.size, s.env_height, (), (), (), (), s.tol)
    oracle = chip_oracle(N, V, env, chip, settings, max_samples=s.max_pairs)
    # the judge's own noise: the oracle again with another seed (erratum E117)
    again = chip_oracle(N, V, env, chip, settings, seed=1, max_samples=s.max_pairs)
    noise = object_delta_E_stats(colour.delta_E(again.result, oracle.result), N[:, 2])
    layered = _layered(N, V, env, chip)
    # where the layered model's error lies: its result with the oracle's specular term
    swapped = layered["result"] - layered["specular"] + oracle.specular
    shaded = {
        "hybrid": chip_hybrid(N, V, maps, model, chip, "fresnel")["I_result"],
        "layered": layered["result"],
        "layered_split_sum": _layered(N, V, env, chip, "split_sum_Karis")["result"],
        "swap": swapped,
    }
    stats = {
        key: object_delta_E_stats(colour.delta_E(radiance, oracle.result), N[:, 2])
        for key, radiance in shaded.items()
    }
    extra = {
        "swap_mean": stats["swap"]["mean"],
        "swap_rim": stats["swap"]["rim"],
        "fis_samples": layered["samples"],
    }
    judge = {"noise_mean": noise["mean"], "noise_rim": noise["rim"], "oracle_pairs": oracle.samples}
    return [
        {"model": key, **chip, **stats[key], **(extra if key == "layered" else {}), **judge}
        for key in MODELS
    ]


def held_out_study(name: str) -> dict:
    """Both real-time models against the oracle for every held-out chip under every shipped map.

    ``name``: a key of :data:`HELD_OUT`.

    Returns
    -------
    dict
        ``settings``; ``rows``: per model, map and chip, the chip and the ΔE00 statistics of
        ``polymer_oracle_study._stats`` (``mean``, ``p95``, ``max``, ``centre``, ``rim``), and
        for the layered model ``swap_mean`` and ``swap_rim``: the same with the oracle's specular
        term in place of the model's (what remains is the body and transmission's error), and
        ``fis_samples``, the sample count its pilot chose (erratum E118); ``worst``: per model (a
        key of :data:`MODELS`) and map, the largest object and rim means over its chips;
        ``noise``: per map, the largest object and rim means between the oracle and the oracle at
        another seed (``noise_mean``, ``noise_rim`` in every row, with ``oracle_pairs``, the
        oracle's pairs per pixel): the judge's own uncertainty; ``samples``: per map, the layered
        model's fewest and most samples and the oracle's most pairs.

    Examples
    --------
    >>> study = held_out_study("tiny")
    >>> sorted(study["worst"]) == sorted(MODELS), sorted(study["worst"]["layered"]) == sorted(MAPS)
    (True, True)
    >>> sorted(study["noise"]) == sorted(MAPS), sorted(study["samples"]["venice_sunset_1k.hdr"])
    (True, ['fis', 'oracle_pairs'])
    """
    s = HELD_OUT[name]
    chips = held_out_chips(s.chips)
    _, N, V = orthographic_sphere(s.size)
    rows = []
    for map_name in MAPS:
        env = map_environment(map_name, s.env_height)
        maps, _ = hybrid_maps(env, sorted({c["gloss"] for c in chips}))
        colour = Colour(env)
        for chip in chips:
            rows += [
                {"map": map_name} | row for row in _chip_rows(N, V, env, chip, maps, colour, s)
            ]

    def most(part, m, models=MODELS):
        return max(r[part] for r in rows if r["map"] == m and r["model"] in models)

    worst = {
        key: {m: {part: most(part, m, (key,)) for part in ("mean", "rim")} for m in MAPS}
        for key in MODELS
    }
    noise = {m: {part: most(f"noise_{part}", m) for part in TARGETS} for m in MAPS}
    samples = {
        m: {
            "fis": sorted({r["fis_samples"] for r in rows if r["map"] == m and "fis_samples" in r}),
            "oracle_pairs": most("oracle_pairs", m),
        }
        for m in MAPS
    }
    settings = {"name": name, "chips": s.chips, "size": s.size, "rows": s.env_height}
    return {
        "settings": settings | {"tol": s.tol, "max_pairs": s.max_pairs, "seed": HELD_OUT_SEED},
        "rows": rows,
        "worst": worst,
        "noise": noise,
        "samples": samples,
    }


def held_out_checks(study: dict) -> list:
    """Per model and map: the worst held-out chip's object and rim mean ΔE00 (:data:`TARGETS`).

    Examples
    --------
    >>> worst = {"layered": {"a.hdr": {"mean": 0.8, "rim": 2.5}}}
    >>> study = {"worst": worst, "settings": {"chips": 3}}
    >>> [(c.passed, c.basis) for c in held_out_checks(study)]
    [(True, 'held out'), (False, 'held out')]
    """
    found = []
    chips = study["settings"]["chips"]
    for name, noise in study.get("noise", {}).items():
        found.append(
            Check(
                f"the layered oracle's own noise, {name}: worst object mean ΔE00 between two "
                f"seeds over {chips} held-out chips (a quarter of the models' target)",
                f"<= {NOISE_LIMIT:g}",
                noise["mean"],
                noise["mean"] <= NOISE_LIMIT,
                "held out",
            )
        )
    for key, per_map in study["worst"].items():
        for name, worst in per_map.items():
            for part, label in (("mean", "object"), ("rim", "rim")):
                value = worst[part]
                found.append(
                    Check(
                        f"{MODELS[key]} vs the layered oracle, {name}: worst {label} mean ΔE00 "
                        f"of {chips} held-out chips",
                        f"<= {TARGETS[part]:g}",
                        value,
                        value <= TARGETS[part],
                        "held out",
                    )
                )
    return found


def held_out_table(study: dict) -> Table:
    """The study's rows: model, map, chip, ΔE00 mean, p95, max, centre and rim.

    Examples
    --------
    >>> row = {"model": "layered", "map": "a.hdr", "thickness_mm": 1.0, "tio2_pct": 0.5,
    ...        "gloss": 0.8, "index": 1.5, "mean": 1.0, "p95": 2.0, "max": 3.0, "centre": 0.5,
    ...        "rim": 2.5}
    >>> held_out_table({"rows": [row], "settings": {"seed": 1}}).rows[0][:5]
    ['the layered model', 'a.hdr', 1.0, 0.5, 0.8]
    """
    keys = ("thickness_mm", "tio2_pct", "gloss", "index", "tint", "mean", "p95", "max", "centre",
            "rim", "swap_mean", "swap_rim", "fis_samples", "noise_mean",
            "oracle_pairs")  # fmt: skip
    head = ["model", "map", "thickness mm", "TiO2 %", "gloss", "index", "tint"]
    swapped = ["mean, oracle's specular", "rim, oracle's specular", "FIS samples"]
    judge = ["oracle's own noise, mean", "oracle's pairs"]
    return Table(
        [*head, "mean", "p95", "max", "centre", "rim", *swapped, *judge],
        [[MODELS[r["model"]], r["map"], *(r.get(k, "") for k in keys)] for r in study["rows"]],
        "Herbert's hybrid (M_s = fresnel) and the layered model against the layered oracle, "
        "ΔE00, on chips held out of the design (drawn with seed "
        f"{study['settings']['seed']} from the sweeps' ranges) under every shipped environment "
        "map. A tint is a spot colour: the hybrid multiplies its diffuse term by it (Eq. (2), "
        "Herbert et al.), the oracle and the layered model take it as a dye in the slab (erratum "
        "E115), so on a translucent chip they differ by design as well as by approximation. The "
        "columns 'oracle's specular' put the oracle's specular term in the layered model's "
        "place: what they leave is the error of its body and transmission, the rest is its "
        "specular term (erratum E108). 'FIS samples' is the layered model's sample count per "
        "pixel, chosen by its pilot from a tolerance for the map, index and gloss (erratum "
        "E118). The last columns are the judge's own noise, the oracle against itself at "
        "another seed, and the pairs per pixel it took (erratum E117)",
        "{:.3g}",
    )

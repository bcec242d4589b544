"""Report section "Herbert hybrid model": the polymer chips of §3.1 and the hybrid model's terms.

Eq. (1), Herbert et al.: the hybrid model's sum.

compute → :func:`polymer_study`; present → :func:`present`; checks → :func:`checks`.

- Fig. 2, Herbert et al. reproduced from the Kubelka–Munk chip model
  (``shrm.polymer.kubelka_munk``):
  lightness against TiO2 load for the three thicknesses, over black and in transmission, and a
  row of chips like Fig. 3;
- the characterization file's interpolation between chips against the model, in ΔE00 under D65
  and A;
- the terms of Eq. (1), Herbert et al. (``shrm.polymer.hybrid``) as images on a sphere under a
  synthetic
  spectral environment, and their sum; the hybrid under a uniform sky (erratum E34).
"""

from __future__ import annotations

import numpy as np

from reference.colour.colorimetry import (
    XYZ_to_display_RGB,
    XYZ_to_Lab,
    band_weights,
    delta_E_00,
    spectra_to_XYZ,
    white_XYZ,
)
from reference.colour.spectra import DEFAULT_GRID, spectrum_from_dataset
from reference.display.encodings import encode_srgb
from reference.geometry.envmap import latlong_pixel_directions
from reference.materials.fresnel import fresnel_dielectric, fresnel_lut
from shrm.polymer.characterization import HERBERT_THICKNESS_MM, MEASUREMENTS, characterize_model
from shrm.polymer.hybrid import MIRROR_FACTORS, polymer_look, polymer_maps, polymer_terms
from shrm.polymer.kubelka_munk import polymer_constituents, polymer_K_S, slab_measured
from validation.report import Check, ReportContext, ReportSection, SectionData, Table, Text
from validation.report.sections.polymer_held_out import (
    MAPS,
    MODELS,
    TARGETS,
    held_out_checks,
    held_out_study,
    held_out_table,
)
from validation.report.sections.polymer_oracle_study import (
    BASE,
    FAIL_DELTA_E,
    SETTINGS,
    oracle_study,
)
from validation.studies.herbert_fig1 import fig1_study
from validation.studies.metrics import delta_E_stats

#: TiO2 loads of the Fig. 2 reproduction, % by weight.
FIG2_TIO2_PCT = np.array([0.0, 0.02, 0.05, 0.1, 0.2, 0.35, 0.5, 0.75, 1.0, 1.5, 2.0])
ILLUMINANTS = ("D65", "A")
#: Our target for the interpolation between chips (erratum E37): mean ΔE00 below 0.5.
INTERPOLATION_TARGET = 0.5
#: The chip and finish the term images show.
DEMO = {"thickness_mm": 1.524, "tio2_pct": 0.2, "gloss": 0.8, "phong_exponent": 64.0}


def _weights(illuminant: str):
    W = band_weights(DEFAULT_GRID, spectrum_from_dataset("illuminant", illuminant))
    return W, white_XYZ(W)


def _lightness(spectra, illuminant: str = "D65") -> np.ndarray:
    W, white = _weights(illuminant)
    return XYZ_to_Lab(spectra_to_XYZ(spectra, W), white)[..., 0]


def fig2_lightness() -> dict:
    """L* (D65) of the model chips over black and in transmission, per Herbert thickness.

    Examples
    --------
    >>> curves = fig2_lightness()
    >>> sorted(curves), len(curves["0.762"]["L_over_black"])
    (['0.762', '1.524', '3.048'], 11)
    """
    K, S = polymer_K_S(polymer_constituents(), FIG2_TIO2_PCT)
    curves = {}
    for d in HERBERT_THICKNESS_MM:
        R, T = slab_measured(K, S, d)
        curves[f"{d:g}"] = {
            "tio2_pct": FIG2_TIO2_PCT.tolist(),
            "L_over_black": _lightness(R).tolist(),
            "L_transmission": _lightness(T).tolist(),
        }
    return curves


def interpolation_error() -> dict:
    """ΔE00 of the characterization's interpolation against the model at off-grid chips.

    The off-grid chips are the cell centres of the default grid (geometric midpoints in thickness,
    midpoints in TiO2).

    Examples
    --------
    >>> errors = interpolation_error()
    >>> errors["D65"]["transmittance"]["mean"] < 0.5
    True
    """
    ch = characterize_model()
    d = np.sqrt(ch.thickness_mm[1:] * ch.thickness_mm[:-1])
    c = 0.5 * (ch.tio2_pct[1:] + ch.tio2_pct[:-1])
    d, c = (a.ravel() for a in np.meshgrid(d, c, indexing="ij"))
    K, S = polymer_K_S(polymer_constituents(), c)
    truth = dict(zip(("over_black", "transmittance"), slab_measured(K, S, d[:, None]), strict=True))
    truth["over_white"] = slab_measured(K, S, d[:, None], R_g=ch.meta["backing_white"])[0]
    got = ch.lookup(d, c)
    out: dict = {}
    for illuminant in ILLUMINANTS:
        W, white = _weights(illuminant)
        out[illuminant] = {
            name: delta_E_stats(
                delta_E_00(
                    XYZ_to_Lab(spectra_to_XYZ(got[name], W), white),
                    XYZ_to_Lab(spectra_to_XYZ(truth[name], W), white),
                )
            )
            for name in MEASUREMENTS
        }
    return out


def synthetic_environment(height: int = 32) -> np.ndarray:
    """A spectral lat-long test environment: D65 sky gradient, a warm (A) lamp, a grey-brown floor.

    Examples
    --------
    >>> synthetic_environment(8).shape
    (8, 16, 41)
    """
    wl = DEFAULT_GRID.wavelengths_nm
    d = latlong_pixel_directions(height, 2 * height)
    d65 = spectrum_from_dataset("illuminant", "D65")
    lamp = spectrum_from_dataset("illuminant", "A")
    sky = np.interp(wl, d65.wavelengths_nm, d65.values) / 100.0
    warm = np.interp(wl, lamp.wavelengths_nm, lamp.values) / 100.0
    floor = 0.3 * (0.6 + 0.4 * (wl - 380.0) / 400.0)
    up = d[..., 1:2]
    env = np.where(up > 0, (0.4 + 0.6 * up) * sky, floor * 0.5 * sky)
    lamp_dir = np.array([0.5, 0.6, 0.62]) / np.linalg.norm([0.5, 0.6, 0.62])
    env = env + 20.0 * (d @ lamp_dir > 0.97)[..., None] * warm
    return env


def sphere_terms(size: int, mirrors=("fresnel",)) -> dict:
    """The terms of Eq. (1), Herbert et al., on an orthographic sphere.

    Lit by :func:`synthetic_environment`.

    The maps are prefiltered once; each M_s of ``mirrors`` only re-shades (the factor is per pixel).

    Returns
    -------
    dict
        Per mirror factor, a dict of (size, size, n_bands) spectra (zero outside the sphere);
        ``"mask"``, the sphere's pixels.

    Examples
    --------
    >>> terms = sphere_terms(8)
    >>> terms["fresnel"]["I_result"].shape, int(terms["mask"].sum())
    ((8, 8, 41), 52)
    """
    x = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    X, Y = np.meshgrid(x, -x)
    mask = X**2 + Y**2 < 1.0
    N = np.stack([X[mask], Y[mask], np.sqrt(1.0 - X[mask] ** 2 - Y[mask] ** 2)], axis=-1)
    V = np.tile([0.0, 0.0, 1.0], (N.shape[0], 1))
    maps = polymer_maps(synthetic_environment(), DEMO["phong_exponent"], size=32)
    chips = characterize_model()
    out: dict = {"mask": mask}
    for mirror in mirrors:
        look = polymer_look(
            chips, DEMO["thickness_mm"], DEMO["tio2_pct"], gloss=DEMO["gloss"], mirror=mirror
        )
        terms = polymer_terms(N, V, look, maps)
        pieces = {
            "I_d": terms["I_d"],
            "I_s F_r": terms["I_s"] * terms["F_r"],
            "I_trans (1 - F_r)": terms["I_trans"] * (1.0 - terms["F_r"]),
            "I_effect": terms["I_effect"],
            "I_result": terms["I_result"],
        }
        out[mirror] = {}
        for name, values in pieces.items():
            image = np.zeros((size, size, values.shape[-1]))
            image[mask] = values
            out[mirror][name] = image
    return out


def uniform_sky() -> dict:
    """Band-mean I_result of three chips under radiance 1 from everywhere (erratum E34).

    Examples
    --------
    >>> values = uniform_sky()
    >>> values["0.762 mm, 0 %"]["normal"] < 1 < values["0.762 mm, 0 %"]["grazing"]
    True
    """
    maps = polymer_maps(np.ones((16, 32, DEFAULT_GRID.n_bands)), 16.0, size=4)
    ch = characterize_model()
    N = np.tile([0.0, 1.0, 0.0], (2, 1))
    V = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
    out = {}
    for d, c in ((0.762, 0.0), (1.524, 0.5), (3.048, 2.0)):
        result = polymer_terms(N, V, polymer_look(ch, d, c), maps)["I_result"].mean(axis=1)
        out[f"{d:g} mm, {c:g} %"] = {"normal": float(result[0]), "grazing": float(result[1])}
    return out


def polymer_study(ctx: ReportContext | None = None) -> SectionData:
    """Compute every figure of the section.

    Returns
    -------
    SectionData
        ``results``: ``fig2`` (L* curves), ``interpolation`` (ΔE00 stats per illuminant and
        measurement), ``fresnel_lut_max_error``, ``uniform_sky``, ``oracle`` (the design sweeps
        against the layered oracle), ``held_out`` (every shipped map, held-out chips:
        ``polymer_held_out.held_out_study``); ``arrays``: term images per M_s and the chip spectra
        for the swatches.

    Examples
    --------
    >>> data = polymer_study()
    >>> sorted(data.results)
    ['fig1', 'fig2', 'fresnel_lut_max_error', 'held_out', 'interpolation', 'oracle', 'uniform_sky']
    """
    quick = True if ctx is None else ctx.quick
    data = SectionData()
    data.results["fig2"] = fig2_lightness()
    data.results["interpolation"] = interpolation_error()
    c = np.linspace(0.0, 1.0, 100_001)
    lut = fresnel_lut(1.54).lookup(c)
    data.results["fresnel_lut_max_error"] = float(np.abs(lut - fresnel_dielectric(c, 1.54)).max())
    data.results["uniform_sky"] = uniform_sky()
    size = 48 if quick else 160
    data.arrays["terms"] = sphere_terms(size, MIRROR_FACTORS.names())
    K, S = polymer_K_S(polymer_constituents(), FIG2_TIO2_PCT)
    data.arrays["chips"] = slab_measured(K, S, HERBERT_THICKNESS_MM[-1])
    study = "tiny" if ctx is None else ("quick" if quick else "full")
    env = synthetic_environment(SETTINGS[study].env_height)
    data.results["oracle"], data.arrays["oracle"] = oracle_study(env, study)
    # held out of the design: every shipped map, chips the sweeps never took
    data.results["held_out"] = held_out_study(study)
    fig1 = fig1_study({"tiny": 24, "quick": 64, "full": 160}[study])
    data.arrays["fig1"] = fig1.pop("sRGB")
    data.results["fig1"] = fig1
    return data


def _to_srgb(spectra, W, scale: float) -> np.ndarray:
    return encode_srgb(np.clip(XYZ_to_display_RGB(spectra_to_XYZ(spectra, W)) / scale, 0.0, 1.0))


def present(ctx: ReportContext, data: SectionData) -> list:
    """Fig. 2 curves, chip swatches, interpolation table, term images, uniform-sky table."""
    blocks: list = [
        Text(
            "Herbert et al.'s polymer characterization (§3.1) from specref's Kubelka–Munk chip "
            "model (HDPE-like base, rutile TiO2; "
            "`shrm/polymer/data/polymer_hdpe_tio2.toml`, errata "
            "E35–E36), "
            "and the hybrid shading model of Eqs. (1)-(5), Herbert et al. (`shrm.polymer.hybrid`, "
            "errata E5, E30–E34). "
            "Herbert's Fig. 2 plots the green channel at D65; this plots CIE L* under D65."
        )
    ]
    blocks += _chip_figures(ctx, data)
    rows = []
    for illuminant, per in data.results["interpolation"].items():
        for name, stats in per.items():
            rows.append([illuminant, name, stats["mean"], stats["p90"], stats["max"]])
    blocks.append(
        Table(
            ["illuminant", "measurement", "mean ΔE00", "p90 ΔE00", "max ΔE00"],
            rows,
            "Characterization look-up (PCHIP in log thickness, TiO2) against the model at the "
            "centres of the default grid's cells",
            "{:.3f}",
        )
    )
    blocks += _term_figures(ctx, data)
    rows = [[k, v["normal"], v["grazing"]] for k, v in data.results["uniform_sky"].items()]
    blocks.append(
        Table(
            ["chip", "I_result, normal view", "I_result, grazing view"],
            rows,
            "The hybrid under a uniform sky of radiance 1 (band mean; a passive surface returns at "
            "most 1): Eq. (1), Herbert et al. as printed is not energy conserving (erratum E34)",
            "{:.3f}",
        )
    )
    blocks += _oracle_blocks(ctx, data)
    return blocks


def _chip_figures(ctx: ReportContext, data: SectionData) -> list:
    """Fig. 2 reproduced and a row of chips like Fig. 3."""
    import matplotlib.pyplot as plt

    blocks = []
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.4), sharex=True)
    for d, curve in data.results["fig2"].items():
        axes[0].plot(curve["tio2_pct"], curve["L_over_black"], "o-", label=f"{d} mm")
        axes[1].plot(curve["tio2_pct"], curve["L_transmission"], "o-", label=f"{d} mm")
    axes[0].set_title("over black")
    axes[1].set_title("transmission")
    for ax in axes:
        ax.set_xlabel("TiO2 load (% by weight)")
        ax.set_ylabel("L* (D65)")
    axes[0].legend(frameon=False)
    curves = data.results["fig2"].values()
    rises = all(np.all(np.diff(c["L_over_black"]) >= 0) for c in curves)
    falls = all(np.all(np.diff(c["L_transmission"]) <= 0) for c in curves)
    span = ", ".join(
        f"{d} mm {min(c['L_over_black']):.0f}–{max(c['L_over_black']):.0f}"
        for d, c in data.results["fig2"].items()
    )
    trend = (
        f"over black, L* rises with the TiO2 load ({span}) and the transmission falls"
        if rises and falls
        else f"over black, L* spans {span}; not monotone in the load on every chip"
    )
    blocks.append(ctx.figure("fig2", fig, f"Fig. 2 reproduced, HDPE-like chips: {trend}"))
    W, _ = _weights("D65")
    R, T = data.arrays["chips"]
    swatch = 24
    rows = [np.repeat(np.repeat(_to_srgb(s, W, 1.0)[None], swatch, 0), swatch, 1) for s in (R, T)]
    blocks.append(
        ctx.image(
            "chips",
            np.concatenate(rows, axis=0),
            f'Chips like Fig. 3: 0.120" thick, TiO2 {", ".join(f"{c:g}" for c in FIG2_TIO2_PCT)} % '
            "(top: over black, bottom: in transmission), sRGB under D65",
        )
    )
    blocks.append(_fig1_image(ctx, data))
    return blocks


def _fig1_image(ctx: ReportContext, data: SectionData):
    """Fig. 1 rebuilt: the sphere under daylight, fluorescent and tungsten, fully adapted."""
    tiles, dE = data.arrays["fig1"], data.results["fig1"]["delta_E00"]
    first, *others = list(tiles)
    shifts = ", ".join(f"{dE[k]:.2g} under {k}" for k in others)
    return ctx.image(
        "fig1",
        np.concatenate(list(tiles.values()), axis=1),
        f"Fig. 1 rebuilt: the tinted polymer sphere of data:examples/polymer-sphere.toml in "
        f"venice_sunset made spectral and relit under {', '.join(tiles)}, each frame adapted to "
        f"its light's white (CAT02): the sphere's mean colour still moves from {first} by "
        f"ΔE00 {shifts}, the colour inconstancy a renderer multiplying RGB cannot show",
    )


def _term_figures(ctx: ReportContext, data: SectionData) -> list:
    """The terms of Eq. (1), Herbert et al., on a sphere, one figure per M_s."""
    import matplotlib.pyplot as plt

    blocks = []
    W_E = band_weights(DEFAULT_GRID, None)
    for mirror in MIRROR_FACTORS.names():
        terms = data.arrays["terms"][mirror]
        scale = float(np.percentile(spectra_to_XYZ(terms["I_result"], W_E)[..., 1], 99))
        names = list(terms)
        fig, axes = plt.subplots(1, len(names), figsize=(2.2 * len(names), 2.4))
        for ax, name in zip(axes, names, strict=True):
            ax.imshow(_to_srgb(terms[name], W_E, scale))
            ax.set_title(name, fontsize=9)
            ax.axis("off")
        blocks.append(
            ctx.figure(
                f"terms-{mirror}",
                fig,
                f"The terms of Eq. (1), Herbert et al., with M_s = {mirror}: a "
                f"{DEMO['thickness_mm']} mm, "
                f"{DEMO['tio2_pct']} % TiO2 sphere, gloss {DEMO['gloss']}, Phong exponent "
                f"{DEMO['phong_exponent']:g}, under a synthetic spectral sky with a warm lamp "
                "(I_effect is zero: no effect pigment on this material)",
            )
        )
    return blocks


def checks(data: SectionData) -> list[Check]:
    """Interpolation target, Fig. 2's monotone shapes, the Fresnel LUT bound."""
    found = []
    for illuminant, per in data.results["interpolation"].items():
        for name, stats in per.items():
            found.append(
                Check(
                    f"chip look-up, mean ΔE00, {name}, {illuminant}",
                    f"< {INTERPOLATION_TARGET}",
                    stats["mean"],
                    stats["mean"] < INTERPOLATION_TARGET,
                    "held out",  # at the centres of the grid's cells, between its chips
                )
            )
    for d, curve in data.results["fig2"].items():
        rises = bool(np.all(np.diff(curve["L_over_black"]) > 0))
        falls = bool(np.all(np.diff(curve["L_transmission"]) < 0))
        found.append(
            Check(f"Fig. 2, {d} mm: L* over black rises with TiO2", "monotone", str(rises), rises)
        )
        found.append(
            Check(
                f"Fig. 2, {d} mm: L* in transmission falls with TiO2", "monotone", str(falls), falls
            )
        )
    error = data.results["fresnel_lut_max_error"]
    found.append(
        Check("F_r LUT against the closed form, n = 1.54", "<= 1e-6", error, error <= 1e-6)
    )
    found += _oracle_checks(data.results["oracle"])
    if "held_out" in data.results:
        found += held_out_checks(data.results["held_out"])
    return found


def _oracle_blocks(ctx: ReportContext, data: SectionData) -> list:
    """The hybrid against the layered oracle: images, sweeps, failures, speed–accuracy."""
    oracle = data.results["oracle"]
    blocks: list = [
        Text(
            "The layered physical model (`shrm.polymer.oracle`, errata E65–E69): a GGX-rough "
            "dielectric interface (α = 0.5 (1 − gloss)) over the Kubelka–Munk slab, integrated per "
            "pixel over the environment with no prefiltering (body and transmission as sums over "
            "the map's pixels, the rough lobe by seeded Monte Carlo until the 99th percentile of "
            f"the relative standard error is at most {oracle['settings']['tol']:g}). The hybrid "
            "uses the Phong exponent 2/α² − 2 (capped at 1000) and the gloss factor of Eq. (5), "
            "Herbert et al. "
            f"Base chip: {BASE['thickness_mm']} mm, {BASE['tio2_pct']} % TiO2, gloss "
            f"{BASE['gloss']}; each sweep varies one of these. ΔE00 relative to a white "
            "Lambertian surface facing the camera under the same environment."
        )
    ]
    blocks.append(_oracle_image_figure(ctx, data.arrays["oracle"]))
    blocks.append(_sweep_figure(ctx, oracle["sweeps"]))
    blocks.append(_sweep_table(oracle["sweeps"]))
    blocks.append(Text(_failure_text(oracle)))
    blocks.append(_speed_figure(ctx, oracle["speed"]))
    if "held_out" in data.results:
        blocks.append(Text(_held_out_text(data.results["held_out"])))
        blocks.append(held_out_table(data.results["held_out"]))
    return blocks


def _held_out_text(study: dict) -> str:
    """What the held-out table measures, against which targets, and each model's worst map."""
    worst = {
        key: max(per_map.items(), key=lambda item: item[1]["mean"])
        for key, per_map in study["worst"].items()
    }
    found = "; ".join(
        f"{MODELS[key]} is worst under {name} (object mean {w['mean']:.2f}, rim {w['rim']:.2f})"
        for key, (name, w) in worst.items()
    )
    return (
        f"Held out: {study['settings']['chips']} chips the design sweeps never took, under each of "
        f"the {len(MAPS)} environment maps specref ships (real captures, "
        f"{study['settings']['rows']} rows, spectralized), a {study['settings']['size']}² sphere. "
        f"Targets for a real-time polymer model: worst object mean ΔE00 <= {TARGETS['mean']:g} "
        f"and rim mean <= {TARGETS['rim']:g} per map. {found[0].upper()}{found[1:]}."
        + _samples_text(study)
        + _noise_text(study)
    )


def _samples_text(study: dict) -> str:
    """The layered model's sample counts (its pilot's, erratum E118) and the oracle's pairs."""
    if not study.get("samples"):
        return ""
    fis = {m: s["fis"] for m, s in study["samples"].items() if s["fis"]}
    if not fis:
        return ""
    name = max(fis, key=lambda m: max(fis[m]))
    low, high = min(min(k) for k in fis.values()), max(fis[name])
    pairs = max(s["oracle_pairs"] for s in study["samples"].values())
    return (
        f" The layered model's filtered importance sampling took {low} to {high} samples per "
        f"pixel, the most under {name}, as its pilot chose them per map, index and gloss for a "
        f"tolerance (erratum E118); the oracle took up to {pairs} pairs per pixel."
    )


def _noise_text(study: dict) -> str:
    """The judge's own noise: the oracle against itself at another seed, worst map."""
    if not study.get("noise"):
        return ""
    name, noise = max(study["noise"].items(), key=lambda item: item[1]["mean"])
    return (
        f" The oracle against itself at another seed (its own noise, erratum E117) differs by at "
        f"most {noise['mean']:.2f} object mean and {noise['rim']:.2f} rim mean, under {name}."
    )


def _oracle_image_figure(ctx: ReportContext, images: dict):
    """The four terms of Eq. (1), Herbert et al., their sum, the oracle and the ΔE00 map."""
    import matplotlib.pyplot as plt

    W_E = band_weights(DEFAULT_GRID, None)
    scale = float(np.percentile(spectra_to_XYZ(images["oracle"], W_E)[..., 1], 99))
    names = ["I_d", "I_s F_r", "I_trans (1 - F_r)", "I_effect", "hybrid", "oracle"]
    fig, axes = plt.subplots(1, len(names) + 1, figsize=(2.1 * (len(names) + 1), 2.5))
    for ax, name in zip(axes, names, strict=False):
        ax.imshow(_to_srgb(images[name], W_E, scale), interpolation="nearest")
        ax.set_title(name if name != "hybrid" else "hybrid (sum)", fontsize=9)
    shown = axes[-1].imshow(
        np.where(images["mask"], images["delta_E"], np.nan), cmap="magma", interpolation="nearest"
    )
    axes[-1].set_title("ΔE00 hybrid − oracle", fontsize=9)
    fig.colorbar(shown, ax=axes[-1], fraction=0.046)
    for ax in axes:
        ax.axis("off")
    return ctx.figure(
        "oracle-images",
        fig,
        "The terms of Eq. (1), Herbert et al. (M_s = fresnel), their sum, the layered oracle and "
        "the ΔE00 between the sum and the oracle, on the base chip",
    )


def _sweep_figure(ctx: ReportContext, sweeps: dict):
    """Mean (solid) and p95 (dashed) ΔE00 against gloss, thickness and TiO2, per M_s."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(11, 3.3), sharey=True)
    labels = {"gloss": "gloss", "thickness_mm": "thickness (mm)", "tio2_pct": "TiO2 (%)"}
    for ax, (axis, row) in zip(axes, sweeps.items(), strict=True):
        for i, mirror in enumerate(MIRROR_FACTORS.names()):
            colour = f"C{i}"
            ax.plot(row["values"], [s["mean"] for s in row[mirror]], "o-", c=colour, label=mirror)
            ax.plot(row["values"], [s["p95"] for s in row[mirror]], "--", c=colour)
        ax.set_xlabel(labels[axis])
    axes[0].set_ylabel("ΔE00, hybrid against oracle")
    axes[0].legend(title="M_s", frameon=False)
    return ctx.figure(
        "oracle-sweeps",
        fig,
        "ΔE00 of the hybrid against the layered oracle over the sphere: mean (solid) and 95th "
        "percentile (dashed), per M_s (none: M_s ≡ 1; fresnel: specref's M_s; cosine: M_s = cos θ)",
    )


def _sweep_table(sweeps: dict) -> Table:
    rows = []
    for axis, row in sweeps.items():
        for i, value in enumerate(row["values"]):
            for mirror in MIRROR_FACTORS.names():
                s = row[mirror][i]
                rows.append(
                    [axis, value, mirror, s["mean"], s["p95"], s["max"], s["centre"], s["rim"]]
                )
    return Table(
        ["sweep", "value", "M_s", "mean", "p95", "max", "centre", "rim"],
        rows,
        "ΔE00 of the hybrid against the oracle over the sphere (centre: cos θ_v > 0.7; rim: "
        "cos θ_v < 0.3)",
        "{:.3g}",
    )


def _failure_text(oracle: dict) -> str:
    """Where the heuristic fails and by how much, from the sweeps' numbers."""
    sweeps, names = oracle["sweeps"], MIRROR_FACTORS.names()
    means = {m: [s["mean"] for row in sweeps.values() for s in row[m]] for m in names}
    best = min(means, key=lambda m: float(np.mean(means[m])))
    spread = float(np.ptp(np.array([means[m] for m in names]), axis=0).max())
    rim = float(np.mean([s["rim"] for row in sweeps.values() for s in row[best]]))
    centre = float(np.mean([s["centre"] for row in sweeps.values() for s in row[best]]))
    averages = ", ".join(f"{m} {np.mean(v):.2f}" for m, v in means.items())
    balance = "; ".join(
        f"{term} {b['rim']['hybrid'] / b['rim']['oracle']:.2f}× the oracle's at the rim "
        f"({b['centre']['hybrid'] / b['centre']['oracle']:.2f}× at the centre)"
        for term, b in oracle["balance"].items()
    )
    speed = oracle["speed"]
    ratio = speed["reference"]["seconds"] / speed["hybrid"][best]["seconds"]
    layered, split = speed["layered"], speed["layered_split_sum"]
    return (
        f"Where the heuristic fails (mean ΔE00 above {FAIL_DELTA_E:g} over the object or at the "
        "rim, per sweep and M_s): "
        + "; ".join(oracle["failures"])
        + f". Averaged over all sweeps the mean ΔE00 is {averages} (per M_s); the M_s variants "
        f"differ by at most {spread:.2f} in any mean, so the error is not the mirror term's. With "
        f"{best}, the rim (cos θ_v < 0.3) averages {rim:.2f} against {centre:.2f} at the centre "
        f"(cos θ_v > 0.7). On the base chip (band means): {balance} (I_d is not weighted by "
        f"1 − F_r in Eq. (1), Herbert et al.; erratum E34). The hybrid's frame is {ratio:.0f}× "
        "faster than the converged oracle's. The layered model (shrm.polymer.layered) on the "
        f"same chip: mean ΔE00 {layered['mean']:.2f} (rim {layered['rim']:.2f}), its maps "
        f"{layered['maps_seconds']:.2f} s (its pilot's choice of {layered.get('samples', '?')} "
        "samples per pixel included, erratum E118), a frame "
        f"{1e3 * layered['seconds']:.1f} ms, a re-shade "
        f"{1e3 * layered['reshade_seconds']:.2f} ms; with the split sum in place of its filtered "
        f"importance sampling: mean {split['mean']:.2f} (rim {split['rim']:.2f}), maps "
        f"{split['maps_seconds']:.2f} s, a frame {1e3 * split['seconds']:.1f} ms."
    )


def _speed_figure(ctx: ReportContext, speed: dict):
    """Time per frame against mean ΔE00 from the converged oracle."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.5, 3.6))
    runs = speed["oracle"]
    ax.loglog([r["seconds"] for r in runs], [r["mean"] for r in runs], "o-", c="k", label="oracle")
    for r in runs:
        ax.annotate(f"{r['samples']} spp", (r["seconds"], r["mean"]), fontsize=7)
    for i, (mirror, r) in enumerate(speed["hybrid"].items()):
        ax.loglog([r["seconds"]], [r["mean"]], "s", c=f"C{i}", label=f"hybrid, M_s = {mirror}")
    for key, colour, label in (
        ("layered", "C4", "layered model"),
        ("layered_split_sum", "C5", "layered model, split sum"),
    ):
        layered = speed[key]
        ax.loglog([layered["seconds"]], [layered["mean"]], "D", c=colour, label=label)
        ax.loglog(
            [layered["reshade_seconds"]], [layered["mean"]], "d", c=colour, mfc="none",
            label=f"{label}, re-shade",
        )  # fmt: skip
    ax.set_xlabel("seconds per frame")
    ax.set_ylabel("mean ΔE00 against the converged oracle")
    ax.legend(frameon=False, fontsize=8)
    reference = speed["reference"]
    return ctx.figure(
        "oracle-speed",
        fig,
        "Speed against accuracy on the base chip: the hybrid and the layered model from maps "
        "built beforehand (look-up and shading only; the layered model's re-shade after a change "
        "of the slab from its cached pixel parts) and the oracle at fixed sample counts (another "
        "seed), against the "
        f"oracle converged at {reference['samples']} samples per pixel "
        f"({reference['seconds']:.2f} s)",
    )


#: A dynamic change (thickness, TiO2) re-shades the layered model from its cached pixel
#: parts at least this much faster than a cold frame (its maps and a frame).
LAYERED_RESHADE_SPEEDUP = 20.0


def _oracle_checks(oracle: dict) -> list[Check]:
    """The oracle converged and equal to smooth plastic in the furnace; the layered re-shade."""
    reference = oracle["speed"]["reference"]
    tol = oracle["settings"]["tol"]
    furnace = oracle["furnace_error"]
    converged = reference["relative_error"] <= tol
    layered = oracle["speed"]["layered"]
    cold = layered["maps_seconds"] + layered["seconds"]
    return [
        Check(
            "oracle converged (p99 relative standard error of the rough lobe)",
            f"<= {tol:g}",
            reference["relative_error"],
            converged,
        ),
        Check(
            "oracle's opaque smooth limit against the smooth-plastic closed form (furnace)",
            "<= 1e-3",
            furnace,
            furnace <= 1e-3,
        ),
        Check(
            "layered model: a re-shade after a change of the slab against a cold frame (its maps "
            "and a frame), speed-up",
            f">= {LAYERED_RESHADE_SPEEDUP:g}×",
            cold / layered["reshade_seconds"],
            cold / layered["reshade_seconds"] >= LAYERED_RESHADE_SPEEDUP,
        ),
    ]


SECTION = ReportSection(
    "polymer",
    "Herbert hybrid model",
    polymer_study,
    present,
    checks,
    # the same checks on coarser sweeps (30 s less); specref report --full sweeps every value
    default_effort="quick",
    basis="design",  # Fig. 2's chips and the sweeps; the held-out chips and cells say so
)

"""Report section "Examples": renders of the example scenes, their times and a colour check.

The scenes are the examples shipped with specref (``data:examples``, ``reference/data/examples``),
so the report shows exactly what users render. The ColorChecker renders are also checked against
colour-science: at each patch centre, the rendered XYZ divided by the lamp's closed-form
``f_att cos θ`` must equal ``colour.sd_to_XYZ(..., method="ASTM E308")`` for that patch and lamp.

compute → :func:`example_renders`; present → :func:`present`; checks → :func:`checks`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import phong_table  # noqa: F401  (registers its shaders, as `specref render` does)
import shrm  # noqa: F401  (registers the environment-light shaders)
from reference.colour.colorimetry import XYZ_to_Lab, delta_E_00
from reference.colour.spectra import spectrum_to_colour_sd
from reference.data import data_path
from reference.geometry.camera import downsample_box
from reference.scene.colorchecker import ColorCheckerMaterial, colorchecker_patch_pixels
from reference.scene.lights import PointLight, attenuation_Wang
from reference.scene.loader import load_scene
from reference.scene.render import RenderResult, render_scene
from shrm.lobes import DEFAULT_TOL
from validation.report import (
    Check,
    Headline,
    ReportContext,
    ReportSection,
    SectionData,
    Table,
    Text,
)

#: The example scenes shipped with specref.
EXAMPLES_DIR = data_path("examples")
#: (file, image width in --quick mode); full mode uses each scene's own [render] table.
SCENES = (("colorchecker-d65.toml", 120), ("colorchecker-a.toml", 120), ("phong-sphere.toml", 128))
#: The environment-lit example, rendered by the frequency path and by the oracle, at this width.
ENV_SCENE, ENV_WIDTH, ENV_WIDTH_QUICK = "env-lambert-sphere.toml", 48, 20
#: The band weights of erratum E7: the ColorChecker render reproduces colour.sd_to_XYZ(ASTM E308)
#: to this (Y = 100 scale).
CHART_DXYZ_TARGET = 1e-9


def environment_oracle_error(scene_path: Path, width: int) -> dict:
    """Render an environment-lit scene by the SH frequency path and by brute force; compare.

    The brute-force path (``specref render --oracle``) integrates every environment pixel per
    shading point with the same upsampled spectra, so the difference is the SH truncation at the
    order that the frequency path picks for its accuracy (``shrm.accuracy``, 0.5 % mean and 2 % max
    per pixel by default); the check keeps the former bound, 1e-2 of the peak
    (``shrm.lobes.DEFAULT_TOL``).

    Returns
    -------
    dict
        ``max_error_of_peak`` (max |ΔY| over covered pixels ÷ max Y), ``frequency_s``,
        ``bruteforce_s``, ``tolerance``, ``renders`` (the two RenderResults).
    """
    scene = load_scene(scene_path)
    fast = render_scene(scene, width=width, supersample=1)
    slow = render_scene(scene, width=width, supersample=1, options={"environment": "bruteforce"})
    mask = fast.gbuffer.mask  # supersample 1: the G-buffer is at image resolution
    Y_fast, Y_slow = fast.XYZ[..., 1], slow.XYZ[..., 1]
    error = float(np.abs(Y_fast - Y_slow)[mask].max() / Y_slow[mask].max())
    return {
        "max_error_of_peak": error,
        "frequency_s": fast.timings["total"],
        "bruteforce_s": slow.timings["total"],
        "tolerance": DEFAULT_TOL,
        "renders": (fast, slow),
    }


def chart_accuracy(result: RenderResult) -> dict:
    """Rendered ColorChecker patch centres against colour-science's ASTM E308 XYZ.

    The render of a chart lit by one point light is ``f_att cos θ · (R @ W)`` at each sub-sample;
    dividing the box-filtered XYZ by the box-filtered ``f_att cos θ`` (closed form, from the
    G-buffer's positions and normals) leaves the patch XYZ, which colour-science computes
    independently from the same 10 nm data.

    Returns
    -------
    dict
        ``max_abs_dXYZ`` (Y = 1 scale), ``mean_dE00`` and ``max_dE00``.
    """
    import colour

    scene, g = result.scene, result.gbuffer
    chart = next(
        o for o in scene.objects if isinstance(scene.materials[o.material], ColorCheckerMaterial)
    )
    material = scene.materials[chart.material]
    light = next(light for light in scene.lights if isinstance(light, PointLight))
    to_light = np.asarray(light.position) - g.position
    d = np.linalg.norm(to_light, axis=-1)
    cos_theta = np.maximum(np.einsum("...i,...i->...", g.normal, to_light) / d, 0.0)
    factor = downsample_box(attenuation_Wang(d, *light.attenuation) * cos_theta, result.supersample)
    rows, columns = colorchecker_patch_pixels(
        scene.camera, chart, scene.render.width, scene.render.height
    ).T
    rendered = result.XYZ[rows, columns] / factor[rows, columns, None] / light.intensity
    cmfs = colour.MSDS_CMFS[scene.observer]
    illuminant = spectrum_to_colour_sd(light.spectrum)
    wl = scene.grid.wavelengths_nm
    with colour.utilities.suppress_warnings(colour_runtime_warnings=True):
        expected = np.stack(
            [
                colour.sd_to_XYZ(
                    colour.SpectralDistribution(R, wl), cmfs, illuminant, method="ASTM E308"
                )
                for R in material.patches
            ]
        )
        white = colour.sd_to_XYZ(
            colour.SpectralDistribution(np.ones_like(wl), wl), cmfs, illuminant, method="ASTM E308"
        )
    expected, white = expected / 100, white / 100
    dE = delta_E_00(XYZ_to_Lab(rendered, white), XYZ_to_Lab(expected, white))
    return {
        "max_abs_dXYZ": float(np.abs(rendered - expected).max()),
        "mean_dE00": float(dE.mean()),
        "max_dE00": float(dE.max()),
    }


def example_renders(
    ctx: ReportContext | None = None, width: int | None = None, env_width: int | None = None
) -> SectionData:
    """Render the docs example scenes, time them, and check the charts and the environment render.

    Parameters
    ----------
    ctx : ReportContext, optional
        ``ctx.quick``: each scene at its quick width (:data:`SCENES`), supersample 1, and the
        environment scene at :data:`ENV_WIDTH_QUICK`; otherwise each scene's own ``[render]``
        size and :data:`ENV_WIDTH`.
    width, env_width : int, optional
        Override the width of every scene (supersample 1) and of the environment scene.

    Returns
    -------
    SectionData
        ``results["scenes"]``: per scene, ``width``, ``height``, ``supersample``, ``seconds``
        (the render's timings), for the two charts ``accuracy`` (:func:`chart_accuracy`), and for
        :data:`ENV_SCENE` the figures of :func:`environment_oracle_error`.
        ``arrays``: ``encoded`` images by scene, and ``environment`` (frequency and oracle
        images).
    """
    quick = ctx is not None and ctx.quick
    renders: dict[str, RenderResult] = {}
    for name, quick_width in SCENES:
        scene = load_scene(EXAMPLES_DIR / name)
        size = {"width": width or quick_width, "supersample": 1} if quick or width else {}
        renders[name] = render_scene(scene, **size)
    results: dict = {"scenes": {}}
    for name, result in renders.items():
        r = result.scene.render
        results["scenes"][name] = {
            "width": r.width,
            "height": r.height,
            "supersample": r.supersample,
            "seconds": dict(result.timings),
        }
    for label in ("D65", "A"):
        name = f"colorchecker-{label.lower()}.toml"
        results["scenes"][name]["accuracy"] = chart_accuracy(renders[name])
    env_width = env_width or (ENV_WIDTH_QUICK if quick else ENV_WIDTH)
    env = environment_oracle_error(EXAMPLES_DIR / ENV_SCENE, env_width)
    fast, slow = env.pop("renders")
    results["scenes"][ENV_SCENE] = env
    arrays = {
        "encoded": {name: result.encoded for name, result in renders.items()},
        "environment": {
            "oracle": slow.RGB_linear,
            "frequency": fast.RGB_linear,
            "dY_of_peak": (fast.XYZ[..., 1] - slow.XYZ[..., 1]) / slow.XYZ[..., 1].max(),
        },
    }
    results["startup"] = startup_figures(ctx.bench_groups("startup") if ctx else {})
    return SectionData(results, arrays)


#: A warm kernel cache makes the first render of a fresh process cost at most this many times the
#: second render of the same process (``reference.jit``; ``make bench``, group startup-render).
WARM_START_TARGET = 1.5


def startup_figures(groups: dict) -> dict | None:
    """The first render in a fresh process, with numba's cache cold and warm (``make bench``).

    Parameters
    ----------
    groups : dict
        ``ReportContext.bench_groups("startup")``.

    Returns
    -------
    dict or None
        Per cache state (``cold``, ``warm``): the process's seconds and its ``import_s``,
        ``first_s``, ``second_s``; from a run that starts numba first (a one-line cached kernel's
        first call after the imports), ``numba_s`` and ``first_after_numba_s``; ``warm_ratio``
        (first over second render, warm cache) and ``warm_ratio_past_numba`` (the first render
        after numba's start-up over the second). None without benchmarks.

    Examples
    --------
    >>> startup_figures({}) is None
    True
    """
    records = {r["extra_info"].get("cache"): r for r in groups.get("startup-render", [])}
    if not {"cold", "warm"} <= set(records):
        return None
    found = {
        cache: {"process_s": r["stats"]["min"], **{k: r["extra_info"].get(k) for k in _STARTUP}}
        for cache, r in records.items()
    }
    warm = found["warm"]
    found["warm_ratio"] = warm["first_s"] / warm["second_s"]
    if warm["first_after_numba_s"] is not None:
        # what specref adds to the first render beyond numba's own start-up
        found["warm_ratio_past_numba"] = warm["first_after_numba_s"] / warm["second_s"]
    return found


_STARTUP = ("import_s", "first_s", "second_s", "numba_s", "first_after_numba_s")


_ACCURACY = ("max_abs_dXYZ", "mean_dE00", "max_dE00")


def _images(ctx: ReportContext, data: SectionData) -> list:
    """The charts side by side, the Phong sphere, and the environment render beside its oracle."""
    scenes, encoded = data.results["scenes"], data.arrays["encoded"]
    d65, a = encoded["colorchecker-d65.toml"], encoded["colorchecker-a.toml"]
    gap = np.ones((d65.shape[0], max(2, d65.shape[1] // 40), 3))
    env_images = data.arrays["environment"]
    env = scenes[ENV_SCENE]

    def seconds(name):
        return scenes[name]["seconds"]["total"]

    return [
        ctx.image(
            "colorchecker-d65-a",
            np.concatenate([d65, gap, a], axis=1),
            f"ColorChecker (N Ohta) under D65 (left, {seconds('colorchecker-d65.toml'):.2f} s) "
            f"and under illuminant A (right, {seconds('colorchecker-a.toml'):.2f} s), "
            "colorimetric sRGB without chromatic adaptation",
        ),
        ctx.image(
            "phong-sphere",
            encoded["phong-sphere.toml"],
            f"Spectral Phong sphere, exponent 4 (380 nm) to 800 (780 nm) "
            f"({seconds('phong-sphere.toml'):.2f} s)",
        ),
        ctx.comparison(
            "env-lambert-sphere",
            env_images["oracle"],
            env_images["frequency"],
            ("brute-force oracle", "SH frequency path"),
            f"A measured brick reflectance under st_fagans_interior: the SH frequency path "
            f"({env['frequency_s']:.2f} s) is {env['bruteforce_s'] / env['frequency_s']:.0f}× "
            f"faster than the brute-force oracle ({env['bruteforce_s']:.2f} s) and within "
            f"{100 * env['max_error_of_peak']:.2f} % of its peak everywhere",
            difference=env_images["dY_of_peak"],
            difference_label="ΔY / peak Y",
        ),
    ]


def _startup_blocks(startup: dict | None) -> list:
    """The first render of a fresh process, cold and warm kernel cache (or how to measure it)."""
    if startup is None:
        return [Text("First render in a fresh process: run `make bench` (group startup-render).")]
    rows = [[cache, *(startup[cache][k] for k in ("process_s", *_STARTUP))] for cache in _CACHES]
    caption = (
        "phong-sphere.toml at its own size through the compiled table shader, in a fresh "
        "`python` process (make bench, group startup-render). The last two columns come from "
        "another fresh process, same script and cache, with numba started before the first "
        "render (a one-line cached kernel's first call: numba's own start-up, which any numba "
        "program pays once)"
    )
    if "warm_ratio_past_numba" in startup:
        caption += (
            f": with a warm cache the first render is {startup['warm_ratio']:.2f}× the second, "
            f"{startup['warm_ratio_past_numba']:.2f}× without numba's start-up"
        )
    header = ["numba cache", "process s", "imports s", "first render s", "second render s"]
    header += ["numba's start-up s", "first render after it s"]
    return [Table(header, rows, caption, "{:.3g}")]


_CACHES = ("cold", "warm")


def present(ctx: ReportContext, data: SectionData) -> list:
    """The renders, their times and the chart accuracy table."""
    scenes = data.results["scenes"]
    rows = [
        [
            name,
            f"{s['width']}×{s['height']}",
            s["supersample"],
            s["seconds"]["gbuffer"],
            s["seconds"]["shading"],
            s["seconds"]["total"],
        ]
        for name, s in scenes.items()
        if name != ENV_SCENE
    ]
    accuracy_rows = [
        [label, *(scenes[f"colorchecker-{label.lower()}.toml"]["accuracy"][k] for k in _ACCURACY)]
        for label in ("D65", "A")
    ]
    return [
        Text(
            "The example scenes shipped with specref (`reference/data/examples/`), rendered by "
            "`reference.scene.render.render_scene` "
            f"({'small, supersample 1: --quick' if ctx.quick else 'at their own size'}). Render "
            "them yourself with `specref render data:examples/<name>.toml -o <name>.png`."
        ),
        *_images(ctx, data),
        *_startup_blocks(data.results["startup"]),
        Table(
            ["scene", "size", "supersample", "G-buffer s", "shading s", "total s"],
            rows,
            "Render times on this machine",
            "{:.3f}",
        ),
        Table(
            ["lamp", "max |ΔXYZ| (Y = 1)", "mean ΔE00", "max ΔE00"],
            accuracy_rows,
            "ColorChecker patch centres ÷ closed-form f_att cos θ against colour-science "
            "sd_to_XYZ (ASTM E308) on the same 10 nm data",
            "{:.2e}",
        ),
    ]


def checks(data: SectionData) -> list[Check]:
    """The two charts against colour-science, and the environment render against its oracle."""
    scenes = data.results["scenes"]
    found = []
    for label in ("D65", "A"):
        accuracy = scenes[f"colorchecker-{label.lower()}.toml"]["accuracy"]
        found.append(
            Check(
                f"ColorChecker under {label}: rendered patch XYZ vs colour.sd_to_XYZ (ASTM E308), "
                "Y = 100 scale",
                f"<= {CHART_DXYZ_TARGET:g}",
                100 * accuracy["max_abs_dXYZ"],
                100 * accuracy["max_abs_dXYZ"] <= CHART_DXYZ_TARGET,
                "independent",
            )
        )
    env = scenes[ENV_SCENE]
    found.append(
        Check(
            f"{ENV_SCENE}: SH frequency render vs brute-force oracle, max |ΔY| / peak",
            f"<= {env['tolerance']:g} (the adaptive-order tolerance)",
            env["max_error_of_peak"],
            env["max_error_of_peak"] <= env["tolerance"],
        )
    )
    startup = data.results.get("startup")
    if startup is not None:
        name = "first render in a fresh process, warm kernel cache, over the second render"
        found.append(Check.at_most(name, startup["warm_ratio"], WARM_START_TARGET))
    return found


def headlines(data: SectionData) -> list[Headline]:
    """The summary's figures: the ColorChecker renders and the environment render."""
    scenes = data.results["scenes"]
    chart = max(
        100 * scenes[f"colorchecker-{label}.toml"]["accuracy"]["max_abs_dXYZ"]
        for label in ("d65", "a")
    )
    env = scenes[ENV_SCENE]
    speed_up = env["bruteforce_s"] / env["frequency_s"]
    return [
        Headline(
            f"the documentation's ColorChecker scenes render colour-science's XYZ to {chart:.1e} "
            "(Y = 100)",
            f"target ≤ {CHART_DXYZ_TARGET:g}",
        ),
        Headline(
            f"a measured brick under a real interior map: SH path {speed_up:.0f}× "
            f"faster than brute force, within {100 * env['max_error_of_peak']:.2f} % of the peak",
            f"tolerance {100 * env['tolerance']:g} %",
        ),
    ]


SECTION = ReportSection(
    "examples",
    "Examples",
    example_renders,
    present,
    checks,
    headlines=headlines,
    hero="colorchecker-d65-a",
    basis="design",  # the shipped examples
)

"""Report section "Examples": renders of the docs example scenes, their times and a colour check.

The scenes are read from the source tree (``docs/examples``), so the report shows exactly what the
docs ship. The ColorChecker renders are also checked against colour-science: at each patch centre,
the rendered XYZ divided by the lamp's closed-form ``f_att cos θ`` must equal
``colour.sd_to_XYZ(..., method="ASTM E308")`` for that patch and lamp.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import phong_table  # noqa: F401  (registers its shaders, as `specref render` does)
import shrm  # noqa: F401  (registers the environment-light shaders)
from reference.camera import downsample_box
from reference.colorchecker import ColorCheckerMaterial, colorchecker_patch_pixels
from reference.colorimetry import XYZ_to_Lab, delta_E_00
from reference.lights import PointLight, attenuation_Wang
from reference.render import RenderResult, render_scene
from reference.scene import load_scene
from reference.spectra import spectrum_to_colour_sd
from shrm.lobes import DEFAULT_TOL
from validation.report import (
    Check,
    ReportContext,
    ReportSection,
    SectionResult,
    Table,
    Text,
)

#: Where the docs examples live in a source checkout.
EXAMPLES_DIR = Path(__file__).resolve().parents[2] / "docs" / "examples"
#: (file, image width in --quick mode); full mode uses each scene's own [render] table.
SCENES = (("colorchecker-d65.toml", 120), ("colorchecker-a.toml", 120), ("phong-sphere.toml", 128))
#: The environment-lit example, rendered by the frequency path and by the oracle, at this width.
ENV_SCENE, ENV_WIDTH, ENV_WIDTH_QUICK = "env-lambert-sphere.toml", 48, 20
#: Issue 3: the ColorChecker render reproduces colour.sd_to_XYZ(ASTM E308) to this (Y = 100 scale).
CHART_DXYZ_TARGET = 1e-9


def environment_oracle_error(scene_path: Path, width: int) -> dict:
    """Render an environment-lit scene by the SH frequency path and by brute force; compare.

    The brute-force path (``specref render --oracle``) integrates every environment pixel per
    shading point with the same upsampled spectra, so the difference is the SH truncation at the
    adaptive order that the frequency path picks for its tolerance (``shrm.lobes.DEFAULT_TOL``).

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


def run(ctx: ReportContext) -> SectionResult:
    """Render the example scenes (small with ``--quick``), time them, check the charts."""
    if not all((EXAMPLES_DIR / name).is_file() for name, _ in SCENES):
        missing = [name for name, _ in SCENES if not (EXAMPLES_DIR / name).is_file()]
        text = (
            f"The docs example scenes are missing from {EXAMPLES_DIR} ({', '.join(missing)}): "
            "this section reads them from a source checkout, so nothing was rendered."
        )
        return SectionResult([Text(text)], {"missing": missing})
    renders: dict[str, RenderResult] = {}
    for name, quick_width in SCENES:
        scene = load_scene(EXAMPLES_DIR / name)
        size = {"width": quick_width, "supersample": 1} if ctx.quick else {}
        renders[name] = render_scene(scene, **size)
    results: dict = {"scenes": {}}
    rows = []
    for name, result in renders.items():
        r, t = result.scene.render, result.timings
        rows.append(
            [name, f"{r.width}×{r.height}", r.supersample, t["gbuffer"], t["shading"], t["total"]]
        )
        results["scenes"][name] = {
            "width": r.width,
            "height": r.height,
            "supersample": r.supersample,
            "seconds": dict(t),
        }
    d65, a = renders["colorchecker-d65.toml"], renders["colorchecker-a.toml"]
    gap = np.ones((d65.encoded.shape[0], max(2, d65.encoded.shape[1] // 40), 3))
    side_by_side = np.concatenate([d65.encoded, gap, a.encoded], axis=1)
    sphere = renders["phong-sphere.toml"]
    accuracy_rows, checks = [], []
    for label, result in (("D65", d65), ("A", a)):
        accuracy = chart_accuracy(result)
        results["scenes"][f"colorchecker-{label.lower()}.toml"]["accuracy"] = accuracy
        accuracy_rows.append(
            [label, accuracy["max_abs_dXYZ"], accuracy["mean_dE00"], accuracy["max_dE00"]]
        )
        checks.append(
            Check(
                f"ColorChecker under {label}: rendered patch XYZ vs colour.sd_to_XYZ (ASTM E308), "
                "Y = 100 scale",
                f"<= {CHART_DXYZ_TARGET:g}",
                100 * accuracy["max_abs_dXYZ"],
                100 * accuracy["max_abs_dXYZ"] <= CHART_DXYZ_TARGET,
            )
        )
    env = environment_oracle_error(
        EXAMPLES_DIR / ENV_SCENE, ENV_WIDTH_QUICK if ctx.quick else ENV_WIDTH
    )
    fast, slow = env.pop("renders")
    results["scenes"][ENV_SCENE] = env
    checks.append(
        Check(
            f"{ENV_SCENE}: SH frequency render vs brute-force oracle, max |ΔY| / peak",
            f"<= {env['tolerance']:g} (the adaptive-order tolerance)",
            env["max_error_of_peak"],
            env["max_error_of_peak"] <= env["tolerance"],
        )
    )
    blocks = [
        Text(
            "The scenes in `docs/examples/`, rendered by `reference.render.render_scene` "
            f"({'small, supersample 1: --quick' if ctx.quick else 'at their own size'}). Render "
            "them yourself with `specref render docs/examples/<name>.toml -o <name>.png`."
        ),
        ctx.image(
            "colorchecker-d65-a",
            side_by_side,
            f"ColorChecker (N Ohta) under D65 (left, {d65.timings['total']:.2f} s) and under "
            f"illuminant A (right, {a.timings['total']:.2f} s), colorimetric sRGB without "
            "chromatic adaptation",
        ),
        ctx.image(
            "phong-sphere",
            sphere.encoded,
            f"Spectral Phong sphere, exponent 4 (380 nm) to 800 (780 nm) "
            f"({sphere.timings['total']:.2f} s)",
        ),
        ctx.image(
            "env-lambert-sphere",
            np.concatenate([fast.encoded, np.ones((fast.encoded.shape[0], 2, 3)), slow.encoded], 1),
            f"Measured brick reflectance under st_fagans_interior: SH frequency path (left, "
            f"{env['frequency_s']:.2f} s) and brute-force oracle (right, "
            f"{env['bruteforce_s']:.2f} s); "
            f"max difference {100 * env['max_error_of_peak']:.2f} % of peak",
        ),
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
    return SectionResult(blocks, results, checks)


SECTION = ReportSection("examples", "Examples", legacy_run=run)

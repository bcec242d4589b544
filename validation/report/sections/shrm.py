"""Report section "SHRMs": image error against per-pixel brute force, creation and extraction times.

§5.5-5.6, Herbert et al. For each synthesized isotropic BRDF under a shared environment:

- the image error of SHRM rendering against a per-pixel brute-force render (every pixel integrates
  BRDF × environment over all environment pixels), as a function of the view order P, the
  lighting order F, the cube-map size, the frame and the view fit (:mod:`shrm.brdf_sh`: in the
  normal frame the hemisphere fit, and for comparison R&H 2002's projection over all views),
  marking the cheapest setting (by measured creation time) under a tolerance of 1 % of the peak
  (:mod:`validation.report.sections.shrm_study`);
- the creation time in frequency space against angular (brute-force) creation, on the same input
  and the same texels (the angular path on a few of them: its cost is the same for every texel,
  so the ratio is per texel);
- the extraction time per viewpoint against the creation time, and a persistent-cache hit against
  a rebuild;
- the per-stage times of a camera orbit of the change-driven render session (§5.2)
  (:mod:`validation.report.sections.shrm_speed`).

compute → :func:`shrm_study_and_speed`; present → :func:`present`; checks → :func:`checks`.
Every target is a :class:`validation.report.Check`; ``--quick`` checks reduced versions
(named so).
"""

from __future__ import annotations

import numpy as np

from validation.report import (
    Check,
    ReportContext,
    ReportSection,
    SectionData,
    Table,
    Text,
)
from validation.report.sections.shrm_speed import (
    bench_rows,
    creation_speed,
    extraction_speed,
    orbit_stage_times,
    speed_blocks,
    speed_checks,
)
from validation.report.sections.shrm_study import (
    FITS,
    SUITE,
    TOLERANCE,
    study_brdf,
    study_setup,
    sweep_plan,
)

__all__ = ["SETTINGS", "shrm_study_and_speed"]

#: The BRDF whose images the report shows and whose chosen setting the speed figures time.
SHOWN = "ggx"
_SMALL_ORBIT = {"env_height": 16, "size": 8, "resolution": 24, "F_max": 8, "P_max": 4}
#: Sizes per mode: environment rows, image side, the sweep plan, angular texels of the creation
#: comparison, cube size of the extraction comparison, the orbit's scene and frames, and the
#: prefix of the check names. ``tiny`` is for tests: every figure, on small inputs.
SETTINGS = {
    "full": {
        "rows": 64,
        "size": 48,
        "plan": sweep_plan(quick=False),
        "angular_texels": 4,
        "extraction_size": 64,
        "orbit": {},
        "orbit_frames": 8,
        "label": "",
    },
    "quick": {
        "rows": 16,
        "size": 20,
        "plan": sweep_plan(quick=True),
        "angular_texels": 2,
        "extraction_size": 16,
        "orbit": _SMALL_ORBIT,
        "orbit_frames": 3,
        "label": "quick (16-row environment, 20² image): ",
    },
    "tiny": {
        "rows": 8,
        "size": 8,
        "plan": {"P": (2, 4), **{fit: ((4, 8),) for fit in FITS}},
        "angular_texels": 1,
        "extraction_size": 8,
        "orbit": {"env_height": 8, "size": 4, "resolution": 8, "F_max": 2, "P_max": 2},
        "orbit_frames": 2,
        "label": "tiny (8-row environment, 8² image): ",
    },
}


def _study_task(task) -> dict:
    # one BRDF's setting search (a task of ReportContext.run_tasks)
    return study_brdf(*task)


def shrm_study_and_speed(ctx: ReportContext, settings: dict | None = None) -> SectionData:
    """The accuracy study per BRDF of :data:`SUITE`, then creation, extraction, cache and orbit.

    Parameters
    ----------
    ctx : ReportContext
        ``ctx.quick`` picks the sizes; ``ctx.bench`` gives the ``shrm-*`` benchmark groups.
    settings : dict, optional
        One of :data:`SETTINGS` (default ``"quick"`` or ``"full"`` by ``ctx.quick``).

    Returns
    -------
    SectionData
        ``results``: per BRDF its chosen setting, errors and sweep; ``creation``, ``extraction``,
        ``cache``, ``orbit`` and (with benchmarks) ``bench``. ``arrays``: the plan, the studies,
        the shown BRDF's images, the environment's shape, the benchmark groups and the label of
        the check names.

    Examples
    --------
    >>> data = shrm_study_and_speed(ReportContext("."), SETTINGS["tiny"])
    >>> list(data.results)[len(SUITE):]
    ['creation', 'extraction', 'cache', 'orbit']
    >>> len(checks(data)) == 2 * len(SUITE) + 3
    True
    """
    from shrm.transform import project_latlong

    s = settings or SETTINGS["quick" if ctx.quick else "full"]
    env, g, view = study_setup(ctx.quick, s["rows"], s["size"])
    plan = s["plan"]
    F_env = max(F for key in FITS for F, _ in plan[key])
    L_env = project_latlong(env, F_env, backend="ducc0")
    data = SectionData()
    # the setting search, one task per BRDF (serial, or on the report's cluster)
    tasks = [(name, env, L_env, g, view, plan) for name in SUITE]
    found = ctx.run_tasks(_study_task, tasks, "SHRM setting search")
    studies = dict(zip(SUITE, found, strict=True))
    for name, st in studies.items():
        data.results[name] = _study_results(st)
    data.arrays.update(plan=plan, studies=studies, env_shape=env.shape, label=s["label"])
    data.arrays["images"] = _shown_images(studies[SHOWN], g, view)
    # The speed half (validation.report.sections.shrm_speed), at the shown BRDF's chosen setting
    choice = {"brdf": SHOWN, **data.results[SHOWN]}
    creation = data.results["creation"] = creation_speed(
        env, L_env, view, choice, s["angular_texels"]
    )
    data.results["extraction"], data.results["cache"] = extraction_speed(
        env,
        L_env,
        studies[SHOWN]["rho"],
        choice,
        s["extraction_size"],
        creation["brdf_projection_seconds"],
    )
    data.results["orbit"] = orbit_stage_times(s["orbit"], s["orbit_frames"])
    groups = data.arrays["bench_groups"] = ctx.bench_groups("shrm-")
    if groups:
        data.results["bench"] = bench_rows(groups)
    return data


def _study_results(st: dict) -> dict:
    """The results.json entry of one BRDF's study."""
    frame, F, P, S, err, inner, fit = st["choice"]
    low, sphere = st["best_with_P_at_most_10"], st["best_sphere_fit_with_P_at_most_10"]
    return {
        "bruteforce_seconds": st["bruteforce_seconds"],
        "cheapest_under_tolerance": st["meets_tolerance"],
        "frame": frame,
        "view_fit": fit,
        "F": F,
        "P": P,
        "size": S,
        "create_seconds": st["create_seconds"],
        "max_error": err,
        "error_away_from_silhouette": inner,
        "best_error_with_P_at_most_10": low[4],
        "best_setting_with_P_at_most_10": [*low[:4], low[6]],
        "best_sphere_fit_error_with_P_at_most_10": sphere[4],
        "lambert_split": st["lambert_split"],
        "grazing_view_power": st["grazing_view_power"],
        "sweep": [list(c) for c in st["candidates"]],
    }


def _shown_images(st: dict, g, view) -> dict:
    """Brute force and SHRM at the chosen setting, and their difference over 1 % of the peak."""
    from shrm.shrm import render_shrm

    image, truth = render_shrm(g, st["shrm"], view), st["truth"]
    peak = truth[g.mask].max()
    return {
        "truth": truth,
        "shrm": image,
        "peak": peak,
        "difference": np.abs(image - truth).max(-1) / peak / TOLERANCE,
    }


def present(ctx: ReportContext, data: SectionData) -> list:
    """The study's text, table, error chart and images, then the speed tables (module docstring)."""
    env_shape = data.arrays["env_shape"]
    blocks = [
        Text(
            "A sphere under `venice_sunset_1k.hdr` (box-filtered to "
            f"{env_shape[0]}×{env_shape[1]}, RGB), orthographic camera (distant viewer, as global "
            "SHRMs assume), each synthesized BRDF rendered through the G-buffer from its SHRM and "
            "by per-pixel brute force (every pixel sums BRDF × environment over all environment "
            "pixels). The Lambertian part ρ_d/π of Ward, GGX and Lafortune is split off and "
            "rendered from an irradiance map; Ward's 1/sqrt(cos θ_o) is factored out of its "
            "SHRM (`shrm.brdf_sh.shrm_brdf_parts`). In the normal frame the view dependence is "
            "fitted to the views above each texel's horizon (the hemisphere fit of "
            "`shrm.brdf_sh`); R&H 2002's projection over all views (sphere fit, views below the "
            "horizon mirrored) is swept for comparison. Error is the largest per-pixel difference "
            f"over the peak; the target is {TOLERANCE:.0%}. The chosen setting is the fastest to "
            "create (measured) among those that meet the target (or, failing that, the most "
            "accurate). The last columns are the best any setting with P <= 10 (the top of §5.5's "
            "range) reaches, and the best with the sphere fit."
        ),
        _choice_table(data.results),
        _error_chart(ctx, data.arrays["studies"], data.arrays["plan"]),
        *_image_blocks(ctx, data.results[SHOWN], data.arrays["images"]),
    ]
    return blocks + speed_blocks(ctx, data.results)


def _choice_table(results: dict) -> Table:
    rows = []
    for name in SUITE:
        r = results[name]
        rows.append(
            [
                name,
                "yes" if r["cheapest_under_tolerance"] else "no",
                f"{r['frame']} ({r['view_fit']})",
                r["F"],
                r["P"],
                r["size"],
                r["max_error"],
                r["error_away_from_silhouette"],
                r["create_seconds"],
                r["best_error_with_P_at_most_10"],
                r["best_sphere_fit_error_with_P_at_most_10"],
            ]
        )
    return Table(
        [
            "BRDF",
            "meets 1 %",
            "frame (view fit)",
            "F",
            "P",
            "cube size",
            "max error",
            "error N·V>0.2",
            "create s",
            "best, P <= 10",
            "best, P <= 10, sphere fit",
        ],
        rows,
        "Cheapest SHRM setting under the tolerance, per BRDF",
        "{:.4g}",
    )


def _error_chart(ctx, studies, plan):
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(studies), figsize=(4.2 * len(studies), 3.6), sharey=True)
    for ax, (name, st) in zip(np.atleast_1d(axes), studies.items(), strict=True):
        for frame, fit in FITS:
            for F, S in plan[(frame, fit)]:
                errs = [
                    c[4] for c in st["candidates"] if (c[0], c[1], c[3], c[6]) == (frame, F, S, fit)
                ]
                style = {"hemisphere": "-", "sphere": "--" if frame == "normal" else ":"}[fit]
                label = f"{frame} ({fit} fit), F={F}, S={S}"
                ax.plot(plan["P"], errs, style, marker="o", ms=3, label=label)
        ax.axhline(TOLERANCE, color="k", lw=0.8, ls="--")
        ax.axvline(10, color="grey", lw=0.6, ls=":")
        c = st["choice"]
        ax.plot([c[2]], [c[4]], marker="*", ms=14, color="gold", mec="k")
        ax.set_yscale("log")
        ax.set_xlabel("view order P")
        ax.set_title(name, fontsize=9)
    np.atleast_1d(axes)[0].set_ylabel("max |SHRM − brute force| / peak")
    np.atleast_1d(axes)[-1].legend(fontsize=6)
    return ctx.figure(
        "error-vs-P",
        fig,
        "Image error against P, per frame, view fit, F and cube size S; black dashed: the 1 % "
        "target; dotted: P = 10, the top of §5.5's range; star: the cheapest setting under the "
        "target",
    )


def _image_blocks(ctx, choice: dict, images: dict) -> list:
    """Brute force | SHRM at the chosen setting | their difference, for the shown BRDF."""
    truth, shrm = images["truth"], images["shrm"]
    signed = (shrm - truth).mean(axis=-1) / images["peak"]
    worst = float(np.abs(shrm - truth).max() / images["peak"])
    verdict = "within" if worst <= TOLERANCE else "outside"
    return [
        ctx.comparison(
            f"{SHOWN}-comparison",
            truth,
            shrm,
            ("brute force", f"SHRM {choice['frame']} F={choice['F']} P={choice['P']}"),
            f"{SHOWN} under the study's box-filtered environment: the SHRM at the cheapest setting "
            f"that meets the tolerance is {verdict} {100 * TOLERANCE:g} % of the peak "
            f"(largest difference {100 * worst:.2f} %)",
            difference=signed,
            difference_label="(SHRM − brute force) / peak",
        )
    ]


def checks(data: SectionData) -> list[Check]:
    """Per BRDF: within 1 % of peak, and within 1 % with P <= 10; then the speed targets."""
    label, found = data.arrays["label"], []
    for name in SUITE:
        r = data.results[name]
        frame, fit, F, P, S, err = (
            r[k] for k in ("frame", "view_fit", "F", "P", "size", "max_error")
        )
        low_frame, low_F, low_P, low_S, low_fit = r["best_setting_with_P_at_most_10"]
        low_err = r["best_error_with_P_at_most_10"]
        found.append(
            Check(
                f"{label}image within 1 % of peak of brute force, {name} "
                f"({frame} {fit} fit F={F} P={P} S={S})",
                f"<= {TOLERANCE:g}",
                err,
                err <= TOLERANCE,
            )
        )
        # the same target inside §5.5's view orders, P from 2 to 10 (erratum E23)
        found.append(
            Check(
                f"{label}image within 1 % of peak of brute force with P <= 10 (§5.5), {name} "
                f"(best: {low_frame} {low_fit} fit F={low_F} P={low_P} S={low_S})",
                f"<= {TOLERANCE:g}",
                low_err,
                low_err <= TOLERANCE,
            )
        )
    return found + speed_checks(data.arrays["bench_groups"], data.results, label)


SECTION = ReportSection(
    "shrm",
    "SHRMs",
    shrm_study_and_speed,
    present,
    checks,
    default_effort="quick",  # the full settings take minutes: specref report --full
    basis="design",  # the environment the fits were chosen on
)

"""The speed half of the report section "SHRMs" (:mod:`validation.report.sections.shrm`).

§5.5-5.6, Herbert et al.; the speed targets as checks:

- creation in frequency space against angular (brute-force) creation, on the same input and the
  same texels, per texel and at equal error (>= 100×);
- extraction of a reflection map for a new viewpoint against creation (>= 50×);
- a persistent-cache hit against a rebuild (>= 20×);
- and, without a target, the per-stage times of a camera orbit of the render session (§5.2).

Each is measured in the run (:func:`creation_speed`, :func:`extraction_speed`,
:func:`orbit_stage_times`); the checks (:func:`speed_checks`) read ``make bench``
(tests/benchmarks/bench_shrm.py) when it is given and the in-run measurement otherwise, and name
their source.
"""

from __future__ import annotations

import tempfile
import time

import numpy as np

from validation.report import Check, ReportContext, Table, Text
from validation.report.sections.shrm_study import TOLERANCE, create_timed, rho_corner, study_params

__all__ = ["bench_ratio", "bench_rows", "creation_speed", "extraction_speed", "speed_checks"]

#: The speed targets (ratios measured in one run).
CREATION_RATIO, EXTRACTION_RATIO, CACHE_RATIO = 100.0, 50.0, 20.0
#: Cube size of the creation comparison (frequency path on all its texels).
CREATION_SIZE = 8


def creation_speed(env, L_env, view, choice: dict, n_angular: int) -> dict:
    """Creation in frequency space against angular creation, per texel, same input and texels.

    Parameters
    ----------
    env : ndarray, shape (H, 2H, C)
        The environment; ``L_env`` its SH coefficients (at least to the chosen F).
    view : ndarray, shape (3,)
    choice : dict
        The study's entry of the BRDF (``brdf``, ``frame``, ``F``, ``P``, ``view_fit``).
    n_angular : int
        Texels the angular path integrates (a spread among those facing the view).

    Returns
    -------
    dict
        Both times (total and per texel), their ratio (also with the BRDF projection counted),
        and both errors against brute-force reflected radiance at those texels, over its peak.

    Examples
    --------
    >>> from shrm.transform import project_latlong
    >>> env = np.ones((8, 16, 1)); view = np.array([0.0, 0.0, 1.0])
    >>> choice = {"brdf": "ggx", "frame": "normal", "F": 2, "P": 2, "view_fit": "hemisphere"}
    >>> c = creation_speed(env, project_latlong(env, 2), view, choice, 1)
    >>> c["frequency_texels"], c["angular_texels"], c["ratio"] > 0
    (384, 1, True)
    """
    from reference.geometry.cubemap import cubemap_texel_directions
    from shrm.brdf_sh import brdf_sh_coefficients, shrm_brdf_parts
    from shrm.sh import sh_basis
    from shrm.shrm import shrm_extract
    from shrm.shrm_oracles import env_quadrature, reflected_bruteforce, shrm_texels_angular

    name, frame, F, P, fit = (choice[k] for k in ("brdf", "frame", "F", "P", "view_fit"))
    brdf, expand, _, k = shrm_brdf_parts(name, study_params(name))
    start = time.perf_counter()
    rho = brdf_sh_coefficients(brdf, expand, F, P, frame, view_power=k, view_fit=fit)
    t_rho = time.perf_counter() - start
    freq, t_freq = create_timed(L_env, rho, frame, F, CREATION_SIZE, k, None)
    texels = cubemap_texel_directions(CREATION_SIZE).reshape(-1, 3)
    # A spread of texels for the angular path (its cost does not depend on which), among those
    # the view sees (N·v > 0.2, as the benchmark picks them): only there is the error one a
    # render can show (in the normal frame a texel's views below its horizon are never read)
    front = np.nonzero(texels @ view > 0.2)[0]
    pick = front[np.linspace(0, front.size - 1, n_angular).round().astype(int)]
    start = time.perf_counter()
    angular = shrm_texels_angular(env, brdf, expand, P, texels[pick], frame, k, fit)
    t_ang = time.perf_counter() - start
    # Errors of both against the brute-force reflected radiance at those texels, one view
    views = np.broadcast_to(view, (pick.size, 3))
    truth = reflected_bruteforce(brdf, expand, frame, texels[pick], views, env_quadrature(env), k)
    Y = sh_basis(P, view[None])[0]
    f_vals = shrm_extract(freq, view).reshape(-1, truth.shape[-1])[pick]
    per_f, per_a = t_freq / texels.shape[0], t_ang / pick.size
    return {
        "brdf": name,
        "frame": frame,
        "view_fit": fit,
        "F": F,
        "P": P,
        "frequency_texels": int(texels.shape[0]),
        "angular_texels": int(pick.size),
        "frequency_seconds": t_freq,
        "angular_seconds": t_ang,
        "brdf_projection_seconds": t_rho,
        "frequency_seconds_per_texel": per_f,
        "angular_seconds_per_texel": per_a,
        "ratio": per_a / per_f,
        "ratio_with_brdf_projection": per_a / ((t_freq + t_rho) / texels.shape[0]),
        "frequency_error": float(np.abs(f_vals - truth).max() / np.abs(truth).max()),
        "angular_error": float(np.abs(angular @ Y - truth).max() / np.abs(truth).max()),
    }


def extraction_speed(env, L_env, rho, choice: dict, size: int, t_rho: float):
    """Extraction per viewpoint and a persistent-cache hit, against creation at ``size``² × 6.

    ``rho`` are the study's BRDF coefficients of the choice (at least to its F and P) and
    ``t_rho`` the seconds their projection took (part of a rebuild).

    Returns
    -------
    extraction : dict
        ``size``, ``create_seconds``, ``extract_seconds`` (per viewpoint, mean of 8), ``ratio``.
    cache : dict
        ``hit_seconds`` (median of 5), ``rebuild_seconds`` (projections and creation), ``ratio``.

    Examples
    --------
    >>> from shrm.brdf_sh import brdf_sh_coefficients, shrm_brdf_parts
    >>> from shrm.transform import project_latlong
    >>> env = np.ones((8, 16, 3))
    >>> brdf, expand, _, k = shrm_brdf_parts("ggx", study_params("ggx"))
    >>> rho = brdf_sh_coefficients(brdf, expand, 2, 2, "normal", view_power=k)
    >>> choice = {"brdf": "ggx", "frame": "normal", "F": 2, "P": 2}
    >>> ex, cache = extraction_speed(env, project_latlong(env, 2), rho, choice, 4, 0.0)
    >>> ex["size"], ex["ratio"] > 0, cache["ratio"] > 0
    (4, True, True)
    """
    from shrm.brdf_sh import shrm_brdf_parts
    from shrm.cache import Cache, cache_key
    from shrm.shrm import shrm_extract
    from shrm.transform import project_latlong

    name, frame, F, P = (choice[k] for k in ("brdf", "frame", "F", "P"))
    _, _, lam, k = shrm_brdf_parts(name, study_params(name))
    rho = rho_corner(rho, F, P)
    big, t_big = create_timed(L_env, rho, frame, F, size, k, lam)
    views = [
        np.array([np.sin(a), 0.3, np.cos(a)]) for a in np.linspace(0, 2 * np.pi, 8, endpoint=False)
    ]
    start = time.perf_counter()
    for v in views:
        shrm_extract(big, v / np.linalg.norm(v))
    t_ex = (time.perf_counter() - start) / len(views)
    # A persistent-cache hit against a rebuild (projection of environment and BRDF, creation)
    env_coeffs = L_env[:, : (F + 1) ** 2]
    with tempfile.TemporaryDirectory() as folder:
        cache = Cache(folder)
        key = cache_key("shrm.create", "1", {"L": env_coeffs, "rho": rho, "size": size})
        cache.put(key, {"coeffs": big.coeffs, "irradiance": big.irradiance})
        hits = []
        for _ in range(5):
            start = time.perf_counter()
            cache.get(key)
            hits.append(time.perf_counter() - start)
    start = time.perf_counter()
    project_latlong(env, F, backend="ducc0")
    t_project = time.perf_counter() - start
    rebuild = t_project + t_big + t_rho
    t_hit = float(np.median(hits))
    extraction = {"size": size, "create_seconds": t_big, "extract_seconds": t_ex}
    extraction["ratio"] = t_big / t_ex
    return extraction, {"hit_seconds": t_hit, "rebuild_seconds": rebuild, "ratio": rebuild / t_hit}


def orbit_stage_times(state_settings: dict, frames: int) -> dict:
    """Per-stage seconds of each frame of a camera orbit of the render session (§5.2).

    Returns
    -------
    dict
        ``stages`` (names) and ``seconds``: per frame, each stage's seconds (0 = reused) and the
        total.

    Examples
    --------
    >>> small = {"env_height": 8, "size": 4, "resolution": 8, "F_max": 2, "P_max": 2}
    >>> orbit = orbit_stage_times(small, 2)
    >>> len(orbit["seconds"]), len(orbit["seconds"][0]) == len(orbit["stages"]) + 1
    (2, True)
    """
    from shrm.orbit import demo_state, render_orbit
    from shrm.session import RenderSession

    session = RenderSession(demo_state(brdf="lafortune", **state_settings))
    times = render_orbit(session, frames, progress=False)
    names = [s.name for s in session.stages]
    seconds = [[t.get(n, 0.0) for n in names] + [sum(t.values())] for t in times]
    return {"stages": names, "seconds": seconds}


def bench_rows(groups: dict) -> list[list]:
    """Rows of ``make bench``'s ``shrm-*`` groups: group, name, median, per texel, ratio, error.

    Examples
    --------
    >>> base = {"name": "a::base", "stats": {"median": 2.0}, "extra_info": {"role": "baseline"}}
    >>> fast = {"name": "a::fast", "stats": {"median": 0.5}, "extra_info": {"error": 0.01}}
    >>> bench_rows({"shrm-x": [base, fast]})[1]
    ['shrm-x', 'fast', 0.5, 0.5, 4.0, 0.01]
    """
    rows = []
    for group, records in sorted(groups.items()):
        ratio = bench_ratio(records)[0]
        for r in sorted(records, key=lambda r: r["name"]):
            info = r.get("extra_info", {})
            rows.append(
                [
                    group,
                    r["name"].split("::")[-1],
                    r["stats"]["median"],
                    r["stats"]["median"] / info.get("texels", 1),
                    ratio if info.get("role") != "baseline" else float("nan"),
                    info.get("error", float("nan")),
                ]
            )
    return rows


def bench_ratio(records: list[dict]) -> tuple[float, dict, dict]:
    """Baseline over method time of one ``make bench`` group, per texel; and both records.

    Each record's median is divided by its ``extra_info["texels"]`` (1 if absent): the angular
    baseline runs on fewer texels than the frequency path.

    Examples
    --------
    >>> base = {"stats": {"median": 2.0}, "extra_info": {"role": "baseline", "texels": 4}}
    >>> fast = {"stats": {"median": 0.5}, "extra_info": {"texels": 100}}
    >>> bench_ratio([base, fast])[0]
    100.0
    """
    base = [r for r in records if r.get("extra_info", {}).get("role") == "baseline"]
    other = [r for r in records if r not in base]
    if len(base) != 1 or len(other) != 1:
        return float("nan"), {}, {}

    def per(r):
        return r["stats"]["median"] / r.get("extra_info", {}).get("texels", 1)

    return per(base[0]) / per(other[0]), base[0], other[0]


def _creation_check(what, ratio, err_f, err_a) -> Check:
    """Frequency ≥ 100× faster per texel at equal error (no worse than angular, or within 1 %)."""
    equal = err_f <= max(err_a, TOLERANCE)
    return Check(
        f"{what} (errors: frequency {err_f:.3g}, angular {err_a:.3g} of peak)",
        f">= {CREATION_RATIO:g}× at error <= max(angular, {TOLERANCE:g})",
        ratio,
        bool(ratio >= CREATION_RATIO and equal),
    )


def speed_checks(groups: dict, results: dict, label: str = "") -> list:
    """The speed targets as checks: from ``make bench`` groups when present, else in-run.

    Each check's name says its source. Creation (frequency ≥ 100× faster than angular per texel
    at equal error) is one check per ``shrm-create-<brdf>`` group, or the in-run GGX measurement;
    extraction (≥ 50× cheaper than creation) and a cache hit (≥ 20× faster than a rebuild) read
    ``shrm-extract`` and ``shrm-cache``, or the in-run ``results["extraction"]`` and
    ``results["cache"]``.

    Examples
    --------
    >>> results = {"creation": {"ratio": 80.0, "frequency_error": 0.002, "angular_error": 0.003,
    ...                         "brdf": "ggx"},
    ...            "extraction": {"ratio": 60.0}, "cache": {"ratio": 19.0}}
    >>> [(c.measured, c.passed) for c in speed_checks({}, results)]
    [(80.0, False), (60.0, True), (19.0, False)]
    """
    checks = []
    create = {g: r for g, r in groups.items() if g.startswith("shrm-create-")}
    if create:
        for group, records in sorted(create.items()):
            ratio, base, freq = bench_ratio(records)
            err_a = base.get("extra_info", {}).get("error", float("nan"))
            err_f = freq.get("extra_info", {}).get("error", float("nan"))
            what = f"make bench: creation, frequency vs angular per texel ({group})"
            checks.append(_creation_check(what, ratio, err_f, err_a))
    else:
        c = results["creation"]
        what = f"{label}in-run: creation, frequency vs angular per texel ({c['brdf']})"
        checks.append(_creation_check(what, c["ratio"], c["frequency_error"], c["angular_error"]))
    for group, key, target, what in (
        ("shrm-extract", "extraction", EXTRACTION_RATIO, "extraction per viewpoint vs creation"),
        ("shrm-cache", "cache", CACHE_RATIO, "cache hit vs rebuild"),
    ):
        if group in groups:
            ratio, source = bench_ratio(groups[group])[0], f"make bench: {what} ({group})"
        else:
            ratio, source = results[key]["ratio"], f"{label}in-run: {what}"
        checks.append(Check(source, f">= {target:g}×", ratio, bool(ratio >= target)))
    return checks


def speed_blocks(ctx: ReportContext, results: dict) -> list:
    """Tables of creation, extraction and cache speed, the orbit's stages and ``make bench``."""
    return [
        _creation_table(results["creation"]),
        _extraction_table(results["extraction"], results["cache"]),
        *_orbit_blocks(ctx, results["orbit"]),
        _bench_block(results.get("bench")),
    ]


def _creation_table(c: dict) -> Table:
    return Table(
        [
            "texels (freq. / ang.)",
            "frequency s/texel",
            "angular s/texel",
            "angular / frequency",
            "incl. BRDF projection",
            "frequency error",
            "angular error",
        ],
        [
            [
                f"{c['frequency_texels']} / {c['angular_texels']}",
                c["frequency_seconds_per_texel"],
                c["angular_seconds_per_texel"],
                c["ratio"],
                c["ratio_with_brdf_projection"],
                c["frequency_error"],
                c["angular_error"],
            ]
        ],
        f"SHRM creation for {c['brdf']} at its chosen setting, frequency space (the whole "
        f"{CREATION_SIZE}²×6 cube) against brute-force angular integration (a spread of "
        f"{c['angular_texels']} of its texels facing the view; the angular cost is the same for "
        "every texel), same environment, measured in this run. The BRDF's SH projection is a "
        "separate stage, reused for every environment and illuminant. Errors: against "
        "brute-force reflected radiance at those texels for the study's view, over its peak",
        "{:.4g}",
    )


def _extraction_table(ex: dict, cache: dict) -> Table:
    return Table(
        [
            "cube size",
            "creation s",
            "extraction s / viewpoint",
            "creation / extraction",
            "cache hit s",
            "rebuild / hit",
        ],
        [
            [
                ex["size"],
                ex["create_seconds"],
                ex["extract_seconds"],
                ex["ratio"],
                cache["hit_seconds"],
                cache["ratio"],
            ]
        ],
        "Extraction of a reflection map for a new viewpoint (§5.6) against SHRM creation, "
        "and a persistent-cache hit against a rebuild (environment and BRDF projection and "
        "creation)",
        "{:.4g}",
    )


def _orbit_blocks(ctx, orbit: dict) -> list:
    """Per-stage times of a camera orbit of the render session (§5.2, Herbert et al.)."""
    import matplotlib.pyplot as plt

    names, seconds = orbit["stages"], orbit["seconds"]
    frames = len(seconds)
    fig, ax = plt.subplots(figsize=(8, 3.2))
    bottom = np.zeros(frames)
    for k, n in enumerate(names):
        values = np.array([row[k] for row in seconds])
        ax.bar(np.arange(frames), values, bottom=bottom, label=n)
        bottom += values
    ax.set_yscale("symlog", linthresh=1e-3)
    ax.set_xlabel("frame")
    ax.set_ylabel("seconds")
    ax.legend(fontsize=7, ncol=3)
    return [
        Table(
            ["frame", *names, "total"],
            [[f, *row] for f, row in enumerate(seconds)],
            "Camera orbit: seconds per stage per frame "
            "(0 = reused); the first frame pays for creation",
            "{:.3g}",
        ),
        ctx.figure(
            "orbit-stages",
            fig,
            f"Orbit, per-stage time per frame: the first frame takes {seconds[0][-1]:.3g} s "
            f"(creation), the later ones at most {max(r[-1] for r in seconds[1:]):.3g} s"
            if frames > 1
            else "Orbit: per-stage time per frame",
        ),
    ]


def _bench_block(rows):
    """Ratios from ``make bench`` (tests/benchmarks/bench_shrm.py), when given."""
    if rows is None:
        return Text(
            "Benchmarks: not given; the speed checks use this run's measurements. Run "
            "`make bench` to check them on bench_shrm.py's."
        )
    return Table(
        ["group", "benchmark", "median s", "s per texel", "baseline / this", "error / peak"],
        rows,
        "make bench: SHRM and cache benchmarks (ratios in one run, per texel where the "
        "angular baseline ran on fewer texels); the speed checks use these",
        "{:.4g}",
    )

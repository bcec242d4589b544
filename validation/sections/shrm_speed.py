"""The speed half of the report section "SHRMs" (:mod:`validation.sections.shrm` registers it).

§5.5-5.6, Herbert et al.; the targets of issue 7 as checks:

- creation in frequency space against angular (brute-force) creation, on the same input and the
  same texels, per texel and at equal error (>= 100×);
- extraction of a reflection map for a new viewpoint against creation (>= 50×);
- a persistent-cache hit against a rebuild (>= 20×).

Each is measured in the run (``_creation_blocks``, ``_extraction_blocks``); the checks
(:func:`speed_checks`) read ``make bench`` (tests/benchmarks/bench_shrm.py) when it is given and the
in-run measurement otherwise, and name their source.
"""

from __future__ import annotations

import tempfile
import time

import numpy as np

from validation.report import Check, Table, Text
from validation.sections.shrm import (
    CACHE_RATIO,
    CREATION_RATIO,
    EXTRACTION_RATIO,
    TOLERANCE,
    _creation_timed,
    _rho_of,
    study_params,
)

__all__ = ["bench_ratio", "speed_checks"]


def _creation_blocks(ctx, env, L_env, view, results) -> list:
    """Creation in frequency space against angular creation, per texel, same input and texels."""
    from reference.cubemap import cubemap_texel_directions
    from shrm.brdf_sh import brdf_sh_coefficients, shrm_brdf_parts
    from shrm.shrm import shrm_extract
    from shrm.shrm_oracles import env_quadrature, reflected_bruteforce, shrm_texels_angular

    name = "ggx"
    choice = results[name]
    frame, F, P, fit = choice["frame"], choice["F"], choice["P"], choice["view_fit"]
    S = 8
    n_angular = 2 if ctx.quick else 4
    brdf, expand, _, k = shrm_brdf_parts(name, study_params(name))
    start = time.perf_counter()
    rho = brdf_sh_coefficients(brdf, expand, F, P, frame, view_power=k, view_fit=fit)
    t_rho = time.perf_counter() - start
    freq, t_freq = _creation_timed(L_env, rho, frame, F, S, k, None)
    texels = cubemap_texel_directions(S).reshape(-1, 3)
    # A spread of texels for the angular path (its cost does not depend on which), among those
    # the view sees (N·v > 0.2, as the benchmark picks them): only there is the error one a
    # render can show (in the normal frame a texel's views below its horizon are never read)
    front = np.nonzero(texels @ view > 0.2)[0]
    pick = front[np.linspace(0, front.size - 1, n_angular).round().astype(int)]
    start = time.perf_counter()
    angular = shrm_texels_angular(env, brdf, expand, P, texels[pick], frame, k, fit)
    t_ang = time.perf_counter() - start
    # Errors of both against the brute-force reflected radiance at those texels, one view
    truth = reflected_bruteforce(
        brdf,
        expand,
        frame,
        texels[pick],
        np.broadcast_to(view, (pick.size, 3)),
        env_quadrature(env),
        k,
    )
    from shrm.sh import sh_basis

    Y = sh_basis(P, view[None])[0]
    f_vals = shrm_extract(freq, view).reshape(-1, truth.shape[-1])[pick]
    err_f = float(np.abs(f_vals - truth).max() / np.abs(truth).max())
    err_a = float(np.abs(angular @ Y - truth).max() / np.abs(truth).max())
    per_f, per_a = t_freq / texels.shape[0], t_ang / pick.size
    ratio, ratio_rho = per_a / per_f, per_a / ((t_freq + t_rho) / texels.shape[0])
    results["creation"] = {
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
        "ratio": ratio,
        "ratio_with_brdf_projection": ratio_rho,
        "frequency_error": err_f,
        "angular_error": err_a,
    }
    return [
        Table(
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
                    f"{texels.shape[0]} / {pick.size}",
                    per_f,
                    per_a,
                    ratio,
                    ratio_rho,
                    err_f,
                    err_a,
                ]
            ],
            f"SHRM creation for {name} at its chosen setting, frequency space (the whole "
            f"{S}²×6 cube) against brute-force angular integration (a spread of {pick.size} of "
            "its texels facing the view; the angular cost is the same for every texel), same "
            "environment, measured in this run. The BRDF's SH projection is a separate stage, "
            "reused for every environment and illuminant. Errors: against brute-force reflected "
            "radiance at those texels for the study's view, over its peak",
            "{:.4g}",
        )
    ]


def _extraction_blocks(ctx, env, L_env, view, studies, results) -> list:
    """Extraction per viewpoint and a cache hit, against creation (at the default 64² × 6)."""
    from shrm.brdf_sh import shrm_brdf_parts
    from shrm.cache import Cache, cache_key
    from shrm.shrm import shrm_extract
    from shrm.transform import project_latlong

    name = "ggx"
    choice = results[name]
    frame, F, P = choice["frame"], choice["F"], choice["P"]
    S = 16 if ctx.quick else 64
    _, _, lam, k = shrm_brdf_parts(name, study_params(name))
    rho = _rho_of(studies[name]["rho"], F, P)
    big, t_big = _creation_timed(L_env, rho, frame, F, S, k, lam)
    views = [
        np.array([np.sin(a), 0.3, np.cos(a)]) for a in np.linspace(0, 2 * np.pi, 8, endpoint=False)
    ]
    start = time.perf_counter()
    for v in views:
        shrm_extract(big, v / np.linalg.norm(v))
    t_ex = (time.perf_counter() - start) / len(views)
    ratio = t_big / t_ex
    results["extraction"] = {
        "size": S,
        "create_seconds": t_big,
        "extract_seconds": t_ex,
        "ratio": ratio,
    }
    # A persistent-cache hit against a rebuild (projection of environment and BRDF, creation)
    env_coeffs = L_env[:, : (F + 1) ** 2]
    with tempfile.TemporaryDirectory() as folder:
        cache = Cache(folder)
        key = cache_key("shrm.create", "1", {"L": env_coeffs, "rho": rho, "size": S})
        cache.put(key, {"coeffs": big.coeffs, "irradiance": big.irradiance})
        hits = []
        for _ in range(5):
            start = time.perf_counter()
            cache.get(key)
            hits.append(time.perf_counter() - start)
    start = time.perf_counter()
    project_latlong(env, F, backend="ducc0")
    t_project = time.perf_counter() - start
    rebuild = t_project + t_big + results["creation"]["brdf_projection_seconds"]
    t_hit = float(np.median(hits))
    results["cache"] = {"hit_seconds": t_hit, "rebuild_seconds": rebuild, "ratio": rebuild / t_hit}
    return [
        Table(
            [
                "cube size",
                "creation s",
                "extraction s / viewpoint",
                "creation / extraction",
                "cache hit s",
                "rebuild / hit",
            ],
            [[S, t_big, t_ex, ratio, t_hit, rebuild / t_hit]],
            "Extraction of a reflection map for a new viewpoint (§5.6) against SHRM creation, "
            "and a persistent-cache hit against a rebuild (environment and BRDF projection and "
            "creation)",
            "{:.4g}",
        )
    ]


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
    """The speed targets of issue 7 as checks: from ``make bench`` groups when present, else in-run.

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


def _bench_blocks(groups: dict, results) -> list:
    """Ratios from ``make bench`` (tests/benchmarks/bench_shrm.py), when given."""
    if not groups:
        return [
            Text(
                "Benchmarks: not given; the speed checks use this run's measurements. Run "
                "`make bench` to check them on bench_shrm.py's."
            )
        ]
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
    results["bench"] = rows
    return [
        Table(
            ["group", "benchmark", "median s", "s per texel", "baseline / this", "error / peak"],
            rows,
            "make bench: SHRM and cache benchmarks (ratios in one run, per texel where the "
            "angular baseline ran on fewer texels); the speed checks use these",
            "{:.4g}",
        )
    ]

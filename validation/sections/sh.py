"""Report section "Spherical harmonics": basis accuracy to l = 2000, ringing, prefiltering, speed.

The figures (issue 5; Herbert et al. §5.3-5.4, §7.1, §7.3):

- basis error against degree, float64 against mpmath (``tests/data/sh_basis.json``), for the plain
  and the scaled recurrence, with the plain recurrence's limit marked;
- ringing: undershoot (minimum / peak) against order for each window on ``venice_sunset_1k.hdr``,
  the share of negative pixels, and images of the windowed reconstructions at L = 100;
- prefiltering: frequency path against the brute-force angular oracle at L = 100 (error and time)
  per kernel, and the exact Λ_l of the Phong lobe against the Gaussian approximation;
- speed: the ``sh-*`` groups of ``tests/benchmarks/bench_sh.py`` (``make bench``) as ratios to
  their same-run baselines, projection time against order per path, and memory bandwidth.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from reference.display import linear_to_display
from reference.images import read_hdr
from shrm.lobes import adaptive_order, parse_kernel, phong_Lambda_gaussian, truncation_tail
from shrm.prefilter import prefilter_bruteforce, prefilter_coefficients
from shrm.sh import PLAIN_ORDER_LIMIT, legendre_table, order_of, sh_evaluate
from shrm.transform import project_latlong, synthesize_latlong
from shrm.windows import WINDOWS, apply_window, ringing_statistics
from validation.report import (
    Check,
    ReportContext,
    ReportSection,
    SectionResult,
    Table,
    Text,
)

__all__ = ["basis_errors_by_degree", "prefilter_agreement", "ringing_by_order"]

ROOT = Path(__file__).resolve().parents[2]
BASIS_DATA = ROOT / "tests" / "data" / "sh_basis.json"
SHARED = ROOT.parent / "shared" / "data"


def basis_errors_by_degree(max_degree: int = 2500) -> dict:
    """Largest error of the float64 basis against mpmath per degree, for each recurrence.

    Errors are absolute, divided by ``sqrt((2l+1)/4π)`` (the size of ``Y_l0`` at the poles), over
    the precomputed hard points of ``tests/data/sh_basis.json`` (mpmath, 50 digits, checked at 80).

    Returns
    -------
    dict
        ``{method: {l: error}}`` for ``plain`` and ``scaled``.

    Examples
    --------
    >>> errors = basis_errors_by_degree(10)
    >>> sorted(errors), max(errors["plain"].values()) < 1e-14
    (['plain', 'scaled'], True)
    """
    points = np.array(json.loads(BASIS_DATA.read_text())["points"])
    points = points[points[:, 0] <= max_degree]
    out: dict = {"plain": {}, "scaled": {}}
    for l in sorted({int(r[0]) for r in points}):
        rows = points[points[:, 0] == l]
        thetas = np.unique(rows[:, 2])
        scale = np.sqrt((2 * l + 1) / (4 * np.pi))
        for method in out:
            orders = sorted({int(abs(m)) for m in rows[:, 1]})
            table = legendre_table(l, thetas, method, orders=orders, backend="numba")
            starts = dict(zip(orders, np.cumsum([0] + [l + 1 - m for m in orders]), strict=False))
            for _, m, theta, phi, value in rows:
                am = int(abs(m))
                lam = table[starts[am] + l - am, np.searchsorted(thetas, theta)]
                trig = np.sqrt(2.0) * (np.cos(am * phi) if m > 0 else np.sin(am * phi))
                got = lam if m == 0 else trig * lam
                err = float(abs(got - value) / scale)
                out[method][l] = max(out[method].get(l, 0.0), err)
    return out


def ringing_by_order(image, orders, height: int) -> dict:
    """Undershoot and negative share of each window's reconstruction, per order.

    Returns
    -------
    dict
        ``{window: {L: ringing_statistics}}``.

    Examples
    --------
    >>> r = ringing_by_order(np.ones((16, 32, 1)), [4], 8)
    >>> r["none"][4]["negative_share"]
    0.0
    """
    coeffs = project_latlong(image, max(orders), backend="ducc0")
    out: dict = {}
    for window in WINDOWS.names():
        out[window] = {}
        for L in orders:
            c = apply_window(coeffs[:, : (L + 1) ** 2], window)
            out[window][L] = ringing_statistics(synthesize_latlong(c, height, backend="ducc0"))
    return out


def prefilter_agreement(
    image, kernels, size: int, order: int = 100, backend: str = "numba"
) -> dict:
    """Frequency path against brute force on a cube map: relative error and both times.

    The frequency path projects with NumPy and evaluates with ducc0; ``backend`` picks the
    brute-force twin (NumPy avoids the JIT in ``--quick`` runs).

    Returns
    -------
    dict
        ``{kernel: {"relative_error", "frequency_s", "bruteforce_s", "adaptive_order"}}``.

    Examples
    --------
    >>> r = prefilter_agreement(np.ones((8, 16, 1)), ["phong:4"], 2, order=4)
    >>> r["phong:4"]["relative_error"] < 1e-12
    True
    """
    from reference.cubemap import cubemap_texel_directions

    d = cubemap_texel_directions(size)
    out = {}
    for spec in kernels:
        kernel = parse_kernel(spec)
        kernel.Lambda(order)
        start = time.perf_counter()
        coeffs = prefilter_coefficients(project_latlong(image, order), kernel.Lambda(order))
        frequency = sh_evaluate(coeffs, d, backend="ducc0")
        t_frequency = time.perf_counter() - start
        start = time.perf_counter()
        brute = prefilter_bruteforce(image, kernel, d, backend=backend)
        t_brute = time.perf_counter() - start
        out[spec] = {
            "relative_error": float(np.abs(frequency - brute).max() / np.abs(brute).max()),
            "frequency_s": t_frequency,
            "bruteforce_s": t_brute,
            "adaptive_order": adaptive_order(kernel),
            "tail_at_adaptive_order": truncation_tail(kernel, adaptive_order(kernel)),
        }
    return out


def irradiance_images(ctx, path) -> list:
    """The environment and its irradiance / π (Lambert prefilter, adaptive order), as sRGB images.

    Both at the same exposure (0.25 / the mean radiance), so a white Lambertian surface facing
    n shows the irradiance image's colour at n.
    """
    from shrm.prefilter import prefilter_environment

    image = read_hdr(path)
    result = prefilter_environment(image, "lambert", output="latlong", height=64)
    exposure = 0.25 / float(image.mean())
    small = image[:: image.shape[0] // 64, :: image.shape[0] // 64]
    return [
        ctx.image("environment", linear_to_display(small, "srgb", exposure), f"{path.name}"),
        ctx.image(
            "irradiance",
            linear_to_display(result.values / np.pi, "srgb", exposure),
            f"Irradiance / π of {path.name}, Lambert prefilter at order {result.order}",
        ),
    ]


def gaussian_approximation_errors(coeffs, exponents, size: int = 32) -> dict:
    """Per-texel error of prefiltering with ``exp(-l²/2s)`` instead of the exact Λ_l.

    Returns
    -------
    dict
        ``{s: {"max_relative", "median_relative", "max_over_peak"}}`` over a cube map's texels.

    Examples
    --------
    >>> c = np.zeros((1, 9)); c[0, 0] = 1.0
    >>> gaussian_approximation_errors(c, [8], 2)[8]["max_relative"]
    0.0
    """
    from reference.cubemap import cubemap_texel_directions

    L = order_of(coeffs.shape[1])
    d = cubemap_texel_directions(size)
    out = {}
    for s in exponents:
        exact = sh_evaluate(prefilter_coefficients(coeffs, parse_kernel(f"phong:{s}").Lambda(L)), d)
        approx = sh_evaluate(prefilter_coefficients(coeffs, phong_Lambda_gaussian(s, L)), d)
        relative = np.abs(approx - exact) / np.abs(exact)
        out[s] = {
            "max_relative": float(relative.max()),
            "median_relative": float(np.median(relative)),
            "max_over_peak": float(np.abs(approx - exact).max() / np.abs(exact).max()),
        }
    return out


def _basis_chart(ctx, errors):
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 3.4))
    for method, marker in (("plain", "o"), ("scaled", "s")):
        ls = sorted(errors[method])
        ax.semilogy(ls, [max(errors[method][l], 1e-18) for l in ls], marker=marker, label=method)
    ax.axvline(PLAIN_ORDER_LIMIT, color="k", ls="--", lw=1)
    ax.text(
        PLAIN_ORDER_LIMIT,
        0.9,
        "plain limit ",
        fontsize=8,
        ha="right",
        transform=ax.get_xaxis_transform(),
    )
    ax.axvline(1926, color="r", ls=":", lw=1)
    ax.text(
        1926, 0.6, " sin^m θ underflows", fontsize=8, color="r", transform=ax.get_xaxis_transform()
    )
    ax.set_xlabel("degree l")
    ax.set_ylabel("max |Y - Y_mpmath| / sqrt((2l+1)/4π)")
    ax.legend()
    return ctx.figure("basis-error", fig, "float64 basis error against mpmath (50 digits)")


def _ringing_chart(ctx, ringing):
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(9, 3.2))
    for window, stats in ringing.items():
        Ls = sorted(stats)
        a.plot(Ls, [-stats[L]["undershoot"] for L in Ls], marker="o", label=window)
        b.plot(Ls, [stats[L]["negative_share"] for L in Ls], marker="o", label=window)
    a.set_yscale("symlog", linthresh=1e-4)
    a.set_xlabel("order L")
    a.set_ylabel("-(minimum / peak)")
    b.set_xlabel("order L")
    b.set_ylabel("share of negative pixels")
    a.legend(fontsize=8)
    return ctx.figure("ringing", fig, "Undershoot and negative pixels of venice_sunset by window")


def _prefilter_chart(ctx, agreement):
    import matplotlib.pyplot as plt

    names = list(agreement)
    x = np.arange(len(names))
    fig, (a, b) = plt.subplots(1, 2, figsize=(9, 3.2))
    a.bar(x, [max(agreement[k]["relative_error"], 1e-17) for k in names])
    a.set_yscale("log")
    a.set_ylabel("max |frequency − brute| / max")
    b.bar(x - 0.2, [agreement[k]["frequency_s"] for k in names], 0.4, label="frequency")
    b.bar(x + 0.2, [agreement[k]["bruteforce_s"] for k in names], 0.4, label="brute force")
    b.set_yscale("log")
    b.set_ylabel("seconds")
    b.legend(fontsize=8)
    for ax in (a, b):
        ax.set_xticks(x, names, rotation=20, fontsize=7)
    return ctx.figure("prefilter", fig, "Frequency path against brute force at L = 100, per kernel")


def _lambda_chart(ctx, order):
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 3.2))
    for s in (32, 256):
        exact = parse_kernel(f"phong:{s}").Lambda(order)
        approx = phong_Lambda_gaussian(s, order)
        ax.plot(exact, label=f"exact Λ_l, s = {s}")
        ax.plot(approx, ls="--", label=f"exp(-l²/2s), s = {s}")
    ax.set_xlabel("degree l")
    ax.set_ylabel("Λ_l")
    ax.legend(fontsize=8)
    return ctx.figure("phong-lambda", fig, "Normalized Phong lobe: exact Λ_l against exp(-l²/2s)")


def _bench(ctx):
    """Rows for the benchmark table, results, checks and the order chart data."""
    rows, results, checks, by_order = [], {}, [], {}
    for group, records in sorted(ctx.bench_groups("sh-").items()):
        base = [r for r in records if r.get("extra_info", {}).get("role") == "baseline"]
        base_median = base[0]["stats"]["median"] if base else float("nan")
        for r in records:
            info, median = r.get("extra_info", {}), r["stats"]["median"]
            ratio = median / base_median
            rows.append([group, r["name"], 1e3 * median, ratio])
            results[f"{group} {r['name']}"] = {"median_s": median, "ratio_to_baseline": ratio}
            role = info.get("role")
            if group == "sh-project-order":
                by_order.setdefault(role, {})[info["order"]] = median
            elif group == "sh-project-L100" and role in ("baseline", "numpy"):
                limit = 5e-3 if role == "baseline" else 25e-3
                name = "ducc0" if role == "baseline" else "numpy"
                checks.append(
                    Check(
                        f"projection 512×1024 L=100, {name}",
                        f"<= {limit * 1e3:g} ms",
                        1e3 * median,
                        median <= limit,
                    )
                )
            elif group == "sh-project-41band":
                checks.append(
                    Check(
                        "projection 41 bands L=100, ducc0",
                        "<= 250 ms",
                        1e3 * median,
                        median <= 0.25,
                    )
                )
            elif group == "sh-prefilter-cube64" and role != "baseline":
                limit = 20e-3 if role == "frequency-ducc0" else 1.5
                checks.append(
                    Check(
                        f"prefilter 64²×6, {role}",
                        f"<= {limit * 1e3:g} ms",
                        1e3 * median,
                        median <= limit,
                    )
                )
                if role == "frequency-ducc0":
                    speedup = base_median / median
                    checks.append(
                        Check(
                            "prefilter speed-up over brute force",
                            ">= 500×",
                            speedup,
                            speedup >= 500,
                        )
                    )
            elif group == "sh-bandwidth" and role != "baseline":
                base_bw = base[0]["extra_info"]["bytes"] / base_median
                share = info["bytes"] / median / base_bw
                limit = 0.25 if role == "latlong_to_cubemap" else 0.5
                results[f"{group} {r['name']}"]["share_of_copy_bandwidth"] = share
                checks.append(
                    Check(f"{role} bandwidth / np.copyto", f">= {limit:g}", share, share >= limit)
                )
    return rows, results, checks, by_order


def _order_chart(ctx, by_order):
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 3.2))
    for backend, times in sorted(by_order.items()):
        Ls = sorted(times)
        ax.loglog(Ls, [1e3 * times[L] for L in Ls], marker="o", label=backend)
    ax.set_xlabel("order L")
    ax.set_ylabel("ms, one 512×1024 channel")
    ax.legend()
    return ctx.figure("projection-time", fig, "Projection time against order (make bench)")


def run(ctx: ReportContext) -> SectionResult:
    """Basis accuracy, ringing, prefilter agreement and speed (see the module docstring)."""
    blocks, results, checks = [], {}, []
    # Basis accuracy against mpmath.
    errors = basis_errors_by_degree(2500)
    results["basis_error"] = errors
    worst_100 = max(v for l, v in errors["plain"].items() if l <= 101)
    worst_1000 = max(v for l, v in errors["plain"].items() if l <= 1000)
    worst_scaled = max(errors["scaled"].values())
    checks += [
        Check("basis vs mpmath, l <= 101", "<= 5e-13", worst_100, worst_100 <= 5e-13),
        Check("basis vs mpmath, l <= 1000", "<= 1e-11", worst_1000, worst_1000 <= 1e-11),
        Check("basis vs mpmath, all l (scaled)", "<= 1e-11", worst_scaled, worst_scaled <= 1e-11),
    ]
    blocks += [
        Text(
            "The normalized recurrence in float64 against mpmath at points aimed at the hard "
            "places (θ within 1e-12 of the poles, sin θ = 1/e, the equator). The plain recurrence "
            "is exact to rounding until sin^m θ underflows while Y_lm is O(1) (from l ≈ 1930 on; "
            f"measured failures from l = 2100); above l = {PLAIN_ORDER_LIMIT} specref uses the "
            "scaled (extended-exponent) recurrence."
        ),
        _basis_chart(ctx, errors),
    ]
    # Ringing on venice_sunset.
    image = read_hdr(SHARED / "environments" / "venice_sunset_1k.hdr")
    orders = [25, 50, 100] if ctx.quick else [10, 25, 50, 75, 100]
    ringing = ringing_by_order(image, orders, 128 if ctx.quick else 512)
    results["ringing"] = ringing
    gauss = ringing["gaussian"][100]
    checks.append(
        Check(
            "gaussian σ=π/L, L=100: negative pixels",
            "0",
            gauss["negative_share"],
            gauss["negative_share"] == 0.0,
        )
    )
    blocks += [
        Text("Windows against ringing (§7.3, Herbert et al.), venice_sunset (sun ≈ 6.5e3)."),
        _ringing_chart(ctx, ringing),
        Table(
            ["window", "L", "min / peak", "negative share"],
            [
                [w, L, s["undershoot"], s["negative_share"]]
                for w, st in ringing.items()
                for L, s in st.items()
            ],
            "Ringing of the windowed reconstructions",
            "{:.3g}",
        ),
    ]
    coeffs = project_latlong(image, 100, backend="ducc0")
    exposure = 1.0 / np.percentile(image, 99)
    for window in WINDOWS.names():
        rec = synthesize_latlong(apply_window(coeffs, window), 128, backend="ducc0")
        encoded = linear_to_display(rec, "srgb", exposure)
        encoded[(rec < 0).any(axis=-1)] = (1.0, 0.0, 1.0)
        blocks.append(
            ctx.image(f"window-{window}", encoded, f"L = 100, window {window} (negative: magenta)")
        )
    # A prefiltered irradiance map of a shared environment (docs/sh.md shows it).
    blocks += irradiance_images(ctx, SHARED / "environments" / "st_fagans_interior_1k.hdr")
    # Prefiltering: frequency against brute force.
    step = 4
    small = np.ascontiguousarray(image[::step, ::step, :1])
    # A tabulated lobe (the 1-D measured-BRDF case): a Gaussian of 0.15 rad sampled every 0.01 rad.
    angles = np.arange(0.0, 0.8, 0.01)
    lobe = ctx.out_dir / "images" / "sh-gaussian-lobe.csv"
    lobe.parent.mkdir(parents=True, exist_ok=True)
    rows = "\n".join(f"{a:.2f},{np.exp(-0.5 * (a / 0.15) ** 2):.12g}" for a in angles)
    lobe.write_text("angle_rad,value\n" + rows + "\n")
    agreement = prefilter_agreement(
        small,
        ["lambert", "phong:32", "phong:256", f"table:{lobe}"],
        8 if ctx.quick else 16,
        backend="numpy" if ctx.quick else "numba",
    )
    agreement = {k.replace(str(lobe.parent) + "/", ""): v for k, v in agreement.items()}
    results["prefilter"] = agreement
    for spec, bound in (("phong:32", 1e-11), ("phong:256", 2e-9), ("lambert", 5e-4)):
        err = agreement[spec]["relative_error"]
        checks.append(
            Check(f"prefilter {spec} vs brute force, L=100", f"<= {bound:g}", err, err <= bound)
        )
    blocks += [
        Table(
            ["kernel", "relative error", "frequency s", "brute force s", "adaptive L (tol 1e-2)"],
            [
                [
                    k,
                    v["relative_error"],
                    v["frequency_s"],
                    v["bruteforce_s"],
                    v["adaptive_order"],
                ]
                for k, v in agreement.items()
            ],
            f"Frequency path vs brute force at L = 100, input {small.shape[1]}×{small.shape[0]}",
            "{:.3g}",
        ),
        _prefilter_chart(ctx, agreement),
        _lambda_chart(ctx, 100),
    ]
    gauss_errors = gaussian_approximation_errors(coeffs[:1], (32, 256), 16 if ctx.quick else 32)
    results["gaussian_approximation"] = gauss_errors
    blocks.append(
        Table(
            ["s", "max relative", "median relative", "max / peak"],
            [
                [s, v["max_relative"], v["median_relative"], v["max_over_peak"]]
                for s, v in gauss_errors.items()
            ],
            "Phong prefilter of venice_sunset (R, L = 100) with exp(-l²/2s), not the exact Λ_l",
            "{:.3g}",
        )
    )
    # Benchmarks.
    rows, bench_results, bench_checks, by_order = _bench(ctx)
    results["benchmarks"] = bench_results
    checks += bench_checks
    if rows:
        blocks.append(
            Table(
                ["group", "benchmark", "median ms", "ratio to baseline"],
                rows,
                "Benchmarks (make bench)",
                "{:.4g}",
            )
        )
        if by_order:
            blocks.append(_order_chart(ctx, by_order))
    else:
        blocks.append(Text("No benchmark file: run `make bench` for the speed figures."))
    return SectionResult(blocks, results, checks)


SECTION = ReportSection("sh", "Spherical harmonics", legacy_run=run)

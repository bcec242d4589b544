"""Report section "Spherical harmonics": basis accuracy to l = 2000, ringing, prefiltering, speed.

The figures (Herbert et al. §5.3-5.4, §7.1, §7.3):

- basis error against degree, float64 against mpmath (``validation/data/sh_basis.json``), for the
  plain and the scaled recurrence, with the plain recurrence's limit marked;
- ringing: undershoot (minimum / peak) against order for each window on ``venice_sunset_1k.hdr``,
  the share of negative pixels, and images of the windowed reconstructions at L = 100;
- prefiltering: frequency path against the brute-force angular oracle at L = 100 (error and time)
  per kernel, and the exact Λ_l of the Phong lobe against the Gaussian approximation;
- speed: the ``sh-*`` groups of ``tests/benchmarks/bench_sh.py`` (``make bench``) as ratios to
  their same-run baselines, projection time against order per path, and memory bandwidth.

compute → :func:`sh_accuracy_and_speed`; present → :func:`present`; checks → :func:`checks`.
The windows and prefilter kernels studied are read from their registries
(:data:`shrm.windows.WINDOWS`, :data:`shrm.lobes.PREFILTER_KERNELS`).
"""

from __future__ import annotations

import importlib.resources
import json
import time
from pathlib import Path

import numpy as np

from reference.data import data_path
from reference.display.encodings import linear_to_display
from reference.errors import require
from reference.files import write_text_atomic
from reference.images.formats import read_hdr
from reference.registry import ParametricMethod
from shrm.lobes import (
    PREFILTER_KERNELS,
    adaptive_order,
    parse_kernel,
    phong_Lambda_gaussian,
    truncation_tail,
)
from shrm.prefilter import prefilter_bruteforce, prefilter_coefficients
from shrm.sh import PLAIN_ORDER_LIMIT, legendre_table, order_of, sh_evaluate
from shrm.transform import project_latlong, synthesize_latlong
from shrm.windows import WINDOWS, apply_window, ringing_statistics
from validation.report import (
    Check,
    Headline,
    ReportContext,
    ReportSection,
    SectionData,
    Table,
    Text,
)
from validation.report.sections.sh_speed import (
    benchmark_blocks,
    benchmark_checks,
    benchmark_figures,
)

__all__ = [
    "SETTINGS",
    "basis_errors_by_degree",
    "gaussian_approximation_errors",
    "kernel_specs",
    "prefilter_agreement",
    "ringing_by_order",
    "sh_accuracy_and_speed",
    "window_caption",
    "window_reconstructions",
]

#: The mpmath values at hard points (validation/precompute/sh_basis.py), shipped with the package.
BASIS_DATA = Path(str(importlib.resources.files("validation"))) / "data" / "sh_basis.json"
ENVIRONMENT = "venice_sunset_1k.hdr"
IRRADIANCE_ENVIRONMENT = "st_fagans_interior_1k.hdr"

#: The two Legendre recurrences of :func:`shrm.sh.legendre_table` (``"auto"`` switches between
#: them at :data:`shrm.sh.PLAIN_ORDER_LIMIT`, so it is not a third one).
RECURRENCES = ("plain", "scaled")
#: The order of the window images, the prefilter comparison and the Gaussian Λ_l approximation.
ORDER = 100
#: The Phong exponents s of the prefilter comparison, the Λ_l chart and the Gaussian approximation.
PHONG_EXPONENTS = (32, 256)

#: Sizes per mode. ``tiny`` is for tests and the doctest: every figure, on small inputs.
SETTINGS = {
    "full": {
        "max_degree": 2500,
        "ringing_orders": (10, 25, 50, 75, 100),
        "ringing_height": 512,
        "window_height": 128,
        "prefilter_step": 4,
        "prefilter_size": 16,
        "bruteforce_backend": "numba",
        "gaussian_size": 32,
    },
    "quick": {
        "max_degree": 2500,
        "ringing_orders": (25, 50, 100),
        "ringing_height": 128,
        "window_height": 128,
        "prefilter_step": 4,
        "prefilter_size": 8,
        "bruteforce_backend": "numpy",
        "gaussian_size": 16,
    },
    "tiny": {
        "max_degree": 10,
        "ringing_orders": (100,),
        "ringing_height": 101,
        "window_height": 101,
        "prefilter_step": 4,
        "prefilter_size": 2,
        "bruteforce_backend": "numpy",
        "gaussian_size": 2,
    },
}


def sh_accuracy_and_speed(ctx: ReportContext, settings: dict | None = None) -> SectionData:
    """Basis accuracy, ringing, prefilter agreement and benchmark ratios (module docstring).

    Parameters
    ----------
    ctx : ReportContext
        ``ctx.quick`` picks the sizes; the tabulated lobe is written to ``ctx.out_dir/images``;
        ``ctx.bench`` gives the ``sh-*`` benchmark groups.
    settings : dict, optional
        One of :data:`SETTINGS` (default ``"quick"`` or ``"full"`` by ``ctx.quick``).

    Returns
    -------
    SectionData
        ``results``: ``basis_error``, ``ringing``, ``prefilter``, ``gaussian_approximation``,
        ``benchmarks``; ``arrays``: window reconstructions, irradiance maps, Λ_l curves and the
        benchmark records that the checks read.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     data = sh_accuracy_and_speed(ReportContext(Path(folder)), SETTINGS["tiny"])
    >>> list(data.results)
    ['basis_error', 'ringing', 'prefilter', 'gaussian_approximation', 'benchmarks']
    >>> [c.passed for c in checks(data)]
    [True, True, True, True, True, True, True]
    """
    s = settings or SETTINGS["quick" if ctx.quick else "full"]
    data = SectionData()
    # Basis accuracy against mpmath
    data.results["basis_error"] = basis_errors_by_degree(s["max_degree"])
    # Ringing of each window on venice_sunset
    image = read_hdr(data_path(f"environments/{ENVIRONMENT}"))
    data.results["ringing"] = ringing_by_order(image, s["ringing_orders"], s["ringing_height"])
    coeffs = project_latlong(image, ORDER, backend="ducc0")
    data.arrays["windows"] = window_reconstructions(coeffs, s["window_height"])
    data.arrays["window_exposure"] = 1.0 / np.percentile(image, 99)
    # A prefiltered irradiance map of a shared environment (docs/sh.md shows it)
    data.arrays["irradiance"] = irradiance_maps(data_path(f"environments/{IRRADIANCE_ENVIRONMENT}"))
    # Prefiltering: frequency against brute force, and the Gaussian approximation of Λ_l
    small = np.ascontiguousarray(image[:: s["prefilter_step"], :: s["prefilter_step"], :1])
    data.arrays["prefilter_input_shape"] = small.shape
    data.results["prefilter"] = _prefilter_study(ctx, small, s)
    data.arrays["phong_Lambda"] = {
        e: (parse_kernel(f"phong:{e}").Lambda(ORDER), phong_Lambda_gaussian(e, ORDER))
        for e in PHONG_EXPONENTS
    }
    data.results["gaussian_approximation"] = gaussian_approximation_errors(
        coeffs[:1], PHONG_EXPONENTS, s["gaussian_size"]
    )
    # Benchmarks (make bench)
    data.results["benchmarks"], data.arrays["bench"] = benchmark_figures(ctx.bench_groups("sh-"))
    return data


def basis_errors_by_degree(max_degree: int = 2500) -> dict:
    """Largest error of the float64 basis against mpmath per degree, for each recurrence.

    Errors are absolute, divided by ``sqrt((2l+1)/4π)`` (the size of ``Y_l0`` at the poles), over
    the precomputed hard points of ``validation/data/sh_basis.json`` (mpmath, 50 digits, checked at
    80).

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
    out: dict = {method: {} for method in RECURRENCES}
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
    from reference.geometry.cubemap import cubemap_texel_directions

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
        L_adaptive = adaptive_order(kernel)
        out[spec] = {
            "relative_error": float(np.abs(frequency - brute).max() / np.abs(brute).max()),
            "frequency_s": t_frequency,
            "bruteforce_s": t_brute,
            "adaptive_order": L_adaptive,
            "tail_at_adaptive_order": truncation_tail(kernel, L_adaptive),
        }
    return out


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
    from reference.geometry.cubemap import cubemap_texel_directions

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


def window_reconstructions(coeffs, height: int) -> dict:
    """The reconstruction of ``coeffs`` under each registered window, at ``height`` rows.

    Returns
    -------
    dict
        ``{window: ndarray (height, 2 height, C)}`` for every key of :data:`shrm.windows.WINDOWS`.

    Examples
    --------
    >>> c = np.zeros((1, 9)); c[0, 0] = 1.0
    >>> list(window_reconstructions(c, 4)) == WINDOWS.names()
    True
    """
    return {
        window: synthesize_latlong(apply_window(coeffs, window), height, backend="ducc0")
        for window in WINDOWS.names()
    }


def irradiance_maps(path) -> dict:
    """The environment (subsampled to about 64 rows) and its irradiance / π, with one exposure.

    Lambert prefilter at the adaptive order. Both share the exposure 0.25 / the mean radiance, so
    a white Lambertian surface facing n shows the irradiance image's colour at n.

    Returns
    -------
    dict
        ``environment``, ``irradiance`` (linear RGB), ``order``, ``exposure`` and ``name``.
    """
    from shrm.prefilter import prefilter_environment

    image = read_hdr(path)
    result = prefilter_environment(image, "lambert", output="latlong", height=64)
    return {
        "environment": image[:: image.shape[0] // 64, :: image.shape[0] // 64],
        "irradiance": result.values / np.pi,
        "order": result.order,
        "exposure": 0.25 / float(image.mean()),
        "name": Path(path).name,
    }


def kernel_specs(parameters: dict) -> list[str]:
    """Every registered prefilter kernel, once per study value of its parameter.

    A kernel of :data:`shrm.lobes.PREFILTER_KERNELS` without a parameter appears as its name; one
    with a parameter appears as ``name:value`` for each value in ``parameters[name]`` (so a newly
    registered kernel is studied at once, and one with a parameter must be given its values).

    Raises
    ------
    SpecrefError
        A registered kernel takes a parameter and ``parameters`` has no values for it.

    Examples
    --------
    >>> kernel_specs({"phong": (32, 256), "table": ("lobe.csv",)})
    ['lambert', 'phong:32', 'phong:256', 'table:lobe.csv']
    """
    specs = []
    for name, entry in PREFILTER_KERNELS.items():
        if not isinstance(entry, ParametricMethod):
            specs.append(name)
            continue
        require(
            name in parameters,
            f"validation/report/sections/sh.py: kernel {name!r} takes {entry.param}; "
            "give its "
            f"study values (studied: {', '.join(sorted(parameters))})",
        )
        specs += [f"{name}:{value}" for value in parameters[name]]
    return specs


def _prefilter_study(ctx, small, s) -> dict:
    """Frequency path against brute force for every kernel (a tabulated Gaussian lobe included)."""
    # A tabulated lobe (the 1-D measured-BRDF case): a Gaussian of 0.15 rad sampled every 0.01 rad
    angles = np.arange(0.0, 0.8, 0.01)
    lobe = ctx.out_dir / "images" / "sh-gaussian-lobe.csv"
    rows = "\n".join(f"{a:.2f},{np.exp(-0.5 * (a / 0.15) ** 2):.12g}" for a in angles)
    write_text_atomic(lobe, "angle_rad,value\n" + rows + "\n")
    specs = kernel_specs({"phong": PHONG_EXPONENTS, "table": (lobe,)})
    agreement = prefilter_agreement(
        small, specs, s["prefilter_size"], ORDER, backend=s["bruteforce_backend"]
    )
    return {k.replace(str(lobe.parent) + "/", ""): v for k, v in agreement.items()}


def present(ctx: ReportContext, data: SectionData) -> list:
    """Charts, tables and images of the section (module docstring); draws from ``data`` only."""
    return [
        *_basis_blocks(ctx, data.results["basis_error"]),
        *_ringing_blocks(ctx, data),
        *_irradiance_blocks(ctx, data.arrays["irradiance"]),
        *_prefilter_blocks(ctx, data),
        *benchmark_blocks(ctx, data.arrays["bench"]),
    ]


def _basis_blocks(ctx, errors) -> list:
    return [
        Text(
            "The normalized recurrence in float64 against mpmath at points aimed at the hard "
            "places (θ within 1e-12 of the poles, sin θ = 1/e, the equator). The plain recurrence "
            "is exact to rounding until sin^m θ underflows while Y_lm is O(1) (from l ≈ 1930 on; "
            f"measured failures from l = 2100); above l = {PLAIN_ORDER_LIMIT} specref uses the "
            "scaled (extended-exponent) recurrence."
        ),
        _basis_chart(ctx, errors),
    ]


def _ringing_blocks(ctx, data) -> list:
    ringing = data.results["ringing"]
    blocks = [
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
    for window, rec in data.arrays["windows"].items():
        encoded = linear_to_display(rec, "srgb", data.arrays["window_exposure"])
        negative = (rec < 0).any(axis=-1)
        encoded[negative] = (1.0, 0.0, 1.0)
        blocks.append(ctx.image(f"window-{window}", encoded, window_caption(window, rec)))
    return blocks


def window_caption(window: str, reconstruction) -> str:
    """The caption of a windowed reconstruction's picture, from its pixels (magenta: negative).

    Examples
    --------
    >>> rec = np.ones((2, 4, 3)); rec[0, 0] = -0.5
    >>> window_caption("none", rec)
    'L = 100, window none: 12.5 % of pixels negative (magenta), down to -0.5 of the peak'
    >>> window_caption("gaussian", np.ones((2, 4, 3)))
    'L = 100, window gaussian: no pixel negative'
    """
    rec = np.asarray(reconstruction, dtype=np.float64)
    negative = (rec < 0).any(axis=-1)
    if not negative.any():
        return f"L = 100, window {window}: no pixel negative"
    share, low = 100 * float(negative.mean()), float(rec.min() / rec.max())
    return (
        f"L = 100, window {window}: {share:.3g} % of pixels negative (magenta), down to "
        f"{low:.2g} of the peak"
    )


def _irradiance_blocks(ctx, maps) -> list:
    exposure, name = maps["exposure"], maps["name"]
    return [
        ctx.image("environment", linear_to_display(maps["environment"], "srgb", exposure), name),
        ctx.image(
            "irradiance",
            linear_to_display(maps["irradiance"], "srgb", exposure),
            f"Irradiance / π of {name}, Lambert prefilter at order {maps['order']}",
        ),
    ]


def _prefilter_blocks(ctx, data) -> list:
    agreement, gauss_errors = data.results["prefilter"], data.results["gaussian_approximation"]
    shape = data.arrays["prefilter_input_shape"]
    return [
        Table(
            ["kernel", "relative error", "frequency s", "brute force s", "adaptive L (tol 1e-2)"],
            [
                [k, v["relative_error"], v["frequency_s"], v["bruteforce_s"], v["adaptive_order"]]
                for k, v in agreement.items()
            ],
            f"Frequency path vs brute force at L = 100, input {shape[1]}×{shape[0]}",
            "{:.3g}",
        ),
        _prefilter_chart(ctx, agreement),
        _lambda_chart(ctx, data.arrays["phong_Lambda"]),
        Table(
            ["s", "max relative", "median relative", "max / peak"],
            [
                [s, v["max_relative"], v["median_relative"], v["max_over_peak"]]
                for s, v in gauss_errors.items()
            ],
            "Phong prefilter of venice_sunset (R, L = 100) with exp(-l²/2s), not the exact Λ_l",
            "{:.3g}",
        ),
    ]


def _basis_chart(ctx, errors):
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 3.4))
    for method, marker in zip(RECURRENCES, "os", strict=True):
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
    parts = []
    for m in RECURRENCES:
        within = [e for l, e in errors[m].items() if l <= PLAIN_ORDER_LIMIT]
        beyond = [e for l, e in errors[m].items() if l > PLAIN_ORDER_LIMIT]
        text = f"{m} at most {max(within):.1e} up to l = {PLAIN_ORDER_LIMIT}" if within else m
        parts.append(text + (f" and {max(beyond):.1e} beyond" if beyond else ""))
    caption = "float64 basis error against mpmath (50 digits): " + "; ".join(parts)
    return ctx.figure("basis-error", fig, caption)


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
    top = {w: max(stats) for w, stats in ringing.items()}
    worst = max(ringing, key=lambda w: ringing[w][top[w]]["negative_share"])
    best = min(ringing, key=lambda w: ringing[w][top[w]]["negative_share"])
    caption = (
        f"Undershoot and negative pixels of venice_sunset by window: at the highest order "
        f"{worst} leaves {100 * ringing[worst][top[worst]]['negative_share']:.2g} % of pixels "
        f"negative, {best} {100 * ringing[best][top[best]]['negative_share']:.2g} %"
    )
    return ctx.figure("ringing", fig, caption)


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
    worst = max(names, key=lambda k: agreement[k]["relative_error"])
    speed = min(agreement[k]["bruteforce_s"] / agreement[k]["frequency_s"] for k in names)
    caption = (
        f"The frequency path at L = 100 agrees with brute force to "
        f"{agreement[worst]['relative_error']:.1e} of the maximum (worst: {worst}) and is at "
        f"least {speed:.0f}× faster, per kernel"
    )
    return ctx.figure("prefilter", fig, caption)


def _lambda_chart(ctx, curves):
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 3.2))
    for s, (exact, approx) in curves.items():
        ax.plot(exact, label=f"exact Λ_l, s = {s}")
        ax.plot(approx, ls="--", label=f"exp(-l²/2s), s = {s}")
    ax.set_xlabel("degree l")
    ax.set_ylabel("Λ_l")
    ax.legend(fontsize=8)
    gap = max(float(np.max(np.abs(np.asarray(e) - np.asarray(a)))) for e, a in curves.values())
    return ctx.figure(
        "phong-lambda",
        fig,
        "Normalized Phong lobe: the Gaussian exp(-l²/2s) stays within "
        f"{gap:.2g} of the exact Λ_l at every degree shown (specref uses the exact values)",
    )


#: What the basis targets are measured against: mpmath, 50 digits (an independent library).
MPMATH = "independent"


def checks(data: SectionData) -> list[Check]:
    """Basis, ringing and prefilter accuracy, then the speed targets of ``make bench``."""
    return _accuracy_checks(data.results) + benchmark_checks(data.arrays["bench"])


def _accuracy_checks(results: dict) -> list[Check]:
    errors = results["basis_error"]
    worst_100 = max(v for l, v in errors["plain"].items() if l <= 101)
    worst_1000 = max(v for l, v in errors["plain"].items() if l <= 1000)
    worst_scaled = max(errors["scaled"].values())
    gauss = results["ringing"]["gaussian"][ORDER]
    found = [
        Check("basis vs mpmath, l <= 101", "<= 5e-13", worst_100, worst_100 <= 5e-13, MPMATH),
        Check("basis vs mpmath, l <= 1000", "<= 1e-11", worst_1000, worst_1000 <= 1e-11, MPMATH),
        Check(
            "basis vs mpmath, all l (scaled)",
            "<= 1e-11",
            worst_scaled,
            worst_scaled <= 1e-11,
            MPMATH,
        ),
        Check(
            "gaussian σ=π/L, L=100: negative pixels",
            "0",
            gauss["negative_share"],
            gauss["negative_share"] == 0.0,
        ),
    ]
    for spec, bound in (("phong:32", 1e-11), ("phong:256", 2e-9), ("lambert", 5e-4)):
        err = results["prefilter"][spec]["relative_error"]
        found.append(
            Check(f"prefilter {spec} vs brute force, L=100", f"<= {bound:g}", err, err <= bound)
        )
    return found


def headlines(data: SectionData) -> list[Headline]:
    """The summary's figures: the basis against mpmath, prefiltering against brute force."""
    results = data.results
    worst = max(v for l, v in results["basis_error"]["plain"].items() if l <= 1000)
    phong = results["prefilter"]["phong:32"]["relative_error"]
    lambert = results["prefilter"]["lambert"]["relative_error"]
    return [
        Headline(
            f"real SH basis within {worst:.0e} of mpmath up to degree 1000",
            "paper §7.3 needed 320-bit arithmetic for order 100 (erratum E8)",
        ),
        Headline(
            f"frequency-space prefiltering at L = {ORDER} within {phong:.0e} (Phong 32) and "
            f"{lambert:.0e} (Lambert) of brute-force integration",
            "targets ≤ 1e-11 and ≤ 5e-4",
        ),
    ]


SECTION = ReportSection(
    "sh",
    "Spherical harmonics",
    sh_accuracy_and_speed,
    present,
    checks,
    headlines=headlines,
    basis="design",  # the maps and kernels it was built on; mpmath's checks say independent
)

"""The speed half of the report section "Spherical harmonics" (:mod:`.sh`).

The ``sh-*`` groups of ``tests/benchmarks/bench_sh.py`` (``make bench``): each benchmark as a ratio
to its group's same-run baseline, projection time against order per path, memory bandwidth as a
share of ``np.copyto``'s, and the speed targets as checks. Without a benchmark file there are
no speed figures and no speed checks.
"""

from __future__ import annotations

from validation.report import Check, ReportContext, Table, Text

__all__ = ["benchmark_checks", "benchmark_figures"]


def benchmark_figures(groups: dict) -> tuple[dict, list[dict]]:
    """Ratios of the ``sh-*`` benchmark groups to their same-run baselines, and bandwidth shares.

    Parameters
    ----------
    groups : dict
        ``{group: [pytest-benchmark records]}`` (:meth:`ReportContext.bench_groups`).

    Returns
    -------
    results : dict
        ``{"<group> <name>": {"median_s", "ratio_to_baseline"[, "share_of_copy_bandwidth"]}}``.
    records : list of dict
        Per benchmark, in the same order: ``group``, ``name``, ``role``, ``median``,
        ``baseline_median``, ``extra_info`` and (bandwidth groups) ``share``.

    Examples
    --------
    >>> base = {"name": "copy", "stats": {"median": 0.5}, "extra_info": {"role": "baseline"}}
    >>> fast = {"name": "fast", "stats": {"median": 0.25}, "extra_info": {"role": "numpy"}}
    >>> benchmark_figures({"sh-x": [base, fast]})[0]["sh-x fast"]
    {'median_s': 0.25, 'ratio_to_baseline': 0.5}
    """
    results, records = {}, []
    for group, entries in sorted(groups.items()):
        base = [r for r in entries if r.get("extra_info", {}).get("role") == "baseline"]
        base_median = base[0]["stats"]["median"] if base else float("nan")
        for r in entries:
            info, median = r.get("extra_info", {}), r["stats"]["median"]
            key = f"{group} {r['name']}"
            results[key] = {"median_s": median, "ratio_to_baseline": median / base_median}
            record = {
                "group": group,
                "name": r["name"],
                "role": info.get("role"),
                "median": median,
                "baseline_median": base_median,
                "extra_info": info,
            }
            if group == "sh-bandwidth" and record["role"] != "baseline":
                # Bytes per second over np.copyto's, measured in the same run
                base_bw = base[0]["extra_info"]["bytes"] / base_median
                record["share"] = info["bytes"] / median / base_bw
                results[key]["share_of_copy_bandwidth"] = record["share"]
            records.append(record)
    return results, records


def benchmark_checks(records: list[dict]) -> list[Check]:
    """The speed targets on the records of :func:`benchmark_figures`, in their order.

    Examples
    --------
    >>> base = {"name": "brute", "stats": {"median": 10.0}, "extra_info": {"role": "baseline"}}
    >>> fast = {"name": "f", "stats": {"median": 0.005}, "extra_info": {"role": "frequency-ducc0"}}
    >>> records = benchmark_figures({"sh-prefilter-cube64": [base, fast]})[1]
    >>> [(c.measured, c.passed) for c in benchmark_checks(records)]  # ms; speed-up
    [(5.0, True), (2000.0, True)]
    """
    found = []
    for r in records:
        group, role, median = r["group"], r["role"], r["median"]
        if group == "sh-project-L100" and role in ("baseline", "numpy"):
            limit = 5e-3 if role == "baseline" else 25e-3
            name = "ducc0" if role == "baseline" else "numpy"
            found.append(
                Check(
                    f"projection 512×1024 L=100, {name}",
                    f"<= {limit * 1e3:g} ms",
                    1e3 * median,
                    median <= limit,
                )
            )
        elif group == "sh-project-41band":
            found.append(
                Check("projection 41 bands L=100, ducc0", "<= 250 ms", 1e3 * median, median <= 0.25)
            )
        elif group == "sh-prefilter-cube64" and role != "baseline":
            limit = 20e-3 if role == "frequency-ducc0" else 1.5
            found.append(
                Check(
                    f"prefilter 64²×6, {role}",
                    f"<= {limit * 1e3:g} ms",
                    1e3 * median,
                    median <= limit,
                )
            )
            if role == "frequency-ducc0":
                speedup = r["baseline_median"] / median
                found.append(
                    Check("prefilter speed-up over brute force", ">= 500×", speedup, speedup >= 500)
                )
        elif group == "sh-bandwidth" and role != "baseline":
            limit = 0.25 if role == "latlong_to_cubemap" else 0.5
            share = r["share"]
            found.append(
                Check(f"{role} bandwidth / np.copyto", f">= {limit:g}", share, share >= limit)
            )
    return found


def benchmark_blocks(ctx: ReportContext, records: list[dict]) -> list:
    """The benchmark table and the projection-time chart, or a note that there are no benchmarks."""
    if not records:
        return [Text("No benchmark file: run `make bench` for the speed figures.")]
    rows = [
        [r["group"], r["name"], 1e3 * r["median"], r["median"] / r["baseline_median"]]
        for r in records
    ]
    blocks = [
        Table(
            ["group", "benchmark", "median ms", "ratio to baseline"],
            rows,
            "Benchmarks (make bench)",
            "{:.4g}",
        )
    ]
    by_order: dict = {}
    for r in records:
        if r["group"] == "sh-project-order":
            by_order.setdefault(r["role"], {})[r["extra_info"]["order"]] = r["median"]
    if by_order:
        blocks.append(_order_chart(ctx, by_order))
    return blocks


def _order_chart(ctx, by_order):
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 3.2))
    for backend, times in sorted(by_order.items()):
        Ls = sorted(times)
        ax.loglog(Ls, [1e3 * times[L] for L in Ls], marker="o", label=backend)
    ax.set_xlabel("order L")
    ax.set_ylabel("ms, one 512×1024 channel")
    ax.legend()
    top = max(max(t) for t in by_order.values())
    fastest = min(by_order, key=lambda b: by_order[b].get(top, float("inf")))
    caption = (
        f"Projection time against order (make bench): at L = {top} {fastest} projects one "
        f"512×1024 channel in {1e3 * by_order[fastest][top]:.3g} ms"
    )
    if len(by_order) > 1:
        slowest = max(by_order, key=lambda b: by_order[b].get(top, 0.0))
        ratio = by_order[slowest][top] / by_order[fastest][top]
        caption += f", {ratio:.3g}× faster than {slowest}"
    return ctx.figure("projection-time", fig, caption)

"""Report section "Scale-out": sweeps on Dask and Zarr panoramas, from ``make bench``.

The figures come from ``tests/benchmarks/bench_scaleout.py`` (groups ``scaleout-sweep`` and
``scaleout-zarr``), measured in one run: a 32-task sweep serially and on a 2-worker local cluster,
and the SH projection (L = 100, 41 bands) of a 1024×2048 map in memory and streamed from a Zarr
store. From the sweep's times the section derives the per-task time and the scheduling overhead,
and the speed-up Amdahl's law predicts for more machines (``docs/scale-out.md``). When they ran,
``tests/benchmarks/bench_zarr_panorama.py`` (group ``scaleout-zarr-12k``: a 12k×6k×41 store
projected to L = 100, its wall time and peak resident memory) and
``tests/benchmarks/bench_zarr_layout.py`` (group ``scaleout-zarr-read``: read time and size by
compression and chunk size) add the full-size figures and the layout table.

compute → :func:`scaleout_figures`; present → :func:`present`; checks → :func:`checks`.
"""

from __future__ import annotations

from validation.report import (
    Check,
    Headline,
    ReportContext,
    ReportSection,
    SectionData,
    Table,
    Text,
)

#: Targets (docs/scale-out.md): distributed / serial on 2 cores, streamed / in-memory throughput.
SWEEP_TARGET, ZARR_TARGET = 1.6, 0.7
#: The bound on the 12k×6k×41 projection's peak resident memory (bytes).
PEAK_RSS_TARGET = 2e9
#: Targets of the command-line figures (``tests/benchmarks/bench_scaleout_cli.py``): a cold
#: two-worker sweep against the serial one, and ``env convert``'s peak resident memory above the
#: same command's on a tiny map, in float32 chunks (three in flight and the output's buffer).
CLI_SWEEP_TARGET, CONVERT_CHUNKS_TARGET = 1.7, 4.0


#: Workers the fitted model predicts for (the cores of machines this one stands for).
PREDICT_WORKERS = (4, 8, 16, 64)
#: The model's target at 16 workers (checked on a 16-core machine by whoever has one).
PREDICTED_16_TARGET = 8.0


def _chunks(cells: int, shared: int, workers: int) -> int:
    # Dask tasks of a sweep on ``workers``: chunks of one shared key (reference.tasks), and builds
    from reference.tasks import chunk_size

    grain = chunk_size(cells, workers)
    return shared * -(-(cells // shared) // grain) + shared


def sweep_scaling_model(
    serial_s: float, startup: dict, runs: dict, cells: int, shared: int, task_s: float | None = None
) -> dict:
    """The sweep's time on N workers: start-up, the work divided, its last chunk, Dask's tasks.

    ``T(N) = s(N) + κ·W/N + κ·W/(2·m(N)) + o·m(N)/N``, fitted to cold command-line runs
    (docs/scale-out.md):

    - ``s(N) = s_0 + s_1·N``, the start-up, least squares through the one-cell sweeps on
      ``local:N`` (``startup[N]``; the process, the imports, the cluster, the kernels' loading);
    - ``W = T_serial − s_serial``, the cells' work: the serial sweep less the serial one-cell run;
    - ``κ``, the workers' slowdown on the cells against the serial process (cores shared with the
      client, the scheduler and the nannies; 1 where each has its own);
    - ``m(N)``, the Dask tasks (chunks of one shared key, and the shared builds): the last chunk
      leaves the other workers idle for half a chunk on average (``κ·W/(2·m)``, from 2 workers),
      and ``o`` is Dask's own cost per task;
    - ``κ`` and ``o`` by non-negative least squares through the measured ``T(N)``; with ``task_s``
      (Dask's cost per task measured on its own, with empty tasks) ``o`` is that and ``κ`` alone is
      fitted, so two worker counts no longer determine both exactly.

    The serial fraction is Amdahl's ``f = s(1)/T(1)``. ``predicted_speedup`` assumes one core per
    worker with the start-up's slope as measured here (on fewer cores it holds the workers'
    imports competing for them: a lower bound); ``predicted_speedup_parallel_start`` takes
    ``s_1 = 0`` (every worker starting on its own core: an upper bound).

    Examples
    --------
    >>> m = sweep_scaling_model(70.0, {0: 5.0, 1: 8.0, 2: 8.4}, {1: 74.0, 2: 41.5}, 3840, 8)
    >>> round(m["work_s"], 1), round(m["startup_s"][0], 1), round(m["startup_s"][1], 1)
    (65.0, 7.6, 0.4)
    >>> round(m["slowdown"], 2), round(m["speedup"][2], 2)
    (1.01, 1.69)
    >>> m["predicted_speedup"][16] < m["predicted_speedup_parallel_start"][16]
    True
    """
    import numpy as np
    from scipy.optimize import nnls

    counts = sorted(n for n in startup if n >= 1)
    A = np.vstack([np.ones(len(counts)), counts]).T
    s01 = (
        np.linalg.lstsq(A, [startup[n] for n in counts], rcond=None)[0]
        if len(counts) > 1
        else (np.array([startup[counts[0]], 0.0]))
    )
    s0, s1 = float(s01[0]), max(float(s01[1]), 0.0)
    W = serial_s - startup[0]

    def terms(n):
        # the work divided and the last chunk's wait (per unit κ), and the tasks per worker
        m = _chunks(cells, shared, n)
        return W / n + (W / (2 * m) if n > 1 else 0.0), m / n

    ns = sorted(runs)
    design = np.array([terms(n) for n in ns])
    left = np.array([runs[n] - (s0 + s1 * n) for n in ns])
    if task_s is None:
        kappa, o = (float(v) for v in nnls(design, left)[0])
    else:
        o = max(float(task_s), 0.0)
        rest = left - o * design[:, 1]
        kappa = max(float(design[:, 0] @ rest / (design[:, 0] @ design[:, 0])), 0.0)

    def T(n, slope=s1):
        work, tasks = terms(n)
        return s0 + slope * n + kappa * work + o * tasks

    return {
        "startup_s": (s0, s1),
        "work_s": W,
        "slowdown": kappa,
        "overhead_s": o,
        "serial_fraction": (s0 + s1) / T(1),
        "speedup": {n: serial_s / t for n, t in sorted(runs.items())},
        "fitted_speedup": {n: serial_s / T(n) for n in ns},
        "predicted_speedup": {n: serial_s / T(n) for n in PREDICT_WORKERS},
        "predicted_speedup_parallel_start": {n: serial_s / T(n, 0.0) for n in PREDICT_WORKERS},
    }


def _cli_sweep(cli: dict) -> dict | None:
    # the serial sweep, the runs on local:N and the one-cell start-ups, and the model through them
    serial = cli.get("cli-serial", [])
    runs = {r["extra_info"]["workers"]: r["stats"]["min"] for r in cli.get("cli-workers", [])}
    startup = {r["extra_info"]["workers"]: r["stats"]["min"] for r in cli.get("cli-startup", [])}
    if not (serial and runs and 0 in startup and len(startup) > 1):
        return None
    e = serial[0]["extra_info"]
    serial_s = serial[0]["stats"]["min"]
    overhead = cli.get("cli-task-overhead", [])
    task_s = overhead[0]["extra_info"]["task_s"] if overhead else None
    model = sweep_scaling_model(serial_s, startup, runs, e["cells"], e["shared"], task_s)
    best = max(runs)
    split = cli.get("cli-split", [])
    return {
        "cells": e["cells"],
        "shared": e["shared"],
        "serial_s": serial_s,
        "runs_s": dict(sorted(runs.items())),
        "startup_serial_s": startup[0],
        "task_measured": task_s is not None,
        "workers": best,
        "local_s": runs[best],
        # the machine's ceiling without a scheduler: the sweep cut into serial processes at once
        **(
            {"split_parts": split[0]["extra_info"]["workers"], "split_s": split[0]["stats"]["min"]}
            if split
            else {}
        ),
        **model,
    }


def _cli_figures(groups: dict) -> dict | None:
    """The command-line sweep's speed-ups and model, and env convert's memory (scaleout-cli)."""
    cli: dict = {}
    for record in groups.get("scaleout-cli", []):
        cli.setdefault(record.get("extra_info", {}).get("role"), []).append(record)
    found = {}
    sweep = _cli_sweep(cli)
    if sweep is not None:
        found["sweep"] = sweep
    if "convert-memory" in cli:
        record = cli["convert-memory"][0]
        e = record["extra_info"]
        found["convert"] = {
            **{k: e[k] for k in ("height", "width", "channels", "chunk_bytes", "float32_bytes")},
            "peak_rss_bytes": e["peak_rss_bytes"],
            "baseline_rss_bytes": e["baseline_rss_bytes"],
            "above_chunks": (e["peak_rss_bytes"] - e["baseline_rss_bytes"]) / e["chunk_bytes"],
            "seconds": record["stats"]["min"],
        }
    return found or None


def _present_cli(cli: dict | None) -> list:
    """The command-line figures, when ``make bench`` measured them: a paragraph and the model."""
    if not cli:
        return []
    text, tables = [], []
    if "sweep" in cli:
        s = cli["sweep"]
        s0, s1 = s["startup_s"]
        text.append(
            f"From the command line, cold (new processes; the cluster's start, the workers' "
            f"imports and the shared exact renders included), a {s['cells']:,}-cell Phong sweep "
            f"took {s['serial_s']:.1f} s serially and {s['local_s']:.1f} s on a local cluster of "
            f"{s['workers']} workers: {s['speedup'][s['workers']]:.2f}× (target ≥ "
            f"{CLI_SWEEP_TARGET}×), the CSVs byte-identical. The model fitted to these runs: a "
            f"start-up of {s0:.1f} s + {s1:.2f} s per worker (one-cell sweeps; "
            f"{s['startup_serial_s']:.1f} s serially), {s['work_s']:.1f} s of cells' work divided "
            f"among the workers and run {s.get('slowdown', 1.0):.2f}× as long as serially, half "
            f"a chunk's wait at the end, {1e3 * s['overhead_s']:.0f} ms per Dask task"
            f"{' (measured with empty tasks)' if s.get('task_measured') else ' (fitted)'}; serial "
            f"fraction {100 * s['serial_fraction']:.0f} %. At 16 workers it predicts "
            f"{s['predicted_speedup'][16]:.1f}× with the start-up's slope measured here, "
            f"{s.get('predicted_speedup_parallel_start', s['predicted_speedup'])[16]:.1f}× if "
            "every worker started on its own core."
        )
        if "split_s" in s:
            ceiling = s["serial_s"] / s["split_s"]
            text.append(
                f"Without a scheduler, the same sweep cut by material into {s['split_parts']} "
                f"serial processes started at once took {s['split_s']:.1f} s ({ceiling:.2f}×): "
                "what this machine's cores give the sweep with no cluster to start and no "
                "scheduling, each part paying its own start-up; the cluster reached "
                f"{100 * s['speedup'][s['workers']] / ceiling:.0f} % of it."
            )
        measured = [
            [n, s["runs_s"][n], s["speedup"][n], s["fitted_speedup"][n]] for n in s["runs_s"]
        ]
        predicted = [[n, None, None, v] for n, v in s["predicted_speedup"].items()]
        if "split_s" in s:  # the machine's ceiling: serial processes, no scheduler
            split = [f"{s['split_parts']} serial processes", s["split_s"]]
            measured.append([*split, s["serial_s"] / s["split_s"], None])
        tables.append(
            Table(
                ["workers", "measured (s)", "speed-up", "model's speed-up"],
                measured + predicted,
                f"The {s['cells']:,}-cell sweep on local:N, cold, against {s['serial_s']:.1f} s "
                "serially; beyond the cores present, the model's prediction (one core per "
                f"worker; target ≥ {PREDICTED_16_TARGET:g}× at 16)",
                "{:.3g}",
            )
        )
    if "convert" in cli:
        c = cli["convert"]
        text.append(
            f"`specref env convert` of a {c['width']}×{c['height']} RGB EXR "
            f"({c['float32_bytes'] / 1e6:.0f} MB of float32) peaked at "
            f"{c['peak_rss_bytes'] / 1e6:.0f} MB resident against "
            f"{c['baseline_rss_bytes'] / 1e6:.0f} MB for a 16×32 map: "
            f"{c['above_chunks']:.1f} chunks of {c['chunk_bytes'] / 1e6:.1f} MB above it "
            f"(target ≤ {CONVERT_CHUNKS_TARGET:g}), in {c['seconds']:.1f} s."
        )
    return [Text(" ".join(text)), *tables]


def _cli_checks(cli: dict | None) -> list[Check]:
    found = []
    if cli and "sweep" in cli:
        s = cli["sweep"]
        speedup = s["speedup"][s["workers"]]
        found.append(
            Check(
                f"{s['cells']:,}-cell sweep from the command line, cold: {s['workers']}-worker "
                "local cluster / serial",
                f">= {CLI_SWEEP_TARGET}×",
                speedup,
                speedup >= CLI_SWEEP_TARGET,
            )
        )
        at_16 = s["predicted_speedup"][16]
        found.append(
            Check(
                f"{s['cells']:,}-cell sweep: the fitted model's speed-up at 16 workers",
                f">= {PREDICTED_16_TARGET:g}×",
                at_16,
                at_16 >= PREDICTED_16_TARGET,
            )
        )
    if cli and "convert" in cli:
        c = cli["convert"]
        found.append(
            Check.at_most(
                f"env convert of a {c['width']}×{c['height']} EXR: peak resident memory above a "
                "tiny map's, in float32 chunks",
                c["above_chunks"],
                CONVERT_CHUNKS_TARGET,
            )
        )
    return found


def _by_role(records: list[dict]) -> dict:
    return {r.get("extra_info", {}).get("role"): r for r in records}


_FULL_SIZE_KEYS = (
    "height",
    "width",
    "bands",
    "order",
    "wall_s",
    "peak_rss_bytes",
    "imports_rss_bytes",
    "store_bytes",
    "float32_bytes",
    "rows_per_chunk",
    "compression",
    "generate_s",
)


def _zarr_full_size(groups: dict, memory: dict) -> dict | None:
    # the 12k×6k projection's figures, and its per-pixel throughput against the 2k in-memory path
    full = _by_role(groups.get("scaleout-zarr-12k", [])).get("zarr-12k")
    if full is None:
        return None
    e = full["extra_info"]
    pixels_per_s = e["height"] * e["width"] / e["wall_s"]
    in_memory_pixels_per_s = memory["extra_info"]["pixels"] / memory["stats"]["min"]
    return {key: e[key] for key in _FULL_SIZE_KEYS} | {
        "throughput_vs_2k_in_memory": pixels_per_s / in_memory_pixels_per_s
    }


def _zarr_layout(groups: dict) -> list[dict]:
    # read time and size by map, compression and chunk size (the spectral map first)
    layout = [
        {
            "data": r["extra_info"]["data"],
            "compression": r["extra_info"]["compression"],
            "chunk_mb": r["extra_info"]["chunk_bytes"] / 1e6,
            "ratio": r["extra_info"]["ratio"],
            "read_s": r["stats"]["min"],
            "read_gb_s": r["extra_info"]["float32_bytes"] / r["stats"]["min"] / 1e9,
        }
        for r in groups.get("scaleout-zarr-read", [])
    ]
    return sorted(layout, key=lambda r: (r["data"] != "spectral", r["compression"], r["chunk_mb"]))


def scaleout_figures(ctx: ReportContext | None = None) -> SectionData:
    """The scale-out benchmarks' ratios, or nothing without ``make bench``.

    Returns
    -------
    SectionData
        ``results``: ``measured`` (bool); with benchmarks, ``sweep`` (serial and distributed
        seconds, tasks, workers, speed-up, per-task seconds, overhead per task, predicted
        speed-ups on 1–16 two-core machines) and ``zarr`` (seconds, throughput ratio, peak bytes).

    Examples
    --------
    >>> scaleout_figures().results
    {'measured': False}
    """
    groups = ctx.bench_groups("scaleout") if ctx is not None else {}
    sweep = _by_role(groups.get("scaleout-sweep", []))
    zarr = _by_role(groups.get("scaleout-zarr", []))
    cli = _cli_figures(groups)
    if not (
        {"serial", "distributed"} <= set(sweep) and {"in-memory", "zarr-streamed"} <= set(zarr)
    ):
        return SectionData({"measured": False, **({"cli": cli} if cli else {})})
    serial, dist = sweep["serial"], sweep["distributed"]
    n = serial["extra_info"]["tasks"]
    workers = dist["extra_info"]["workers"]
    t_serial, t_dist = serial["stats"]["min"], dist["stats"]["min"]
    task = t_serial / n
    # Amdahl with the measured overhead: t_dist = n·task/workers + n·o
    overhead = max(t_dist - n * task / workers, 0.0) / n
    predicted = {
        machines: t_serial / (n * task / (2 * machines) + n * overhead + task)
        for machines in (1, 2, 4, 8, 16)
    }
    memory, streamed = zarr["in-memory"], zarr["zarr-streamed"]
    full, layout = _zarr_full_size(groups, memory), _zarr_layout(groups)
    return SectionData(
        {
            "measured": True,
            "sweep": {
                "tasks": n,
                "workers": workers,
                "serial_s": t_serial,
                "distributed_s": t_dist,
                "speedup": t_serial / t_dist,
                "task_s": task,
                "overhead_s": overhead,
                "predicted_speedup": predicted,
            },
            "zarr": {
                "in_memory_s": memory["stats"]["min"],
                "streamed_s": streamed["stats"]["min"],
                "throughput_ratio": memory["stats"]["min"] / streamed["stats"]["min"],
                "peak_python_bytes": streamed["extra_info"].get("peak_python_bytes"),
                "no_readahead_ratio": (
                    memory["stats"]["min"] / zarr["zarr-streamed-no-readahead"]["stats"]["min"]
                    if "zarr-streamed-no-readahead" in zarr
                    else None
                ),
            },
            "zarr_12k": full,
            "zarr_layout": layout,
            "cli": cli,
        }
    )


def present(ctx: ReportContext, data: SectionData) -> list:
    """The sweep and Zarr figures, and the predicted speed-up on more machines."""
    r = data.results
    if not r["measured"]:
        return [
            Text("Not measured in this run: `make bench` runs the scale-out benchmarks."),
            *_present_cli(r.get("cli")),
        ]
    s, z = r["sweep"], r["zarr"]
    peak = z["peak_python_bytes"]
    return [
        Text(
            f"A sweep of {s['tasks']} independent tasks ran {s['speedup']:.2f}× faster on a "
            f"{s['workers']}-worker local Dask cluster than serially ({s['serial_s']:.1f} s → "
            f"{s['distributed_s']:.1f} s): {s['task_s']:.2f} s per task and "
            f"{1e3 * s['overhead_s']:.0f} ms of scheduling per task. The streamed projection of a "
            f"Zarr panorama ran at {100 * z['throughput_ratio']:.0f} % of the in-memory "
            "projection's speed"
            + (
                f" ({100 * z['no_readahead_ratio']:.0f} % without the thread that reads the next "
                "chunk meanwhile)"
                if z.get("no_readahead_ratio")
                else ""
            )
            + (f", with {peak / 1e6:.0f} MB of peak Python memory." if peak else ".")
        ),
        Table(
            ["two-core machines", "predicted speed-up"],
            [[m, v] for m, v in s["predicted_speedup"].items()],
            "Amdahl's law with this run's task time and overhead (docs/scale-out.md)",
            "{:.3g}",
        ),
        *_present_cli(r.get("cli")),
        *_present_zarr(r.get("zarr_12k"), r.get("zarr_layout") or []),
    ]


def _present_zarr(full: dict | None, layout: list[dict]) -> list:
    out = []
    if full is not None:
        out.append(
            Text(
                f"A synthetic {full['width']}×{full['height']}×{full['bands']} panorama "
                f"({full['float32_bytes'] / 1e9:.1f} GB as float32; a {full['compression']} "
                f"store of {full['store_bytes'] / 1e9:.1f} GB, {full['rows_per_chunk']} rows per "
                f"chunk) projected to L = {full['order']} in every band in "
                f"{full['wall_s']:.1f} s with a peak resident memory of "
                f"{full['peak_rss_bytes'] / 1e9:.2f} GB ({full['imports_rss_bytes'] / 1e9:.2f} GB "
                "of it the interpreter and its libraries), at "
                f"{100 * full['throughput_vs_2k_in_memory']:.0f} % of the per-pixel throughput of "
                "the in-memory projection of the 2k map."
            )
        )
    if layout:
        out.append(
            Table(
                ["map", "compression", "chunk (MB)", "size ratio", "read (s)", "read (GB/s)"],
                [
                    [
                        r["data"],
                        r["compression"],
                        r["chunk_mb"],
                        r["ratio"],
                        r["read_s"],
                        r["read_gb_s"],
                    ]
                    for r in layout
                ],
                "Reading a 512×1024×41 store chunk by chunk: float32 bytes over stored bytes, "
                "and the fastest of 5 reads (docs/scale-out.md, Zarr layout)",
                "{:.3g}",
            )
        )
    return out


def checks(data: SectionData) -> list[Check]:
    """The scale-out targets, when the benchmarks ran."""
    r = data.results
    if not r["measured"]:
        return _cli_checks(r.get("cli"))
    full = r.get("zarr_12k")
    memory = []
    if full is not None:
        memory = [
            Check(
                f"{full['width']}×{full['height']}×{full['bands']} Zarr panorama to "
                f"L = {full['order']}, peak resident memory (GB)",
                f"<= {PEAK_RSS_TARGET / 1e9:.0f}",
                full["peak_rss_bytes"] / 1e9,
                full["peak_rss_bytes"] <= PEAK_RSS_TARGET,
            )
        ]
    return [
        Check(
            f"{r['sweep']['tasks']}-task sweep, 2-worker local cluster / serial",
            f">= {SWEEP_TARGET}×",
            r["sweep"]["speedup"],
            r["sweep"]["speedup"] >= SWEEP_TARGET,
        ),
        Check(
            "streamed Zarr SH projection / in-memory projection, throughput",
            f">= {ZARR_TARGET}",
            r["zarr"]["throughput_ratio"],
            r["zarr"]["throughput_ratio"] >= ZARR_TARGET,
        ),
        *memory,
        *_cli_checks(r.get("cli")),
    ]


def headlines(data: SectionData) -> list[Headline]:
    """The summary's figure: the sweep's speed-up on a local cluster."""
    r = data.results
    if not r["measured"]:
        return [Headline("sweeps on Dask and Zarr panoramas: measured by `make bench`")]
    return [
        Headline(
            f"a {r['sweep']['tasks']}-task sweep {r['sweep']['speedup']:.2f}× faster on a "
            f"2-worker Dask cluster; Zarr panoramas project at "
            f"{100 * r['zarr']['throughput_ratio']:.0f} % of in-memory speed",
            f"targets ≥ {SWEEP_TARGET}× and ≥ {100 * ZARR_TARGET:.0f} %",
        )
    ]


SECTION = ReportSection(
    "scaleout", "Scale-out", scaleout_figures, present, checks, headlines=headlines
)

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


#: The start-up model holds where its wall time at the held-out worker counts (beyond the cores)
#: is within this share of the measured one.
STARTUP_HELD_OUT_TOLERANCE = 0.15
#: The sweep the command-line targets are measured on takes at least this long serially (s).
SERIAL_SWEEP_MIN_S = 60.0


def startup_model(startup: dict, cores: int) -> dict:
    """A run's start-up on N workers: its processes' CPU shared among the cores, and a latency.

    ``startup[N] = (wall_s, cpu_s)`` of a one-cell sweep on ``local:N`` (N ≥ 1; 0, the serial
    run, is not used) on a machine of ``cores`` cores (docs/scale-out.md):

    - ``u(N) = u₁ + c·(N − 1)``: the CPU seconds of the command's processes (the client with its
      scheduler and nannies, and the workers), a straight line by least squares;
      ``c`` is one more worker's start (its interpreter, its imports, its kernels' loading);
    - ``s(N; P) = L + u(N) / min(N + 1, P)``: that CPU spread over the busy processes (the client
      and N workers) on P cores, and a latency ``L`` that no core shortens (process spawns,
      handshakes). Both are fitted on the design counts N ≤ ``cores``; the counts beyond them,
      where the workers' starts compete for the cores, are held out: the model's wall time there,
      from the line's CPU, against the measured one.

    On a machine with a core per worker (P = N) the start-up is ``L + u(N)/N``, which tends to
    ``L + c``: each worker's own start stays on the way to its first task.

    Examples
    --------
    >>> m = startup_model({0: (1.7, 1.8), 1: (2.7, 2.8), 2: (3.0, 3.7), 3: (3.5, 4.7),
    ...                    4: (4.6, 6.6)}, cores=2)
    >>> round(m["latency_s"], 2), [round(v, 2) for v in m["cpu_s"]]
    (1.23, [2.8, 0.9])
    >>> {n: round(v, 2) for n, v in m["held_out_error"].items()}
    {3: 0.01, 4: -0.14}
    >>> round(m["predict"](16, 16), 2)
    2.24
    """
    import numpy as np

    counts = sorted(n for n in startup if n >= 1)
    wall = {n: startup[n][0] for n in counts}
    cpu = {n: startup[n][1] for n in counts}
    design = [n for n in counts if n <= cores] or counts[:1]
    if len(design) > 1:
        A = np.vstack([np.ones(len(design)), np.subtract(design, 1)]).T
        u1, c = (float(v) for v in np.linalg.lstsq(A, [cpu[n] for n in design], rcond=None)[0])
    else:
        u1, c = cpu[design[0]], 0.0
    c = max(c, 0.0)

    def u(n):
        return u1 + c * (n - 1)

    L = float(np.mean([wall[n] - u(n) / min(n + 1, cores) for n in design]))

    def predict(n, P):
        return L + u(n) / min(n + 1, P)

    held_out = {n: predict(n, cores) / wall[n] - 1 for n in counts if n > cores}
    return {
        "latency_s": L,
        "cpu_s": (u1, c),
        "design": design,
        "held_out_error": held_out,
        "predict_here": {n: predict(n, cores) for n in counts},
        "predict": predict,
    }


def sweep_scaling_model(
    serial_s: float,
    startup: dict,
    runs: dict,
    cells: int,
    shared: int,
    cores: int,
    task_s: float | None = None,
) -> dict:
    """The sweep's time on N workers: start-up, the work divided, its last chunk, Dask's tasks.

    ``T(N) = s(N) + κ·W/N + κ·W/(2·m(N)) + o·m(N)/N``, fitted to cold command-line runs
    (docs/scale-out.md):

    - ``s(N)``, the start-up (:func:`startup_model`, from the one-cell sweeps' wall and CPU
      times ``startup[N] = (wall_s, cpu_s)``; ``startup[0]`` is the serial one);
    - ``W = T_serial − s_serial``, the cells' work: the serial sweep less the serial one-cell run;
    - ``κ``, the workers' slowdown on the cells against the serial process (cores shared with the
      client, the scheduler and the nannies);
    - ``m(N)``, the Dask tasks (chunks of one shared key, and the shared builds): the last chunk
      leaves the other workers idle for half a chunk on average (``κ·W/(2·m)``, from 2 workers),
      and ``o`` is Dask's own cost per task;
    - ``κ`` and ``o`` by non-negative least squares through the measured ``T(N)`` (on ``cores``
      cores); with ``task_s`` (Dask's cost per task measured on its own, with empty tasks) ``o``
      is that and ``κ`` alone is fitted.

    The serial fraction is Amdahl's ``f = s(1)/T(1)``. ``predicted_speedup`` is for a machine
    with a core per worker, as the runs here had (the client and N workers on N cores).

    Examples
    --------
    >>> startup = {0: (5.0, 5.2), 1: (8.0, 9.0), 2: (8.4, 10.0)}
    >>> m = sweep_scaling_model(70.0, startup, {1: 74.0, 2: 41.5}, 3840, 8, cores=2)
    >>> round(m["work_s"], 1), round(m["slowdown"], 2), round(m["speedup"][2], 2)
    (65.0, 1.01, 1.69)
    >>> round(m["predicted_speedup"][16], 1)
    7.6
    """
    import numpy as np
    from scipy.optimize import nnls

    start = startup_model(startup, cores)
    W = serial_s - startup[0][0]

    def terms(n):
        # the work divided and the last chunk's wait (per unit κ), and the tasks per worker
        m = _chunks(cells, shared, n)
        return W / n + (W / (2 * m) if n > 1 else 0.0), m / n

    ns = sorted(runs)
    design = np.array([terms(n) for n in ns])
    left = np.array([runs[n] - start["predict"](n, cores) for n in ns])
    if task_s is None:
        kappa, o = (float(v) for v in nnls(design, left)[0])
    else:
        o = max(float(task_s), 0.0)
        rest = left - o * design[:, 1]
        kappa = max(float(design[:, 0] @ rest / (design[:, 0] @ design[:, 0])), 0.0)

    def T(n, P):
        work, tasks = terms(n)
        return start["predict"](n, P) + kappa * work + o * tasks

    return {
        "startup": {k: v for k, v in start.items() if k != "predict"},
        "work_s": W,
        "slowdown": kappa,
        "overhead_s": o,
        "serial_fraction": start["predict"](1, cores) / T(1, cores),
        "speedup": {n: serial_s / t for n, t in sorted(runs.items())},
        "fitted_speedup": {n: serial_s / T(n, cores) for n in ns},
        "predicted_startup_s": {n: start["predict"](n, n) for n in PREDICT_WORKERS},
        "predicted_speedup": {n: serial_s / T(n, n) for n in PREDICT_WORKERS},
    }


def _cli_sweep(cli: dict) -> dict | None:
    # the serial sweep, the runs on local:N and the one-cell start-ups, and the model through them
    serial = cli.get("cli-serial", [])
    runs = {r["extra_info"]["workers"]: r["stats"]["min"] for r in cli.get("cli-workers", [])}
    startup = {
        r["extra_info"]["workers"]: (r["stats"]["min"], r["extra_info"].get("cpu_s"))
        for r in cli.get("cli-startup", [])
    }
    if not (serial and runs and 0 in startup):
        return None
    e = serial[0]["extra_info"]
    serial_s = serial[0]["stats"]["min"]
    best = max(runs)
    split = cli.get("cli-split", [])
    found = {
        "cells": e["cells"],
        "shared": e["shared"],
        "serial_s": serial_s,
        "runs_s": dict(sorted(runs.items())),
        "speedup": {n: serial_s / t for n, t in sorted(runs.items())},
        "startup_serial_s": startup[0][0],
        "startup_runs": {n: {"wall_s": w, "cpu_s": c} for n, (w, c) in sorted(startup.items())},
        "workers": best,
        "local_s": runs[best],
        # the machine's ceiling without a scheduler: the sweep cut into serial processes at once
        **(
            {"split_parts": split[0]["extra_info"]["workers"], "split_s": split[0]["stats"]["min"]}
            if split
            else {}
        ),
    }
    cores = next((r["extra_info"].get("cores") for r in cli.get("cli-startup", [])), None)
    if cores is None or len(startup) < 2 or any(c is None for _, c in startup.values()):
        return found  # a benchmark file from before the CPU times: no model
    overhead = cli.get("cli-task-overhead", [])
    task_s = overhead[0]["extra_info"]["task_s"] if overhead else None
    model = sweep_scaling_model(
        serial_s, startup, runs, e["cells"], e["shared"], cores, task_s=task_s
    )
    return {**found, "cores": cores, "task_measured": task_s is not None, **model}


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


def _model_text(s: dict) -> str:
    # the start-up model and the sweep's, in words (docs/scale-out.md)
    st = s["startup"]
    u1, c = st["cpu_s"]
    held = ", ".join(
        f"{100 * err:+.0f} % at {n}" for n, err in sorted(st["held_out_error"].items())
    )
    return (
        f"The start-up (one-cell sweeps; {s['startup_serial_s']:.1f} s serially) is "
        f"{u1:.1f} s of CPU on one worker and {c:.2f} s more per further worker (the worker's "
        f"interpreter, imports and kernels), spread over the busy processes on the "
        f"{s['cores']} cores, plus a latency of {st['latency_s']:.2f} s that no core shortens "
        f"(fitted on 1 to {s['cores']} workers"
        + (f"; on the held-out counts beyond the cores the model is off by {held}" if held else "")
        + f"). The sweep's {s['work_s']:.1f} s of cells' work is divided among the workers and "
        f"runs {s['slowdown']:.2f}× as long as serially, with half a chunk's wait at the end and "
        f"{1e3 * s['overhead_s']:.0f} ms per Dask task"
        f"{' (measured with empty tasks)' if s.get('task_measured') else ' (fitted)'}; serial "
        f"fraction {100 * s['serial_fraction']:.0f} %. On a machine with a core per worker it "
        f"predicts {s['predicted_speedup'][16]:.1f}× at 16 workers (target ≥ "
        f"{PREDICTED_16_TARGET:g}×), with a start-up of {s['predicted_startup_s'][16]:.1f} s."
    )


def _sweep_text(s: dict) -> list[str]:
    text = [
        f"From the command line, cold (new processes; the cluster's start, the workers' "
        f"imports and the shared exact renders included), a {s['cells']:,}-cell Phong sweep "
        f"took {s['serial_s']:.1f} s serially and {s['local_s']:.1f} s on a local cluster of "
        f"{s['workers']} workers: {s['speedup'][s['workers']]:.2f}× (target ≥ "
        f"{CLI_SWEEP_TARGET}×), the CSVs byte-identical."
    ]
    if "predicted_speedup" in s:
        text.append(_model_text(s))
    if "split_s" in s:
        ceiling = s["serial_s"] / s["split_s"]
        text.append(
            f"Without a scheduler, the same sweep cut by material into {s['split_parts']} "
            f"serial processes started at once took {s['split_s']:.1f} s ({ceiling:.2f}×): "
            "what this machine's cores give the sweep with no cluster to start and no "
            "scheduling, each part paying its own start-up; the cluster reached "
            f"{100 * s['speedup'][s['workers']] / ceiling:.0f} % of it."
        )
    return text


def _sweep_tables(s: dict) -> list:
    fitted = s.get("fitted_speedup", {})
    rows = [[n, s["runs_s"][n], s["speedup"][n], fitted.get(n)] for n in s["runs_s"]]
    if "split_s" in s:  # the machine's ceiling: serial processes, no scheduler
        split = [f"{s['split_parts']} serial processes", s["split_s"]]
        rows.append([*split, s["serial_s"] / s["split_s"], None])
    rows += [[n, None, None, v] for n, v in s.get("predicted_speedup", {}).items()]
    tables = [
        Table(
            ["workers", "measured (s)", "speed-up", "model's speed-up"],
            rows,
            f"The {s['cells']:,}-cell sweep on local:N, cold, against {s['serial_s']:.1f} s "
            "serially; beyond the cores present, the model's prediction (one core per "
            f"worker; target ≥ {PREDICTED_16_TARGET:g}× at 16)",
            "{:.3g}",
        )
    ]
    if "startup" in s:
        st = s["startup"]
        model = st.get("predict_here", {})
        starts = [
            [
                n,
                r["wall_s"],
                r["cpu_s"],
                model.get(n),
                "held out" if n > s["cores"] else ("design" if n >= 1 else "serial"),
            ]
            for n, r in s["startup_runs"].items()
        ]
        tables.append(
            Table(
                ["workers", "wall (s)", "CPU (s)", "model's wall (s)", "fit"],
                starts,
                f"A one-cell sweep on local:N, cold, on {s['cores']} cores: the start-up model "
                f"is fitted on 1 to {s['cores']} workers and held out beyond (target: within "
                f"{100 * STARTUP_HELD_OUT_TOLERANCE:.0f} %)",
                "{:.3g}",
            )
        )
    return tables


def _present_cli(cli: dict | None) -> list:
    """The command-line figures, when ``make bench`` measured them: a paragraph and the model."""
    if not cli:
        return []
    text, tables = [], []
    if "sweep" in cli:
        text += _sweep_text(cli["sweep"])
        tables += _sweep_tables(cli["sweep"])
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


def _sweep_checks(s: dict) -> list[Check]:
    # "design": the benchmarks' own inputs, on which the settings (chunks, allocator, Dask's
    # housekeeping) were chosen; the start-up model's counts beyond the cores are held out
    speedup = s["speedup"][s["workers"]]
    found = [
        Check(
            f"{s['cells']:,}-cell sweep from the command line, cold: {s['workers']}-worker "
            "local cluster / serial",
            f">= {CLI_SWEEP_TARGET}×",
            speedup,
            speedup >= CLI_SWEEP_TARGET,
            "design",
        ),
        Check(
            f"{s['cells']:,}-cell sweep: its serial time (s), which the sweep's targets are "
            "measured on",
            f">= {SERIAL_SWEEP_MIN_S:g}",
            s["serial_s"],
            s["serial_s"] >= SERIAL_SWEEP_MIN_S,
            "design",
        ),
    ]
    if "predicted_speedup" not in s:
        return found
    held = s["startup"]["held_out_error"]
    if held:
        worst = max(abs(v) for v in held.values())
        found.append(
            Check.at_most(
                f"start-up model on {', '.join(map(str, sorted(held)))} workers "
                f"({s['cores']} cores): largest |model − measured| / measured",
                worst,
                STARTUP_HELD_OUT_TOLERANCE,
                "held out",
            )
        )
    at_16 = s["predicted_speedup"][16]
    found.append(
        Check(
            f"{s['cells']:,}-cell sweep: the fitted model's speed-up at 16 workers",
            f">= {PREDICTED_16_TARGET:g}×",
            at_16,
            at_16 >= PREDICTED_16_TARGET,
            "design",
        )
    )
    return found


def _cli_checks(cli: dict | None) -> list[Check]:
    found = []
    if cli and "sweep" in cli:
        found += _sweep_checks(cli["sweep"])
    if cli and "convert" in cli:
        c = cli["convert"]
        found.append(
            Check.at_most(
                f"env convert of a {c['width']}×{c['height']} EXR: peak resident memory above a "
                "tiny map's, in float32 chunks",
                c["above_chunks"],
                CONVERT_CHUNKS_TARGET,
                "design",
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
                "design",
            )
        ]
    return [
        Check(
            f"{r['sweep']['tasks']}-task sweep, 2-worker local cluster / serial",
            f">= {SWEEP_TARGET}×",
            r["sweep"]["speedup"],
            r["sweep"]["speedup"] >= SWEEP_TARGET,
            "design",
        ),
        Check(
            "streamed Zarr SH projection / in-memory projection, throughput",
            f">= {ZARR_TARGET}",
            r["zarr"]["throughput_ratio"],
            r["zarr"]["throughput_ratio"] >= ZARR_TARGET,
            "design",
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

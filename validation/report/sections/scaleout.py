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


def _cli_figures(groups: dict) -> dict | None:
    """The command-line sweep's speed-up and env convert's memory, from group scaleout-cli."""
    cli = _by_role(groups.get("scaleout-cli", []))
    found = {}
    if {"cli-serial", "cli-local"} <= set(cli):
        serial, local = cli["cli-serial"], cli["cli-local"]
        found["sweep"] = {
            "cells": serial["extra_info"]["cells"],
            "workers": local["extra_info"]["workers"],
            "serial_s": serial["stats"]["min"],
            "local_s": local["stats"]["min"],
            "speedup": serial["stats"]["min"] / local["stats"]["min"],
        }
    if "convert-memory" in cli:
        e = cli["convert-memory"]["extra_info"]
        found["convert"] = {
            **{k: e[k] for k in ("height", "width", "channels", "chunk_bytes", "float32_bytes")},
            "peak_rss_bytes": e["peak_rss_bytes"],
            "baseline_rss_bytes": e["baseline_rss_bytes"],
            "above_chunks": (e["peak_rss_bytes"] - e["baseline_rss_bytes"]) / e["chunk_bytes"],
            "seconds": cli["convert-memory"]["stats"]["min"],
        }
    return found or None


def _present_cli(cli: dict | None) -> list:
    """The command-line figures as a paragraph, when ``make bench`` measured them."""
    if not cli:
        return []
    text = []
    if "sweep" in cli:
        s = cli["sweep"]
        text.append(
            f"From the command line, cold (new processes; the cluster's start, the workers' "
            f"imports and exact renders included), a {s['cells']}-cell Phong sweep took "
            f"{s['serial_s']:.1f} s serially and {s['local_s']:.1f} s on a local cluster of "
            f"{s['workers']} workers: {s['speedup']:.2f}× (target ≥ {CLI_SWEEP_TARGET}×), the CSVs "
            "byte-identical."
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
    return [Text(" ".join(text))]


def _cli_checks(cli: dict | None) -> list[Check]:
    found = []
    if cli and "sweep" in cli:
        s = cli["sweep"]
        found.append(
            Check(
                f"{s['cells']}-cell sweep from the command line, cold: {s['workers']}-worker "
                "local cluster / serial",
                f">= {CLI_SWEEP_TARGET}×",
                s["speedup"],
                s["speedup"] >= CLI_SWEEP_TARGET,
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

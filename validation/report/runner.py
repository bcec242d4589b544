"""The main job, ``specref report``: run every section and write the report.

:func:`run_report` runs the sections of :data:`SECTIONS` in order at an effort (:data:`EFFORTS`:
``quick``, ``default``, ``full``; each section's ``default_effort`` says which of its settings the
default run uses), says on stderr what it runs (a bar on a terminal; otherwise one line per section
with its time) and writes, each atomically:

- ``DIR/index.html``: the readable report, rewritten after every section with the sections still
  to come listed as such, so a run stopped half-way leaves a readable page;
- ``DIR/results.json``: every figure, by section;
- ``DIR/images/*.png``: images and matplotlib charts;
- ``DIR/first-screen.png``: the first screen in headless Chromium, where Chromium is installed,
  so a reviewer can look without a browser;
- optionally a Markdown rendering (``docs/results.md`` is generated this way, never typed).

A new section is a module in ``validation/report/sections/`` that defines ``SECTION`` (a
:class:`~validation.report.types.ReportSection`) and one entry in a part of :data:`PARTS`.
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import json
import os
import platform
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from reference.errors import require, require_choice
from reference.files import read_json, write_bytes_atomic, write_text_atomic
from reference.registry import Registry
from reference.tasks import LOCAL, SERIAL, dask_client, scheduler_address
from validation.report.render import render_html, render_markdown
from validation.report.sections import (
    conformance,
    crosscheck,
    display,
    examples,
    impastor,
    impastor_settings,
    phong,
    polymer,
    polymer_scene,
    raster,
    scaleout,
    sh,
    sh_order,
    shrm,
    shrm_fullres,
    spectral,
    spectral_env,
)
from validation.report.types import (
    EFFORTS,
    ReportContext,
    ReportPart,
    ReportSection,
    SectionResult,
    to_jsonable,
)

__all__ = ["EFFORTS", "PARTS", "REPORT_SECTIONS", "SECTIONS", "run_report", "start_order"]

#: The report's parts, one per paper and one for the shared core, each with its sections in the
#: order a reader meets them. The summary shows one block per part.
PARTS: tuple[ReportPart, ...] = (
    ReportPart(
        "core",
        "The shared spectral core",
        "Spectra, colorimetry, the rasterizer, the scenes all papers render with; a cross-check.",
        (
            spectral.SECTION,
            raster.SECTION,
            examples.SECTION,
            crosscheck.SECTION,
            conformance.SECTION,
            scaleout.SECTION,
        ),
    ),
    ReportPart(
        "wang",
        "Wang, Chern & Lee: spectral Phong tables",
        "Importance-driven adaptive tables and parabolic interpolation for spectral Phong.",
        (phong.SECTION,),
    ),
    ReportPart(
        "herbert",
        "Herbert et al.: SH, SHRMs, the hybrid polymer model, spectral environments, calibration",
        "SH to order 100, prefiltering, SHRMs, spectral panoramas, display calibration.",
        (
            sh.SECTION,
            sh_order.SECTION,
            spectral_env.SECTION,
            shrm.SECTION,
            shrm_fullres.SECTION,
            polymer.SECTION,
            polymer_scene.SECTION,
            display.SECTION,
        ),
    ),
    ReportPart(
        "ferwerda",
        "Ferwerda: ImpastoR",
        "Six-channel multispectral rendering, Ward–Dür gloss, median cut, FIS and horizon shadows.",
        (impastor.SECTION, impastor_settings.SECTION),
    ),
)

#: The report's sections, in reading order (the parts' sections, one after the other).
SECTIONS: tuple[ReportSection, ...] = tuple(s for part in PARTS for s in part.sections)

#: One chart style for every section: fonts readable at the size the page shows the charts.
CHART_STYLE = {
    "font.size": 11,
    "axes.titlesize": 12,
    "axes.labelsize": 11,
    "xtick.labelsize": 10,
    "ytick.labelsize": 10,
    "legend.fontsize": 9,
    "legend.framealpha": 0.85,
    "axes.grid": True,
    "grid.alpha": 0.3,
}


def _commit() -> str:
    """The git commit of the running code (``+dirty`` with local changes), or ``unknown``."""
    here = Path(__file__).resolve().parent
    try:
        head = subprocess.run(
            ["git", "-C", str(here), "rev-parse", "--short=12", "HEAD"],
            capture_output=True,
            text=True,
            timeout=10,
            check=True,
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "-C", str(here), "status", "--porcelain", "--untracked-files=no"],
            capture_output=True,
            text=True,
            timeout=10,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return head + ("+dirty" if dirty else "")


def _quiet() -> bool:
    """Progress bars stay off under CI and when stderr is not a terminal."""
    return bool(os.environ.get("CI")) or not sys.stderr.isatty()


#: Report sections by key (``specref report --only`` takes the keys).
REPORT_SECTIONS = Registry("report section", ReportSection)
for _section in SECTIONS:
    REPORT_SECTIONS.register(_section)


def run_report(
    out_dir="report",
    effort: str = "default",
    only: list[str] | None = None,
    bench_json=None,
    markdown=None,
    markdown_image_prefix: str = "",
    progress: bool = True,
    sections=None,
    screenshot: bool = False,
    scheduler: str | None = None,
    jobs: int = 1,
) -> dict:
    """Run the report sections and write ``index.html`` and ``results.json`` into ``out_dir``.

    Parameters
    ----------
    out_dir : str or Path
        Output folder (created).
    effort : {"quick", "default", "full"}
        How much to compute (:data:`EFFORTS`; ``default``: each section's ``default_effort``).
    only : list of str, optional
        Section keys to run; default all.
    bench_json : str or Path, optional
        pytest-benchmark JSON from ``make bench`` (the sections that read benchmarks show it).
    markdown, markdown_image_prefix : str or Path, optional
        Also write a Markdown rendering there (``docs/results.md``), its image links prefixed with
        the path from it to ``out_dir``.
    progress : bool
        Say on stderr what runs: a bar on a terminal, else a line per section with its time.
    sections : sequence of ReportSection, optional
        The sections to choose from (default :data:`SECTIONS`).
    screenshot : bool
        Also write ``first-screen.png`` with headless Chromium (where it is installed).
    scheduler : str, optional
        Where the sections' independent tasks run (:meth:`ReportContext.run_tasks`): a scheduler
        address, ``"local"`` or ``"serial"``; default ``$SPECREF_SCHEDULER``, else serial (the
        sections time methods, and a cluster's workers would share the cores they measure).
    jobs : int
        Sections side by side in this many processes (serial scheduler only).

    Returns
    -------
    dict
        The content of ``results.json``.

    Raises
    ------
    SpecrefError
        Unknown section key or effort, unreadable benchmark file.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     results = run_report(folder, "quick", only=["spectral-core"], progress=False)
    >>> round(results["sections"]["spectral-core"]["380-780/10 FL2 point"]["mean"], 1)
    4.0
    """
    require_choice(effort, EFFORTS, "report effort")
    out_dir = Path(out_dir)
    sections = _chosen_sections(list(SECTIONS if sections is None else sections), only)
    bench = _read_bench(bench_json)
    address = scheduler_address(scheduler, default=SERIAL)
    meta = _meta(effort, bench_json, address)
    # Run the sections, timed; the page is rewritten after each (the rest listed as to come).
    run = _Run(out_dir, effort, bench, address, meta, sections, jobs if address == SERIAL else 1)
    done = _run_sections(run, progress)
    # Write the page, the figures and, on request, the Markdown and the first screen.
    results = _results(meta, done)
    parts = _parts(done, sections)
    write_text_atomic(out_dir / "index.html", render_html("specref report", meta, done, parts))
    _write_results(out_dir, results)
    if markdown is not None:
        text = render_markdown("specref results", meta, done, markdown_image_prefix, parts)
        write_text_atomic(markdown, text)
    if screenshot:
        results["meta"]["screenshot"] = _first_screen(out_dir)
        _write_results(out_dir, results)
    return results


def _chosen_sections(sections: list, only: list[str] | None) -> list:
    """The sections named in ``only`` (all when it is empty); an unknown key is refused."""
    if only:
        known = Registry("report section", ReportSection)
        for section in sections:
            known.register(section)
        for name in only:
            known.lookup(name)
        sections = [s for s in sections if s.name in only]
    return sections


def _read_bench(bench_json) -> dict | None:
    """The pytest-benchmark JSON of ``make bench``, or None when no file is given."""
    if bench_json is None:
        return None
    bench = read_json(bench_json, "pytest-benchmark JSON file")
    require(isinstance(bench, dict), f"{bench_json}: not a pytest-benchmark JSON file")
    return bench


def _meta(effort: str, bench_json, address: str | None) -> dict:
    """The run's description: commit, date, effort, machine, benchmark file and scheduler."""
    return {
        "commit": _commit(),
        "date": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "mode": effort,
        "cores": os.cpu_count(),
        "python": platform.python_version(),
        "machine": platform.machine(),
        "benchmarks": str(bench_json) if bench_json else "none (run make bench)",
        "scheduler": "serial" if address == SERIAL else (address or "local cluster"),
    }


def _results(meta: dict, done: list) -> dict:
    """The content of ``results.json``: ``meta``, every section's checks and figures."""
    results: dict = {"meta": meta, "checks": [], "sections": {}}
    for section, result in done:
        results["sections"][section.name] = to_jsonable(result.results)
        for c in result.checks:
            results["checks"].append(to_jsonable({"section": section.name, **c.__dict__}))
    return results


def _parts(done: list, sections: list) -> list[ReportPart]:
    """The parts with the sections that ran; one untitled part when they belong to none."""
    parts = [p.only(s.name for s, _ in done) for p in PARTS]
    return [p for p in parts if p.sections] or [ReportPart("all", "", "", tuple(sections))]


def _first_screen(out_dir: Path) -> str:
    """Write ``first-screen.png`` of ``index.html``; returns the outcome for ``results.json``."""
    from validation.report.browser import screenshot_first_screen

    return screenshot_first_screen(out_dir / "index.html", out_dir / "first-screen.png")


def _write_results(out_dir: Path, results: dict) -> None:
    """Write ``results.json`` atomically."""
    write_text_atomic(out_dir / "results.json", json.dumps(results, indent=1, sort_keys=False))


@dataclass(frozen=True)
class _Run:
    """What every section of one run shares: where it writes, its effort and its inputs."""

    out_dir: Path
    effort: str
    bench: dict | None
    address: str | None
    meta: dict
    sections: list
    jobs: int = 1


def _run_sections(run: _Run, progress: bool) -> list:
    """Run each section; returns ``[(section, result), ...]`` in reading order.

    The sections draw in :data:`CHART_STYLE`. For ``reference.tasks.SERIAL`` they run in this
    process, or side by side in ``run.jobs`` forked processes; otherwise each section is a task
    on the Dask cluster at ``run.address`` (a local cluster for None) and sends its own tasks to
    the same cluster (:func:`run_section_task`), so independent sections run side by side. After
    each section the page is rewritten with the sections still to come, and stderr gets a line
    with the section's time (or a bar, on a terminal).
    """
    import matplotlib

    done: dict[str, tuple[ReportSection, SectionResult]] = {}
    tracker = _Tracker(run, progress and not _quiet(), progress)
    with matplotlib.rc_context(CHART_STYLE), contextlib.ExitStack() as stack:
        if run.jobs > 1:
            finished = _side_by_side(run, stack)
        else:
            if run.address == SERIAL:
                finished = ((s, _run_section(run, s, None)) for s in run.sections)
            else:
                finished = _on_scheduler(
                    run, stack.enter_context(dask_client(run.address or LOCAL))
                )
        for section, result in finished:
            done[section.name] = (section, result)
            tracker.finished(
                section, result, [done[s.name] for s in run.sections if s.name in done]
            )
    return [done[s.name] for s in run.sections]


class _Tracker:
    """What the run says as sections finish: a bar or a line each, and the partial page."""

    def __init__(self, run: _Run, bars: bool, lines: bool):
        from tqdm import tqdm

        self.run, self.lines = run, lines and not bars
        self.bar = tqdm(total=len(run.sections), file=sys.stderr, disable=not bars)
        self.started = time.perf_counter()
        self.count = 0

    def finished(self, section: ReportSection, result: SectionResult, done: list) -> None:
        """Note one finished section: progress, the run's times, the page so far."""
        self.count += 1
        self.bar.set_description(section.title)
        self.bar.update(1)
        self.run.meta["total_seconds"] = round(time.perf_counter() - self.started, 1)
        self.run.meta["section_seconds"] = {s.name: round(r.seconds, 1) for s, r in done}
        if self.lines:
            n = len(self.run.sections)
            sys.stderr.write(f"[{self.count}/{n}] {section.title}: {result.seconds:.1f} s\n")
            sys.stderr.flush()
        _write_partial_page(self.run, done)
        if self.count == len(self.run.sections):
            self.bar.close()


#: The sections of a run with ``jobs`` > 1, as forked processes see them.
_FORKED: dict = {}


def _run_forked(index: int) -> tuple[int, SectionResult]:
    """Run section ``index`` of the forked run (in a worker process, in the chart style).

    Each process gets its share of the cores for BLAS and OpenMP (threadpoolctl): two
    processes with a multithreaded BLAS each would run four threads on two cores, and such
    oversubscription makes matrix-heavy sections two to three times slower.
    """
    import matplotlib
    from threadpoolctl import threadpool_limits

    run = _FORKED["run"]
    share = max(1, (os.cpu_count() or 1) // run.jobs)
    with threadpool_limits(limits=share), matplotlib.rc_context(CHART_STYLE):
        return index, _run_section(run, run.sections[index], None)


def _side_by_side(run: _Run, stack: contextlib.ExitStack):
    """Yield ``(section, result)`` as the sections finish in ``run.jobs`` forked processes."""
    import concurrent.futures
    import multiprocessing

    _FORKED["run"] = run
    pool = stack.enter_context(
        concurrent.futures.ProcessPoolExecutor(
            run.jobs, mp_context=multiprocessing.get_context("fork")
        )
    )
    futures = [
        pool.submit(_run_forked, i) for i in start_order(run.sections, run.out_dir, run.effort)
    ]
    for future in concurrent.futures.as_completed(futures):
        index, result = future.result()
        yield run.sections[index], result


def start_order(sections, out_dir, effort: str) -> list[int]:
    """The order in which side-by-side sections start: the longest first.

    Longest first (the LPT rule, Graham 1969) ends a run on few processes sooner than reading
    order, whose long sections came last. The lengths are the last run's, from
    ``out_dir/results.json`` when it ran at the same effort; without them, the sections whose
    settings are heavy enough to be quick under the default effort (``default_effort="quick"``)
    start first. The page keeps the reading order.

    Examples
    --------
    >>> import json, tempfile
    >>> from pathlib import Path
    >>> parts = [ReportSection("a", "A"), ReportSection("b", "B", default_effort="quick"),
    ...          ReportSection("c", "C")]
    >>> folder = Path(tempfile.mkdtemp())
    >>> start_order(parts, folder, "default")
    [1, 0, 2]
    >>> meta = {"mode": "default", "section_seconds": {"a": 1.0, "b": 2.0, "c": 9.0}}
    >>> _ = (folder / "results.json").write_text(json.dumps({"meta": meta}))
    >>> start_order(parts, folder, "default"), start_order(parts, folder, "full")
    ([2, 1, 0], [1, 0, 2])
    """
    seconds = {}
    try:
        meta = json.loads((Path(out_dir) / "results.json").read_text(encoding="utf-8"))["meta"]
        if meta.get("mode") == effort:
            seconds = {k: float(v) for k, v in meta.get("section_seconds", {}).items()}
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        seconds = {}  # no earlier run here, or not one this can read: the heuristic below
    if seconds and all(s.name in seconds for s in sections):
        return sorted(range(len(sections)), key=lambda i: -seconds[sections[i].name])
    heavy = [i for i, s in enumerate(sections) if s.default_effort == "quick"]
    return heavy + [i for i in range(len(sections)) if i not in heavy]


def run_section_task(section: ReportSection, effort: str, bench: dict | None) -> tuple:
    """One report section as a Dask task: its result and the files it wrote, by relative path.

    The section runs in a temporary folder of the worker (the client writes the files into the
    report's folder, so workers need no shared file system), in the chart style, and sends its
    own independent tasks to the same cluster (``distributed.worker_client``).
    """
    import tempfile

    import matplotlib
    from distributed import worker_client

    with (
        tempfile.TemporaryDirectory() as folder,
        matplotlib.rc_context(CHART_STYLE),
        worker_client() as client,
    ):
        run = _Run(Path(folder), effort, bench, None, {}, [section])
        result = _run_section(run, section, client)
        files = {
            path.relative_to(folder).as_posix(): path.read_bytes()
            for path in sorted(Path(folder).rglob("*"))
            if path.is_file()
        }
    return result, files


def _on_scheduler(run: _Run, client):
    """Yield ``(section, result)`` as the sections finish, each a task on ``client``'s cluster."""
    from distributed import as_completed

    futures = {
        client.submit(run_section_task, section, run.effort, run.bench, pure=False): section
        for section in run.sections
    }
    for future in as_completed(futures):
        result, files = future.result()
        for name, data in files.items():
            write_bytes_atomic(run.out_dir / name, data)
        yield futures[future], result


def _run_section(run: _Run, section: ReportSection, client) -> SectionResult:
    """One section at the settings the run's effort gives it, timed."""
    quick = section.quick_under(run.effort)
    ctx = ReportContext(run.out_dir, quick, run.bench, section.name, client)
    start = time.perf_counter()
    result = section.run(ctx)
    result.seconds = time.perf_counter() - start
    result.quick = quick
    result.results.setdefault("section_seconds", result.seconds)
    return result


def _write_partial_page(run: _Run, done: list) -> None:
    """``index.html`` with the sections done so far; the others are listed as still to come."""
    names = {s.name for s, _ in done}
    pending = [s for s in run.sections if s.name not in names]
    page = render_html("specref report", run.meta, done, _parts(done, run.sections), pending)
    write_text_atomic(run.out_dir / "index.html", page)

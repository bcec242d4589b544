"""The main job, ``specref report``: run every section and write the report.

:func:`run_report` runs the sections of :data:`SECTIONS` in order, with tqdm progress on stderr, and
writes, each atomically:

- ``DIR/index.html``: the readable report;
- ``DIR/results.json``: every figure, by section;
- ``DIR/images/*.png``: images and matplotlib charts;
- optionally a Markdown rendering (``docs/results.md`` is generated this way, never typed).

A new section is a module in ``validation/sections/`` that defines ``SECTION`` (a
:class:`~validation.report.types.ReportSection`) and one entry in :data:`SECTIONS`.
"""

from __future__ import annotations

import datetime as _dt
import json
import platform
import sys
import time
from pathlib import Path

from reference.errors import require
from reference.images import read_json, write_text_atomic
from reference.registry import Registry
from validation.report.render import render_html, render_markdown
from validation.report.types import ReportContext, ReportSection, SectionResult, to_jsonable
from validation.sections import (
    display,
    examples,
    impastor,
    phong,
    polymer,
    raster,
    sh,
    sh_order,
    shrm,
    spectral,
    spectral_env,
)

__all__ = ["REPORT_SECTIONS", "SECTIONS", "run_report"]

#: The report's sections, in the order a reader meets them.
SECTIONS: tuple[ReportSection, ...] = (
    spectral.SECTION,
    raster.SECTION,
    examples.SECTION,
    phong.SECTION,
    sh.SECTION,
    sh_order.SECTION,
    spectral_env.SECTION,
    shrm.SECTION,
    polymer.SECTION,
    impastor.SECTION,
    display.SECTION,
)

#: Report sections by key (``specref report --only`` takes the keys).
REPORT_SECTIONS = Registry("report section")
for _section in SECTIONS:
    REPORT_SECTIONS.register(_section)


def run_report(
    out_dir="report",
    quick: bool = False,
    only: list[str] | None = None,
    bench_json=None,
    markdown=None,
    markdown_image_prefix: str = "",
    progress: bool = True,
    sections=None,
) -> dict:
    """Run the report sections and write ``index.html`` and ``results.json`` into ``out_dir``.

    Parameters
    ----------
    out_dir : str or Path
        Output folder (created).
    quick : bool
        Small sizes (under a minute in all).
    only : list of str, optional
        Section keys to run; default all.
    bench_json : str or Path, optional
        pytest-benchmark JSON from ``make bench``, shown by the sections that read benchmarks.
    markdown : str or Path, optional
        Also write a Markdown rendering here (``docs/results.md``).
    markdown_image_prefix : str
        Prefix for image links in the Markdown (the path from the Markdown file to ``out_dir``).
    progress : bool
        Show tqdm progress on stderr.
    sections : sequence of ReportSection, optional
        The sections to choose from (default :data:`SECTIONS`).

    Returns
    -------
    dict
        The content of ``results.json``.

    Raises
    ------
    SpecrefError
        Unknown section key, unreadable benchmark file.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     results = run_report(folder, quick=True, only=["spectral-core"], progress=False)
    >>> round(results["sections"]["spectral-core"]["380-780/10 FL2 point"]["mean"], 1)
    4.0
    """
    from tqdm import tqdm

    out_dir = Path(out_dir)
    sections = list(SECTIONS if sections is None else sections)
    if only:
        known = Registry("report section")
        for section in sections:
            known.register(section)
        for name in only:
            known.lookup(name)
        sections = [s for s in sections if s.name in only]
    bench = None
    if bench_json is not None:
        bench = read_json(bench_json, "pytest-benchmark JSON file")
        require(isinstance(bench, dict), f"{bench_json}: not a pytest-benchmark JSON file")
    meta = {
        "date": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "mode": "quick" if quick else "full",
        "python": platform.python_version(),
        "machine": platform.machine(),
        "benchmarks": str(bench_json) if bench_json else "none (run make bench)",
    }
    done: list[tuple[ReportSection, SectionResult]] = []
    results: dict = {"meta": meta, "checks": [], "sections": {}}
    bar = tqdm(
        sections, desc="specref report", unit="section", file=sys.stderr, disable=not progress
    )
    for section in bar:
        bar.set_postfix_str(section.name)
        ctx = ReportContext(out_dir=out_dir, quick=quick, bench=bench, section=section.name)
        start = time.perf_counter()
        result = section.run(ctx)
        result.results.setdefault("section_seconds", time.perf_counter() - start)
        done.append((section, result))
        results["sections"][section.name] = to_jsonable(result.results)
        for c in result.checks:
            results["checks"].append(to_jsonable({"section": section.name, **c.__dict__}))
    title = "specref report"
    write_text_atomic(out_dir / "index.html", render_html(title, meta, done))
    write_text_atomic(out_dir / "results.json", json.dumps(results, indent=1, sort_keys=False))
    if markdown is not None:
        write_text_atomic(
            markdown, render_markdown("specref results", meta, done, markdown_image_prefix)
        )
    return results

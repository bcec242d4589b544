"""The main job, ``specref report``: every section's figures, tables, images and charts.

A report section is a registry entry (:data:`REPORT_SECTIONS`): a function that takes a
:class:`ReportContext` and returns a :class:`SectionResult`, made of blocks (:class:`Text`,
:class:`Table`, :class:`Image`) and a dict of results. :func:`run_report` runs the sections in order
with tqdm progress on
stderr and writes, each atomically:

- ``DIR/index.html``: the readable report;
- ``DIR/results.json``: every figure, by section;
- ``DIR/images/*.png``: images and matplotlib charts;
- optionally a Markdown rendering (``docs/results.md`` is generated this way, never typed).

A later issue adds a section by registering it in a module imported by
``validation/sections/__init__.py``; it never edits this dispatcher.
"""

from __future__ import annotations

import datetime as _dt
import html
import json
import math
import platform
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reference.errors import SpecrefError, require
from reference.images import write_png, write_text_atomic
from reference.registry import Registry

__all__ = [
    "REPORT_SECTIONS",
    "Check",
    "Image",
    "ReportContext",
    "ReportSection",
    "SectionResult",
    "Table",
    "Text",
    "run_report",
    "to_jsonable",
]


@dataclass(frozen=True)
class Text:
    """A paragraph (plain text; ``code`` spans in backticks are kept)."""

    text: str


@dataclass(frozen=True)
class Table:
    """A table: column headers, rows of cells (numbers formatted with ``fmt``), and a caption."""

    columns: list[str]
    rows: list[list]
    caption: str = ""
    fmt: str = "{:.4g}"


@dataclass(frozen=True)
class Image:
    """An image file written under ``DIR/images`` (path relative to ``DIR``) with a caption."""

    path: str
    caption: str = ""


@dataclass(frozen=True)
class Check:
    """A target and the measured value that meets it or not, shown in the report's summary.

    Parameters
    ----------
    name : str
        What is checked, e.g. ``"FL2 mean ΔE00, 41 bands"``.
    target : str
        The target as text, e.g. ``"<= 0.06"`` (from the issue or the paper).
    measured : float or str
        The measured value.
    passed : bool
        Whether the target holds.
    """

    name: str
    target: str
    measured: float | str
    passed: bool


@dataclass
class SectionResult:
    """What a section returns: blocks to show, results for ``results.json`` and target checks."""

    blocks: list = field(default_factory=list)
    results: dict = field(default_factory=dict)
    checks: list = field(default_factory=list)


@dataclass(frozen=True)
class ReportSection:
    """A registered report section.

    Parameters
    ----------
    name : str
        Key (``--only`` takes it) and anchor, e.g. ``"spectral-core"``.
    title : str
        Heading.
    order : float
        Sort key; the foundation uses 10-30, later issues larger numbers.
    run : callable
        ``run(ctx: ReportContext) -> SectionResult``.
    """

    name: str
    title: str
    order: float
    run: Callable[[ReportContext], SectionResult]


#: Report sections by key.
REPORT_SECTIONS = Registry("report section")


@dataclass
class ReportContext:
    """What a section may use: the output folder, the quick flag, benchmark results, and writers.

    Attributes
    ----------
    out_dir : Path
        The report folder.
    quick : bool
        Small sizes, so that ``--quick`` runs in under a minute.
    bench : dict or None
        Parsed pytest-benchmark JSON (``make bench``), or None.
    section : str
        The running section's key (prefix for file names).
    """

    out_dir: Path
    quick: bool = False
    bench: dict | None = None
    section: str = ""

    def image(self, name: str, encoded, caption: str = "") -> Image:
        """Write an encoded image (floats in [0, 1] or uint8) as ``images/<section>-<name>.png``."""
        rel = f"images/{self.section}-{name}.png"
        write_png(self.out_dir / rel, encoded)
        return Image(rel, caption)

    def figure(self, name: str, fig, caption: str = "") -> Image:
        """Save a matplotlib figure as ``images/<section>-<name>.png`` (atomically) and close it."""
        import io

        import matplotlib.pyplot as plt

        from reference.images import write_bytes_atomic

        rel = f"images/{self.section}-{name}.png"
        buffer = io.BytesIO()
        fig.savefig(buffer, format="png", dpi=110, bbox_inches="tight")
        plt.close(fig)
        write_bytes_atomic(self.out_dir / rel, buffer.getvalue())
        return Image(rel, caption)

    def bench_groups(self, prefix: str) -> dict[str, list[dict]]:
        """Benchmarks whose group starts with ``prefix``, as ``{group: [benchmark records]}``."""
        groups: dict[str, list[dict]] = {}
        for record in (self.bench or {}).get("benchmarks", []):
            group = record.get("group") or ""
            if group.startswith(prefix):
                groups.setdefault(group, []).append(record)
        return groups


def to_jsonable(value):
    """Convert NumPy scalars and arrays (also nested) to JSON types; non-finite floats become None.

    Examples
    --------
    >>> to_jsonable({"a": np.float64(1.5), "b": np.array([1, 2]), "c": float("nan")})
    {'a': 1.5, 'b': [1, 2], 'c': None}
    """
    if isinstance(value, dict):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [to_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return to_jsonable(value.tolist())
    if isinstance(value, np.integer | np.bool_):
        return value.item()
    if isinstance(value, float | np.floating):
        value = float(value)
        return value if math.isfinite(value) else None
    return value


def _cell(value, fmt: str) -> str:
    if isinstance(value, float | np.floating):
        return fmt.format(float(value)) if math.isfinite(value) else "—"
    return str(value)


_CSS = " ".join(
    [
        "body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;",
        "line-height:1.45;color:#222}",
        "table{border-collapse:collapse;margin:.6em 0 1.4em}",
        "td,th{border:1px solid #ccc;padding:.25em .6em;text-align:right;",
        "font-variant-numeric:tabular-nums}",
        "th{background:#f3f3f3} td:first-child,th:first-child{text-align:left}",
        "caption{caption-side:top;text-align:left;font-weight:600;padding:.3em 0}",
        "figure{display:inline-block;margin:.5em 1em .5em 0;vertical-align:top}",
        "figcaption{font-size:.9em;color:#555;max-width:520px} img{max-width:520px}",
        "code{background:#f5f5f5;padding:0 .2em} .meta{color:#666;font-size:.9em}",
    ]
)


def _render_html(
    title: str, meta: dict, sections: list[tuple[ReportSection, SectionResult]]
) -> str:
    esc = html.escape
    parts = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        f"<title>{esc(title)}</title>",
        f"<style>{_CSS}</style></head><body>",
        f"<h1>{esc(title)}</h1>",
        "<p class='meta'>" + esc(", ".join(f"{k}: {v}" for k, v in meta.items())) + "</p>",
        "<nav><ul>",
    ]
    for section, _ in sections:
        parts.append(f"<li><a href='#{esc(section.name)}'>{esc(section.title)}</a></li>")
    parts.append("</ul></nav>")
    checks = [(s, c) for s, r in sections for c in r.checks]
    if checks:
        failed = sum(not c.passed for _, c in checks)
        parts.append(
            f"<h2>Targets</h2><p>{len(checks) - failed} of {len(checks)} targets hold"
            + (f"; <b>{failed} do not</b>." if failed else ".")
            + "</p><table><tr><th>section</th><th>check</th><th>target</th><th>measured</th>"
            "<th>holds</th></tr>"
        )
        for section, c in checks:
            mark = "yes" if c.passed else "<b>NO</b>"
            parts.append(
                f"<tr><td>{esc(section.title)}</td><td>{esc(c.name)}</td><td>{esc(c.target)}</td>"
                f"<td>{esc(_cell(c.measured, '{:.4g}'))}</td><td>{mark}</td></tr>"
            )
        parts.append("</table>")
    for section, result in sections:
        parts.append(f"<section id='{esc(section.name)}'><h2>{esc(section.title)}</h2>")
        for block in result.blocks:
            if isinstance(block, Text):
                text = esc(block.text)
                pieces = text.split("`")
                text = "".join(
                    p if i % 2 == 0 else f"<code>{p}</code>" for i, p in enumerate(pieces)
                )
                parts.append(f"<p>{text}</p>")
            elif isinstance(block, Table):
                parts.append(f"<table><caption>{esc(block.caption)}</caption><tr>")
                parts.extend(f"<th>{esc(str(c))}</th>" for c in block.columns)
                parts.append("</tr>")
                for row in block.rows:
                    cells = "".join(f"<td>{esc(_cell(v, block.fmt))}</td>" for v in row)
                    parts.append(f"<tr>{cells}</tr>")
                parts.append("</table>")
            elif isinstance(block, Image):
                parts.append(
                    f"<figure><img src='{esc(block.path)}' alt='{esc(block.caption)}'>"
                    f"<figcaption>{esc(block.caption)}</figcaption></figure>"
                )
        parts.append("</section>")
    parts.append("</body></html>")
    return "\n".join(parts)


def _render_markdown(title: str, meta: dict, sections, image_prefix: str) -> str:
    lines = [
        f"# {title}",
        "",
        "<!-- Generated by `specref report`; do not edit by hand. -->",
        "",
        ", ".join(f"{k}: {v}" for k, v in meta.items()),
        "",
    ]
    checks = [(s, c) for s, r in sections for c in r.checks]
    if checks:
        failed = sum(not c.passed for _, c in checks)
        lines += ["## Targets", "", f"{len(checks) - failed} of {len(checks)} targets hold.", ""]
        lines += ["| section | check | target | measured | holds |", "|---|---|---|---|---|"]
        for section, c in checks:
            measured = _cell(c.measured, "{:.4g}")
            holds = "yes" if c.passed else "**NO**"
            lines.append(f"| {section.title} | {c.name} | {c.target} | {measured} | {holds} |")
        lines.append("")
    for section, result in sections:
        lines += [f"## {section.title}", ""]
        for block in result.blocks:
            if isinstance(block, Text):
                lines += [block.text, ""]
            elif isinstance(block, Table):
                if block.caption:
                    lines += [f"**{block.caption}**", ""]
                lines.append("| " + " | ".join(str(c) for c in block.columns) + " |")
                lines.append("|" + "---|" * len(block.columns))
                for row in block.rows:
                    lines.append("| " + " | ".join(_cell(v, block.fmt) for v in row) + " |")
                lines.append("")
            elif isinstance(block, Image):
                lines += [f"![{block.caption}]({image_prefix}{block.path})", ""]
    return "\n".join(lines)


def run_report(
    out_dir="report",
    quick: bool = False,
    only: list[str] | None = None,
    bench_json=None,
    markdown=None,
    markdown_image_prefix: str = "",
    progress: bool = True,
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

    import validation.sections  # noqa: F401  (registers the sections)

    out_dir = Path(out_dir)
    sections = sorted(REPORT_SECTIONS.values(), key=lambda s: s.order)
    if only:
        for name in only:
            REPORT_SECTIONS.lookup(name)
        sections = [s for s in sections if s.name in only]
    bench = None
    if bench_json is not None:
        try:
            bench = json.loads(Path(bench_json).read_text())
        except FileNotFoundError:
            raise SpecrefError(f"{bench_json}: file not found") from None
        except (OSError, ValueError) as error:
            raise SpecrefError(
                f"{bench_json}: not a pytest-benchmark JSON file ({error})"
            ) from None
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
    write_text_atomic(out_dir / "index.html", _render_html(title, meta, done))
    write_text_atomic(out_dir / "results.json", json.dumps(results, indent=1, sort_keys=False))
    if markdown is not None:
        write_text_atomic(
            markdown, _render_markdown("specref results", meta, done, markdown_image_prefix)
        )
    return results

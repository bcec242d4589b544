"""The report's data types: blocks, checks, sections and the context a section runs in.

A report section (:class:`ReportSection`) is three functions:

1. ``compute(ctx) -> SectionData``: the measurements, as plain data. It is the same function that
   the CLI and the tests call, and it draws nothing;
2. ``present(ctx, data) -> list`` of blocks (:class:`Text`, :class:`Table`, :class:`Image`): the
   tables, charts and images a reader sees (``ctx.image`` and ``ctx.figure`` write the files);
3. ``checks(data) -> list[Check]``: each target, the measured value and whether it holds.

This module imports no section; ``validation.report.runner`` imports the sections explicitly and
runs them. ``validation.report.render`` writes the HTML and Markdown.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reference.images import write_png

__all__ = [
    "Check",
    "Image",
    "ReportContext",
    "ReportSection",
    "SectionData",
    "SectionResult",
    "Table",
    "Text",
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


@dataclass
class SectionData:
    """What a section's ``compute`` returns.

    Attributes
    ----------
    results : dict
        Every figure, as plain data (numbers, strings, lists, dicts; NumPy values are converted):
        written to ``results.json`` and read by the checks.
    arrays : dict
        Images and curves that only the presenter needs (never written to ``results.json``).
    """

    results: dict = field(default_factory=dict)
    arrays: dict = field(default_factory=dict)


def _no_checks(data: SectionData) -> list:
    return []


@dataclass(frozen=True)
class ReportSection:
    """A report section: compute → present → checks.

    Parameters
    ----------
    name : str
        Key (``--only`` takes it) and anchor, e.g. ``"spectral-core"``.
    title : str
        Heading.
    compute : callable
        ``compute(ctx: ReportContext) -> SectionData``: the measurements; draws nothing.
    present : callable
        ``present(ctx: ReportContext, data: SectionData) -> list`` of blocks.
    checks : callable
        ``checks(data: SectionData) -> list[Check]``.

    Examples
    --------
    >>> section = ReportSection(
    ...     "demo",
    ...     "Demo",
    ...     compute=lambda ctx: SectionData({"x": 2.0}),
    ...     present=lambda ctx, data: [Text(f"x is {data.results['x']}")],
    ...     checks=lambda data: [Check("x", "<= 3", data.results["x"], data.results["x"] <= 3)],
    ... )
    >>> result = section.run(ReportContext(out_dir="."))
    >>> result.blocks[0].text, result.checks[0].passed
    ('x is 2.0', True)
    """

    name: str
    title: str
    compute: Callable[[ReportContext], SectionData] | None = None
    present: Callable[[ReportContext, SectionData], list] | None = None
    checks: Callable[[SectionData], list] = _no_checks
    #: Transitional: a section that still computes, presents and checks in one function.
    legacy_run: Callable[[ReportContext], SectionResult] | None = None

    def run(self, ctx: ReportContext) -> SectionResult:
        """Compute, present and check: the section's blocks, results and checks."""
        if self.legacy_run is not None:
            return self.legacy_run(ctx)
        data = self.compute(ctx)
        blocks = self.present(ctx, data)
        return SectionResult(blocks, data.results, self.checks(data))


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

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

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reference.errors import require_choice
from reference.images.formats import write_png

__all__ = [
    "CHECK_BASES",
    "EFFORTS",
    "Check",
    "Headline",
    "Image",
    "ReportContext",
    "ReportPart",
    "ReportSection",
    "SectionData",
    "SectionResult",
    "Table",
    "Text",
    "to_jsonable",
]


#: How much a report run computes: ``quick`` (every section at its quick settings: tests and a
#: first look), ``default`` (``specref report``: each section at the settings its
#: ``default_effort`` names) and ``full`` (every section at its full settings: ``make results``).
EFFORTS = ("quick", "default", "full")


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
    """An image file written under ``DIR/images`` (path relative to ``DIR``) with a caption.

    ``width`` and ``height`` are the file's true size in pixels (0 when unknown); the HTML shows
    small images enlarged by a whole factor, without smoothing, and states the true size.
    """

    path: str
    caption: str = ""
    width: int = 0
    height: int = 0


@dataclass(frozen=True)
class Headline:
    """A headline figure for the report's summary: what was measured, and its anchor.

    Parameters
    ----------
    text : str
        The figure as a sentence fragment, computed from the run, e.g.
        ``"Phong table 12.8× faster than exact at RMS 9e-05"``.
    anchor : str
        What it is measured against: the paper's figure or a target of ours, e.g.
        ``"paper: ~10×"``.
    """

    text: str
    anchor: str = ""


#: What a target is measured on, against what its method was designed on (:attr:`Check.basis`).
CHECK_BASES = {
    "design": "the inputs the method was designed or tuned on",
    "held out": "inputs the design never used",
    "independent": "an independent renderer, library or published data",
}


@dataclass(frozen=True)
class Check:
    """A target and the measured value that meets it or not, shown in the report's summary.

    Parameters
    ----------
    name : str
        What is checked, e.g. ``"FL2 mean ΔE00, 41 bands"``.
    target : str
        The target as text, e.g. ``"<= 0.06"`` (the paper's figure or a target of ours).
    measured : float or str
        The measured value.
    passed : bool
        Whether the target holds.
    basis : str
        What it is measured on: a key of :data:`CHECK_BASES`, or ``""`` where not yet stated
        (the summary counts those apart).
    """

    name: str
    target: str
    measured: float | str
    passed: bool
    basis: str = ""

    def __post_init__(self):
        if self.basis and self.basis not in CHECK_BASES:
            raise ValueError(f"Check.basis: {self.basis!r}; allowed: {', '.join(CHECK_BASES)}")

    @classmethod
    def at_most(cls, name: str, measured: float, limit: float, basis: str = "") -> Check:
        """The check ``measured <= limit``, its target written ``<= limit``.

        Examples
        --------
        >>> Check.at_most("warm start / second render", 2.1, 1.5, "design")
        Check(name='warm start / second render', target='<= 1.5', measured=2.1, passed=False,
              basis='design')
        """
        return cls(name, f"<= {limit:g}", measured, bool(measured <= limit), basis)


@dataclass
class SectionResult:
    """What a section returns: blocks to show, results for ``results.json`` and target checks."""

    blocks: list = field(default_factory=list)
    results: dict = field(default_factory=dict)
    checks: list = field(default_factory=list)
    headlines: list = field(default_factory=list)
    seconds: float = 0.0
    quick: bool = False


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


def _format(value) -> str:
    """A measured value as the report shows it (4 significant digits; non-finite as a dash)."""
    if isinstance(value, float | np.floating):
        return f"{float(value):.4g}" if math.isfinite(value) else "—"
    return str(value)


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
    headlines : callable, optional
        ``headlines(data: SectionData) -> list[Headline]``: the section's figures for the
        report's summary (by default, the first two checks).
    hero : str
        Name of the image (as given to ``ctx.image``/``ctx.figure``) that stands for the
        section in the summary; empty: the section's first image.
    default_effort : {"full", "quick"}
        The settings the default ``specref report`` runs this section with: ``"full"`` where
        they cost seconds, ``"quick"`` where the full settings take minutes (full-resolution maps,
        long sweeps); ``specref report --full`` runs every section at its full settings and
        ``--quick`` every section at its quick ones.
    basis : str
        What the section's checks that state no basis of their own are measured on (a key of
        :data:`CHECK_BASES`, or ``""``): ``"design"`` for a section whose targets are measured on
        the cases its methods were designed on; checks on other inputs say so themselves.

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
    headlines: Callable[[SectionData], list] | None = None
    hero: str = ""
    default_effort: str = "full"
    basis: str = ""

    def __post_init__(self):
        if self.basis:
            require_choice(self.basis, tuple(CHECK_BASES), f"report section {self.name}: basis")

    def quick_under(self, effort: str) -> bool:
        """Whether this section runs its quick settings under a report ``effort``.

        Examples
        --------
        >>> heavy = ReportSection("maps", "Maps", default_effort="quick")
        >>> [heavy.quick_under(e) for e in ("quick", "default", "full")]
        [True, True, False]
        >>> [ReportSection("x", "X").quick_under(e) for e in ("quick", "default", "full")]
        [True, False, False]
        """
        require_choice(effort, EFFORTS, "report effort")
        return effort == "quick" or (effort == "default" and self.default_effort == "quick")

    def run(self, ctx: ReportContext) -> SectionResult:
        """Compute, present and check: the section's blocks, results, checks and headlines."""
        data = self.compute(ctx)
        blocks = self.present(ctx, data)
        checks = [
            c if c.basis or not self.basis else dataclasses.replace(c, basis=self.basis)
            for c in self.checks(data)
        ]
        if self.headlines is not None:
            headlines = list(self.headlines(data))
        else:
            headlines = [Headline(f"{c.name}: {_format(c.measured)}", c.target) for c in checks[:2]]
        return SectionResult(blocks, data.results, checks, headlines)


@dataclass(frozen=True)
class ReportPart:
    """A part of the report: one paper (or the shared core) and its sections, in reading order.

    The report's summary shows one block per part: a hero image, the sections' headline figures
    and the count of targets that hold, linking to the sections.

    Examples
    --------
    >>> a, b = ReportSection("a", "A"), ReportSection("b", "B")
    >>> part = ReportPart("demo", "Demo paper", "What it is about.", (a, b))
    >>> [s.name for s in part.only(["b"]).sections]
    ['b']
    """

    name: str
    title: str
    about: str
    sections: tuple[ReportSection, ...]

    def only(self, names) -> ReportPart:
        """The same part with only the sections whose keys are in ``names``."""
        names = set(names)
        kept = tuple(s for s in self.sections if s.name in names)
        return ReportPart(self.name, self.title, self.about, kept)


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
    client : distributed.Client or None
        Where :meth:`run_tasks` sends a section's independent tasks; None: in this process.
    """

    out_dir: Path
    quick: bool = False
    bench: dict | None = None
    section: str = ""
    client: object = None

    def run_tasks(self, function, tasks, desc: str = "tasks") -> list:
        """``[function(task) for task in tasks]`` through :func:`reference.tasks.run_tasks`.

        On the report's Dask client (``specref report --scheduler``), else serially; results in
        task order, the same either way.

        Examples
        --------
        >>> ReportContext(Path(".")).run_tasks(abs, [-2, 3])
        [2, 3]
        """
        from reference.tasks import SERIAL, run_tasks

        scheduler = None if self.client is not None else SERIAL
        return run_tasks(function, tasks, scheduler, self.client, progress=False, desc=desc)

    def image(self, name: str, encoded, caption: str = "") -> Image:
        """Write an encoded image (floats in [0, 1] or uint8) as ``images/<section>-<name>.png``."""
        rel = f"images/{self.section}-{name}.png"
        write_png(self.out_dir / rel, encoded)
        height, width = np.shape(encoded)[:2]
        return Image(rel, caption, int(width), int(height))

    def comparison(
        self,
        name: str,
        reference,
        method,
        labels=("reference", "method"),
        caption: str = "",
        difference=None,
        difference_label: str = "difference (reference units)",
    ) -> Image:
        """Reference | method | difference, the report's one layout for every comparison.

        ``reference`` and ``method`` are linear images of the same shape, ``(H, W)`` or
        ``(H, W, 3)`` (display RGB; the difference is taken on their luminance-like mean). They
        are shown with one exposure (the reference's 99th percentile maps to white), the
        difference ``method − reference`` on a diverging colour scale symmetric about zero,
        in the reference's units, with its colour bar. Pixels are shown without smoothing.
        ``difference`` replaces that difference (for example ΔY relative to the peak), labelled
        ``difference_label``.
        """
        import matplotlib.pyplot as plt

        ref = np.asarray(reference, dtype=float)
        got = np.asarray(method, dtype=float)
        scale = float(np.percentile(ref, 99)) or 1.0
        diff = got - ref if difference is None else np.asarray(difference, dtype=float)
        if diff.ndim == 3:
            diff = diff.mean(axis=-1)
        limit = float(np.max(np.abs(diff))) or 1.0
        fig, axes = plt.subplots(1, 3, figsize=(10.5, 3.6), constrained_layout=True)
        for ax, image, label in zip(axes[:2], (ref, got), labels, strict=True):
            ax.imshow(np.clip(image / scale, 0, 1) ** (1 / 2.2), interpolation="nearest")
            ax.set_title(label)
        shown = axes[2].imshow(
            diff, cmap="RdBu_r", vmin=-limit, vmax=limit, interpolation="nearest"
        )
        axes[2].set_title(f"{labels[1]} − {labels[0]}")
        fig.colorbar(shown, ax=axes[2], shrink=0.85, label=difference_label)
        for ax in axes:
            ax.set_xticks([])
            ax.set_yticks([])
        return self.figure(name, fig, caption)

    def figure(self, name: str, fig, caption: str = "") -> Image:
        """Save a matplotlib figure as ``images/<section>-<name>.png`` (atomically) and close it."""
        import io

        import matplotlib.pyplot as plt
        from PIL import Image as PILImage

        from reference.files import write_bytes_atomic

        rel = f"images/{self.section}-{name}.png"
        buffer = io.BytesIO()
        fig.savefig(buffer, format="png", dpi=110, bbox_inches="tight")
        plt.close(fig)
        write_bytes_atomic(self.out_dir / rel, buffer.getvalue())
        buffer.seek(0)
        width, height = PILImage.open(buffer).size
        return Image(rel, caption, width, height)

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

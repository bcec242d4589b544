"""The report: data types, HTML and Markdown, and the runner.

:mod:`validation.report.types` (blocks, checks, sections), :mod:`validation.report.render` (HTML and
Markdown) and :mod:`validation.report.runner` (the sections in order, ``run_report``).

Sections import the types from here; only the runner imports the sections, so there is no import
circle. ``specref report`` calls :func:`validation.report.runner.run_report`.
"""

from validation.report.types import (
    Check,
    Headline,
    Image,
    ReportContext,
    ReportSection,
    SectionData,
    SectionResult,
    Table,
    Text,
    to_jsonable,
)

__all__ = [
    "Check",
    "Headline",
    "Image",
    "ReportContext",
    "ReportSection",
    "SectionData",
    "SectionResult",
    "Table",
    "Text",
    "to_jsonable",
]

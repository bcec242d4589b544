"""The report: data types (:mod:`validation.report.types`), HTML and Markdown
(:mod:`validation.report.render`) and the runner (:mod:`validation.report.runner`).

Sections import the types from here; only the runner imports the sections, so there is no import
circle. ``specref report`` calls :func:`validation.report.runner.run_report`.
"""

from validation.report.types import (
    Check,
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
    "Image",
    "ReportContext",
    "ReportSection",
    "SectionData",
    "SectionResult",
    "Table",
    "Text",
    "to_jsonable",
]

"""Report sections: one module per section, each defining ``SECTION`` (a ``ReportSection``).

``validation.report.runner.SECTIONS`` lists them in order; nothing registers on import.
"""

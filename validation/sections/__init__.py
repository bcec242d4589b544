"""Report sections; importing this package registers them in ``validation.report.REPORT_SECTIONS``.

Each module registers one section. A new section is a new module plus one import line here.
"""

from validation.sections import examples, impastor, phong, raster, sh, shrm, spectral  # noqa: F401

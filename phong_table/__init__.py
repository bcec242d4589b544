"""Spectral Phong tables after Wang, Chern & Lee: model, placements, interpolations, render.

Users write ``phong_table.SpectralPhong``, ``phong_table.build_table`` and
``phong_table.render_sphere``; the modules hold the equations (``docs/phong-tables.md`` teaches the
method).

- :mod:`phong_table.model`: diffuse RGB and specular functions, Eqs. (7) and (11), Wang et al.
- :mod:`phong_table.placement`: ``PLACEMENT_METHODS`` (importance, uniform, error).
- :mod:`phong_table.interpolation`: ``INTERPOLATION_METHODS`` (parabolic, parabolic_w, linear,
  monotone).
- :mod:`phong_table.table`: ``build_table`` and ``SpecularTable``.
- :mod:`phong_table.render`: the exact and table shading paths and ``render_sphere``.
- :mod:`phong_table.scenes`: the reconstructed scenes R1-R3, the failure cases and the views.
- :mod:`phong_table.shader`: the ``"table"`` Phong shader for scenes (``options["phong"]``).
- :mod:`phong_table.materialfile`: TOML material files for ``specref phong --material``.
- :mod:`phong_table.editor`: the WYSIWYG material editor of §1 and §5 (``specref phong edit``; Bokeh
  is imported only when the page is served).
"""

from phong_table import shader  # noqa: F401  (registers the table shader)
from phong_table.interpolation import INTERPOLATION_METHODS
from phong_table.model import SpectralPhong
from phong_table.placement import PLACEMENT_METHODS
from phong_table.render import RENDER_METHODS, render_sphere, shade_exact, shade_table
from phong_table.scenes import SCENES, VIEWS
from phong_table.table import SpecularTable, build_table

__all__ = [
    "INTERPOLATION_METHODS",
    "PLACEMENT_METHODS",
    "RENDER_METHODS",
    "SCENES",
    "VIEWS",
    "SpectralPhong",
    "SpecularTable",
    "build_table",
    "render_sphere",
    "shade_exact",
    "shade_table",
]

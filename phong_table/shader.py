"""The table shader: scenes render Phong materials through a table by ``options["phong"]``.

``reference.scene.shading.shade_phong_point`` dispatches on ``ctx.options["phong"]["method"]``; this
module registers ``"table"`` in ``reference.scene.shading.PHONG_POINT_METHODS``. The exact shader
stays the default. Keys of ``options["phong"]`` read here:

- ``method``: ``"table"`` (``"exact"``, the default, is the exact spectral shader);
- ``placement``: a key of ``PLACEMENT_METHODS`` (default ``"error"``);
- ``interpolation``: a key of ``INTERPOLATION_METHODS`` (default ``"monotone"``);
- ``entries``: the table size m (default 200);
- ``segments``: importance segments p (default None, i.e. p = m).

The table is built in XYZ (the band weights of the scene's grid, light folded in, take the place of
the spectra-to-RGB matrix of Eq. (9), Wang et al.), so the result adds up with other shaders.
"""

from __future__ import annotations

import numpy as np

from phong_table import _kernels
from phong_table.interpolation import INTERPOLATION_METHODS
from phong_table.model import SpectralPhong
from phong_table.placement import MAX_ENTRIES, PLACEMENT_METHODS, check_entries
from phong_table.render import ShadingBuffer, compiled_shader
from phong_table.table import build_table, check_interpolation
from reference.errors import require
from reference.jit import kernel_input
from reference.registry import Method
from reference.scene.options import (
    check_choice,
    check_int_range,
    check_table,
    register_render_option,
)
from reference.scene.shading import PHONG_POINT_METHODS

__all__ = ["OPTION_KEYS", "check_phong_options", "shade_phong_point_table"]

#: The keys of ``options["phong"]`` and their defaults.
OPTION_KEYS = {
    "method": "table",
    "placement": "error",
    "interpolation": "monotone",
    "entries": 200,
    "segments": None,
}


def shade_phong_point_table(surface, material, light, ctx) -> np.ndarray:
    """XYZ of a Phong material under a point light through a table of Eq. (11), Wang et al.

    Eq. (11), Wang et al. tabulated in XYZ (the ``X_sp, Y_sp, Z_sp`` of Eq. (8), Wang et al., as
    functions of ``t``); ``f_att`` and ``cos θ`` per pixel (Eq. (7), Wang et al.). The table's
    settings come from ``ctx.options["phong"]`` (module docstring).

    Examples
    --------
    >>> from reference.scene.lights import PointLight
    >>> from reference.materials.types import PhongMaterial
    >>> from reference.scene.shading import ShadingContext, Surface, shade_phong_point
    >>> m = PhongMaterial(np.full(41, 0.3), np.full(41, 0.5), np.full(41, 40.0))
    >>> z = np.array([[0.0, 0.0, 1.0]])
    >>> s = Surface(np.zeros((1, 3)), z, z, np.zeros((1, 2)))
    >>> ctx = ShadingContext(options={"phong": {"method": "table", "entries": 64}})
    >>> table = shade_phong_point(s, m, PointLight((0.0, 0.0, 3.0)), ctx)
    >>> exact = shade_phong_point(s, m, PointLight((0.0, 0.0, 3.0)), ShadingContext())
    >>> bool(np.allclose(table, exact, atol=1e-9))
    True
    """
    options = dict(ctx.options.get("phong", {}))
    for key in options:
        require(
            key in OPTION_KEYS,
            f"options.phong: unknown key {key!r}; allowed: {', '.join(sorted(OPTION_KEYS))}",
        )
    settings = {**OPTION_KEYS, **options}
    model = SpectralPhong(
        material,
        light,
        grid=ctx.grid,
        colourspace="XYZ",
        observer=ctx.observer,
        weights_method=ctx.weights_method,
    )
    position = kernel_input(surface.position)
    rows = _kernels.light_geometry_kernel(
        position,
        kernel_input(surface.normal),
        kernel_input(surface.view),
        kernel_input(light.position),
        kernel_input(light.attenuation),
        np.empty((3, position.shape[0])),
    )
    buffer = ShadingBuffer(None, *(np.ascontiguousarray(r) for r in rows))
    table = build_table(
        model,
        settings["entries"],
        settings["placement"],
        settings["segments"],
        compiled=True,
        t_range=buffer.t_range,
        t_density=buffer.t_density,
        interpolation=settings["interpolation"],
    )
    check_interpolation(settings["interpolation"], table.entries)
    shade = compiled_shader(model, table, settings["interpolation"])
    return shade(buffer, np.empty((position.shape[0], 3)))


PHONG_POINT_METHODS.register(
    Method("table", shade_phong_point_table, None, "Eq. (11), Wang et al.")
)


def check_phong_options(value) -> dict:
    """``[render.options.phong]`` checked where the scene is loaded (keys of :data:`OPTION_KEYS`).

    Examples
    --------
    >>> check_phong_options({"method": "table", "entries": 64})
    {'method': 'table', 'entries': 64}
    >>> check_phong_options({"method": "table", "placement": "errror"})
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: placement: unknown value 'errror'; allowed: error, importance,
    uniform
    """
    options = check_table(value, {
        "method": lambda v: check_choice(v, PHONG_POINT_METHODS),
        "placement": lambda v: check_choice(v, PLACEMENT_METHODS),
        "interpolation": lambda v: check_choice(v, INTERPOLATION_METHODS),
        "entries": lambda v: check_entries(v, None, "table")[0],
        "segments": lambda v: check_int_range(v, 1, MAX_ENTRIES),
    })  # fmt: skip
    settings = {**OPTION_KEYS, **options}
    check_entries(settings["entries"], settings["segments"], "table")
    check_interpolation(settings["interpolation"], settings["entries"])
    return options


register_render_option("phong", check_phong_options, "Phong materials through a table")

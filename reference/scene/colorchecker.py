"""The ColorChecker chart as a material: 24 measured patches in the standard 6 × 4 layout.

A :class:`ColorCheckerMaterial` is Lambertian, with a reflectance that depends on the surface's
texture coordinates: on a rectangle (``reference.geometry.shapes.Plane`` with a ``size``) the 24
patches of a colour-science ColorChecker set (N Ohta by default) sit in the standard layout, six
columns and four rows, ``dark skin`` at the top left (u = 0, v = 0) and ``black 2`` at the bottom
right. Each patch fills the middle of its cell; the rest of the cell, a band of ``gap_width`` (a
fraction of the patch pitch along each axis) split between its sides, shows the ``gap`` reflectance,
by default the set's own black patch. Texture coordinates outside [0, 1] (an unbounded plane) show
the gap.

Its shaders (registered in ``reference.scene.shading.SHADERS``) are the diffuse term of Eq. (2),
Wang et al. under a point light and the ambient term of Eq. (1), Wang et al., evaluated exactly:
each patch's XYZ under the light is one product ``R @ W`` with the light's band weights, so a
chart lit by a unit ambient light reproduces ``colour.sd_to_XYZ(..., method="ASTM E308")`` for every
patch.

References
----------
- C. S. McCamy, H. Marcus, J. G. Davidson, "A Color-Rendition Chart", J. Appl. Photogr. Eng. 2(3),
  1976 (the layout).
- N. Ohta, spectral reflectances of the ColorChecker, as distributed by colour-science.
- C.-M. Wang, J.-R. Chern, J. Lee, "An Efficient Spectral Rendering Technique for Phong Illumination
  Model".
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.colour.spectra import (
    DEFAULT_GRID,
    EXTRAPOLATIONS,
    INTERPOLATIONS,
    SpectralGrid,
    resample_spectrum,
    spectrum_from_dataset,
)
from reference.errors import require, require_nonnegative
from reference.geometry.shapes import plane_uv_to_point
from reference.materials.types import MATERIAL_TYPES, MaterialType
from reference.registry import Method
from reference.scene.lights import AmbientLight, PointLight, attenuation_Wang, point_light_vectors
from reference.scene.shading import SHADERS, Surface
from reference.scene.sphere_light import sphere_light_shader
from reference.scene.values import SceneReader

__all__ = [
    "COLORCHECKER_LAYOUT",
    "ColorCheckerMaterial",
    "colorchecker_material",
    "colorchecker_patch_centres_uv",
    "colorchecker_patch_index",
    "colorchecker_patch_pixels",
    "shade_colorchecker_ambient",
    "shade_colorchecker_point",
    "shade_colorchecker_sphere",
]

#: Columns and rows of the standard chart.
COLORCHECKER_LAYOUT = (6, 4)
_N_PATCHES = COLORCHECKER_LAYOUT[0] * COLORCHECKER_LAYOUT[1]
#: The colour-science set used when a scene names none.
DEFAULT_COLORCHECKER_SET = "ColorChecker N Ohta"


@dataclass(frozen=True, eq=False)
class ColorCheckerMaterial:
    """A Lambertian ColorChecker chart: 24 patch reflectances and a gap reflectance on a grid.

    Parameters
    ----------
    patches : ndarray, shape (24, n_bands)
        Patch reflectances in chart order (row by row from the top left), >= 0.
    gap : ndarray, shape (n_bands,)
        Reflectance between and around the patches, >= 0.
    gap_width : float
        Width of the gap as a fraction of the patch pitch along each axis, in [0, 1).
    name : str
        Name used in messages.
    patch_names : tuple of str
        The patches' names, in chart order.

    Examples
    --------
    >>> m = colorchecker_material(DEFAULT_GRID)
    >>> m.reflectances.shape, m.patch_names[0], m.patch_names[-1]
    ((25, 41), 'dark skin', 'black 2 (1.5 D)')
    """

    patches: np.ndarray
    gap: np.ndarray
    gap_width: float = 0.1
    name: str = "colorchecker"
    patch_names: tuple = ()

    def __post_init__(self):
        patches = require_nonnegative(self.patches, f"{self.name}.patches")
        require(
            patches.ndim == 2 and patches.shape[0] == _N_PATCHES,
            f"{self.name}.patches: must have shape (24, n_bands), got {patches.shape}",
        )
        gap = require_nonnegative(self.gap, f"{self.name}.gap")
        require(
            gap.shape == patches.shape[1:],
            f"{self.name}.gap: has {gap.size} bands but the patches have {patches.shape[1]}",
        )
        require(
            np.isfinite(self.gap_width) and 0.0 <= self.gap_width < 1.0,
            f"{self.name}.gap_width: must be in [0, 1), got {self.gap_width}",
        )
        patches, gap = patches.copy(), gap.copy()
        patches.setflags(write=False)
        gap.setflags(write=False)
        object.__setattr__(self, "patches", patches)
        object.__setattr__(self, "gap", gap)
        object.__setattr__(self, "gap_width", float(self.gap_width))

    @property
    def reflectances(self) -> np.ndarray:
        """Patches then the gap, shape ``(25, n_bands)``: row ``i`` is what index ``i`` shows."""
        return np.vstack([self.patches, self.gap[None, :]])

    @property
    def n_bands(self) -> int:
        """Number of bands."""
        return self.patches.shape[1]


def colorchecker_patch_index(uv, gap_width: float = 0.1) -> np.ndarray:
    """Which patch each texture coordinate shows: 0-23 in chart order, 24 for the gap.

    Parameters
    ----------
    uv : array_like, shape (..., 2)
        Texture coordinates; u to the right, v down, both in [0, 1] on the chart.
    gap_width : float
        Gap as a fraction of the patch pitch, in [0, 1).

    Returns
    -------
    ndarray of int, shape (...,)

    Examples
    --------
    >>> colorchecker_patch_index([[0.05, 0.1], [0.99, 0.9], [1 / 6, 0.1], [1.5, 0.5]])
    array([ 0, 23, 24, 24])
    """
    uv = np.asarray(uv, dtype=np.float64)
    columns, rows = COLORCHECKER_LAYOUT
    with np.errstate(invalid="ignore"):
        x, y = uv[..., 0] * columns, uv[..., 1] * rows
        on_chart = (x >= 0) & (x <= columns) & (y >= 0) & (y <= rows)
        column = np.clip(np.floor(np.where(on_chart, x, 0.0)), 0, columns - 1)
        row = np.clip(np.floor(np.where(on_chart, y, 0.0)), 0, rows - 1)
        # Position inside the cell, in [0, 1]; the patch is the middle 1 - gap_width of it.
        s, t = x - column, y - row
        half = gap_width / 2.0
        on_patch = on_chart & (s >= half) & (s <= 1 - half) & (t >= half) & (t <= 1 - half)
    index = (row * columns + column).astype(np.int64)
    return np.where(on_patch, index, _N_PATCHES)


def colorchecker_patch_centres_uv() -> np.ndarray:
    """Texture coordinates of the 24 patch centres, in chart order, shape ``(24, 2)``.

    Examples
    --------
    >>> colorchecker_patch_centres_uv()[[0, 23]].round(4)
    array([[0.0833, 0.125 ],
           [0.9167, 0.875 ]])
    """
    columns, rows = COLORCHECKER_LAYOUT
    row, column = np.divmod(np.arange(_N_PATCHES), columns)
    return np.stack([(column + 0.5) / columns, (row + 0.5) / rows], axis=-1)


def colorchecker_patch_pixels(camera, chart, width: int, height: int) -> np.ndarray:
    """Image pixels ``(row, column)`` under the 24 patch centres of a chart seen by a camera.

    Parameters
    ----------
    camera : Camera
        The camera.
    chart : Plane
        The rectangle that carries the chart.
    width, height : int
        Image size.

    Returns
    -------
    ndarray of int, shape (24, 2)
        Row and column of each patch centre's pixel, in chart order; -1 where the centre falls
        outside the image or behind the camera.

    Examples
    --------
    >>> from reference.geometry.camera import Camera
    >>> from reference.geometry.shapes import Plane
    >>> cam = Camera(projection="orthographic", extent=0.4)
    >>> chart = Plane((0, 0, 0), (0, 0, 1), (1, 0, 0), size=(0.6, 0.4))
    >>> colorchecker_patch_pixels(cam, chart, 66, 44)[[0, 23]]
    array([[ 5,  5],
           [38, 60]])
    """
    points = plane_uv_to_point(chart, colorchecker_patch_centres_uv())
    x, y, depth = camera.project(points, width, height)
    with np.errstate(invalid="ignore"):
        inside = (depth > 0) & (x >= 0) & (x < width) & (y >= 0) & (y < height)
    pixels = np.stack([np.floor(y), np.floor(x)], axis=-1)
    return np.where(inside[:, None], np.nan_to_num(pixels, nan=-1), -1).astype(np.int64)


def colorchecker_material(
    grid: SpectralGrid = DEFAULT_GRID,
    set_name: str = DEFAULT_COLORCHECKER_SET,
    gap=None,
    gap_width: float = 0.1,
    extrapolation: str = "error",
    interpolation: str = "linear",
    name: str = "colorchecker",
) -> ColorCheckerMaterial:
    """A ColorChecker material from a colour-science set, resampled onto ``grid``.

    Parameters
    ----------
    grid : SpectralGrid
        The scene's grid.
    set_name : str
        A key of ``colour.SDS_COLOURCHECKERS`` with 24 patches (``"ColorChecker N Ohta"``, 380-780
        nm at 5 nm; ``"BabelColor Average"``, 380-730 nm, needs an extrapolation on the 41-band
        grid).
    gap : ndarray, shape (n_bands,), optional
        Gap reflectance on the grid; default the set's last patch (its black).
    gap_width : float
        Gap as a fraction of the patch pitch, in [0, 1).
    extrapolation, interpolation : str
        How the patches are resampled (:func:`reference.colour.spectra.resample_spectrum`).
    name : str
        Name used in messages.

    Returns
    -------
    ColorCheckerMaterial

    Raises
    ------
    SpecrefError
        Unknown set, a set without 24 patches, patches that do not cover the grid.

    Examples
    --------
    >>> colorchecker_material(set_name="PMC")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: colorchecker set 'PMC' has 30 patches; a chart needs 24
    """
    import colour

    from reference.errors import require_choice

    require_choice(set_name, list(colour.SDS_COLOURCHECKERS), "colorchecker set")
    names = tuple(colour.SDS_COLOURCHECKERS[set_name])
    require(
        len(names) == _N_PATCHES,
        f"colorchecker set {set_name!r} has {len(names)} patches; a chart needs {_N_PATCHES}",
    )
    patches = np.stack(
        [
            resample_spectrum(
                spectrum_from_dataset("colorchecker", patch, set_name),
                grid,
                extrapolation,
                interpolation,
            )
            for patch in names
        ]
    )
    gap = patches[-1] if gap is None else gap
    return ColorCheckerMaterial(patches, gap, gap_width, name, names)


def _check_bands(material: ColorCheckerMaterial, ctx) -> None:
    require(
        material.n_bands == ctx.grid.n_bands,
        f"{material.name}: has {material.n_bands} bands but the grid {ctx.grid.label} has "
        f"{ctx.grid.n_bands}",
    )


def shade_colorchecker_point(
    surface: Surface, material: ColorCheckerMaterial, light: PointLight, ctx
) -> np.ndarray:
    """XYZ of a ColorChecker chart under a point light: the diffuse term of Eq. (2), Wang et al.

    Each patch's XYZ under the light, ``R_patch @ W``, is computed once; a pixel scales its patch's
    value by ``f_att cos θ``.

    Examples
    --------
    >>> from reference.scene.shading import ShadingContext
    >>> s = Surface(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), np.array([[0.0, 0.0, 1.0]]),
    ...             np.array([[0.05, 0.1]]))
    >>> m = colorchecker_material()
    >>> shade_colorchecker_point(s, m, PointLight((0.0, 0.0, 3.0)), ShadingContext()).round(4)
    array([[0.1098, 0.0971, 0.0604]])
    """
    _check_bands(material, ctx)
    L, d = point_light_vectors(light.position, surface.position)
    f_att = attenuation_Wang(d, *light.attenuation)
    cos_theta = np.maximum(np.einsum("...i,...i->...", surface.normal, L), 0.0)
    patch_XYZ = material.reflectances @ ctx.weights(light.spectrum)
    index = colorchecker_patch_index(surface.uv, material.gap_width)
    # Eq. (2), Wang et al., diffuse term: I(λ)/I_p(λ) = f_att k_d(λ) cos θ, with k_d from the chart
    return light.intensity * (f_att * cos_theta)[:, None] * patch_XYZ[index]


def shade_colorchecker_ambient(
    surface: Surface, material: ColorCheckerMaterial, light: AmbientLight, ctx
) -> np.ndarray:
    """XYZ of a ColorChecker chart under ambient light: ``I_a k_a`` of Eq. (1), Wang et al.

    The ambient coefficient is the patch reflectance, as for Lambert materials.

    Examples
    --------
    >>> from reference.scene.shading import ShadingContext
    >>> s = Surface(np.zeros((1, 3)), np.zeros((1, 3)), np.zeros((1, 3)), np.array([[0.05, 0.1]]))
    >>> m = colorchecker_material()
    >>> shade_colorchecker_ambient(s, m, AmbientLight(), ShadingContext()).round(4)
    array([[0.1098, 0.0971, 0.0604]])
    """
    _check_bands(material, ctx)
    patch_XYZ = material.reflectances @ ctx.weights(light.spectrum)
    index = colorchecker_patch_index(surface.uv, material.gap_width)
    # Eq. (1), Wang et al.: ambient term I_a k_a
    return light.intensity * patch_XYZ[index]


def _parse_colorchecker(reader: SceneReader, table: dict, key: str, name: str):
    """Scene-file parser: ``set``, ``gap`` (a spectrum), ``gap_width``, resampling options."""
    import colour

    reader.table(
        table,
        key,
        ("type", "set", "gap", "gap_width", "extrapolation", "interpolation"),
    )
    set_name = reader.choice(
        table.get("set", DEFAULT_COLORCHECKER_SET), f"{key}.set", colour.SDS_COLOURCHECKERS
    )
    gap = reader.spectrum_on_grid(table["gap"], f"{key}.gap") if "gap" in table else None
    gap_width = reader.number(
        table.get("gap_width", 0.1), f"{key}.gap_width", 0.0, 1.0, exclusive_maximum=True
    )
    extrapolation = reader.choice(
        table.get("extrapolation", "error"), f"{key}.extrapolation", EXTRAPOLATIONS
    )
    interpolation = reader.choice(
        table.get("interpolation", "linear"), f"{key}.interpolation", INTERPOLATIONS
    )
    with reader.context(key, alias=name):
        return colorchecker_material(
            reader.grid, set_name, gap, gap_width, extrapolation, interpolation, name
        )


MATERIAL_TYPES.register(
    MaterialType(
        "colorchecker",
        ColorCheckerMaterial,
        (),
        ("set", "gap", "gap_width", "extrapolation", "interpolation"),
        "Eq. (2), Wang et al. (diffuse term), textured by the chart layout",
        parse=_parse_colorchecker,
    )
)
SHADERS.register(
    Method(
        "ColorCheckerMaterial/PointLight",
        shade_colorchecker_point,
        None,
        "Eq. (2), Wang et al.",
    )
)
_colorchecker_sphere = sphere_light_shader(shade_colorchecker_point)


def shade_colorchecker_sphere(
    surface: Surface, material: ColorCheckerMaterial, light, ctx
) -> np.ndarray:
    """XYZ of a ColorChecker chart under a sphere light, over the light's cone.

    Eq. (2), Wang et al.'s diffuse term integrated over the cone (``reference.scene.sphere_light``).

    Examples
    --------
    >>> from reference.scene.lights import SphereLight
    >>> from reference.scene.shading import ShadingContext
    >>> s = Surface(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), np.array([[0.0, 0.0, 1.0]]),
    ...             np.array([[0.05, 0.1]]))
    >>> m = colorchecker_material()
    >>> light = SphereLight((0.0, 0.0, 3.0), 1.0, intensity=9.0)   # L r²/d² = 1
    >>> shade_colorchecker_sphere(s, m, light, ShadingContext()).round(4)
    array([[0.1098, 0.0971, 0.0604]])
    """
    return _colorchecker_sphere(surface, material, light, ctx)


SHADERS.register(
    Method(
        "ColorCheckerMaterial/SphereLight",
        shade_colorchecker_sphere,
        None,
        "§12.2, Pharr et al. (pbrt-v4); Eq. (2), Wang et al.",
    )
)
SHADERS.register(
    Method(
        "ColorCheckerMaterial/AmbientLight",
        shade_colorchecker_ambient,
        None,
        "Eq. (1), Wang et al.",
    )
)

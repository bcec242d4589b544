"""Deferred shading of the sphere scenes: the exact and the table paths, NumPy and numba.

Both paths start from the same cached G-buffer (:func:`sphere_gbuffer`: positions, normals and view
vectors of the visible sphere pixels) and its per-pixel light geometry (:class:`ShadingBuffer`:
``cos θ``, ``t``, ``f_att``, which stay fixed while a user edits spectra), and end in linear display
RGB, ``(N, 3)`` per pixel:

- ``exact`` (:func:`shade_exact`): Eq. (2), Wang et al. per band, converted by the spectra-to-RGB
  matrix: ``ambient + f_att (cos θ · D + Σ_λ C(λ) t^{n(λ)})``, the speed baseline (one ``ln t`` per
  pixel, one ``exp`` per band in the kernel);
- ``table`` (:func:`shade_table`): the same with ``Σ_λ C(λ) t^{n(λ)}`` read from a
  :class:`~phong_table.table.SpecularTable`.

:data:`RENDER_METHODS` lists the two paths with their numba twins
(``phong_table._kernels.shade_exact_kernel``, ``shade_table_kernel``); :func:`render_sphere` is the
public entry point. The per-pixel geometry (:func:`light_geometry`) is computed as
``reference.scene.shading.phong_cosines`` and ``reference.scene.lights.attenuation_Wang`` do.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property, lru_cache

import numpy as np

from phong_table import _kernels
from phong_table.interpolation import INTERPOLATION_METHODS
from phong_table.model import SpectralPhong
from phong_table.placement import pixel_density
from phong_table.scenes import SPHERE, view_camera
from phong_table.table import SpecularTable, build_table, check_interpolation, tabulate
from reference.display.encodings import linear_to_display
from reference.errors import require, require_choice
from reference.geometry.gbuffer import GBuffer, render_gbuffer
from reference.jit import kernel_input
from reference.registry import Method, Registry
from reference.scene.lights import attenuation_Wang, point_light_vectors
from reference.scene.shading import phong_cosines

__all__ = [
    "MAX_STUDY_RESOLUTION",
    "RENDER_METHODS",
    "SHADING_PATHS",
    "ShadingBuffer",
    "SphereGeometry",
    "compiled_shader",
    "light_geometry",
    "render_sphere",
    "render_sphere_gbuffer",
    "rms_8bit",
    "shade_exact",
    "shade_pixels",
    "shade_table",
    "shading_buffer",
    "sphere_gbuffer",
]


@dataclass(frozen=True, eq=False)
class SphereGeometry:
    """The visible pixels of a G-buffer, flattened and contiguous (what the kernels read).

    Attributes
    ----------
    gbuffer : GBuffer
        The full G-buffer.
    position, normal, view : ndarray, shape (N, 3)
        The covered pixels, in row-major order.
    """

    gbuffer: GBuffer
    position: np.ndarray
    normal: np.ndarray
    view: np.ndarray

    @classmethod
    def from_gbuffer(cls, gbuffer: GBuffer) -> SphereGeometry:
        """Flatten the covered pixels of ``gbuffer``."""
        mask = gbuffer.mask
        arrays = [np.ascontiguousarray(getattr(gbuffer, k)[mask]) for k in ("position", "normal")]
        view = np.ascontiguousarray(gbuffer.view[mask])
        for a in (*arrays, view):
            a.setflags(write=False)
        return cls(gbuffer, arrays[0], arrays[1], view)

    @property
    def shape(self) -> tuple[int, int]:
        """``(H, W)`` of the image."""
        return self.gbuffer.shape

    def to_image(self, pixels: np.ndarray) -> np.ndarray:
        """Scatter per-pixel values ``(N, 3)`` into an image ``(H, W, 3)``, 0 off the sphere."""
        image = np.zeros((*self.shape, pixels.shape[-1]))
        image[self.gbuffer.mask] = pixels
        return image


#: The largest image side of the Phong study's sphere (:func:`render_sphere_gbuffer`).
MAX_STUDY_RESOLUTION = 2048


def render_sphere_gbuffer(view: str, resolution: int = 512) -> SphereGeometry:
    """Ray-cast the sphere's G-buffer for a view (uncached: the full-frame timing calls this).

    Examples
    --------
    >>> render_sphere_gbuffer("far", 16).position.shape
    (148, 3)
    """
    # the study's spectral images hold resolution² × 41 bands several times over: 4096² ran out
    # of 8 GB; 2048² is 1.4 GB an image
    require(
        isinstance(resolution, int) and 1 <= resolution <= MAX_STUDY_RESOLUTION,
        f"render: resolution: must be an integer in [1, {MAX_STUDY_RESOLUTION}], got "
        f"{resolution!r}",
    )
    camera = view_camera(view)
    return SphereGeometry.from_gbuffer(render_gbuffer([SPHERE], camera, resolution, resolution))


@lru_cache(maxsize=8)
def sphere_gbuffer(view: str, resolution: int = 512) -> SphereGeometry:
    """The cached G-buffer of a view: every method is shaded on the same one.

    Examples
    --------
    >>> sphere_gbuffer("near", 8) is sphere_gbuffer("near", 8)
    True
    """
    return render_sphere_gbuffer(view, resolution)


def light_geometry(position, normal, view, light_position, attenuation) -> np.ndarray:
    """``cos θ``, ``t`` and ``f_att`` of G-buffer pixels under a point light (NumPy reference).

    Eq. (1), Wang et al. (Figure 1 and Erratum E2), by ``reference.scene.shading.phong_cosines`` and
    ``reference.scene.lights.attenuation_Wang``.

    Parameters
    ----------
    position, normal, view : ndarray, shape (N, 3)
        World position, unit normal and unit vector to the eye.
    light_position : array_like, shape (3,)
        The point light.
    attenuation : array_like, shape (3,)
        ``(c1, c2, c3)``.

    Returns
    -------
    ndarray, shape (3, N)
        Rows ``cos θ``, ``t`` and ``f_att``.

    Examples
    --------
    >>> z = np.array([[0.0, 0.0, 1.0]])
    >>> light_geometry(z, z, z, [0.0, 0.0, 3.0], [0.0, 0.0, 1.0]).ravel()
    array([1.  , 1.  , 0.25])
    """
    L, d = point_light_vectors(light_position, position)
    f_att = attenuation_Wang(d, *np.asarray(attenuation, dtype=np.float64))
    cos_theta, t = phong_cosines(normal, L, view)
    return np.stack([cos_theta, t, f_att])


@dataclass(frozen=True, eq=False)
class ShadingBuffer:
    """Per-pixel ``cos θ``, ``t`` and ``f_att`` of a G-buffer under one light position.

    This is what stays fixed while a user edits spectra (Wang et al.'s WYSIWYG use): both shading
    paths read it, and the timings of ``specref phong`` shade from it.

    Attributes
    ----------
    geometry : SphereGeometry
        The G-buffer pixels.
    cos_theta, t, f_att : ndarray, shape (N,)
        Rows of :func:`light_geometry`.
    """

    geometry: SphereGeometry
    cos_theta: np.ndarray
    t: np.ndarray
    f_att: np.ndarray

    @cached_property
    def t_range(self) -> tuple[float, float] | None:
        """``(min, max)`` of ``t`` over the lit pixels (``t > 0``), or None when none is lit.

        The range a table for this frame must cover (``build_table(..., t_range=)``); pixels at
        ``t = 0`` read the table's first value exactly.

        Examples
        --------
        >>> ShadingBuffer(None, np.ones(3), np.array([0.0, 0.5, 0.9]), np.ones(3)).t_range
        (0.5, 0.9)
        """
        lit = self.t[self.t > 0.0]
        return (float(lit.min()), float(lit.max())) if lit.size else None

    @cached_property
    def t_density(self) -> np.ndarray | None:
        """The lit pixels' density in ``t`` over :attr:`t_range` (``build_table(..., t_density=)``).

        ``phong_table.placement.pixel_density``: pixels per unit ``t`` on 64 uniform cells,
        integrating to 1; None when :attr:`t_range` is None or a single ``t``.

        Examples
        --------
        >>> buffer = ShadingBuffer(None, np.ones(4), np.array([0.0, 0.5, 0.6, 0.9]), np.ones(4))
        >>> density = buffer.t_density
        >>> density.shape, float(density.sum() * (0.9 - 0.5) / density.size)
        ((64,), 1.0)
        """
        return pixel_density(self.t, self.t_range)


def shading_buffer(
    geometry: SphereGeometry, model: SpectralPhong, compiled: bool = True
) -> ShadingBuffer:
    """The :class:`ShadingBuffer` of a G-buffer under the model's light.

    Examples
    --------
    >>> from phong_table.scenes import constant_material
    >>> buffer = shading_buffer(sphere_gbuffer("far", 16), constant_material(5.0))
    >>> float(buffer.t.max()) <= 1.0, buffer.t.shape
    (True, (148,))
    """
    light_position = np.asarray(model.light.position, dtype=np.float64)
    attenuation = np.asarray(model.light.attenuation, dtype=np.float64)
    arrays = (geometry.position, geometry.normal, geometry.view, light_position, attenuation)
    if compiled:
        arrays = tuple(kernel_input(x) for x in arrays)
        rows = _kernels.light_geometry_kernel(*arrays, np.empty((3, geometry.position.shape[0])))
    else:
        rows = light_geometry(*arrays)
    return ShadingBuffer(geometry, *(np.ascontiguousarray(row) for row in rows))


def shade_exact(cos_theta, t, f_att, model: SpectralPhong) -> np.ndarray:
    """Exact spectral Phong shading of pixels to linear display RGB (NumPy reference).

    Eq. (2), Wang et al., through Eq. (7) and Eq. (11), Wang et al.: ``ambient + f_att (cos θ · D +
    Σ_λ C(λ) t^{n(λ)})``.

    Parameters
    ----------
    cos_theta, t, f_att : ndarray, shape (N,)
        Per-pixel geometry (:func:`light_geometry`).
    model : SpectralPhong
        Material and light.

    Returns
    -------
    ndarray, shape (N, 3)
        Linear display RGB (unclipped).

    Examples
    --------
    >>> from phong_table.scenes import constant_material
    >>> model = constant_material(10.0)
    >>> shade_exact(np.array([0.5]), np.array([0.9]), np.array([1.0]), model).round(4)
    array([[0.3919, 0.3919, 0.3918]])
    """
    # Eq. (11), Wang et al.: f_sp(t) = Σ_λ C(λ) t^{n(λ)}, exactly
    specular = model.specular(t)
    # Eq. (7), Wang et al.: ambient + f_att (cos θ · D + f_sp)
    return model.ambient_RGB + f_att[:, None] * (cos_theta[:, None] * model.diffuse_RGB + specular)


def shade_table(
    cos_theta, t, f_att, model: SpectralPhong, table: SpecularTable, interpolation: str
) -> np.ndarray:
    """Spectral Phong shading with ``f_sp`` read from a table (NumPy reference).

    Eq. (7) and Eq. (11), Wang et al.: ``ambient + f_att (cos θ · D + table(t))``; ``f_att`` is
    applied per pixel, not tabulated (Erratum E18).

    Parameters
    ----------
    cos_theta, t, f_att : ndarray, shape (N,)
        Per-pixel geometry (:func:`light_geometry`).
    model : SpectralPhong
        Material and light (the table must have been built from it).
    table : SpecularTable
        From :func:`phong_table.build_table`.
    interpolation : str
        A key of ``INTERPOLATION_METHODS``.

    Returns
    -------
    ndarray, shape (N, 3)

    Examples
    --------
    >>> from phong_table.scenes import constant_material
    >>> model = constant_material(10.0)
    >>> table = build_table(model, 32, "error")
    >>> shade_table(np.array([0.5]), np.array([0.9]), np.array([1.0]), model, table,
    ...             "monotone").round(4)
    array([[0.3919, 0.3919, 0.3918]])
    """
    specular = table.lookup(t, interpolation)
    # Eq. (7), Wang et al.: ambient + f_att (cos θ · D + tabulated f_sp)
    return model.ambient_RGB + f_att[:, None] * (cos_theta[:, None] * model.diffuse_RGB + specular)


def compiled_shader(
    model: SpectralPhong, table: SpecularTable | None = None, interpolation: str = "monotone"
):
    """A function ``shade(buffer, out)`` that calls the exact or the table kernel directly.

    Everything but the pixels is bound once, as a renderer does between frames; the timings of
    ``specref phong`` call it per tile.

    Examples
    --------
    >>> from phong_table.scenes import constant_material
    >>> model = constant_material(5.0)
    >>> buffer = shading_buffer(sphere_gbuffer("far", 8), model)
    >>> shade = compiled_shader(model)
    >>> shade(buffer, np.empty((buffer.t.size, 3))).shape
    (32, 3)
    """
    if table is None:
        bound = (model.diffuse_RGB, model.specular_weights, model.n, model.ambient_RGB)

        def shade(buffer: ShadingBuffer, out):
            return _kernels.shade_exact_kernel(*_buffer_inputs(buffer), *bound, out)

        return shade
    check_interpolation(interpolation, table.entries)
    bound = (
        model.diffuse_RGB,
        model.ambient_RGB,
        table.nodes,
        table.values,
        table.inv_width,
        table.cubic,
        table.guide,
        table.steps,
        table.uniform,
        table.an + 1.0,
        table.zero_below,
    )
    # the interpolation's own kernel (shade_table_kernel's branch): a render compiles only it
    kernel = _kernels.TABLE_KERNELS[INTERPOLATION_METHODS.lookup(interpolation).code]

    def shade(buffer: ShadingBuffer, out):
        return kernel(*_buffer_inputs(buffer), *bound, out)

    return shade


def _buffer_inputs(buffer: ShadingBuffer) -> tuple:
    """The buffer's cos θ, t and f_att as kernel inputs (one compiled signature for any view)."""
    return tuple(kernel_input(row) for row in (buffer.cos_theta, buffer.t, buffer.f_att))


def _exact_compiled(buffer: ShadingBuffer, model: SpectralPhong, out):
    return compiled_shader(model)(buffer, out)


def _table_compiled(buffer: ShadingBuffer, model, table: SpecularTable, interpolation: str, out):
    return compiled_shader(model, table, interpolation)(buffer, out)


#: The kernels of the render path, each a NumPy reference with its numba twin: the two shading
#: paths (``compiled`` calls the kernel on a :class:`ShadingBuffer`), the per-pixel geometry and
#: the tabulation of a table's values, slopes and index.
RENDER_METHODS = Registry("shading path")
RENDER_METHODS.register(
    Method(
        "exact",
        shade_exact,
        _kernels.shade_exact_kernel,
        "Eq. (2), Wang et al.",
        compiled=_exact_compiled,
    )
)
RENDER_METHODS.register(
    Method(
        "table",
        shade_table,
        _kernels.shade_table_kernel,
        "Eq. (11), Wang et al.",
        compiled=_table_compiled,
    )
)
RENDER_METHODS.register(
    Method(
        "geometry",
        light_geometry,
        _kernels.light_geometry_kernel,
        "Eq. (1), Wang et al.",
        compiled=_kernels.light_geometry_kernel,
    )
)
RENDER_METHODS.register(
    Method(
        "tabulate",
        tabulate,
        _kernels.tabulate_kernel,
        "Eq. (11), Wang et al.",
        compiled=_kernels.tabulate_kernel,
    )
)
#: The keys of :data:`RENDER_METHODS` that shade (``render_sphere``'s ``method``).
SHADING_PATHS = ("exact", "table")


def shade_pixels(
    buffer: ShadingBuffer,
    model: SpectralPhong,
    method: str = "exact",
    table: SpecularTable | None = None,
    interpolation: str = "monotone",
    compiled: bool = True,
    out: np.ndarray | None = None,
) -> np.ndarray:
    """Shade the pixels of a :class:`ShadingBuffer` with a path, compiled or NumPy.

    Parameters
    ----------
    buffer : ShadingBuffer
        Per-pixel geometry.
    model : SpectralPhong
        Material and light.
    method : {"exact", "table"}
        The shading path.
    table : SpecularTable, optional
        For ``"table"``.
    interpolation : str
        For ``"table"``.
    compiled : bool
        numba kernel (default) or NumPy reference.
    out : ndarray, shape (N, 3), optional
        The frame buffer the kernel writes (reused between frames); allocated if None.

    Returns
    -------
    ndarray, shape (N, 3)
        Linear display RGB.

    Examples
    --------
    >>> from phong_table.scenes import constant_material
    >>> model = constant_material(30.0)
    >>> buffer = shading_buffer(sphere_gbuffer("far", 16), model)
    >>> exact = shade_pixels(buffer, model, "exact")
    >>> bool(np.allclose(exact, shade_pixels(buffer, model, "exact", compiled=False)))
    True
    """
    require_choice(method, SHADING_PATHS, "shading path")
    entry = RENDER_METHODS.lookup(method)
    rows = (buffer.cos_theta, buffer.t, buffer.f_att)
    if method == "table":
        require(table is not None, "shade_pixels: the table path needs a table")
        check_interpolation(interpolation, table.entries)
    if not compiled:
        extra = () if method == "exact" else (table, interpolation)
        return entry.reference(*rows, model, *extra)
    if out is None:
        out = np.empty((buffer.t.size, 3))
    if method == "exact":
        return entry.compiled(buffer, model, out)
    return entry.compiled(buffer, model, table, interpolation, out)


def render_sphere(
    material: SpectralPhong,
    view: str = "far",
    method: str = "exact",
    placement: str = "error",
    interpolation: str = "monotone",
    entries: int = 200,
    segments: int | None = None,
    resolution: int = 512,
    compiled: bool = True,
) -> np.ndarray:
    """Render a scene's sphere in linear display RGB, exactly or through a table.

    Eq. (2), Wang et al. (``method="exact"``), or Eq. (11), Wang et al. tabulated with a registered
    placement and interpolation (``method="table"``).

    Parameters
    ----------
    material : SpectralPhong
        Material and light (e.g. ``SCENES.lookup("R1").build()``).
    view : {"far", "near"}
        The whole sphere, or zoomed on the highlight.
    method : {"exact", "table"}
        The shading path.
    placement, interpolation : str
        Keys of ``PLACEMENT_METHODS`` and ``INTERPOLATION_METHODS`` (table path).
    entries, segments : int
        Table size ``m`` and importance segments ``p``.
    resolution : int
        Image width and height, pixels.
    compiled : bool
        Use the numba kernels (default) or the NumPy references.

    Returns
    -------
    ndarray, shape (resolution, resolution, 3)
        Linear display RGB, unclipped, 0 off the sphere.

    Examples
    --------
    >>> from phong_table.scenes import SCENES
    >>> R1 = SCENES.lookup("R1").build()
    >>> exact = render_sphere(R1, "near", "exact", resolution=32)
    >>> table = render_sphere(R1, "near", "table", "error", "monotone", 64, resolution=32)
    >>> float(255 * np.abs(table - exact).max()) < 1e-3
    True
    """
    require_choice(method, SHADING_PATHS, "shading path")
    geometry = sphere_gbuffer(view, resolution)
    buffer = shading_buffer(geometry, material, compiled)
    table = None
    if method == "table":
        table = build_table(
            material,
            entries,
            placement,
            segments,
            compiled=compiled,
            t_range=buffer.t_range,
            t_density=buffer.t_density,
        )
        check_interpolation(interpolation, table.entries)
    pixels = shade_pixels(buffer, material, method, table, interpolation, compiled)
    return geometry.to_image(pixels)


def rms_8bit(RGB, RGB_exact, encoding: str = "srgb", exact_encoded=None) -> tuple[float, float]:
    """RMS error in 8-bit units over pixels and channels: display (clipped, encoded) and linear.

    Parameters
    ----------
    RGB, RGB_exact : ndarray, shape (N, 3)
        Linear display RGB of the method and of the exact render, same pixels.
    encoding : str
        Display encoding (``reference.display.encodings.ENCODINGS``).
    exact_encoded : ndarray, shape (N, 3), optional
        ``linear_to_display(RGB_exact)``, if already computed.

    Returns
    -------
    rms_display, rms_linear : float
        ``255 · sqrt(mean((enc(clip(RGB)) − enc(clip(RGB_exact)))²))`` and
        ``255 · sqrt(mean((RGB − RGB_exact)²))``; ``inf`` if ``RGB`` is not finite.

    Examples
    --------
    >>> [round(x, 6) for x in rms_8bit(np.array([[0.5, 0.5, -0.1]]), np.array([[0.5, 0.5, 0.0]]))]
    [0.0, 14.722432]
    """
    RGB = np.asarray(RGB, dtype=np.float64)
    if not np.isfinite(RGB).all():
        return float("inf"), float("inf")
    if exact_encoded is None:
        exact_encoded = linear_to_display(RGB_exact, encoding)
    display = linear_to_display(RGB, encoding)
    rms_display = 255.0 * float(np.sqrt(np.mean((display - exact_encoded) ** 2)))
    rms_linear = 255.0 * float(np.sqrt(np.mean((RGB - RGB_exact) ** 2)))
    return rms_display, rms_linear

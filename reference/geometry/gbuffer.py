"""The G-buffer: per-pixel surface attributes that deferred shading reads.

Rendering in specref is deferred. :func:`render_gbuffer` resolves visibility once, and shading
models are pure functions of the G-buffer, the lights and the materials, so a material edit
re-shades without re-rasterizing (Wang et al.'s WYSIWYG editing use, Herbert et al.'s change-driven
frames).

Each primitive type registers a function in :data:`PRIMITIVES` that returns the nearest hits of its
own surface; :func:`render_gbuffer` keeps, per pixel, the nearest over all objects (a z-buffer on
camera depth).
Analytic spheres and planes are ray cast exactly; triangle meshes are rasterized
(``reference.geometry.raster`` registers ``"TriangleMesh"``).

Supersampling renders the G-buffer at ``factor × factor`` the resolution; shade it, then resolve
with ``reference.geometry.camera.downsample_box``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, fields

import numpy as np

from reference.errors import require
from reference.geometry.camera import Camera, _check_resolution
from reference.geometry.shapes import Hit, Plane, Sphere, intersect_plane, intersect_sphere
from reference.progress import Progress
from reference.registry import Registry

__all__ = [
    "GBUFFER_BAND_SAMPLES",
    "PRIMITIVES",
    "RAY_CAST_PRIMITIVES",
    "GBuffer",
    "empty_gbuffer",
    "gbuffer_from_hit",
    "render_gbuffer",
]


@dataclass
class GBuffer:
    """Per-pixel surface attributes, shape ``(H, W, ...)``.

    Attributes
    ----------
    position : ndarray, (H, W, 3)
        World position of the visible surface (NaN off the surface).
    normal : ndarray, (H, W, 3)
        Unit shading normal (NaN off the surface).
    uv : ndarray, (H, W, 2)
        Texture coordinates.
    depth : ndarray, (H, W)
        Camera depth (distance along the view axis), ``inf`` off the surface.
    material_id : ndarray of int32, (H, W)
        Index into the scene's materials, −1 off the surface.
    object_id : ndarray of int32, (H, W)
        Index into the scene's objects, −1 off the surface.
    mask : ndarray of bool, (H, W)
        Coverage: True where a surface is visible.
    view : ndarray, (H, W, 3)
        Unit vector from the surface towards the eye (for orthographic cameras, the constant
        −forward).
    """

    position: np.ndarray
    normal: np.ndarray
    uv: np.ndarray
    depth: np.ndarray
    material_id: np.ndarray
    object_id: np.ndarray
    mask: np.ndarray
    view: np.ndarray

    @property
    def shape(self) -> tuple[int, int]:
        """``(H, W)``."""
        return self.depth.shape

    def clear(self) -> None:
        """Nothing visible (in place): NaN attributes, infinite depth, ids −1, no coverage."""
        for name in ("position", "normal", "uv", "view"):
            getattr(self, name).fill(np.nan)
        self.depth.fill(np.inf)
        self.material_id.fill(-1)
        self.object_id.fill(-1)
        self.mask.fill(False)

    def rows(self, start: int, stop: int) -> GBuffer:
        """Rows ``start:stop`` (views, no copies: writing to them writes to this G-buffer)."""
        return GBuffer(**{f.name: getattr(self, f.name)[start:stop] for f in fields(GBuffer)})

    def composite(self, other: GBuffer) -> None:
        """Keep, per pixel, the nearer of ``self`` and ``other`` (in place): the z-buffer test."""
        nearer = other.depth < self.depth
        for name in ("position", "normal", "uv", "view"):
            getattr(self, name)[nearer] = getattr(other, name)[nearer]
        for name in ("depth", "material_id", "object_id", "mask"):
            getattr(self, name)[nearer] = getattr(other, name)[nearer]


def empty_gbuffer(height: int, width: int) -> GBuffer:
    """A G-buffer with nothing visible.

    Examples
    --------
    >>> g = empty_gbuffer(2, 3)
    >>> g.shape, bool(g.mask.any())
    ((2, 3), False)
    """
    g = _allocated_gbuffer(height, width)
    g.clear()
    return g


def _allocated_gbuffer(height: int, width: int) -> GBuffer:
    """A G-buffer's arrays, not yet written (:meth:`GBuffer.clear` them)."""
    return GBuffer(
        position=np.empty((height, width, 3)),
        normal=np.empty((height, width, 3)),
        uv=np.empty((height, width, 2)),
        depth=np.empty((height, width)),
        material_id=np.empty((height, width), dtype=np.int32),
        object_id=np.empty((height, width), dtype=np.int32),
        mask=np.empty((height, width), dtype=bool),
        view=np.empty((height, width, 3)),
    )


def gbuffer_from_hit(
    hit: Hit, camera: Camera, directions, material: int, object_id: int
) -> GBuffer:
    """A G-buffer from analytic ray hits: depth along the view axis, view vectors, ids.

    Parameters
    ----------
    hit : Hit
        Intersections of the primary rays.
    camera : Camera
        The camera that made the rays.
    directions : ndarray, shape (H, W, 3)
        The unit ray directions.
    material, object_id : int
        Ids written where the rays hit.

    Returns
    -------
    GBuffer

    Examples
    --------
    >>> from reference.geometry.shapes import intersect_sphere, Sphere
    >>> cam = Camera(eye=(0, 0, 5))
    >>> origins, directions = cam.rays(4, 4)
    >>> g = gbuffer_from_hit(intersect_sphere(Sphere(), origins, directions), cam, directions, 0, 0)
    >>> int(g.mask.sum()), float(g.depth[g.mask].min()).__round__(3)
    (4, 4.213)
    """
    H, W = hit.t.shape
    g = empty_gbuffer(H, W)
    found = np.isfinite(hit.t)
    back = camera.basis()[2]
    depth = hit.t * (directions @ -back)
    g.depth[found] = depth[found]
    g.position[found] = hit.position[found]
    g.normal[found] = hit.normal[found]
    g.uv[found] = hit.uv[found]
    g.view[found] = -directions[found]
    g.material_id[found] = material
    g.object_id[found] = object_id
    g.mask[found] = True
    return g


def _gbuffer_sphere(
    obj: Sphere, camera: Camera, width: int, height: int, object_id: int, rows=None
) -> GBuffer:
    origins, directions = camera.rays(width, height, rows)
    return gbuffer_from_hit(
        intersect_sphere(obj, origins, directions), camera, directions, obj.material, object_id
    )


def _gbuffer_plane(
    obj: Plane, camera: Camera, width: int, height: int, object_id: int, rows=None
) -> GBuffer:
    origins, directions = camera.rays(width, height, rows)
    return gbuffer_from_hit(
        intersect_plane(obj, origins, directions), camera, directions, obj.material, object_id
    )


#: G-buffer writers by primitive class name: ``f(obj, camera, width, height, object_id)``.
PRIMITIVES = Registry("primitive", Callable)
PRIMITIVES.register(_gbuffer_sphere, "Sphere")
PRIMITIVES.register(_gbuffer_plane, "Plane")
#: The writers that cast one ray per sample and so can write a band of rows at a time:
#: ``f(obj, camera, width, height, object_id, rows=(start, stop))``.
RAY_CAST_PRIMITIVES = Registry("ray-cast primitive", Callable)
RAY_CAST_PRIMITIVES.register(_gbuffer_sphere, "Sphere")
RAY_CAST_PRIMITIVES.register(_gbuffer_plane, "Plane")
#: Samples per band of a ray-cast G-buffer: the rays' temporaries stay within tens of MB and a
#: long G-buffer reports its progress.
GBUFFER_BAND_SAMPLES = 1 << 18


def render_gbuffer(
    objects: Sequence,
    camera: Camera,
    width: int,
    height: int,
    supersample: int = 1,
    progress=None,
) -> GBuffer:
    """Resolve visibility for a list of primitives: the nearest surface per pixel (sub-sample).

    Parameters
    ----------
    objects : sequence
        Primitives (``Sphere``, ``Plane``, ``TriangleMesh``, ...) whose class names are in
        :data:`PRIMITIVES`.
    camera : Camera
        The camera.
    width, height : int
        Image size in pixels, in [1, MAX_RESOLUTION].
    supersample : int
        Sub-samples per pixel per axis, in [1, 16]; the G-buffer is ``(supersample·height,
        supersample·width)``.
    progress : file-like, optional
        Where to report progress (:class:`reference.progress.Progress`, by rows of each
        object); ray-cast primitives (:data:`RAY_CAST_PRIMITIVES`) are written in bands of
        :data:`GBUFFER_BAND_SAMPLES` samples.

    Returns
    -------
    GBuffer

    Examples
    --------
    >>> cam = Camera(eye=(0, 0, 5), target=(0, 0, 0), fov_deg=30)
    >>> g = render_gbuffer([Sphere((0, 0, 0), 1.0)], cam, 8, 8)
    >>> int(g.mask.sum()), g.normal[4, 4].round(3)
    (32, array([ 0.135, -0.135,  0.982]))
    """
    require(
        isinstance(supersample, int) and 1 <= supersample <= 16,
        f"render.supersample: must be an integer in [1, 16], got {supersample!r}",
    )
    _check_resolution(width, height)
    H, W = height * supersample, width * supersample
    names = [type(obj).__name__ for obj in objects]
    # rasterized meshes cover the whole image at once, ray-cast primitives a band at a time
    whole = {
        i: PRIMITIVES.lookup(name)(objects[i], camera, W, H, i)
        for i, name in enumerate(names)
        if name not in RAY_CAST_PRIMITIVES
    }
    g = _allocated_gbuffer(H, W)  # each band is cleared as it is reached
    band = max(1, GBUFFER_BAND_SAMPLES // W)
    with Progress("G-buffer", H, progress) as bar:
        for start in range(0, H, band):
            stop = min(start + band, H)
            rows = g.rows(start, stop)
            rows.clear()
            for i, obj in enumerate(objects):  # in order: the nearer wins, the first on a tie
                if i in whole:
                    rows.composite(whole[i].rows(start, stop))
                else:
                    writer: Callable = RAY_CAST_PRIMITIVES.lookup(names[i])
                    rows.composite(writer(obj, camera, W, H, i, (start, stop)))
            bar.update(stop - start)
    return g

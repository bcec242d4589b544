"""Analytic primitives and their exact ray intersections: the sphere and the plane (or rectangle).

Each primitive intersects a batch of rays in closed form and reports the hit distance, the position,
the geometric normal and texture coordinates. Triangle meshes are rasterized instead
(``reference.geometry.raster``).

- **Sphere** (centre ``c``, radius ``r``): the smaller positive root of ``|o + t d − c|² = r²``; the
normal
  is ``(p − c)/r`` (outward); ``uv`` follows the lat-long convention of
  ``reference.geometry.envmap`` applied to the normal, so a texture on the sphere is oriented like
  an environment map.
- **Plane** (point ``p0``, unit normal ``n``, in-plane axis ``a``): ``t = (p0 − o)·n / (d·n)``; with
a
  ``size = (w, h)`` it is the rectangle centred on ``p0`` with ``u`` along ``a`` and ``v`` along ``n
  × a`` (both in [0, 1]; v = 0 at the edge on the ``+(n × a)`` side, so images map with row 0 at
  that edge).

References
----------
- M. Pharr, W. Jakob, G. Humphreys, *Physically Based Rendering*, 4th ed., §6.2 (spheres).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.errors import require, require_finite
from reference.geometry.envmap import direction_to_latlong_uv

__all__ = ["Hit", "Plane", "Sphere", "intersect_plane", "intersect_sphere", "plane_uv_to_point"]


@dataclass(frozen=True)
class Hit:
    """Intersections of a batch of rays with one primitive; ``t = inf`` where a ray misses.

    Attributes
    ----------
    t : ndarray, shape (...,)
        Distance along the (unit) ray.
    position, normal : ndarray, shape (..., 3)
        Hit point and unit geometric normal (NaN where missed).
    uv : ndarray, shape (..., 2)
        Texture coordinates.
    """

    t: np.ndarray
    position: np.ndarray
    normal: np.ndarray
    uv: np.ndarray


@dataclass(frozen=True)
class Sphere:
    """An analytic sphere.

    Parameters
    ----------
    center : array_like, shape (3,)
        Centre, world units.
    radius : float
        Radius, > 0.
    material : int
        Index of the object's material in the scene's material list.

    Examples
    --------
    >>> Sphere((0, 0, 0), 1.0).radius
    1.0
    """

    center: tuple = (0.0, 0.0, 0.0)
    radius: float = 1.0
    material: int = 0

    def __post_init__(self):
        c = require_finite(self.center, "sphere.center")
        require(c.shape == (3,), f"sphere.center: must be 3 numbers, got shape {c.shape}")
        require(
            np.isfinite(self.radius) and self.radius > 0,
            f"sphere.radius: must be > 0, got {self.radius}",
        )
        object.__setattr__(self, "center", tuple(float(x) for x in c))
        object.__setattr__(self, "radius", float(self.radius))


@dataclass(frozen=True)
class Plane:
    """An analytic plane, or a rectangle when ``size`` is given.

    Parameters
    ----------
    point : array_like, shape (3,)
        A point on the plane (the rectangle's centre).
    normal : array_like, shape (3,)
        Normal (normalised internally).
    u_axis : array_like, shape (3,)
        In-plane direction of increasing u (projected into the plane and normalised).
    size : tuple of float, optional
        ``(width, height)`` of the rectangle along ``u_axis`` and ``normal × u_axis``; None is
        unbounded, with ``uv`` in world units from ``point``.
    material : int
        Index of the object's material.

    Examples
    --------
    >>> Plane((0, 0, 0), (0, 0, 1), (1, 0, 0), size=(2.0, 1.0)).size
    (2.0, 1.0)
    """

    point: tuple = (0.0, 0.0, 0.0)
    normal: tuple = (0.0, 1.0, 0.0)
    u_axis: tuple = (1.0, 0.0, 0.0)
    size: tuple | None = None
    material: int = 0

    def __post_init__(self):
        p = require_finite(self.point, "plane.point")
        n = require_finite(self.normal, "plane.normal")
        a = require_finite(self.u_axis, "plane.u_axis")
        for key, value in (("point", p), ("normal", n), ("u_axis", a)):
            require(value.shape == (3,), f"plane.{key}: must be 3 numbers, got shape {value.shape}")
        require(np.linalg.norm(n) > 0, "plane.normal: must be non-zero")
        n = n / np.linalg.norm(n)
        a = a - (a @ n) * n
        require(np.linalg.norm(a) > 1e-9, "plane.u_axis: must not be parallel to the normal")
        a = a / np.linalg.norm(a)
        if self.size is not None:
            size = require_finite(self.size, "plane.size")
            require(
                size.shape == (2,) and (size > 0).all(),
                f"plane.size: must be two numbers > 0, got {self.size}",
            )
            object.__setattr__(self, "size", (float(size[0]), float(size[1])))
        object.__setattr__(self, "point", tuple(float(x) for x in p))
        object.__setattr__(self, "normal", tuple(float(x) for x in n))
        object.__setattr__(self, "u_axis", tuple(float(x) for x in a))


def intersect_sphere(sphere: Sphere, origins, directions) -> Hit:
    """Exact ray-sphere intersection for a batch of rays.

    Parameters
    ----------
    sphere : Sphere
        The sphere.
    origins, directions : ndarray, shape (..., 3)
        Ray origins and unit directions.

    Returns
    -------
    Hit
        The nearest hit with ``t > 0`` (from inside, the far root), outward normals.

    Examples
    --------
    >>> hit = intersect_sphere(Sphere(), np.array([[0.0, 0.0, 5.0]]), np.array([[0.0, 0.0, -1.0]]))
    >>> hit.t, hit.normal
    (array([4.]), array([[0., 0., 1.]]))
    """
    o = np.asarray(origins, dtype=np.float64)
    d = np.asarray(directions, dtype=np.float64)
    c = np.asarray(sphere.center)
    r = sphere.radius
    # |o + t d - c|² = r², with |d| = 1: t² + 2 b t + q = 0; the stable form avoids cancellation.
    oc = o - c
    b = np.einsum("...i,...i->...", oc, d)
    q = np.einsum("...i,...i->...", oc, oc) - r * r
    disc = b * b - q
    hit = disc >= 0.0
    sq = np.sqrt(np.where(hit, disc, 0.0))
    t_near = -b - sq
    t_far = -b + sq
    t = np.where(t_near > 1e-9, t_near, np.where(t_far > 1e-9, t_far, np.inf))
    t = np.where(hit, t, np.inf)
    found = np.isfinite(t)
    position = o + np.where(found, t, np.nan)[..., None] * d
    normal = (position - c) / r
    # Project hit points exactly onto the sphere: the normal is then unit length to rounding.
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    position = np.where(found[..., None], c + r * normal, np.nan)
    u, v = direction_to_latlong_uv(np.where(found[..., None], normal, 0.0))
    uv = np.stack([u, v], axis=-1)
    return Hit(t, position, normal, uv)


def intersect_plane(plane: Plane, origins, directions) -> Hit:
    """Exact ray-plane (or ray-rectangle) intersection for a batch of rays.

    Parameters
    ----------
    plane : Plane
        The plane.
    origins, directions : ndarray, shape (..., 3)
        Ray origins and unit directions.

    Returns
    -------
    Hit
        Hits with ``t > 0`` inside the rectangle (if bounded); the normal is the plane's, both
        sides.

    Examples
    --------
    >>> P = Plane((0, 0, 0), (0, 0, 1), (1, 0, 0), size=(2.0, 2.0))
    >>> hit = intersect_plane(P, np.array([[0.5, 0.5, 3.0]]), np.array([[0.0, 0.0, -1.0]]))
    >>> hit.t, hit.uv
    (array([3.]), array([[0.75, 0.25]]))
    """
    o = np.asarray(origins, dtype=np.float64)
    d = np.asarray(directions, dtype=np.float64)
    p0, n, a = (np.asarray(v) for v in (plane.point, plane.normal, plane.u_axis))
    b_axis = np.cross(n, a)
    denom = d @ n
    with np.errstate(divide="ignore", invalid="ignore"):
        t = ((p0 - o) @ n) / denom
    t = np.where((np.abs(denom) > 1e-15) & (t > 1e-9), t, np.inf)
    position = o + np.where(np.isfinite(t), t, np.nan)[..., None] * d
    local = position - p0
    s, r = local @ a, local @ b_axis
    if plane.size is not None:
        w, h = plane.size
        inside = (np.abs(s) <= w / 2) & (np.abs(r) <= h / 2)
        t = np.where(inside, t, np.inf)
        uv = np.stack([s / w + 0.5, 0.5 - r / h], axis=-1)
    else:
        uv = np.stack([s, -r], axis=-1)
    found = np.isfinite(t)
    position = np.where(found[..., None], position, np.nan)
    normal = np.broadcast_to(n, position.shape).copy()
    return Hit(t, position, normal, np.where(found[..., None], uv, np.nan))


def plane_uv_to_point(plane: Plane, uv) -> np.ndarray:
    """World points of texture coordinates on a plane: the inverse of its ``uv`` in hits.

    On a rectangle ``p = p0 + (u − ½) w a + (½ − v) h (n × a)``; on an unbounded plane ``u`` and
    ``v`` are world units from ``p0`` along ``a`` and ``−(n × a)``.

    Parameters
    ----------
    plane : Plane
        The plane or rectangle.
    uv : array_like, shape (..., 2)
        Texture coordinates.

    Returns
    -------
    ndarray, shape (..., 3)

    Examples
    --------
    >>> P = Plane((0, 0, 0), (0, 0, 1), (1, 0, 0), size=(2.0, 2.0))
    >>> plane_uv_to_point(P, [0.75, 0.25])
    array([0.5, 0.5, 0. ])
    """
    uv = np.asarray(uv, dtype=np.float64)
    p0, n, a = (np.asarray(v) for v in (plane.point, plane.normal, plane.u_axis))
    b_axis = np.cross(n, a)
    if plane.size is not None:
        w, h = plane.size
        s, r = (uv[..., 0] - 0.5) * w, (0.5 - uv[..., 1]) * h
    else:
        s, r = uv[..., 0], -uv[..., 1]
    return p0 + s[..., None] * a + r[..., None] * b_axis

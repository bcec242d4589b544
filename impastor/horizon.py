"""Horizon-map shadows and normal maps from height maps (§3.1.3 and §3.5.3, Ferwerda).

ImpastoR models surface relief ("impasto") with a height map. Shading uses a normal map derived
from it (Peercy et al. 1997); shadowing uses *horizon maps* (Max 1988; Sloan & Cohen 2000): for
every pixel and each of S azimuth sectors, the elevation angle of the horizon. A light at azimuth
φ and elevation β is blocked where β is below the horizon of the sector that contains φ. The paper
uses S = 18 sectors of 20°, stored as six three-channel floating-point images.

Conventions. Height maps are ``(H, W)`` in metres with square pixels of side ``pixel_size`` (m),
periodic at the borders (the surface tiles). Azimuth φ is measured in the image plane from +x (the
column direction) towards +y (the row direction, downwards in the image); elevation β from the
base plane. Sector s is centred on ``(s + ½) Δ`` with ``Δ = 2π/S``; its horizon is computed along
that centre. Rays march in steps of ``step`` pixels (¼ by default) up to ``max_steps`` pixels,
sampling the height bilinearly; the horizon angle is ``max(0, max_t atan(Δh(t) / (t·pixel_size)))``.
A light's horizon is interpolated linearly in azimuth between the two nearest sector centres
(Sloan & Cohen 2000; the paper reads the one sector that holds φ: ``interpolate=False``).

The ray-marched reference (:func:`ray_march_shadows`) marches along the light's exact azimuth with
the same steps, so the horizon map differs from it only in azimuth. Steps of one pixel (the
first version) miss ridges between samples: a one-pixel march disagrees with a converged one
(⅛ pixel) on 3.6 % of the pixels at 10° elevation, more than the sectors do; see
``docs/impastor.md`` and erratum E95.

References
----------
- J. A. Ferwerda, "ImpastoR: A realistic surface display system", Vision Research 109, 2015.
- N. Max, "Horizon mapping: shadows for bump-mapped surfaces", The Visual Computer 4, 1988.
- P.-P. Sloan, M. F. Cohen, "Interactive horizon mapping", EGWR 2000.
- M. Peercy, J. Airey, B. Cabral, "Efficient bump mapping hardware", SIGGRAPH 1997.
"""

from __future__ import annotations

import numpy as np

from impastor._kernels import (
    horizon_at_texels_kernel,
    horizon_map_kernel,
    ray_march_shadows_kernel,
)
from reference.errors import require, require_choice, require_finite, require_positive_int
from reference.jit import kernel_input
from reference.registry import Method, Registry

__all__ = [
    "BACKENDS",
    "HORIZON_BAND_TEXELS",
    "HORIZON_METHODS",
    "horizon_at_texels",
    "horizon_images_to_map",
    "horizon_lookup",
    "horizon_map",
    "horizon_map_to_images",
    "light_azimuth_elevation",
    "normal_map_from_height",
    "ray_march_shadows",
    "tangent_to_world",
]

BACKENDS = ("numpy", "numba")


def _check_height(height, pixel_size) -> tuple[np.ndarray, float]:
    h = require_finite(height, "height map")
    require(h.ndim == 2 and min(h.shape) >= 2, f"height map: must be (H, W), got shape {h.shape}")
    require(
        np.isfinite(pixel_size) and pixel_size > 0,
        f"height map: pixel_size: must be > 0 m, got {pixel_size}",
    )
    return np.ascontiguousarray(h), float(pixel_size)


def _check_step(step, where: str) -> float:
    step = float(step)
    require(0.0 < step <= 1.0, f"{where}: step: must be in (0, 1] pixels, got {step:g}")
    return step


def _sample_periodic(h, y, x):
    """Bilinear height at fractional pixel coordinates (periodic)."""
    H, W = h.shape
    x0, y0 = np.floor(x).astype(np.int64), np.floor(y).astype(np.int64)
    fx, fy = x - x0, y - y0
    x0, y0 = x0 % W, y0 % H
    x1, y1 = (x0 + 1) % W, (y0 + 1) % H
    top = h[y0, x0] * (1 - fx) + h[y0, x1] * fx
    bottom = h[y1, x0] * (1 - fx) + h[y1, x1] * fx
    return top * (1 - fy) + bottom * fy


def _horizon_along(h, pixel_size, phi, max_steps, step):
    """Horizon elevation (radians, >= 0) along azimuth ``phi`` (scalar or (H, W)) at every pixel."""
    H, W = h.shape
    rows, cols = np.meshgrid(
        np.arange(H, dtype=np.float64), np.arange(W, dtype=np.float64), indexing="ij"
    )
    dx, dy = np.cos(phi), np.sin(phi)
    best = np.zeros((H, W))
    for k in range(1, round(max_steps / step) + 1):
        t = k * step
        rise = _sample_periodic(h, rows + t * dy, cols + t * dx) - h
        # Sloan & Cohen 2000: the horizon is the largest elevation angle seen along the ray
        best = np.maximum(best, rise / (t * pixel_size))
    return np.arctan(best)


#: Texel-sectors per call of the horizon map's kernel: a 512² map of 36 sectors is 2¹⁵ of them
#: per band (about 0.1 s), so Ctrl-C and SIGTERM are handled between bands.
HORIZON_BAND_TEXELS = 1 << 15


def horizon_map(
    height,
    pixel_size: float,
    n_sectors: int = 18,
    max_steps: int = 32,
    backend: str = "numpy",
    step: float = 0.25,
) -> np.ndarray:
    """Horizon elevation angles for ``n_sectors`` azimuth sectors at every pixel.

    §3.5.3, Ferwerda: "for each surface point, a horizon map stored the critical elevation angle at
    which light would be blocked from reaching that point from a given azimuthal direction".

    Parameters
    ----------
    height : array_like, shape (H, W)
        Heights, m (periodic).
    pixel_size : float
        Pixel side, m.
    n_sectors : int
        S (18 in the paper, 20° each).
    max_steps : int
        March length in pixels.
    backend : {"numpy", "numba"}
    step : float
        March step in pixels, in (0, 1] (erratum E95: ¼, not 1).

    Returns
    -------
    ndarray, shape (H, W, S)
        Elevation angles in [0, π/2), radians.

    Examples
    --------
    >>> h = np.zeros((8, 8)); h[:, 6] = 1.0          # a ridge two pixels to the right
    >>> hm = horizon_map(h, 1.0, n_sectors=4, max_steps=4, step=1.0)
    >>> round(float(np.degrees(hm[4, 4, 0])), 1), float(hm[4, 4, 2])
    (16.3, 0.0)
    """
    require_choice(backend, BACKENDS, "backend")
    h, pixel_size = _check_height(height, pixel_size)
    S = require_positive_int(n_sectors, "horizon map: n_sectors", 360)
    steps = require_positive_int(max_steps, "horizon map: max_steps", 4096)
    step = _check_step(step, "horizon map")
    out = np.zeros((*h.shape, S))
    if backend == "numba":
        # a band of rows per call, so a signal (Ctrl-C) is handled within a fraction of a second
        band = max(1, HORIZON_BAND_TEXELS // (h.shape[1] * S))
        for row0 in range(0, h.shape[0], band):
            horizon_map_kernel(h, pixel_size, S, steps, step, row0, out[row0 : row0 + band])
        return out
    for s in range(S):
        # Sector s is marched along its centre azimuth (s + ½) 2π/S.
        out[..., s] = _horizon_along(h, pixel_size, (s + 0.5) * 2.0 * np.pi / S, steps, step)
    return out


def horizon_at_texels(
    height,
    pixel_size: float,
    rows,
    cols,
    n_sectors: int = 18,
    max_steps: int = 32,
    backend: str = "numpy",
    step: float = 0.25,
) -> np.ndarray:
    """The horizon map's angles at a few texels only: ``horizon_map(...)[rows, cols]``.

    §3.5.3, Ferwerda, as :func:`horizon_map`, marched from the listed texels alone: a pilot that
    compares sector counts at a thousand texels pays for a thousand, not for the whole map.

    Parameters
    ----------
    height : array_like, shape (H, W)
    pixel_size : float
    rows, cols : array_like of int, shape (n,)
        Texel indices.
    n_sectors, max_steps, backend, step
        As in :func:`horizon_map`.

    Returns
    -------
    ndarray, shape (n, S)
        Elevation angles in [0, π/2), radians.

    Examples
    --------
    >>> h = np.zeros((8, 8)); h[:, 6] = 1.0
    >>> angles = horizon_at_texels(h, 1.0, [4], [4], n_sectors=4, max_steps=4, step=1.0)
    >>> bool(np.array_equal(angles, horizon_map(h, 1.0, 4, 4, step=1.0)[[4], [4]]))
    True
    """
    require_choice(backend, BACKENDS, "backend")
    h, pixel_size = _check_height(height, pixel_size)
    S = require_positive_int(n_sectors, "horizon map: n_sectors", 360)
    steps = require_positive_int(max_steps, "horizon map: max_steps", 4096)
    step = _check_step(step, "horizon map")
    r, c = (np.ascontiguousarray(x, dtype=np.int64).ravel() for x in (rows, cols))
    require(
        r.shape == c.shape and ((r >= 0) & (r < h.shape[0]) & (c >= 0) & (c < h.shape[1])).all(),
        f"horizon at texels: rows and cols must be indices of the {h.shape} height map",
    )
    out = np.zeros((r.size, S))
    if backend == "numba":
        horizon_at_texels_kernel(h, pixel_size, r, c, S, steps, step, out)
        return out
    t = step * np.arange(1, round(steps / step) + 1)[:, None]  # every step of the march at once
    for s in range(S):
        phi = (s + 0.5) * 2.0 * np.pi / S
        rise = _sample_periodic(h, r + t * np.sin(phi), c + t * np.cos(phi)) - h[r, c]
        # Sloan & Cohen 2000: the horizon is the largest elevation angle seen along the ray
        out[:, s] = np.arctan(np.maximum(0.0, (rise / (t * pixel_size)).max(axis=0)))
    return out


def horizon_map_to_images(hmap) -> list[np.ndarray]:
    """Pack an ``(H, W, S)`` horizon map into ``ceil(S/3)`` three-channel images (zero-padded).

    §3.5.3, Ferwerda: 18 sectors "stored as six floating-point images".

    Examples
    --------
    >>> images = horizon_map_to_images(np.zeros((2, 2, 18)))
    >>> len(images), images[0].shape
    (6, (2, 2, 3))
    """
    hmap = np.asarray(hmap, dtype=np.float64)
    S = hmap.shape[-1]
    padded = np.concatenate([hmap, np.zeros((*hmap.shape[:-1], -S % 3))], axis=-1)
    return [padded[..., k : k + 3].copy() for k in range(0, padded.shape[-1], 3)]


def horizon_images_to_map(images, n_sectors: int) -> np.ndarray:
    """Inverse of :func:`horizon_map_to_images`.

    Examples
    --------
    >>> hm = np.random.default_rng(0).random((2, 2, 18))
    >>> bool(np.array_equal(horizon_images_to_map(horizon_map_to_images(hm), 18), hm))
    True
    """
    stacked = np.concatenate([np.asarray(i, dtype=np.float64) for i in images], axis=-1)
    require(
        stacked.shape[-1] >= n_sectors,
        f"horizon images: hold {stacked.shape[-1]} channels, fewer than {n_sectors} sectors",
    )
    return stacked[..., :n_sectors]


def horizon_lookup(hmap, phi, beta, interpolate: bool = True) -> np.ndarray:
    """Visibility of a light at azimuth ``phi`` and elevation ``beta`` from a horizon map.

    §3.5.3, Ferwerda: the light is blocked where β is below the horizon angle at φ (and always
    where β <= 0). The paper reads the map of the sector that contains φ (``interpolate=False``);
    by default the angle is interpolated linearly in φ between the two nearest sector centres
    (Sloan & Cohen 2000; erratum E95), which halves the disagreement with ray-marched shadows at
    raking light.

    Parameters
    ----------
    hmap : ndarray, shape (..., S)
        Horizon angles per pixel (for example ``(H, W, S)``, or ``(P, 1, S)`` for P pixels).
    phi, beta : array_like
        Light azimuth and elevation, radians, broadcast against ``hmap.shape[:-1]``.
    interpolate : bool
        Linear in φ between sector centres (True) or the sector that holds φ (False).

    Returns
    -------
    ndarray of bool
        True where the light reaches the pixel, in the broadcast shape.

    Examples
    --------
    >>> hm = np.zeros((1, 1, 4)); hm[..., 1] = 0.5
    >>> horizon_lookup(hm, [[np.pi / 2]], [[0.4]], False), horizon_lookup(hm, [[np.pi]], [[0.4]])
    (array([[False]]), array([[ True]]))
    >>> horizon_lookup(hm, 3 * np.pi / 4, [[0.4]]), horizon_lookup(hm, np.pi / 2, [[0.2]])
    (array([[False]]), array([[False]]))
    """
    hmap = np.asarray(hmap, dtype=np.float64)
    S = hmap.shape[-1]
    phi, beta = np.asarray(phi, float), np.asarray(beta, float)
    shape = np.broadcast_shapes(hmap.shape[:-1], phi.shape, beta.shape)
    hmap = np.broadcast_to(hmap, (*shape, S))
    phi, beta = np.broadcast_to(phi, shape), np.broadcast_to(beta, shape)
    x = np.mod(phi, 2.0 * np.pi) / (2.0 * np.pi / S)
    if interpolate:
        # Sloan & Cohen 2000: linear in φ between the sector centres (s + ½) Δ either side
        s0 = np.floor(x - 0.5).astype(np.int64)
        f = x - 0.5 - s0
        h0 = np.take_along_axis(hmap, (s0 % S)[..., None], axis=-1)[..., 0]
        h1 = np.take_along_axis(hmap, ((s0 + 1) % S)[..., None], axis=-1)[..., 0]
        critical = (1.0 - f) * h0 + f * h1
    else:
        sector = np.floor(x).astype(np.int64) % S
        critical = np.take_along_axis(hmap, sector[..., None], axis=-1)[..., 0]
    # §3.5.3, Ferwerda: the source counts only above the critical elevation
    return (beta > critical) & (beta > 0.0)


def ray_march_shadows(
    height,
    pixel_size: float,
    phi,
    beta,
    max_steps: int = 32,
    backend: str = "numpy",
    step: float = 0.25,
) -> np.ndarray:
    """Reference shadows: march towards the light along its exact azimuth.

    Sloan & Cohen 2000's horizon test with no sector quantisation: lit where ``β`` exceeds the
    horizon elevation along φ itself.

    Parameters
    ----------
    height : array_like, shape (H, W)
    pixel_size : float
    phi, beta : float or array_like, shape (H, W)
        Light azimuth and elevation per pixel, radians.
    max_steps : int
        March length in pixels.
    backend : {"numpy", "numba"}
    step : float
        March step in pixels, in (0, 1]; its own error is measured by halving it.

    Returns
    -------
    ndarray of bool, shape (H, W)
        True where lit.

    Examples
    --------
    >>> h = np.zeros((8, 8)); h[4, 6] = 1.0
    >>> lit = ray_march_shadows(h, 1.0, 0.0, np.radians(20.0), 4, step=1.0)
    >>> bool(lit[4, 4]), bool(lit[4, 2])
    (False, True)
    """
    require_choice(backend, BACKENDS, "backend")
    h, pixel_size = _check_height(height, pixel_size)
    steps = require_positive_int(max_steps, "ray march: max_steps", 4096)
    step = _check_step(step, "ray march")
    phi = np.ascontiguousarray(np.broadcast_to(np.asarray(phi, float), h.shape))
    beta = np.ascontiguousarray(np.broadcast_to(np.asarray(beta, float), h.shape))
    if backend == "numba":
        out = np.zeros(h.shape, dtype=np.bool_)
        phi, beta = kernel_input(phi), kernel_input(beta)
        ray_march_shadows_kernel(kernel_input(h), pixel_size, phi, beta, steps, step, out)
        return out
    return (beta > _horizon_along(h, pixel_size, phi, steps, step)) & (beta > 0.0)


def normal_map_from_height(height, pixel_size: float) -> np.ndarray:
    """Tangent-space unit normals of a height map by central differences (periodic).

    ``n ∝ (−∂h/∂x, −∂h/∂y, 1)`` with x along columns and y along rows (Peercy et al. 1997).

    Parameters
    ----------
    height : array_like, shape (H, W)
        Heights, m.
    pixel_size : float
        Pixel side, m.

    Returns
    -------
    ndarray, shape (H, W, 3)
        Unit normals in the frame (x: columns, y: rows, z: up from the base plane).

    Examples
    --------
    >>> x = np.arange(8.0)
    >>> n = normal_map_from_height(np.tile(0.5 * np.sin(2 * np.pi * x / 8), (4, 1)), 1.0)
    >>> n.shape, n[0, 0].round(3)
    ((4, 8, 3), array([-0.333, -0.   ,  0.943]))
    """
    h, pixel_size = _check_height(height, pixel_size)
    dh_dx = (np.roll(h, -1, axis=1) - np.roll(h, 1, axis=1)) / (2.0 * pixel_size)
    dh_dy = (np.roll(h, -1, axis=0) - np.roll(h, 1, axis=0)) / (2.0 * pixel_size)
    n = np.stack([-dh_dx, -dh_dy, np.ones_like(h)], axis=-1)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def tangent_to_world(tangent_normals, T, B, N) -> np.ndarray:
    """World normals ``n_x T + n_y B + n_z N`` from tangent-space normals.

    Parameters
    ----------
    tangent_normals : array_like, shape (..., 3)
    T, B, N : array_like, shape (3,) or (..., 3)
        World directions of the map's x (columns), y (rows) and up axes.

    Examples
    --------
    >>> tangent_to_world([0.0, 0.0, 1.0], [1, 0, 0], [0, 0, 1], [0, 1, 0])
    array([0., 1., 0.])
    """
    t = np.asarray(tangent_normals, dtype=np.float64)
    world = (
        t[..., 0:1] * np.asarray(T, float)
        + t[..., 1:2] * np.asarray(B, float)
        + t[..., 2:3] * np.asarray(N, float)
    )
    return world / np.linalg.norm(world, axis=-1, keepdims=True)


def light_azimuth_elevation(directions, T, B, N) -> tuple[np.ndarray, np.ndarray]:
    """Azimuth (from T towards B) and elevation (from the base plane) of directions to a light.

    Examples
    --------
    >>> phi, beta = light_azimuth_elevation([0.0, 1.0, 1.0], [1, 0, 0], [0, 0, 1], [0, 1, 0])
    >>> round(float(np.degrees(phi)), 6), round(float(np.degrees(beta)), 6)
    (90.0, 45.0)
    """
    d = np.asarray(directions, dtype=np.float64)
    d = d / np.linalg.norm(d, axis=-1, keepdims=True)
    x, y, z = (np.einsum("...i,...i->...", d, np.asarray(v, float)) for v in (T, B, N))
    return np.mod(np.arctan2(y, x), 2.0 * np.pi), np.arcsin(np.clip(z, -1.0, 1.0))


def _example(rng):
    return (rng.normal(size=(16, 16)) * 1e-3, 1e-3)


#: Horizon methods: ``horizon_map`` (the paper's) and ``ray_march`` (the reference).
HORIZON_METHODS = Registry("horizon method")
HORIZON_METHODS.register(
    Method(
        "horizon_map",
        horizon_map,
        horizon_map_kernel,
        "§3.5.3, Ferwerda (horizon maps, Sloan & Cohen 2000)",
        _example,
    )
)
HORIZON_METHODS.register(
    Method(
        "horizon_at_texels",
        horizon_at_texels,
        horizon_at_texels_kernel,
        "§3.5.3, Ferwerda (horizon maps at chosen texels)",
        _example,
    )
)
HORIZON_METHODS.register(
    Method(
        "ray_march",
        ray_march_shadows,
        ray_march_shadows_kernel,
        "§3.5.3, Ferwerda (ray-marched reference)",
        _example,
    )
)

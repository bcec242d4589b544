"""Cube maps: face layout, texel directions and solid angles, and transforms from and to lat-long.

§7.1, Herbert et al.: panoramic transforms between lat-long and cube maps, bilinearly filtered, at
speeds limited by memory bandwidth. specref's cube maps are arrays ``(6, S, S, C)`` in the OpenGL
face order and orientation (``docs/conventions.md``): faces +x, −x, +y, −y, +z, −z; texel
``(face, j, i)`` has face coordinates ``s = 2(i + ½)/S − 1`` (right) and ``t = 2(j + ½)/S − 1``
(down), and direction

    +x: (1, −t, −s)   −x: (−1, −t, s)   +y: (s, 1, t)   −y: (s, −1, −t)   +z: (s, −t, 1)
    −z: (−s, −t, −1)

(normalized), as seen from the cube's centre with y up. The solid angle of a texel is exact:
``Ω = A(s1, t1) − A(s0, t1) − A(s1, t0) + A(s0, t0)`` with ``A(x, y) = atan2(xy, sqrt(x² + y² +
1))``. Lookups are bilinear and seamless: a tap beyond a face edge is re-projected onto the
neighbouring face.

References
----------
- F. Herbert, J. Kirkenaer, O. Unter Ecker, "Achieving a Multi-spectral Virtual Reality", 2004.
- The OpenGL 4.6 specification, §8.13 (cube map texture selection).
"""

from __future__ import annotations

import functools
from collections.abc import Iterable

import numpy as np

from reference.errors import require, require_choice, require_positive_int
from reference.geometry import _cubemap_kernels as _k
from reference.geometry.envmap import (
    check_latlong_shape,
    direction_to_latlong_uv,
    latlong_pixel_directions,
)
from reference.jit import kernel_input
from reference.registry import Method, Registry

__all__ = [
    "CUBEMAP_FACES",
    "CUBEMAP_METHODS",
    "cubemap_lookup_bilinear",
    "cubemap_texel_directions",
    "cubemap_texel_solid_angles",
    "cubemap_to_latlong",
    "gather_bilinear",
    "latlong_blocks_to_cubemap",
    "latlong_to_cubemap",
]

#: Face order of specref's cube maps.
CUBEMAP_FACES = ("+x", "-x", "+y", "-y", "+z", "-z")


def _face_coordinates(size: int) -> np.ndarray:
    return 2.0 * (np.arange(size) + 0.5) / size - 1.0


def _face_directions(face: int, s, t) -> np.ndarray:
    one = np.ones_like(s)
    table = {
        0: (one, -t, -s),
        1: (-one, -t, s),
        2: (s, one, t),
        3: (s, -one, -t),
        4: (s, -t, one),
        5: (-s, -t, -one),
    }
    return np.stack(table[face], axis=-1)


def cubemap_texel_directions(size: int) -> np.ndarray:
    """Unit directions of the texel centres of a ``6 × size × size`` cube map.

    Returns
    -------
    ndarray, shape (6, size, size, 3)

    Examples
    --------
    >>> d = cubemap_texel_directions(1)
    >>> d[:, 0, 0] + 0.0
    array([[ 1.,  0.,  0.],
           [-1.,  0.,  0.],
           [ 0.,  1.,  0.],
           [ 0., -1.,  0.],
           [ 0.,  0.,  1.],
           [ 0.,  0., -1.]])
    """
    size = require_positive_int(size, "cube map size", 16384)
    c = _face_coordinates(size)
    s, t = np.meshgrid(c, c)
    d = np.stack([_face_directions(f, s, t) for f in range(6)])
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def cubemap_texel_solid_angles(size: int) -> np.ndarray:
    """Exact solid angle (sr) of each texel of a cube map; all six faces are alike.

    Returns
    -------
    ndarray, shape (6, size, size)
        Sums to 4π.

    Examples
    --------
    >>> round(float(cubemap_texel_solid_angles(8).sum() / (4 * np.pi)), 12)
    1.0
    """
    size = require_positive_int(size, "cube map size", 16384)
    edges = np.linspace(-1.0, 1.0, size + 1)
    x, y = np.meshgrid(edges, edges)
    # Solid angle of [0, x] × [0, y] on the plane at distance 1: A = atan2(xy, sqrt(x² + y² + 1))
    A = np.arctan2(x * y, np.sqrt(x * x + y * y + 1.0))
    face = A[1:, 1:] - A[:-1, 1:] - A[1:, :-1] + A[:-1, :-1]
    return np.broadcast_to(face, (6, size, size)).copy()


def _direction_faces(d: np.ndarray):
    """Face index and (s, t) of directions, vectorized (the major axis picks the face)."""
    a = np.abs(d)
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    major_x = (a[..., 0] >= a[..., 1]) & (a[..., 0] >= a[..., 2])
    major_y = ~major_x & (a[..., 1] >= a[..., 2])
    face = np.where(
        major_x,
        np.where(x > 0, 0, 1),
        np.where(major_y, np.where(y > 0, 2, 3), np.where(z > 0, 4, 5)),
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        s_table = [
            -z / a[..., 0],
            z / a[..., 0],
            x / a[..., 1],
            x / a[..., 1],
            x / a[..., 2],
            -x / a[..., 2],
        ]
        t_table = [
            -y / a[..., 0],
            -y / a[..., 0],
            z / a[..., 1],
            -z / a[..., 1],
            -y / a[..., 2],
            -y / a[..., 2],
        ]
    s = np.choose(face, s_table)
    t = np.choose(face, t_table)
    return face, s, t


def _fetch(cube: np.ndarray, face, i, j):
    """Texels at integer (face, j, i), continued across face edges by re-projecting the tap."""
    S = cube.shape[1]
    outside = (i < 0) | (i >= S) | (j < 0) | (j >= S)
    if outside.any():
        s = 2.0 * (i[outside] + 0.5) / S - 1.0
        t = 2.0 * (j[outside] + 0.5) / S - 1.0
        d = np.stack([_face_directions(f, s, t) for f in range(6)])  # (6, n, 3)
        d = d[face[outside], np.arange(s.size)]
        f2, s2, t2 = _direction_faces(d)
        face, i, j = face.copy(), i.copy(), j.copy()
        face[outside] = f2
        i[outside] = np.clip(np.floor((s2 + 1.0) * 0.5 * S), 0, S - 1).astype(np.int64)
        j[outside] = np.clip(np.floor((t2 + 1.0) * 0.5 * S), 0, S - 1).astype(np.int64)
    return cube[face, j, i]


def cubemap_lookup_bilinear(cube, directions, backend: str = "numpy") -> np.ndarray:
    """Seamless bilinear lookup of a cube map in directions ``d``.

    §7.1, Herbert et al.; the shading of §5.1 reads the prefiltered maps (E_x) with such lookups.

    Texels are point samples at their centres; a tap beyond a face edge is taken from the
    neighbouring face (re-projected), so lookups are continuous across edges.

    Parameters
    ----------
    cube : ndarray, shape (6, S, S, C)
    directions : array_like, shape (..., 3)
        Directions (need not be unit).
    backend : {"numpy", "numba"}

    Returns
    -------
    ndarray, shape (..., C)

    Examples
    --------
    >>> cube = np.arange(6.0).reshape(6, 1, 1, 1) * np.ones((6, 2, 2, 1))
    >>> cubemap_lookup_bilinear(cube, [[0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
    array([[4.],
           [3.]])
    """
    cube = np.asarray(cube)
    require(
        cube.ndim == 4 and cube.shape[0] == 6 and cube.shape[1] == cube.shape[2],
        f"cube map: expected shape (6, S, S, C), got {cube.shape}",
    )
    require_choice(backend, ("numpy", "numba"), "cube-map backend")
    d = np.asarray(directions, dtype=np.float64)
    shape = d.shape[:-1]
    d = d.reshape(-1, 3)
    S = cube.shape[1]
    if backend == "numba":
        out = np.empty((d.shape[0], cube.shape[3]))
        _k.cubemap_lookup_kernel(np.ascontiguousarray(cube, dtype=np.float64), d, out)
        return out.reshape(*shape, -1)
    face, s, t = _direction_faces(d)
    x = (s + 1.0) * 0.5 * S - 0.5
    y = (t + 1.0) * 0.5 * S - 0.5
    x0 = np.floor(x).astype(np.int64)
    y0 = np.floor(y).astype(np.int64)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    out = (
        _fetch(cube, face, x0, y0) * (1 - fx) * (1 - fy)
        + _fetch(cube, face, x0 + 1, y0) * fx * (1 - fy)
        + _fetch(cube, face, x0, y0 + 1) * (1 - fx) * fy
        + _fetch(cube, face, x0 + 1, y0 + 1) * fx * fy
    )
    return out.reshape(*shape, -1)


@functools.lru_cache(maxsize=8)
def _latlong_taps(
    height: int, width: int, size: int, dtype: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Bilinear taps (flat pixel indices), weights and output texels of a cube map's texel centres.

    The sampling pattern depends only on the sizes, so it is computed once
    (``reference.geometry.envmap`` lookup rules: u wraps, v clamps at the poles). Rows are sorted by
    their first tap, so that :func:`gather_bilinear` reads the lat-long map in memory order;
    ``texel`` (N,) is the flat (face, row, column) index each row writes. Shapes (N, 4), (N, 4),
    (N,); weights in ``dtype``.
    """
    d = cubemap_texel_directions(size).reshape(-1, 3)
    u, v = direction_to_latlong_uv(d)
    x = u * width - 0.5
    y = np.clip(v * height - 0.5, 0.0, height - 1.0)
    x0 = np.floor(x).astype(np.int64)
    y0 = np.minimum(np.floor(y).astype(np.int64), height - 1)
    fx, fy = x - x0, y - y0
    x1, y1 = (x0 + 1) % width, np.minimum(y0 + 1, height - 1)
    x0 = x0 % width
    taps = np.stack([y0 * width + x0, y0 * width + x1, y1 * width + x0, y1 * width + x1], -1)
    weights = np.stack([(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy], -1)
    texel = np.argsort(taps[:, 0], kind="stable")
    taps, weights = np.ascontiguousarray(taps[texel]), np.ascontiguousarray(weights[texel], dtype)
    for array in (taps, weights, texel):
        array.setflags(write=False)
    return taps, weights, texel


def gather_bilinear(image, taps, weights, texel=None, out=None) -> np.ndarray:
    """Weighted sum of four taps per output: ``out[texel[j]] = Σ_k w[j, k] image[taps[j, k]]``.

    The data movement of §7.1, Herbert et al. (bilinear filtering at memory bandwidth), as used by
    :func:`latlong_to_cubemap`; the numba twin streams all channels of a texel together.

    Parameters
    ----------
    image : ndarray, shape (P, C)
        Flattened pixels.
    taps : ndarray of int, shape (N, 4)
        Flat pixel indices.
    weights : ndarray, shape (N, 4)
        Bilinear weights.
    texel : ndarray of int, shape (N,), optional
        The output row of each tap row, a permutation of ``range(N)`` (default: the identity), so
        that the rows can be sorted for the order in which they read ``image``.
    out : ndarray, shape (M, C), optional
        Write ``out[texel[j]]`` here instead (a subset of the texels: a row block's).

    Returns
    -------
    ndarray, shape (N, C), the dtype of ``image`` (``out`` when given)

    Examples
    --------
    >>> gather_bilinear(np.array([[0.0], [2.0]]), np.array([[0, 1, 0, 1]]), np.full((1, 4), 0.25))
    array([[1.]])
    >>> taps, w = np.array([[0] * 4, [1] * 4]), np.full((2, 4), 0.25)
    >>> gather_bilinear(np.array([[0.0], [2.0]]), taps, w, texel=np.array([1, 0]))
    array([[2.],
           [0.]])
    """
    gathered = np.zeros((taps.shape[0], image.shape[1]), dtype=np.result_type(image, weights))
    for k in range(4):
        gathered += weights[:, k, None] * image[taps[:, k]]
    if out is not None:
        out[np.arange(taps.shape[0]) if texel is None else texel] = gathered
        return out
    if texel is None:
        return gathered.astype(image.dtype)
    out = np.empty_like(gathered, dtype=image.dtype)
    out[texel] = gathered
    return out


def latlong_to_cubemap(image, size: int = 64, backend: str = "numba", out=None) -> np.ndarray:
    """Resample a lat-long map onto a cube map by bilinear lookups at the texel centres.

    §7.1, Herbert et al. (fast environment transforms); lat-long convention of
    ``reference.geometry.envmap``. The tap pattern is cached per size; the numba kernel then streams
    the channels of each texel, keeping the input dtype (float32 stays float32).

    Parameters
    ----------
    image : array_like, shape (H, W, C)
        A 2:1 lat-long map.
    size : int
        Face size S.
    backend : {"numba", "numpy"}
    out : ndarray, shape (6, S, S, C), optional
        Output buffer of the input's dtype (reused across calls; numba backend).

    Returns
    -------
    ndarray, shape (6, S, S, C)

    Examples
    --------
    >>> cube = latlong_to_cubemap(np.ones((4, 8, 2), np.float32), 2)
    >>> cube.shape, cube.dtype, float(cube.min())
    ((6, 2, 2, 2), dtype('float32'), 1.0)
    """
    image = np.asarray(image)
    require(image.ndim == 3, f"latlong_to_cubemap: expected (H, W, C), got {image.shape}")
    check_latlong_shape(image.shape, "latlong_to_cubemap")
    size = require_positive_int(size, "cube map size", 16384)
    require_choice(backend, ("numba", "numpy"), "cube-map backend")
    if image.dtype not in (np.float32, np.float64):
        image = image.astype(np.float64)
    H, W, C = image.shape
    taps, weights, texel = _latlong_taps(H, W, size, image.dtype.str)
    flat = np.ascontiguousarray(image).reshape(H * W, C)
    if backend == "numpy":
        return gather_bilinear(flat, taps, weights, texel).reshape(6, size, size, C)
    if out is None:
        out = np.empty((6, size, size, C), dtype=image.dtype)
    require(
        out.shape == (6, size, size, C) and out.dtype == image.dtype and out.flags.c_contiguous,
        f"latlong_to_cubemap: out must be a C-contiguous {image.dtype} array (6, {size}, {size}, "
        f"{C}), got {out.dtype} {out.shape}",
    )
    inputs = (kernel_input(x, None) for x in (flat, taps, weights, texel))
    _k.gather_bilinear_kernel(*inputs, out.reshape(-1, C))
    return out


def latlong_blocks_to_cubemap(
    blocks: Iterable[tuple[int, np.ndarray]], height: int, size: int = 64, backend: str = "numba"
) -> np.ndarray:
    """:func:`latlong_to_cubemap` of a lat-long map given as row blocks, block by block.

    §7.1, Herbert et al. Each texel's four bilinear taps lie on two adjacent rows ``y0`` and
    ``y0 + 1`` (:func:`_latlong_taps`, sorted by ``y0``), so the texels whose rows both lie in a
    block are gathered from that block, and those on the seam between two blocks from the last
    row of one and the first row of the next. Every texel gets the same four products in the same
    order as in memory: the result is bit-identical to :func:`latlong_to_cubemap` of the whole map,
    with one block (and one saved row) in memory.

    Parameters
    ----------
    blocks : iterable of (first_row, ndarray (rows, W, C))
        Consecutive row blocks, in row order, covering the ``height`` rows once; the first
        block's dtype (float32 or float64) is kept.
    height : int
        The whole map's height H (``W = 2H``).
    size : int
        Face size S.
    backend : {"numba", "numpy"}

    Returns
    -------
    ndarray, shape (6, S, S, C)

    Examples
    --------
    >>> image = np.random.default_rng(2).random((8, 16, 3))
    >>> blocks = [(0, image[:3]), (3, image[3:4]), (4, image[4:])]
    >>> streamed = latlong_blocks_to_cubemap(blocks, 8, 4)
    >>> bool((streamed == latlong_to_cubemap(image, 4)).all())
    True
    """
    size = require_positive_int(size, "cube map size", 16384)
    require_choice(backend, ("numba", "numpy"), "cube-map backend")
    out, seam, row = None, None, 0

    def gather(pixels, first_row, y0_from, y0_to):
        # texels with y0 in [y0_from, y0_to), read from ``pixels`` (rows from first_row on)
        lo, hi = np.searchsorted(taps[:, 0], [y0_from * W, y0_to * W])
        local = taps[lo:hi] - first_row * W
        flat = np.ascontiguousarray(pixels).reshape(-1, C)
        if backend == "numpy":
            gather_bilinear(flat, local, weights[lo:hi], texel[lo:hi], out=out)
        else:
            inputs = (kernel_input(x, None) for x in (flat, local, weights[lo:hi], texel[lo:hi]))
            _k.gather_bilinear_kernel(*inputs, out)

    for start, block in blocks:
        block = np.asarray(block)
        if out is None:
            require(block.ndim == 3, f"latlong_blocks_to_cubemap: a block of shape {block.shape}")
            W, C = block.shape[1:]
            check_latlong_shape((height, W, C), "latlong_blocks_to_cubemap")
            dtype = block.dtype if block.dtype in (np.float32, np.float64) else np.float64
            taps, weights, texel = _latlong_taps(height, W, size, np.dtype(dtype).str)
            out = np.empty((6 * size * size, C), dtype=dtype)
        block = np.asarray(block, dtype=dtype)
        stop = start + block.shape[0]
        require(
            start == row and block.shape[1:] == (W, C) and stop <= height,
            f"latlong_blocks_to_cubemap: block at row {start} of shape {block.shape}; expected "
            f"the rows from {row} on of a ({height}, {W}, {C}) map, in order",
        )
        if seam is not None:  # texels on rows start − 1 and start
            gather(np.concatenate([seam, block[:1]]), start - 1, start - 1, start)
        last = stop == height  # on the last row, y0 + 1 clamps to y0
        gather(block, start, start, stop if last else stop - 1)
        seam, row = block[-1:].copy(), stop
    require(row == height and out is not None, f"latlong_blocks_to_cubemap: {row} of {height} rows")
    return out.reshape(6, size, size, C)


def cubemap_to_latlong(cube, height: int, backend: str = "numpy") -> np.ndarray:
    """Resample a cube map onto an ``height × 2·height`` lat-long map (seamless bilinear).

    §7.1, Herbert et al.

    Examples
    --------
    >>> cubemap_to_latlong(np.ones((6, 4, 4, 1)), 2).shape
    (2, 4, 1)
    """
    height = require_positive_int(height, "lat-long height", 16384)
    d = latlong_pixel_directions(height, 2 * height)
    return cubemap_lookup_bilinear(cube, d, backend)


#: Cube-map transforms: NumPy references and their numba kernels.
CUBEMAP_METHODS = Registry("cube-map transform")
CUBEMAP_METHODS.register(
    Method(
        "gather_bilinear",
        gather_bilinear,
        _k.gather_bilinear_kernel,
        "§7.1, Herbert et al. (environment transforms)",
        lambda rng: (
            rng.random((50, 3)),
            rng.integers(0, 50, (20, 4)),
            rng.random((20, 4)),
            rng.permutation(20),
        ),
    )
)
CUBEMAP_METHODS.register(
    Method(
        "cubemap_lookup_bilinear",
        cubemap_lookup_bilinear,
        _k.cubemap_lookup_kernel,
        "§7.1, Herbert et al. (environment transforms)",
        lambda rng: (rng.random((6, 4, 4, 2)), rng.normal(size=(50, 3))),
    )
)

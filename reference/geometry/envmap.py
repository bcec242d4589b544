"""Lat-long environment maps: the direction convention, pixel centres, solid angles and lookups.

specref follows Mitsuba 3's axes for lat-long (equirectangular) maps, with y up:

- ``u = atan2(d.x, -d.z) / 2π`` wrapped to [0, 1), ``v = acos(d.y) / π``;
- so −z is at the left/right seam (u = 0), +x at u = 1/4, +z at the image centre (u = 1/2), −x at u
= 3/4,
  and +y is the top row (v = 0);
- the inverse is ``d = (sin θ sin φ, cos θ, −sin θ cos φ)`` with ``φ = 2πu``, ``θ = πv``.

Pixel ``(j, i)`` (row j, column i) of an ``H × W`` map has its centre at ``u = (i + ½)/W``,
``v = (j + ½)/H``. The row centres ``θ_j = (j + ½)π/H`` are the nodes of Fejér's first quadrature
rule, which the SH engine relies on. Mitsuba 3 itself puts row centres at ``v = j/(H − 1)`` (row 0
on the pole), which differs by up to half a row near the poles (0.18° for 1024×512); see
``docs/conventions.md``. :data:`TEXEL_PLACEMENTS` lets a map be read under Mitsuba's placement
(``"mitsuba"``, for like-for-like comparisons with it; the default is specref's ``"centred"``):
:func:`latlong_rows_mitsuba_to_centred` resamples it onto specref's rows. OpenEXR's
``envmap = LATLONG`` attribute uses the same orientation as Mitsuba 3.

References
----------
- W. Jakob et al., Mitsuba 3 renderer, ``src/emitters/envmap.cpp`` (2022).
- L. Fejér, "Mechanische Quadraturen mit positiven Cotesschen Zahlen", Math. Z. 37, 1933.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.errors import require
from reference.registry import Method, Registry

__all__ = [
    "DEFAULT_TEXEL_PLACEMENT",
    "TEXEL_PLACEMENTS",
    "check_latlong_shape",
    "direction_to_latlong_uv",
    "latlong_lookup_bilinear",
    "latlong_lookup_trilinear",
    "latlong_mip_pyramid",
    "latlong_pixel_directions",
    "latlong_pixel_solid_angles",
    "latlong_rows_centred",
    "latlong_rows_mitsuba_to_centred",
    "latlong_uv_to_direction",
]


def direction_to_latlong_uv(d) -> tuple[np.ndarray, np.ndarray]:
    """Lat-long texture coordinates of unit directions (Mitsuba 3 convention).

    Parameters
    ----------
    d : array_like, shape (..., 3)
        Unit directions, y up.

    Returns
    -------
    u : ndarray, shape (...,)
        ``atan2(d.x, -d.z) / 2π`` wrapped to [0, 1).
    v : ndarray, shape (...,)
        ``acos(d.y) / π`` in [0, 1].

    Examples
    --------
    >>> u, v = direction_to_latlong_uv([[0, 0, -1], [1, 0, 0], [0, 0, 1], [0, 1, 0]])
    >>> u, v
    (array([0.  , 0.25, 0.5 , 0.  ]), array([0.5, 0.5, 0.5, 0. ]))
    """
    d = np.asarray(d, dtype=np.float64)
    u = np.arctan2(d[..., 0], -d[..., 2]) / (2.0 * np.pi)
    u = np.where(u < 0.0, u + 1.0, u)
    u = np.where(u >= 1.0, 0.0, u)
    v = np.arccos(np.clip(d[..., 1], -1.0, 1.0)) / np.pi
    return u, v


def latlong_uv_to_direction(u, v) -> np.ndarray:
    """Unit directions of lat-long texture coordinates (inverse of :func:`direction_to_latlong_uv`).

    Parameters
    ----------
    u, v : array_like
        Texture coordinates in [0, 1].

    Returns
    -------
    ndarray, shape (..., 3)
        ``(sin θ sin φ, cos θ, −sin θ cos φ)`` with ``φ = 2πu``, ``θ = πv``.

    Examples
    --------
    >>> latlong_uv_to_direction([0.5, 0.25], [0.5, 0.5]).round(12)
    array([[ 0.,  0.,  1.],
           [ 1.,  0., -0.]])
    """
    u, v = np.broadcast_arrays(np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64))
    phi = 2.0 * np.pi * u
    theta = np.pi * v
    s = np.sin(theta)
    return np.stack([s * np.sin(phi), np.cos(theta), -s * np.cos(phi)], axis=-1)


def check_latlong_shape(shape, where: str = "environment map") -> None:
    """Refuse images that are not 2:1 lat-long maps.

    Raises
    ------
    SpecrefError
        When the width is not twice the height.

    Examples
    --------
    >>> check_latlong_shape((512, 1024, 3))
    >>> check_latlong_shape((512, 512, 3), "sky.hdr")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: sky.hdr: a lat-long map must be 2:1 (width = 2 × height), got
    512×512
    """
    require(len(shape) >= 2, f"{where}: expected an image, got shape {tuple(shape)}")
    H, W = shape[0], shape[1]
    require(
        H >= 1 and W == 2 * H,
        f"{where}: a lat-long map must be 2:1 (width = 2 × height), got {W}×{H}",
    )


def latlong_pixel_directions(height: int, width: int) -> np.ndarray:
    """Directions of the pixel centres of an ``height × width`` lat-long map.

    Parameters
    ----------
    height, width : int
        Map size.

    Returns
    -------
    ndarray, shape (height, width, 3)
        Directions at ``u = (i + ½)/W``, ``v = (j + ½)/H``.

    Examples
    --------
    >>> d = latlong_pixel_directions(2, 4)
    >>> d.shape, bool(np.allclose(np.linalg.norm(d, axis=-1), 1))
    ((2, 4, 3), True)
    """
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(height) + 0.5) / height
    return latlong_uv_to_direction(u[None, :], v[:, None])


def latlong_pixel_solid_angles(height: int, width: int) -> np.ndarray:
    """Exact solid angle of each pixel of a lat-long map, sr: ``(2π/W)(cos θ_top − cos θ_bottom)``.

    Returns
    -------
    ndarray, shape (height, width)
        Sums to 4π.

    Examples
    --------
    >>> float(latlong_pixel_solid_angles(64, 128).sum() / (4 * np.pi)).__round__(12)
    1.0
    """
    edges = np.pi * np.arange(height + 1) / height
    band = np.cos(edges[:-1]) - np.cos(edges[1:])
    return np.broadcast_to((2.0 * np.pi / width) * band[:, None], (height, width)).copy()


def latlong_lookup_bilinear(image, d) -> np.ndarray:
    """Bilinearly filtered values of a lat-long map in directions ``d``.

    Texels are point samples at their centres; u wraps around the seam, v clamps at the poles.

    Parameters
    ----------
    image : ndarray, shape (H, W, C)
        The map.
    d : array_like, shape (..., 3)
        Unit directions.

    Returns
    -------
    ndarray, shape (..., C)

    Examples
    --------
    >>> image = np.arange(8.0).reshape(2, 4, 1)
    >>> latlong_lookup_bilinear(image, [[0.0, 0.0, 1.0]]).round(6)
    array([[3.5]])
    """
    image = np.asarray(image, dtype=np.float64)
    H, W = image.shape[:2]
    u, v = direction_to_latlong_uv(d)
    x = u * W - 0.5
    y = np.clip(v * H - 0.5, 0.0, H - 1.0)
    x0 = np.floor(x).astype(np.int64)
    y0 = np.minimum(np.floor(y).astype(np.int64), H - 1)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    x1, y1 = (x0 + 1) % W, np.minimum(y0 + 1, H - 1)
    x0 = x0 % W
    top = image[y0, x0] * (1 - fx) + image[y0, x1] * fx
    bottom = image[y1, x0] * (1 - fx) + image[y1, x1] * fx
    return top * (1 - fy) + bottom * fy


def latlong_mip_pyramid(image) -> list[np.ndarray]:
    """The lat-long map and its successive 2 × 2 reductions, each texel the solid-angle mean.

    Level ``k + 1`` averages the 2 × 2 texels of level ``k`` weighted by their exact solid angles
    (:func:`latlong_pixel_solid_angles`), so every level keeps the map's integral over the sphere.
    The pyramid stops at a level whose height is odd (or 1); a 2:1 map of ``2^m`` rows goes down
    to 1 × 2 texels. Filtered importance sampling reads it (Colbert & Křivánek 2007, GPU Gems 3,
    ch. 20).

    Parameters
    ----------
    image : array_like, shape (H, W, C)
        Lat-long map (W = 2H).

    Returns
    -------
    list of ndarray
        Level 0 (the map, float64) first; level k of shape (H / 2^k, W / 2^k, C).

    Examples
    --------
    >>> levels = latlong_mip_pyramid(np.ones((8, 16, 2)))
    >>> [lv.shape[:2] for lv in levels], bool(np.allclose(levels[-1], 1.0))
    ([(8, 16), (4, 8), (2, 4), (1, 2)], True)
    """
    levels = [np.asarray(image, dtype=np.float64)]
    check_latlong_shape(levels[0].shape, "mip pyramid")
    while levels[-1].shape[0] > 1 and levels[-1].shape[0] % 2 == 0:
        top = levels[-1]
        H, W, C = top.shape
        omega = latlong_pixel_solid_angles(H, W)[..., None]
        # Σ Ω L / Σ Ω over each 2 × 2 block
        weighted = (top * omega).reshape(H // 2, 2, W // 2, 2, C).sum(axis=(1, 3))
        total = omega.reshape(H // 2, 2, W // 2, 2, 1).sum(axis=(1, 3))
        levels.append(weighted / total)
    return levels


def latlong_lookup_trilinear(levels, d, level) -> np.ndarray:
    """Look-ups of a mip pyramid between levels: bilinear in each, linear across (GPU trilinear).

    Parameters
    ----------
    levels : list of ndarray
        From :func:`latlong_mip_pyramid`.
    d : array_like, shape (..., 3)
        Unit directions, y up.
    level : array_like, shape (...,)
        Fractional levels, clamped to ``[0, len(levels) − 1]``.

    Returns
    -------
    ndarray, shape (..., C)

    Examples
    --------
    >>> levels = latlong_mip_pyramid(np.arange(32.0).reshape(4, 8, 1))
    >>> up = [[0.0, 1.0, 0.0]]
    >>> bool(np.allclose(latlong_lookup_trilinear(levels, up, [0.0]),
    ...                  latlong_lookup_bilinear(levels[0], up)))
    True
    >>> a, b = (latlong_lookup_bilinear(levels[k], up) for k in (1, 2))
    >>> bool(np.allclose(latlong_lookup_trilinear(levels, up, [1.25]), 0.75 * a + 0.25 * b))
    True
    """
    d = np.asarray(d, dtype=np.float64)
    level = np.clip(np.asarray(level, dtype=np.float64), 0.0, len(levels) - 1.0)
    lo = np.minimum(np.floor(level).astype(np.int64), len(levels) - 1)
    t = (level - lo)[..., None]
    out = np.zeros((*d.shape[:-1], levels[0].shape[-1]))
    for k in np.unique(lo):
        at = lo == k
        above = levels[min(k + 1, len(levels) - 1)]
        out[at] = (1.0 - t[at]) * latlong_lookup_bilinear(levels[k], d[at]) + t[
            at
        ] * latlong_lookup_bilinear(above, d[at])
    return out


def latlong_rows_centred(image) -> np.ndarray:
    """Specref's own texel placement: rows at ``v = (j + ½)/H`` already; the map unchanged.

    Fejér's first rule (module docstring): row j is the sample at ``θ_j = (j + ½)π/H``.

    Examples
    --------
    >>> latlong_rows_centred(np.ones((2, 4, 1))).shape
    (2, 4, 1)
    """
    return np.asarray(image, dtype=np.float64)


def latlong_rows_mitsuba_to_centred(image) -> np.ndarray:
    """A map whose rows sit at Mitsuba 3's ``v = j/(H − 1)``, averaged onto specref's rows.

    Mitsuba 3 (``src/emitters/envmap.cpp``, ``eval_spectrum``) reads texel ``(j, i)`` of an
    ``H × W`` map as the sample at ``u = (i + ½)/W``, ``v = j/(H − 1)`` (rows on the poles) and
    interpolates linearly between rows and columns. Columns already agree with specref's. Row j of
    specref spans ``v ∈ [j/H, (j + 1)/H]``, Mitsuba row coordinates ``y ∈ [j, j + 1](H − 1)/H``;
    it receives the mean of Mitsuba's piecewise-linear radiance over that span (its exact integral,
    divided by the span), so a light one texel wide keeps its power: a point sample at the row
    centre would alias it by up to ±2/H. A map linear in v is reproduced exactly. (Mitsuba
    interpolates the upsampled spectrum's shape and its scale separately and multiplies them;
    applied after upsampling, this interpolates their product, erratum E81.)

    Parameters
    ----------
    image : array_like, shape (H, W, C)
        The map as Mitsuba 3 reads it, H >= 2.

    Returns
    -------
    ndarray, shape (H, W, C)
        Its radiance averaged over specref's rows.

    Examples
    --------
    >>> ramp = np.arange(4.0)[:, None, None] * np.ones((4, 8, 1))   # row j holds j: linear in v
    >>> latlong_rows_mitsuba_to_centred(ramp)[:, 0, 0]              # (j + 1/2)(H - 1)/H
    array([0.375, 1.125, 1.875, 2.625])
    >>> spike = np.zeros((4, 8, 1)); spike[1] = 1.0                 # one bright row
    >>> float(latlong_rows_mitsuba_to_centred(spike)[:, 0, 0].sum() / 4 * 3)   # power kept
    1.0
    """
    image = np.asarray(image, dtype=np.float64)
    H = image.shape[0]
    require(H >= 2, f"Mitsuba texel placement: needs at least 2 rows, got {H}")
    # Integral F(y) of the piecewise-linear rows: trapezoids between integer nodes
    F_nodes = np.concatenate(
        [np.zeros_like(image[:1]), np.cumsum(0.5 * (image[1:] + image[:-1]), axis=0)]
    )

    def F(y):
        n = np.minimum(np.floor(y).astype(np.int64), H - 2)
        t = (y - n).reshape(-1, *([1] * (image.ndim - 1)))
        return F_nodes[n] + image[n] * t + 0.5 * (image[n + 1] - image[n]) * t * t

    # Specref row j spans y in [j, j + 1] (H - 1)/H: mean of Mitsuba's radiance over it
    edges = np.arange(H + 1) * (H - 1) / H
    F_edges = F(edges)
    return (F_edges[1:] - F_edges[:-1]) / ((H - 1) / H)


#: The default texel placement of lat-long maps: specref's pixel-centred rows.
DEFAULT_TEXEL_PLACEMENT = "centred"


@dataclass(frozen=True, kw_only=True)
class TexelPlacement(Method):
    """A lat-long texel placement: where row j and column i of a map look, as render metadata says.

    Parameters
    ----------
    rows, columns : str
        The texel centres, ``"v = (j + 1/2)/H"``, ``"u = (i + 1/2)/W"``.
    """

    rows: str
    columns: str


#: Lat-long texel placements (scene key ``texel_placement`` of environment lights, ``specref render
#: --texel-placement``): each entry turns a map read under that placement into specref's rows.
TEXEL_PLACEMENTS = Registry("texel placement", TexelPlacement)
TEXEL_PLACEMENTS.register(
    TexelPlacement(
        "centred",
        latlong_rows_centred,
        None,
        "Fejér's first rule: rows at v = (j + 1/2)/H",
        rows="v = (j + 1/2)/H",
        columns="u = (i + 1/2)/W",
    )
)
TEXEL_PLACEMENTS.register(
    TexelPlacement(
        "mitsuba",
        latlong_rows_mitsuba_to_centred,
        None,
        "Mitsuba 3, src/emitters/envmap.cpp: rows at v = j/(H - 1)",
        rows="v = j/(H - 1)",
        columns="u = (i + 1/2)/W",
    )
)

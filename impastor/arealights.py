"""Area lights as images: the booth-ceiling plane and the light-plane lookup.

ImpastoR (Ferwerda 2015, §3.2 and §3.5) captures each light of its viewing booth as a
high-dynamic-range image mapped onto the booth ceiling, a rectangle (:class:`PlaneLight`). Its
point lights (median cut, variance minimization) and their diffuse illuminance, Eqs. (2)-(3),
Ferwerda, are ``impastor.point_lights``; the light-plane lookup of Eqs. (5)-(8), Ferwerda, that
specular lighting uses is here.

Plane lights (Fig. 7, Ferwerda). The rectangle has its top-left corner ``o_TL``, unit directions
``A`` (left to right) and ``B`` (top to bottom), and physical sizes ``l_A``, ``l_B`` (m). Pixel
``(j, i)`` of an ``H × W`` image is centred at ``o_TL + (i + ½)/W·l_A A + (j + ½)/H·l_B B``; every
pixel has area ``A/P = l_A l_B / (H W)``. The light emits from the side of ``n_light = A × B``
(for a ceiling with A = +x and B = +z this is −y, downwards). Pixel values are luminance (cd/m²)
or any per-channel radiance ``(H, W, C)``; the light's spectrum is applied separately (Eq. (3),
Ferwerda).

Lat-long lights follow ``reference.geometry.envmap``'s convention (see ``impastor.point_lights``).

References
----------
- J. A. Ferwerda, "ImpastoR: A realistic surface display system", Vision Research 109, 2015.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.errors import require, require_finite, require_positive_int

__all__ = [
    "PlaneLight",
    "booth_light_image",
    "check_light_image",
    "light_plane_lookup",
    "light_plane_uv",
    "plane_image_from_latlong",
]


def check_light_image(image, where: str) -> np.ndarray:
    """A light image as ``(H, W, C)`` float64, finite and non-negative, or a one-line error.

    Parameters
    ----------
    image : array_like, shape (H, W) or (H, W, C)
        Radiance per pixel (and channel).
    where : str
        What the image is, for the error message.

    Returns
    -------
    ndarray, shape (H, W, C)

    Raises
    ------
    SpecrefError
        Not finite, not an image, empty, or a negative value (the first pixel is named).

    Examples
    --------
    >>> check_light_image(np.ones((2, 3)), "light").shape
    (2, 3, 1)
    """
    image = require_finite(image, where)
    require(
        image.ndim in (2, 3),
        f"{where}: must be an image (H, W) or (H, W, C), got shape {image.shape}",
    )
    if image.ndim == 2:
        image = image[..., None]
    require(image.shape[0] >= 1 and image.shape[1] >= 1, f"{where}: empty image")
    negative = image < 0
    if negative.any():
        j, i, c = (int(v) for v in np.argwhere(negative)[0])
        value = float(image[j, i, c])
        require(False, f"{where}: radiance must be >= 0, got {value:g} at pixel ({j}, {i})")
    return image


@dataclass(frozen=True)
class PlaneLight:
    """A rectangular area light given as an image on a plane (the booth ceiling), Fig. 7, Ferwerda.

    Parameters
    ----------
    image : array_like, shape (H, W) or (H, W, C)
        Radiance (luminance in cd/m², or per channel), >= 0; row 0 is the ``o_TL`` edge.
    origin : array_like, shape (3,)
        ``o_TL``, the top-left corner, m.
    A, B : array_like, shape (3,)
        Left-to-right and top-to-bottom directions (normalised; must be orthogonal).
    l_A, l_B : float
        Physical width and height, m.

    Examples
    --------
    >>> light = PlaneLight(np.ones((2, 4)), (0, 1, 0), (1, 0, 0), (0, 0, 1), 1.2, 0.6)
    >>> light.n_light, light.pixel_area
    (array([ 0., -1.,  0.]), 0.09)
    """

    image: np.ndarray
    origin: tuple
    A: tuple
    B: tuple
    l_A: float
    l_B: float

    def __post_init__(self):
        image = check_light_image(self.image, "plane light: image")
        object.__setattr__(self, "image", image)
        vectors = {}
        for key in ("origin", "A", "B"):
            v = require_finite(getattr(self, key), f"plane light: {key}")
            require(v.shape == (3,), f"plane light: {key}: must be 3 numbers, got shape {v.shape}")
            vectors[key] = v
        for key in ("A", "B"):
            require(np.linalg.norm(vectors[key]) > 0, f"plane light: {key}: must be non-zero")
            vectors[key] = vectors[key] / np.linalg.norm(vectors[key])
        require(
            abs(vectors["A"] @ vectors["B"]) < 1e-9,
            f"plane light: A and B must be orthogonal, got A·B = {vectors['A'] @ vectors['B']:g}",
        )
        for key in ("l_A", "l_B"):
            value = getattr(self, key)
            require(
                np.isfinite(value) and value > 0, f"plane light: {key}: must be > 0 m, got {value}"
            )
        for key, v in vectors.items():
            object.__setattr__(self, key, tuple(float(x) for x in v))

    @property
    def shape(self) -> tuple[int, int]:
        """``(H, W)`` of the image."""
        return self.image.shape[:2]

    @property
    def n_light(self) -> np.ndarray:
        """Unit normal of the emitting side, ``A × B``."""
        return np.cross(np.asarray(self.A), np.asarray(self.B))

    @property
    def pixel_area(self) -> float:
        """``A/P`` of Eq. (2), Ferwerda: light area over pixel count, m²."""
        H, W = self.shape
        return self.l_A * self.l_B / (H * W)

    def pixel_positions(self, rows=None, cols=None) -> np.ndarray:
        """World positions of pixel centres (or of fractional pixel coordinates), shape (..., 3).

        Examples
        --------
        >>> light = PlaneLight(np.ones((2, 2)), (0, 1, 0), (1, 0, 0), (0, 0, 1), 2.0, 2.0)
        >>> light.pixel_positions()[0, 0]
        array([0.5, 1. , 0.5])
        """
        H, W = self.shape
        if rows is None:
            rows, cols = np.meshgrid(np.arange(H) + 0.5, np.arange(W) + 0.5, indexing="ij")
        o, A, B = (np.asarray(v) for v in (self.origin, self.A, self.B))
        a = np.asarray(cols, dtype=np.float64) / W
        b = np.asarray(rows, dtype=np.float64) / H
        return o + (a * self.l_A)[..., None] * A + (b * self.l_B)[..., None] * B


def booth_light_image(kind: str = "fluorescent", width: int = 128, height: int = 64) -> np.ndarray:
    """A procedural booth-ceiling luminance image (cd/m²): the built-in stand-in for a capture.

    ``"fluorescent"``: four diffused tubes across the ceiling (the D50/D65 sources of a GTI
    booth); ``"incandescent"``: two diffused spot lamps (source A). Both have a dim, even
    background from the diffuser panel.

    Parameters
    ----------
    kind : {"fluorescent", "incandescent"}
    width, height : int
        Image size.

    Returns
    -------
    ndarray, shape (height, width)
        Luminance, cd/m², peak about 4000.

    Examples
    --------
    >>> image = booth_light_image("fluorescent", 32, 16)
    >>> image.shape, bool(image.min() > 0)
    ((16, 32), True)
    """
    from reference.errors import require_choice

    require_choice(kind, ("fluorescent", "incandescent"), "booth light")
    width = require_positive_int(width, "booth light: width", 8192)
    height = require_positive_int(height, "booth light: height", 8192)
    x = (np.arange(width) + 0.5) / width
    y = (np.arange(height) + 0.5) / height
    X, Y = np.meshgrid(x, y)
    image = np.full((height, width), 60.0)
    if kind == "fluorescent":
        for centre in (0.2, 0.4, 0.6, 0.8):
            across = np.exp(-0.5 * ((Y - centre) / 0.035) ** 2)
            along = 1.0 / (1.0 + np.exp(-(X - 0.08) / 0.01)) / (1.0 + np.exp((X - 0.92) / 0.01))
            image += 3500.0 * across * along
    else:
        for cx in (0.3, 0.7):
            r2 = ((X - cx) / 0.09) ** 2 + ((Y - 0.5) / 0.18) ** 2
            image += 4000.0 * np.exp(-0.5 * r2)
    return image


def plane_image_from_latlong(image, plane: PlaneLight, centre=(0.0, 0.0, 0.0), supersample=4):
    """A captured room seen through a plane light: the lat-long map's radiance behind each pixel.

    specref's own bridge from an HDR panorama to ImpastoR's booth (erratum E113): each pixel of
    ``plane`` takes the mean of the map, looked up bilinearly
    (:func:`reference.geometry.envmap.latlong_lookup_bilinear`), in the directions from ``centre``
    (the canvas's centre) through ``supersample²`` points spread over the pixel. The plane then
    sends the canvas's centre exactly the map's radiance in the solid angle it covers; light from
    outside it (walls, a window to the side) is left out, and points away from the centre see the
    plane's radiance at a slightly different angle than the room's.

    Parameters
    ----------
    image : array_like, shape (H_map, W_map) or (H_map, W_map, C)
        The lat-long map (``reference.geometry.envmap``'s orientation, y up), radiance.
    plane : PlaneLight
        Its geometry (the image it holds is ignored).
    centre : (3,) array_like
        The point the room is seen from, m.
    supersample : int
        Sub-pixel points per axis.

    Returns
    -------
    ndarray, shape (H, W) or (H, W, C)
        The plane's new image at its own resolution.

    Examples
    --------
    >>> plane = PlaneLight(np.ones((2, 4)), (-0.6, 0.6, -1.0), (1, 0, 0), (0, 0, 1), 1.2, 0.8)
    >>> plane_image_from_latlong(np.full((8, 16), 5.0), plane).round(12)
    array([[5., 5., 5., 5.],
           [5., 5., 5., 5.]])
    """
    from reference.geometry.envmap import latlong_lookup_bilinear

    image = check_light_image(image, "light map")
    n = require_positive_int(supersample, "supersample", 64)
    H, W = plane.shape
    offsets = (np.arange(n) + 0.5) / n
    rows = (np.arange(H)[:, None] + offsets[None]).reshape(-1)
    cols = (np.arange(W)[:, None] + offsets[None]).reshape(-1)
    R, C = np.meshgrid(rows, cols, indexing="ij")
    d = plane.pixel_positions(R, C) - np.asarray(centre, dtype=np.float64)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    L = latlong_lookup_bilinear(image, d)  # (H n, W n, C)
    L = L.reshape(H, n, W, n, -1).mean(axis=(1, 3))
    return L[..., 0] if L.shape[-1] == 1 else L


# --- the light-plane lookup: where a direction meets the light plane ----------------------------


def light_plane_uv(light: PlaneLight, points, directions):
    """Texture coordinates ``(a, b)`` where rays from surface points meet the light plane.

    Eq. (5), Ferwerda: ``d = ((o_TL − p_surf)·n_light) / (i_world·n_light)``;
    Eq. (6), Ferwerda: ``p_light = d i_world + p_surf``;
    Eq. (7), Ferwerda: ``p_relative = p_light − o_TL``;
    Eq. (8), Ferwerda: ``(a, b) = pinv([l_A A, l_B B]) p_relative``.

    Parameters
    ----------
    light : PlaneLight
    points : array_like, shape (..., 3)
        ``p_surf``, m.
    directions : array_like, shape (..., 3)
        Unit ``i_world`` (towards the light).

    Returns
    -------
    a, b : ndarray, shape (...,)
        Unit pixel coordinates, inside the light where both are in [0, 1].
    d : ndarray, shape (...,)
        Ray distance, m; ``inf`` where the ray runs parallel to, or away from, the plane, or hits
        its back.

    Examples
    --------
    >>> plane = PlaneLight(np.ones((2, 2)), (-1, 1, -1), (1, 0, 0), (0, 0, 1), 2.0, 2.0)
    >>> a, b, d = light_plane_uv(plane, [0.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    >>> float(a), float(b), float(d)
    (0.5, 0.5, 1.0)
    """
    p = np.asarray(points, dtype=np.float64)
    i = np.asarray(directions, dtype=np.float64)
    o, A, B = (np.asarray(v) for v in (light.origin, light.A, light.B))
    n = light.n_light
    denom = i @ n
    with np.errstate(divide="ignore", invalid="ignore"):
        # Eq. (5), Ferwerda: distance along i_world to the plane
        d = ((o - p) @ n) / denom
    # Only the emitting side counts: the ray must travel against n_light (denom < 0).
    d = np.where((denom < -1e-15) & (d > 0), d, np.inf)
    # Eq. (6), Ferwerda: p_light = d i_world + p_surf
    hit = np.isfinite(d)[..., None]
    p_light = np.where(hit, np.where(hit, d[..., None], 0.0) * i + p, np.nan)
    # Eq. (7), Ferwerda: p_relative = p_light − o_TL
    p_relative = p_light - o
    # Eq. (8), Ferwerda: (a, b) = pinv([l_A A  l_B B]) p_relative
    basis = np.stack([light.l_A * A, light.l_B * B], axis=1)  # (3, 2)
    ab = p_relative @ np.linalg.pinv(basis).T
    return ab[..., 0], ab[..., 1], d


def light_plane_lookup(light: PlaneLight, points, directions) -> np.ndarray:
    """Radiance of the light plane seen along rays (nearest pixel; 0 off the rectangle).

    Eqs. (5)-(8), Ferwerda, then a texel fetch.

    Returns
    -------
    ndarray, shape (..., C)

    Examples
    --------
    >>> plane = PlaneLight(np.arange(4.0).reshape(2, 2), (-1, 1, -1), (1, 0, 0), (0, 0, 1), 2, 2)
    >>> light_plane_lookup(plane, [[0.0, 0.0, 0.0]], [[0.6, 0.8, 0.6]])
    array([[3.]])
    """
    directions = np.asarray(directions, dtype=np.float64)
    directions = directions / np.linalg.norm(directions, axis=-1, keepdims=True)
    a, b, d = light_plane_uv(light, points, directions)
    H, W = light.shape
    inside = np.isfinite(d) & (a >= 0) & (a < 1) & (b >= 0) & (b < 1)
    col = np.clip(np.floor(np.where(inside, a, 0) * W).astype(np.int64), 0, W - 1)
    row = np.clip(np.floor(np.where(inside, b, 0) * H).astype(np.int64), 0, H - 1)
    return np.where(inside[..., None], light.image[row, col], 0.0)

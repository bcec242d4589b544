"""Point lights from area lights: median cut, variance minimization, Eqs. (2)-(3), Ferwerda.

ImpastoR (Ferwerda 2015, §3.5.1) renders diffuse reflection from 32 point lights that the
median-cut algorithm places on the booth-ceiling light image (``impastor.arealights``).

Point lights. A *partition* splits the image into N axis-aligned regions with summed-area tables
(:data:`LIGHT_SAMPLING_METHODS`): Debevec's median cut, which halves the energy across the longer
side, and Viriyothai & Debevec's variance minimization, which picks the cut (either axis) that
minimises the summed energy-weighted spatial variance of the two halves. Each region becomes one
light at its energy centroid carrying the region's summed radiance, so the lights' total equals
the image's total exactly (power conservation).

Lat-long lights follow ``reference.geometry.envmap``'s convention; their point lights are
directional and carry ``Σ L dω`` per channel (irradiance at normal incidence).

References
----------
- J. A. Ferwerda, "ImpastoR: A realistic surface display system", Vision Research 109, 2015.
- P. Debevec, "A median cut algorithm for light probe sampling", SIGGRAPH 2005 poster.
- K. Viriyothai, P. Debevec, "Variance minimization light probe sampling", SIGGRAPH 2009 poster.
- F. C. Crow, "Summed-area tables for texture mapping", SIGGRAPH 1984.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from impastor.arealights import PlaneLight, check_light_image
from reference.errors import require, require_positive_int
from reference.geometry.envmap import check_latlong_shape, latlong_pixel_directions
from reference.registry import Method, Registry

__all__ = [
    "LIGHT_SAMPLING_METHODS",
    "PointLights",
    "diffuse_radiance",
    "illuminance_point_lights",
    "median_cut",
    "point_lights_every_pixel",
    "point_lights_from_latlong",
    "point_lights_from_plane",
    "region_sums",
    "summed_area_table",
    "variance_minimization",
]


# --- summed-area tables and partitions ---------------------------------------------------------


def summed_area_table(image) -> np.ndarray:
    """Summed-area table with a zero first row and column (Crow 1984).

    ``T[j, i] = Σ_{y<j, x<i} image[y, x]``, so a region ``[y0, y1) × [x0, x1)`` sums to
    ``T[y1, x1] − T[y0, x1] − T[y1, x0] + T[y0, x0]``.

    Parameters
    ----------
    image : array_like, shape (H, W, ...)

    Returns
    -------
    ndarray, shape (H + 1, W + 1, ...)

    Examples
    --------
    >>> T = summed_area_table(np.arange(6.0).reshape(2, 3))
    >>> float(T[2, 3]), float(T[1, 2])
    (15.0, 1.0)
    """
    image = np.asarray(image, dtype=np.float64)
    T = np.zeros((image.shape[0] + 1, image.shape[1] + 1, *image.shape[2:]))
    T[1:, 1:] = image.cumsum(axis=0).cumsum(axis=1)
    return T


def _box(T, y0, y1, x0, x1):
    return T[y1, x1] - T[y0, x1] - T[y1, x0] + T[y0, x0]


def region_sums(image, regions) -> np.ndarray:
    """Sums of ``image`` over regions ``(y0, y1, x0, x1)`` (half-open pixel ranges).

    Examples
    --------
    >>> region_sums(np.ones((4, 4)), [(0, 2, 0, 4), (2, 4, 0, 4)])
    array([8., 8.])
    """
    T = summed_area_table(image)
    return np.array([_box(T, *r) for r in regions])


def _coordinates(shape, pixel_width, pixel_height, row_scale):
    """Physical coordinates of pixel centres: x along columns (scaled per row), y along rows."""
    H, W = shape
    X = (np.arange(W) + 0.5)[None, :] * pixel_width * row_scale[:, None]
    Y = np.broadcast_to((np.arange(H) + 0.5)[:, None] * pixel_height, (H, W))
    return X, Y


def _split_levels(n_lights: int):
    """Region splits per level: full doubling while it fits, then the remainder (largest first)."""
    levels = []
    count = 1
    while count * 2 <= n_lights:
        levels.append(count)
        count *= 2
    if count < n_lights:
        levels.append(n_lights - count)
    return levels


def _partition(energy, n_lights, sizes, choose_cut, priority, where):
    """Shared driver: split regions level by level with a cut chooser; see :func:`median_cut`."""
    energy = check_light_image(energy, f"{where}: energy")[..., 0]
    n_lights = require_positive_int(n_lights, f"{where}: n_lights", energy.size)
    geometry = _geometry(energy, *sizes)
    H, W = energy.shape
    X, Y = _coordinates(energy.shape, *geometry)
    tables = {
        "E": summed_area_table(energy),
        "Ex": summed_area_table(energy * X),
        "Ey": summed_area_table(energy * Y),
        "Exx": summed_area_table(energy * X * X),
        "Eyy": summed_area_table(energy * Y * Y),
    }
    regions = [(0, H, 0, W)]
    for n_split in _split_levels(n_lights):
        order = sorted(range(len(regions)), key=lambda k: -priority(tables, regions[k]))
        chosen = set(order[:n_split])
        new = []
        for k, region in enumerate(regions):
            y0, y1, x0, x1 = region
            if k in chosen and (y1 - y0 > 1 or x1 - x0 > 1):
                new.extend(choose_cut(tables, region, geometry))
            else:
                new.append(region)
        regions = new
    return regions


def _balanced(partial, total) -> int:
    """Index of the cut whose left part is nearest half the energy; ties go to the middle."""
    gap = np.abs(partial - total / 2.0)
    ties = np.flatnonzero(gap <= gap.min() + 1e-12 * max(total, 1e-300))
    return int(ties[np.argmin(np.abs(ties - (partial.size - 1) / 2.0))])


def _median_cut_split(tables, region, geometry):
    y0, y1, x0, x1 = region
    T = tables["E"]
    pixel_width, pixel_height, row_scale = geometry
    width = (x1 - x0) * pixel_width * float(row_scale[y0:y1].mean())
    height = (y1 - y0) * pixel_height
    along_x = (width >= height and x1 - x0 > 1) or y1 - y0 == 1
    total = _box(T, y0, y1, x0, x1)
    if along_x:
        # Debevec 2005: cut the longer side where the cumulative energy reaches half
        partial = np.array([_box(T, y0, y1, x0, c) for c in range(x0 + 1, x1)])
        c = x0 + 1 + _balanced(partial, total)
        return [(y0, y1, x0, c), (y0, y1, c, x1)]
    partial = np.array([_box(T, y0, r, x0, x1) for r in range(y0 + 1, y1)])
    r = y0 + 1 + _balanced(partial, total)
    return [(y0, r, x0, x1), (r, y1, x0, x1)]


def _variance(tables, region):
    """Energy-weighted spatial variance ``Σ E |p − c|²`` of a region, from the tables."""
    E = _box(tables["E"], *region)
    if E <= 0.0:
        return 0.0
    Ex, Ey = _box(tables["Ex"], *region), _box(tables["Ey"], *region)
    Exx, Eyy = _box(tables["Exx"], *region), _box(tables["Eyy"], *region)
    return float(Exx - Ex * Ex / E + Eyy - Ey * Ey / E)


def _variance_split(tables, region, geometry):
    y0, y1, x0, x1 = region
    candidates = [((y0, y1, x0, c), (y0, y1, c, x1)) for c in range(x0 + 1, x1)]
    candidates += [((y0, r, x0, x1), (r, y1, x0, x1)) for r in range(y0 + 1, y1)]
    # Viriyothai & Debevec 2009: the cut that minimises the summed variance of the two halves
    costs = [_variance(tables, a) + _variance(tables, b) for a, b in candidates]
    return list(candidates[int(np.argmin(costs))])


def _geometry(energy, pixel_width, pixel_height, row_scale):
    H = energy.shape[0]
    row_scale = np.ones(H) if row_scale is None else np.asarray(row_scale, dtype=np.float64)
    require(row_scale.shape == (H,), f"light sampling: row_scale: expected shape ({H},)")
    return float(pixel_width), float(pixel_height), row_scale


def median_cut(
    energy, n_lights: int = 32, pixel_width: float = 1.0, pixel_height: float = 1.0, row_scale=None
):
    """Debevec's median cut: split regions in two across their longer side at the energy median.

    Eq. (2), Ferwerda (the 32 "median cut lights" it sums over).

    Regions are split level by level (all regions per level, 2^k in all); when ``n_lights`` is
    not a power of two, the last level splits only the regions of highest energy.

    Parameters
    ----------
    energy : array_like, shape (H, W)
        Non-negative energy per pixel (luminance × pixel solid angle or area).
    n_lights : int
        Number of regions N >= 1.
    pixel_width, pixel_height : float
        Physical size of a pixel (for the longer-side test and the centroids).
    row_scale : array_like, shape (H,), optional
        Factor on each row's width: ``sin θ`` for lat-long maps (Debevec 2005), 1 by default.

    Returns
    -------
    list of tuple
        ``(y0, y1, x0, x1)`` half-open pixel ranges, disjoint, covering the image.

    Examples
    --------
    >>> image = np.ones((4, 8)); image[:, 6:] = 3.0
    >>> median_cut(image, 2)
    [(0, 4, 0, 6), (0, 4, 6, 8)]
    """
    sizes = (pixel_width, pixel_height, row_scale)
    energy_of = lambda tables, region: _box(tables["E"], *region)  # noqa: E731
    return _partition(energy, n_lights, sizes, _median_cut_split, energy_of, "median cut")


def variance_minimization(
    energy, n_lights: int = 32, pixel_width: float = 1.0, pixel_height: float = 1.0, row_scale=None
):
    """Viriyothai & Debevec's variance minimization: the cut minimising the halves' variance.

    Eq. (2), Ferwerda (an alternative to its median-cut lights).

    Both axes and every cut position are tried with summed-area tables of ``E``, ``E x``, ``E y``,
    ``E x²`` and ``E y²``, so each candidate costs O(1). Levels and arguments as in
    :func:`median_cut`; when N is not a power of two the last level splits the regions of highest
    variance.

    Examples
    --------
    >>> image = np.zeros((4, 8)); image[:, 1] = 1.0; image[:, 6] = 1.0
    >>> variance_minimization(image, 2)
    [(0, 4, 0, 2), (0, 4, 2, 8)]
    """
    sizes = (pixel_width, pixel_height, row_scale)
    return _partition(energy, n_lights, sizes, _variance_split, _variance, "variance minimization")


#: Partitions of a light image into N regions; ``reference(energy, n_lights, pixel_width,
#: pixel_height, row_scale)`` returns the regions.
LIGHT_SAMPLING_METHODS = Registry("light sampling")
LIGHT_SAMPLING_METHODS.register(
    Method(
        "median_cut",
        median_cut,
        None,
        "Eq. (2), Ferwerda (median cut, Debevec 2005)",
        lambda rng: (rng.random((16, 32)), 8),
    )
)
LIGHT_SAMPLING_METHODS.register(
    Method(
        "variance_min",
        variance_minimization,
        None,
        "Eq. (2), Ferwerda (variance minimization, Viriyothai & Debevec 2009)",
        lambda rng: (rng.random((16, 32)), 8),
    )
)


@dataclass(frozen=True)
class PointLights:
    """N point (or directional) lights made from a light image.

    Attributes
    ----------
    position : ndarray, shape (N, 3)
        Plane lights: world positions (energy centroids). Lat-long lights: unit directions.
    L : ndarray, shape (N, C)
        Plane lights: summed radiance of each region's pixels (``L_n`` of Eq. (2), Ferwerda).
        Lat-long lights: ``Σ L dω`` per channel.
    regions : list of tuple
        The image regions ``(y0, y1, x0, x1)``.
    directional : bool
        True for lights at infinity (lat-long).
    n_light : ndarray, shape (3,)
        Emitting-side normal of the plane (NaN for directional lights).
    pixel_area : float
        ``A/P`` of Eq. (2), Ferwerda (1 for directional lights).
    spread : ndarray, shape (N,)
        Energy-weighted spatial variance of each region about its light, ``Σ E |x − c|² / Σ E``
        (m² for plane lights, sr for lat-long lights): how far a point light misplaces energy.
    method : str
        The partition that made them (a key of :data:`LIGHT_SAMPLING_METHODS`).
    """

    position: np.ndarray
    L: np.ndarray
    regions: list
    directional: bool
    n_light: np.ndarray
    pixel_area: float
    spread: np.ndarray
    method: str = "median_cut"


def point_lights_every_pixel(light: PlaneLight) -> PointLights:
    """Every pixel of a plane light a point light at its centre: Eq. (2), Ferwerda, unreduced.

    The brute force the sampled lights are measured against.

    Examples
    --------
    >>> plane = PlaneLight(np.full((2, 3), 10.0), (-0.5, 1, -0.5), (1, 0, 0), (0, 0, 1), 1.0, 1.0)
    >>> lights = point_lights_every_pixel(plane)
    >>> lights.position.shape, float(lights.L.sum())
    ((6, 3), 60.0)
    """
    H, W = light.shape
    rows, cols = np.meshgrid(np.arange(H) + 0.5, np.arange(W) + 0.5, indexing="ij")
    position = light.pixel_positions(rows.ravel(), cols.ravel())
    L = np.asarray(light.image, dtype=np.float64).reshape(H * W, -1)
    regions = [(i, i + 1, j, j + 1) for i in range(H) for j in range(W)]
    spread = np.zeros(H * W)
    return PointLights(position, L, regions, False, light.n_light, light.pixel_area, spread, "all")


def point_lights_from_plane(light: PlaneLight, method: str = "median_cut", n_lights: int = 32):
    """Point lights on a plane light by a registered partition (median cut by default).

    Eq. (2), Ferwerda (the 32 median-cut lights and their summed luminance ``L_n``).

    Parameters
    ----------
    light : PlaneLight
    method : str
        A key of :data:`LIGHT_SAMPLING_METHODS`.
    n_lights : int
        N >= 1 (default 32, as in the paper).

    Returns
    -------
    PointLights
        ``L.sum(axis=0)`` equals the image's sum over pixels exactly (power conservation).

    Examples
    --------
    >>> from impastor.arealights import booth_light_image
    >>> plane = PlaneLight(booth_light_image("fluorescent", 32, 16), (0, 1, 0), (1, 0, 0),
    ...                    (0, 0, 1), 1.2, 0.6)
    >>> lights = point_lights_from_plane(plane, "median_cut", 8)
    >>> lights.position.shape, bool(np.isclose(lights.L.sum(), plane.image.sum(), rtol=1e-12))
    ((8, 3), True)
    """
    partition = LIGHT_SAMPLING_METHODS.lookup(method).reference
    image = light.image
    energy = image.mean(axis=-1)
    H, W = light.shape
    regions = partition(energy, n_lights, light.l_A / W, light.l_B / H)
    rows, cols = np.meshgrid(np.arange(H) + 0.5, np.arange(W) + 0.5, indexing="ij")
    T_E, T_r, T_c = (summed_area_table(v) for v in (energy, energy * rows, energy * cols))
    y_m, x_m = rows * (light.l_B / H), cols * (light.l_A / W)
    T_xx, T_yy = summed_area_table(energy * x_m**2), summed_area_table(energy * y_m**2)
    T_L = summed_area_table(image)
    positions, L, spread = [], [], []
    for region in regions:
        e = _box(T_E, *region)
        y0, y1, x0, x1 = region
        # Energy centroid (Debevec 2005); a dark region keeps its geometric centre.
        r = _box(T_r, *region) / e if e > 0 else (y0 + y1) / 2.0
        c = _box(T_c, *region) / e if e > 0 else (x0 + x1) / 2.0
        positions.append(light.pixel_positions(r, c))
        L.append(_box(T_L, *region))
        x_c, y_c = c * light.l_A / W, r * light.l_B / H
        second = (_box(T_xx, *region) + _box(T_yy, *region)) / e if e > 0 else 0.0
        spread.append(max(second - x_c**2 - y_c**2, 0.0))
    return PointLights(
        np.array(positions),
        np.array(L),
        regions,
        False,
        light.n_light,
        light.pixel_area,
        np.array(spread),
        method,
    )


def point_lights_from_latlong(image, method: str = "median_cut", n_lights: int = 32):
    """Directional lights from a lat-long map (Mitsuba 3 convention) by a registered partition.

    Energy is radiance × pixel solid angle; the longer-side test uses each row's true width
    (``sin θ`` times the equator's), as Debevec 2005 does.

    Parameters
    ----------
    image : array_like, shape (H, 2H) or (H, 2H, C)
        Radiance, >= 0.
    method : str
        A key of :data:`LIGHT_SAMPLING_METHODS`.
    n_lights : int
        N >= 1.

    Returns
    -------
    PointLights
        Directions (energy-weighted mean direction of each region, normalised) and ``Σ L dω``.

    Examples
    --------
    >>> env = np.ones((8, 16))
    >>> lights = point_lights_from_latlong(env, "median_cut", 4)
    >>> float(lights.L.sum()).__round__(10) == round(4 * np.pi, 10)
    True
    """
    from reference.geometry.envmap import latlong_pixel_solid_angles

    image = check_light_image(image, "lat-long light")
    check_latlong_shape(image.shape, "lat-long light")
    H, W = image.shape[:2]
    omega = latlong_pixel_solid_angles(H, W)
    energy = image.mean(axis=-1) * omega
    theta = (np.arange(H) + 0.5) * np.pi / H
    partition = LIGHT_SAMPLING_METHODS.lookup(method).reference
    # Debevec 2005: a row's true width is sin θ times the equator's (dφ = 2π/W, dθ = π/H)
    regions = partition(energy, n_lights, 2 * np.pi / W, np.pi / H, np.sin(theta))
    dirs = latlong_pixel_directions(H, W)
    T_d = summed_area_table(energy[..., None] * dirs)
    T_E = summed_area_table(energy)
    T_L = summed_area_table(image * omega[..., None])
    directions, L, spread = [], [], []
    for region in regions:
        d = _box(T_d, *region)
        e = _box(T_E, *region)
        norm = np.linalg.norm(d)
        if norm <= 0:
            y0, y1, x0, x1 = region
            d = dirs[(y0 + y1 - 1) // 2, (x0 + x1 - 1) // 2]
            norm = e = 1.0
        directions.append(d / norm)
        L.append(_box(T_L, *region))
        # Σ E |ω − c|² / Σ E = 2 (1 − |mean ω|) for unit vectors: the angular spread, sr.
        spread.append(2.0 * (1.0 - min(norm / e, 1.0)) if e > 0 else 0.0)
    return PointLights(
        np.array(directions),
        np.array(L),
        regions,
        True,
        np.full(3, np.nan),
        1.0,
        np.array(spread),
        method,
    )


# --- diffuse illuminance and reflection from point lights ----------------------------------------


def illuminance_point_lights(points, normals, lights: PointLights, visibility=None) -> np.ndarray:
    """Illuminance at surface points from point lights, per channel.

    Eq. (2), Ferwerda: ``E = Σ_n L_n (N_surf·I_n)(−N_light·I_n) (A/P) / d_n²``, with ``I_n`` the
    unit vector from the surface point to light n (see ``docs/errata.md`` for the sign of the
    light-side cosine). Directional lights give ``E = Σ_n L_n max(N_surf·ω_n, 0)``.

    Parameters
    ----------
    points, normals : array_like, shape (..., 3)
        Surface positions (m) and unit shading normals.
    lights : PointLights
    visibility : array_like, shape (..., N), optional
        1 where light n reaches the point, 0 where it is shadowed (e.g. from a horizon map).

    Returns
    -------
    ndarray, shape (..., C)
        Illuminance (lux for luminance images).

    Examples
    --------
    >>> plane = PlaneLight(np.full((1, 1), 1000.0), (-0.5, 1, -0.5), (1, 0, 0), (0, 0, 1), 1.0, 1.0)
    >>> lights = point_lights_from_plane(plane, "median_cut", 1)
    >>> illuminance_point_lights([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], lights)
    array([1000.])
    """
    p = np.asarray(points, dtype=np.float64)
    n = np.asarray(normals, dtype=np.float64)
    if lights.directional:
        cos_s = np.maximum(n @ lights.position.T, 0.0)  # (..., N)
        geometry = cos_s
    else:
        to_light = lights.position - p[..., None, :]  # (..., N, 3)
        d2 = np.einsum("...i,...i->...", to_light, to_light)
        I_n = to_light / np.sqrt(d2)[..., None]
        cos_s = np.maximum(np.einsum("...ni,...i->...n", I_n, n), 0.0)
        cos_l = np.maximum(-(I_n @ lights.n_light), 0.0)
        # Eq. (2), Ferwerda: (N_surf·I_n)(N_light·I_n) A/P / d_n²
        geometry = cos_s * cos_l * lights.pixel_area / d2
    if visibility is not None:
        geometry = geometry * np.asarray(visibility, dtype=np.float64)
    # Eq. (2), Ferwerda: E = Σ_n L_n · geometry_n
    return geometry @ lights.L


def diffuse_radiance(rho_d, S, E) -> np.ndarray:
    """Diffuse reflected radiance per channel.

    Eq. (3), Ferwerda: ``L_out,j = ρ_d,j S_j E / π``.

    Parameters
    ----------
    rho_d : array_like, shape (..., C)
        Diffuse reflectance per channel.
    S : array_like, shape (C,)
        The light's normalised channel values (``light_to_channels``).
    E : array_like, shape (..., 1) or (..., C)
        Illuminance from Eq. (2), Ferwerda.

    Returns
    -------
    ndarray, shape (..., C)

    Examples
    --------
    >>> diffuse_radiance([0.5, 0.2], [1.0, 1.0], [np.pi]).round(12)
    array([0.5, 0.2])
    """
    # Eq. (3), Ferwerda: L_out,j = ρ_d,j S_j E / π
    return np.asarray(rho_d, float) * np.asarray(S, float) * np.asarray(E, float) / np.pi

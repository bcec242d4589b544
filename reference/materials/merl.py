"""Measured isotropic BRDFs in the MERL binary layout (Matusik et al. 2003): read, write, evaluate.

The MERL BRDF database (Matusik et al. 2003) tabulates each material in Rusinkiewicz's (1998)
half/difference angles: ``θ_h``, the angle of the half vector ``h = (ω_i + ω_o)/|ω_i + ω_o|`` from
the normal, and ``(θ_d, φ_d)``, the polar angles of ``ω_i`` in a frame whose pole is ``h`` (the
half vector's azimuth ``φ_h`` is dropped: the BRDF is isotropic). A file holds:

- **a header** of three little-endian int32, the dimensions ``(90, 90, 180)`` of
  ``(θ_h, θ_d, φ_d)``;
- **the values**: ``3 · 90 · 90 · 180`` little-endian float64, channel-major (all red, then all
  green, then all blue), each channel C-ordered ``[θ_h][θ_d][φ_d]`` (``φ_d`` fastest);
- **the scales**: the BRDF (1/sr) is the stored value times 1/1500 (red), 1.15/1500 (green) and
  1.66/1500 (blue); a negative stored value means "no data" (a geometry below the horizon).

The bins, as the database's reader BRDFRead.cpp (MERL 2005) indexes them, in continuous index
coordinates ``u`` whose integer part is the bin (clamped to the table):
``u_h = 90 √(θ_h / (π/2))`` (square-root spacing: fine bins near the specular peak),
``u_d = 90 θ_d / (π/2)`` and ``u_p = 180 φ_d / π`` with ``φ_d`` taken modulo π (reciprocity:
exchanging ``ω_i`` and ``ω_o`` turns ``φ_d`` into ``φ_d + π``).

specref's evaluation (:func:`brdf_merl`; the choices are ours, docs/brdf-format.md):

- **sample positions**: each bin holds the BRDF at its centre in index coordinates,
  ``u = k + ½`` (:func:`merl_bin_centres`); :func:`write_merl_brdf` samples there;
- **interpolation** ``"trilinear"`` (default): trilinear in ``(u_h, u_d, u_p)`` between bin centres,
  clamped to the first and last centres in ``θ_h`` and ``θ_d``, periodic in ``φ_d`` (period π);
  nodes without data are left out and the weights of the others renormalized (0 if none has
  data). ``"nearest"`` is BRDFRead.cpp's lookup: the bin ``floor(u)``, clamped; no data gives 0.
- **below the horizon** the BRDF is 0; the channels are R, G, B, the axis last, ``(..., 3)``.

:func:`merl_to_brdf_table` resamples a MERL BRDF onto a
:class:`~reference.materials.table.BRDFTable` (the path into rendering and SHRMs), its RGB turned
into bands by a given ``(3, C)`` matrix.

References
----------
- W. Matusik, H. Pfister, M. Brand, L. McMillan, "A data-driven reflectance model", ACM
  Transactions on Graphics 22(3) (SIGGRAPH 2003), 759-769; the database's reader BRDFRead.cpp
  (Mitsubishi Electric Research Laboratories, 2005).
- S. Rusinkiewicz, "A new change of variables for efficient BRDF representation", Eurographics
  Workshop on Rendering 1998.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from reference.errors import SpecrefError, require, require_choice
from reference.files import atomic_write
from reference.materials.brdf import _dot, frame_from_normal
from reference.materials.isotropic import isotropic_directions
from reference.materials.table import MAX_TABLE_ANGLES, BRDFTable

__all__ = [
    "MAX_MERL_ALBEDO",
    "MERLBRDF",
    "MERL_BYTES",
    "MERL_DIMENSIONS",
    "MERL_INTERPOLATIONS",
    "MERL_SCALES",
    "brdf_merl",
    "directions_to_half_diff",
    "half_diff_to_directions",
    "half_diff_to_merl_coordinates",
    "merl_albedo",
    "merl_bin_centres",
    "merl_to_brdf_table",
    "read_merl_brdf",
    "tabulate_merl",
    "write_merl_brdf",
]

#: Bins of ``(θ_h, θ_d, φ_d)`` in a MERL file (Matusik et al. 2003; BRDFRead.cpp).
MERL_DIMENSIONS = (90, 90, 180)

#: Stored value → BRDF (1/sr) per channel R, G, B (BRDFRead.cpp's RED/GREEN/BLUE_SCALE).
MERL_SCALES = np.array([1.0, 1.15, 1.66]) / 1500.0

#: Size of a MERL file: the 12-byte header and 3 · 90 · 90 · 180 float64.
MERL_BYTES = 12 + 3 * 8 * int(np.prod(MERL_DIMENSIONS))

#: The lookups :func:`brdf_merl` offers (module docstring).
MERL_INTERPOLATIONS = ("nearest", "trilinear")

_CHANNELS = ("red", "green", "blue")


@dataclass(frozen=True, eq=False)
class MERLBRDF:
    """A measured isotropic BRDF on the MERL grid, in 1/sr, channels R, G, B.

    Matusik et al. 2003 (the 90 × 90 × 180 tabulation in Rusinkiewicz 1998's half/difference
    angles).

    Parameters
    ----------
    values : ndarray, shape (90, 90, 180, 3)
        ``values[k_h, k_d, k_p, c]``, the BRDF (1/sr) of bin ``(θ_h, θ_d, φ_d)`` in channel
        ``c`` (R, G, B), already scaled; negative means no data. Finite.
    name : str
        Shown in messages.

    Examples
    --------
    >>> m = MERLBRDF(np.full((90, 90, 180, 3), 0.1), name="grey")
    >>> m.values.shape, float(m.measured.mean())
    ((90, 90, 180, 3), 1.0)
    """

    values: np.ndarray
    name: str = "merl"

    def __post_init__(self):
        values = np.asarray(self.values, dtype=np.float64)
        shape = (*MERL_DIMENSIONS, 3)
        where = self.name
        require(
            values.shape == shape, f"{where}: values: must have shape {shape}, got {values.shape}"
        )
        require(bool(np.isfinite(values).all()), f"{where}: values: must be finite (no NaN)")
        values = values.copy()
        values.setflags(write=False)
        object.__setattr__(self, "values", values)

    @property
    def measured(self) -> np.ndarray:
        """Where the table has data, ``(90, 90, 180, 3)`` bool (a stored value >= 0)."""
        return self.values >= 0.0


# --- Rusinkiewicz's half/difference angles ---------------------------------------------------


def directions_to_half_diff(wi, wo, normal=(0.0, 0.0, 1.0)):
    """Half/difference angles ``(θ_h, θ_d, φ_d)`` of direction pairs, radians.

    Rusinkiewicz 1998 (the half/difference change of variables), as BRDFRead.cpp computes it:
    ``h`` is the normalized ``ω_i + ω_o``; the frame ``(x_h, y_h, h)`` is ``(t, b, n)`` rotated
    by ``θ_h`` about ``b`` and then by ``φ_h`` about ``n``, and ``(θ_d, φ_d)`` are the polar
    angles of ``ω_i`` in it. The tangent ``t`` is that of
    :func:`~reference.materials.brdf.frame_from_normal`; the three angles do not depend on it
    (except ``φ_d`` at ``θ_h = 0``, where an isotropic BRDF does not depend on ``φ_d``).

    Parameters
    ----------
    wi, wo : array_like, shape (..., 3)
        Unit directions away from the surface (they broadcast).
    normal : array_like, shape (3,) or (..., 3)
        The unit normal.

    Returns
    -------
    theta_h, theta_d : ndarray, shape (...,)
        In [0, π].
    phi_d : ndarray, shape (...,)
        In (−π, π]; ``φ_d`` of ``(ω_o, ω_i)`` is that of ``(ω_i, ω_o)`` ± π.

    Examples
    --------
    >>> wi = np.array([np.sin(0.5), 0.0, np.cos(0.5)]); wo = wi * [-1, -1, 1]  # the mirror pair
    >>> [round(float(a), 12) for a in directions_to_half_diff(wi, wo)]
    [0.0, 0.5, 0.0]
    """
    wi, wo, normal = (np.asarray(v, dtype=np.float64) for v in (wi, wo, normal))
    t, b = frame_from_normal(normal)
    h = wi + wo
    h = h / np.maximum(np.linalg.norm(h, axis=-1), 1e-300)[..., None]
    # Rusinkiewicz 1998: θ_h, φ_h, the polar angles of h in the frame (t, b, n)
    h_t, h_b, h_n = _dot(h, t), _dot(h, b), _dot(h, normal)
    theta_h = np.arctan2(np.hypot(h_t, h_b), h_n)
    phi_h = np.arctan2(h_b, h_t)
    # The frame with h as its pole: x_h = R_n(φ_h) R_b(θ_h) t, y_h = R_n(φ_h) b
    cos_h, sin_h = np.cos(theta_h)[..., None], np.sin(theta_h)[..., None]
    cos_p, sin_p = np.cos(phi_h)[..., None], np.sin(phi_h)[..., None]
    x_h = cos_h * cos_p * t + cos_h * sin_p * b - sin_h * normal
    y_h = -sin_p * t + cos_p * b
    # Rusinkiewicz 1998: the difference vector d = ω_i in (x_h, y_h, h), and its polar angles
    d_x, d_y, d_z = _dot(wi, x_h), _dot(wi, y_h), _dot(wi, h)
    theta_d = np.arctan2(np.hypot(d_x, d_y), d_z)
    phi_d = np.arctan2(d_y, d_x)
    return theta_h, theta_d, phi_d


def half_diff_to_directions(theta_h, theta_d, phi_d):
    """Directions ``(ω_i, ω_o)`` about the normal +z with the given half/difference angles.

    Rusinkiewicz 1998 (the inverse change of variables), with ``φ_h = 0``: ``h = (sin θ_h, 0,
    cos θ_h)``, ``ω_i = R_y(θ_h) d`` with ``d = (sin θ_d cos φ_d, sin θ_d sin φ_d, cos θ_d)``, and
    ``ω_o = 2 (ω_i·h) h − ω_i``, the mirror of ``ω_i`` about ``h``.

    Parameters
    ----------
    theta_h, theta_d, phi_d : array_like
        Angles, radians; they broadcast.

    Returns
    -------
    wi, wo : ndarray, shape (..., 3)
        Unit vectors; either may lie below the horizon (``z < 0``).

    Examples
    --------
    >>> wi, wo = half_diff_to_directions(0.0, np.pi / 4, 0.0)
    >>> wi.round(6), wo.round(6)
    (array([0.707107, 0.      , 0.707107]), array([-0.707107,  0.      ,  0.707107]))
    """
    theta_h, theta_d, phi_d = np.broadcast_arrays(
        *(np.asarray(a, dtype=np.float64) for a in (theta_h, theta_d, phi_d))
    )
    sin_d = np.sin(theta_d)
    d_x, d_y, d_z = sin_d * np.cos(phi_d), sin_d * np.sin(phi_d), np.cos(theta_d)
    cos_h, sin_h = np.cos(theta_h), np.sin(theta_h)
    # Rusinkiewicz 1998: ω_i = R_y(θ_h) d
    wi = np.stack([d_x * cos_h + d_z * sin_h, d_y, d_z * cos_h - d_x * sin_h], axis=-1)
    h = np.stack([sin_h, np.zeros_like(sin_h), cos_h], axis=-1)
    # ω_o, the mirror of ω_i about h
    wo = 2.0 * _dot(wi, h)[..., None] * h - wi
    return wi, wo


def half_diff_to_merl_coordinates(theta_h, theta_d, phi_d):
    """Continuous MERL index coordinates ``(u_h, u_d, u_p)`` of half/difference angles.

    Matusik et al. 2003 (the database's bins, BRDFRead.cpp ``theta_half_index``,
    ``theta_diff_index``, ``phi_diff_index``): ``u_h = 90 √(θ_h/(π/2))``, ``u_d = 90 θ_d/(π/2)``,
    ``u_p = 180 (φ_d mod π)/π``. BRDFRead.cpp's bin is ``floor(u)`` clamped to ``[0, n − 1]``.

    Parameters
    ----------
    theta_h, theta_d : array_like
        Radians, in [0, π/2] (larger values give ``u`` beyond the table).
    phi_d : array_like
        Radians, any value (taken modulo π).

    Returns
    -------
    u_h, u_d, u_p : ndarray
        Bin coordinates, unclamped; ``u_p`` in [0, 180).

    Examples
    --------
    >>> [float(u) for u in half_diff_to_merl_coordinates(np.pi / 8, np.pi / 4, -np.pi / 2)]
    [45.0, 45.0, 90.0]
    """
    theta_h, theta_d, phi_d = (np.asarray(a, dtype=np.float64) for a in (theta_h, theta_d, phi_d))
    n_h, n_d, n_p = MERL_DIMENSIONS
    # Matusik et al. 2003 (BRDFRead.cpp): square-root spacing in θ_h, linear in θ_d and φ_d
    u_h = n_h * np.sqrt(np.maximum(theta_h, 0.0) / (np.pi / 2))
    u_d = n_d * theta_d / (np.pi / 2)
    # Reciprocity: φ_d and φ_d + π are one bin
    u_p = n_p * np.mod(phi_d, np.pi) / np.pi
    return u_h, u_d, np.where(u_p >= n_p, 0.0, u_p)


def merl_bin_centres():
    """The angles of the MERL bins' centres ``u = k + ½``, radians (module docstring).

    Matusik et al. 2003 (BRDFRead.cpp's index functions, inverted): ``θ_h = (π/2)((k + ½)/90)²``,
    ``θ_d = (π/2)(k + ½)/90``, ``φ_d = π (k + ½)/180``.

    Returns
    -------
    theta_h, theta_d : ndarray, shape (90,)
    phi_d : ndarray, shape (180,)

    Examples
    --------
    >>> theta_h, theta_d, phi_d = merl_bin_centres()
    >>> [round(float(np.degrees(a[-1])), 4) for a in (theta_h, theta_d, phi_d)]
    [89.0028, 89.5, 179.5]
    """
    n_h, n_d, n_p = MERL_DIMENSIONS
    k_h, k_d, k_p = (np.arange(n) + 0.5 for n in MERL_DIMENSIONS)
    return (np.pi / 2) * (k_h / n_h) ** 2, (np.pi / 2) * k_d / n_d, np.pi * k_p / n_p


# --- evaluation ------------------------------------------------------------------------------


def _axis_nodes(u: np.ndarray, n: int, periodic: bool):
    """Lower and upper node (bin centres ``k + ½``) and the weight of the upper one."""
    s = u - 0.5
    if periodic:
        low = np.floor(s)
        return np.mod(low, n).astype(np.int64), np.mod(low + 1, n).astype(np.int64), s - low
    s = np.clip(s, 0.0, n - 1.0)
    low = np.minimum(np.floor(s), n - 2).astype(np.int64)
    return low, low + 1, s - low


def _lookup_trilinear(values: np.ndarray, u_h, u_d, u_p) -> np.ndarray:
    """Trilinear between bin centres over the nodes with data, renormalized; 0 where none has."""
    n_h, n_d, n_p = MERL_DIMENSIONS
    low_h, high_h, t_h = _axis_nodes(u_h, n_h, periodic=False)
    low_d, high_d, t_d = _axis_nodes(u_d, n_d, periodic=False)
    low_p, high_p, t_p = _axis_nodes(u_p, n_p, periodic=True)
    total = np.zeros((*np.shape(t_h), 3))
    weight = np.zeros_like(total)
    flat = values.reshape(-1, 3)
    # Trilinear interpolation: the 8 corners, weighted by their opposite volumes
    for k_h, w_h in ((low_h, 1.0 - t_h), (high_h, t_h)):
        for k_d, w_d in ((low_d, 1.0 - t_d), (high_d, t_d)):
            for k_p, w_p in ((low_p, 1.0 - t_p), (high_p, t_p)):
                node = flat[(k_h * n_d + k_d) * n_p + k_p]
                # A node without data (negative) takes no weight
                w = (w_h * w_d * w_p)[..., None] * (node >= 0.0)
                total += w * np.maximum(node, 0.0)
                weight += w
    return np.where(weight > 0.0, total / np.where(weight > 0.0, weight, 1.0), 0.0)


def _lookup_nearest(values: np.ndarray, u_h, u_d, u_p) -> np.ndarray:
    """BRDFRead.cpp's lookup: the bin ``floor(u)``, clamped; no data gives 0."""
    k_h, k_d, k_p = (
        np.clip(np.floor(u), 0, n - 1).astype(np.int64)
        for u, n in zip((u_h, u_d, u_p), MERL_DIMENSIONS, strict=True)
    )
    return np.maximum(values[k_h, k_d, k_p], 0.0)


def brdf_merl(wi, wo, normal, merl: MERLBRDF, interpolation: str = "trilinear") -> np.ndarray:
    """A MERL BRDF at direction pairs, per channel R, G, B (1/sr).

    Matusik et al. 2003 (the tabulated BRDF), in Rusinkiewicz 1998's half/difference angles
    (:func:`directions_to_half_diff`, :func:`half_diff_to_merl_coordinates`); the
    interpolation is specref's (module docstring). The calling convention of
    :data:`reference.materials.brdf.BRDF_METHODS`, so
    :func:`~reference.materials.table.tabulate_brdf` takes it.

    Parameters
    ----------
    wi, wo, normal : array_like, shape (..., 3)
        Unit directions away from the surface and the unit normal.
    merl : MERLBRDF
        The table.
    interpolation : {"trilinear", "nearest"}
        Between bin centres, or BRDFRead.cpp's bin lookup.

    Returns
    -------
    ndarray, shape (..., 3)
        BRDF, 1/sr, R, G, B; 0 below the horizon and where the table has no data.

    Examples
    --------
    >>> m = MERLBRDF(np.full((90, 90, 180, 3), 0.25))
    >>> z = np.array([0.0, 0.0, 1.0]); w = np.array([0.6, 0.0, 0.8])
    >>> brdf_merl(w, z, z, m), brdf_merl(-w, z, z, m, "nearest")
    (array([0.25, 0.25, 0.25]), array([0., 0., 0.]))
    """
    require(isinstance(merl, MERLBRDF), "brdf_merl: merl: must be a MERLBRDF")
    require_choice(interpolation, MERL_INTERPOLATIONS, "MERL interpolation")
    wi, wo, normal = (np.asarray(v, dtype=np.float64) for v in (wi, wo, normal))
    above = (_dot(wi, normal) > 0.0) & (_dot(wo, normal) > 0.0)
    u = half_diff_to_merl_coordinates(*directions_to_half_diff(wi, wo, normal))
    lookup = _lookup_trilinear if interpolation == "trilinear" else _lookup_nearest
    return np.where(above[..., None], lookup(merl.values, *u), 0.0)


def merl_albedo(merl: MERLBRDF, theta_i: float, order: int = 8) -> np.ndarray:
    """Directional albedo ``∫ f(ω_i, ω_o) cos θ_o dω_o`` of a MERL BRDF, per channel.

    Matusik et al. 2003 (the measured BRDF, :func:`brdf_merl`, trilinear), integrated by
    composite Gauss–Legendre in ``θ_o`` (16 panels of ``order`` nodes, weight ``sin θ_o cos θ_o``)
    and the midpoint rule over ``Δφ`` in [0, 2π) (``32 · order`` nodes).

    Parameters
    ----------
    merl : MERLBRDF
        The measured BRDF.
    theta_i : float
        Incidence angle from the normal, radians, in [0, π/2).
    order : int
        Gauss–Legendre nodes per panel.

    Returns
    -------
    ndarray, shape (3,)
        The albedo per channel R, G, B (dimensionless; 1 for a white diffuser).

    Examples
    --------
    >>> merl_albedo(MERLBRDF(np.full((90, 90, 180, 3), 0.5 / np.pi)), 0.3).round(6)
    array([0.5, 0.5, 0.5])
    """
    x, w = np.polynomial.legendre.leggauss(order)
    edges = np.linspace(0.0, np.pi / 2, 17)
    half = np.diff(edges) / 2
    theta_o = ((edges[:-1] + half)[:, None] + half[:, None] * x).ravel()
    w_theta = (half[:, None] * w).ravel() * np.sin(theta_o) * np.cos(theta_o)
    n_phi = 32 * order
    phi = 2.0 * np.pi * (np.arange(n_phi) + 0.5) / n_phi
    wi, wo = isotropic_directions(theta_i, theta_o[:, None], phi[None, :])
    f = brdf_merl(np.broadcast_to(wi, wo.shape), wo, np.array([0.0, 0.0, 1.0]), merl)
    # ∫ f cos θ_o dω_o with dω_o = sin θ_o dθ_o dΔφ
    return np.einsum("tpc,t->c", f, w_theta) * (2.0 * np.pi / n_phi)


# --- files -----------------------------------------------------------------------------------


def tabulate_merl(brdf, params: dict | None = None) -> np.ndarray:
    """A BRDF sampled at the MERL bin centres: the ``values`` of a :class:`MERLBRDF`.

    Matusik et al. 2003 (the grid), sampled at :func:`merl_bin_centres` (our choice of sample
    position, module docstring); pairs with a direction below the horizon get −1 (no data).

    Parameters
    ----------
    brdf : callable
        ``brdf(wi, wo, normal, **params) -> (..., C)`` (the ``BRDF_METHODS`` convention) with
        ``C`` 1 (grey) or 3 (R, G, B), finite and >= 0 above the horizon.
    params : dict, optional
        Its parameters.

    Returns
    -------
    ndarray, shape (90, 90, 180, 3)
        BRDF, 1/sr; −1 where either direction is below the horizon.

    Examples
    --------
    >>> from reference.materials.brdf import brdf_lambert
    >>> v = tabulate_merl(brdf_lambert, {"rho_d": 0.5})
    >>> v.shape, float(v.max()).__round__(6), float(v.min())
    ((90, 90, 180, 3), 0.159155, -1.0)
    """
    theta_h, theta_d, phi_d = merl_bin_centres()
    z = np.array([0.0, 0.0, 1.0])
    out = np.empty((*MERL_DIMENSIONS, 3))
    # Ten θ_h rows at a time: the directions of all 1,458,000 bins at once take 100s of MB
    for start in range(0, MERL_DIMENSIONS[0], 10):
        rows = slice(start, start + 10)
        wi, wo = half_diff_to_directions(
            theta_h[rows, None, None], theta_d[None, :, None], phi_d[None, None, :]
        )
        f = np.asarray(brdf(wi, wo, z, **(params or {})), dtype=np.float64)
        require(
            f.shape[-1] in (1, 3),
            f"tabulate_merl: the BRDF must give 1 or 3 channels, got {f.shape[-1]}",
        )
        above = (wi[..., 2] > 0.0) & (wo[..., 2] > 0.0)
        f = np.broadcast_to(f, (*above.shape, 3))
        ok = np.isfinite(f) & (f >= 0.0)
        require(
            bool(ok[above].all()),
            "tabulate_merl: the BRDF must be finite and >= 0 above the horizon",
        )
        out[rows] = np.where(above[..., None], f, -1.0)
    return out


def write_merl_brdf(path, brdf, params: dict | None = None) -> Path:
    """Write a BRDF in the MERL binary layout (Matusik et al. 2003), atomically.

    Matusik et al. 2003 (the layout of the module docstring): the header ``(90, 90, 180)``, then
    the values divided by :data:`MERL_SCALES`, channel-major; no data is written as −1.

    Parameters
    ----------
    path : str or Path
        Destination (MERL files end in ``.binary``).
    brdf : MERLBRDF, ndarray of shape (90, 90, 180, 3), or callable
        The values (1/sr, R, G, B; negative = no data), or a BRDF sampled by
        :func:`tabulate_merl` with ``params``.
    params : dict, optional
        The callable's parameters.

    Returns
    -------
    Path

    Examples
    --------
    >>> import tempfile, os
    >>> from reference.materials.brdf import brdf_lambert
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = write_merl_brdf(os.path.join(d, "white.binary"), brdf_lambert, {"rho_d": 1.0})
    ...     p.stat().st_size == MERL_BYTES, read_merl_brdf(p).values.max().round(6)
    (True, np.float64(0.31831))
    """
    if isinstance(brdf, MERLBRDF):
        values = brdf.values
    elif callable(brdf):
        values = tabulate_merl(brdf, params)
    else:
        values = MERLBRDF(brdf, name=f"{path}").values
    # Matusik et al. 2003: stored = BRDF / scale, no data as −1, channel-major
    stored = np.where(values >= 0.0, values / MERL_SCALES, -1.0)
    header = np.array(MERL_DIMENSIONS, dtype="<i4").tobytes()
    body = np.ascontiguousarray(np.moveaxis(stored, -1, 0), dtype="<f8").tobytes()
    with atomic_write(path, "wb") as handle:
        handle.write(header + body)
    return Path(path)


#: The largest directional albedo at normal incidence that a MERL file may have: energy
#: conservation allows 1; the rest is room for measurement error.
MAX_MERL_ALBEDO = 1.5


def read_merl_brdf(path) -> MERLBRDF:
    """Read a MERL BRDF file (Matusik et al. 2003), checked.

    Matusik et al. 2003 (the layout of the module docstring; BRDFRead.cpp ``read_brdf``).

    Parameters
    ----------
    path : str or Path
        The ``.binary`` file.

    Returns
    -------
    MERLBRDF
        Scaled to 1/sr, named after the file.

    Raises
    ------
    SpecrefError
        One line naming the file: not found or unreadable, shorter than its header, dimensions
        other than (90, 90, 180), a size other than :data:`MERL_BYTES` (truncated or extra
        bytes), NaN or infinite values, no value with data, or an albedo at normal incidence
        above :data:`MAX_MERL_ALBEDO`.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = os.path.join(d, "short.binary")
    ...     _ = open(p, "wb").write(np.array([90, 90, 90], "<i4").tobytes())
    ...     read_merl_brdf(p)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: .../short.binary: MERL header: dimensions (90, 90, 90); ...
    """
    path = Path(path)
    stored = _read_merl_values(path)
    bad = ~np.isfinite(stored)
    if bad.any():
        c, k_h, k_d, k_p = np.argwhere(bad)[0]
        raise SpecrefError(
            f"{path}: {int(bad.sum()):,} NaN or infinite values in the MERL data (first: "
            f"{_CHANNELS[c]}, theta_h bin {k_h}, theta_d bin {k_d}, phi_d bin {k_p})"
        )
    require(bool((stored >= 0).any()), f"{path}: no MERL value with data (all are negative)")
    # Matusik et al. 2003: BRDF = stored value × scale, per channel; channel axis last
    merl = MERLBRDF(np.moveaxis(stored, 0, -1) * MERL_SCALES, name=path.stem)
    with np.errstate(over="ignore", invalid="ignore"):
        # energy conservation: a file of 1e308 was read, and its albedo printed as 300 digits
        albedo = merl_albedo(merl, 0.0)
    if not np.all(albedo <= MAX_MERL_ALBEDO):  # NaN and inf fail too
        channel = int(np.argmax(~(albedo <= MAX_MERL_ALBEDO)))
        raise SpecrefError(
            f"{path}: albedo at normal incidence {albedo[channel]:.4g} in {_CHANNELS[channel]}; "
            f"a surface reflects at most the light it receives (<= {MAX_MERL_ALBEDO:g} allowed, "
            "room for measurement error): a wrong scale or not a MERL BRDF"
        )
    return merl


def _read_merl_values(path: Path) -> np.ndarray:
    """The stored values ``(3, 90, 90, 180)`` of a file whose header and size are checked."""
    try:
        with open(path, "rb") as handle:
            size = os.fstat(handle.fileno()).st_size
            header = handle.read(12)
            require(
                len(header) == 12,
                f"{path}: truncated MERL BRDF: {size} bytes, shorter than its 12-byte header",
            )
            dims = tuple(int(d) for d in np.frombuffer(header, dtype="<i4"))
            require(
                dims == MERL_DIMENSIONS,
                f"{path}: MERL header: dimensions {dims}; a MERL BRDF has {MERL_DIMENSIONS} "
                "(theta_h, theta_d, phi_d)",
            )
            require(
                size == MERL_BYTES,
                f"{path}: {size:,} bytes; a MERL BRDF of {MERL_DIMENSIONS} has {MERL_BYTES:,} "
                f"(12-byte header and 3 x 1,458,000 float64): "
                + ("truncated" if size < MERL_BYTES else "extra bytes at the end"),
            )
            data = handle.read(MERL_BYTES - 12)
    except FileNotFoundError:
        raise SpecrefError(f"{path}: file not found") from None
    except OSError as error:
        raise SpecrefError(f"{path}: unreadable MERL BRDF ({error.strerror or error})") from None
    require(len(data) == MERL_BYTES - 12, f"{path}: truncated MERL BRDF while reading")
    return np.frombuffer(data, dtype="<f8").reshape(3, *MERL_DIMENSIONS)


# --- into rendering ----------------------------------------------------------------------------


def merl_to_brdf_table(
    merl: MERLBRDF,
    RGB_to_bands,
    wavelengths_nm,
    theta_step_deg: float = 2.0,
    phi_step_deg: float = 4.0,
) -> BRDFTable:
    """A MERL BRDF resampled onto a :class:`~reference.materials.table.BRDFTable`, spectral.

    Matusik et al. 2003 (the measured BRDF, :func:`brdf_merl`, trilinear) at ``θ_i, θ_o = 0,
    step, ..., 90°`` and ``Δφ = 0, step, ..., 180°``; each RGB triple becomes bands by
    ``f(λ) = f_RGB @ RGB_to_bands`` (a linear RGB → spectrum method, e.g. Mallett & Yuksel's
    primaries: ``reference.colour.upsampling.RGB_to_spectra_Mallett2019(np.eye(3), grid)``).

    Parameters
    ----------
    merl : MERLBRDF
        The measured BRDF.
    RGB_to_bands : array_like, shape (3, C)
        Row c: the spectrum of unit channel c (R, G, B), >= 0.
    wavelengths_nm : array_like, shape (C,)
        The bands, nm, increasing.
    theta_step_deg, phi_step_deg : float
        Grid steps, degrees, dividing 90 and 180.

    Returns
    -------
    BRDFTable
        ``(91/θ step + 1)² × (180/φ step + 1)`` angles × C bands, named after ``merl``.

    Examples
    --------
    >>> m = MERLBRDF(np.full((90, 90, 180, 3), 0.2) * [1.0, 0.5, 0.25])
    >>> t = merl_to_brdf_table(m, np.eye(3)[::-1], [450.0, 550.0, 650.0], 30.0, 90.0)
    >>> t.values.shape, t.values[0, 0, 0].round(6)  # bands B, G, R
    ((4, 4, 3, 3), array([0.05, 0.1 , 0.2 ]))
    """
    require(isinstance(merl, MERLBRDF), "merl_to_brdf_table: merl: must be a MERLBRDF")
    basis = np.asarray(RGB_to_bands, dtype=np.float64)
    require(
        basis.ndim == 2 and basis.shape[0] == 3,
        f"merl_to_brdf_table: RGB_to_bands: must have shape (3, C), got {basis.shape}",
    )
    counts = []
    for label, step, span in (("theta", theta_step_deg, 90.0), ("phi", phi_step_deg, 180.0)):
        count = span / step if np.isfinite(step) and step > 0 else 0.5
        require(
            count >= 1 and abs(count - round(count)) < 1e-9,
            f"MERL to table: {label} step: must divide {span:g} degrees, got {step:g}",
        )
        counts.append(round(count) + 1)
    angles = counts[0] ** 2 * counts[1]
    require(
        angles <= MAX_TABLE_ANGLES,
        f"MERL to table: the steps give {angles:,} angle triples; at most {MAX_TABLE_ANGLES:,}",
    )
    theta = np.linspace(0.0, 90.0, counts[0])
    phi = np.linspace(0.0, 180.0, counts[1])
    # Nodes at exactly 90° lie on the horizon, where the BRDF is 0; evaluate just above it
    lift = np.radians(np.minimum(theta, 90.0 - 1e-6))
    wi, wo = isotropic_directions(lift[:, None, None], lift[None, :, None], np.radians(phi))
    RGB = brdf_merl(wi, wo, np.array([0.0, 0.0, 1.0]), merl)
    return BRDFTable(theta, theta, phi, wavelengths_nm, RGB @ basis, name=merl.name)

"""A table of the specular functions of Eq. (11), Wang et al.: nodes, values and lookups.

:func:`build_table` places the nodes with a registered placement, evaluates ``f_sp`` there exactly
(without ``f_att``, Erratum E18), and precomputes what every lookup needs: the monotone slopes and
the inverse-map index. :meth:`SpecularTable.lookup` interpolates with any registered interpolation
(NumPy, the readable reference); the renderer uses the compiled twin
(``phong_table._kernels.shade_table_kernel``) on the same arrays.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from phong_table import _kernels
from phong_table.interpolation import (
    GUIDE_CELLS_PER_ENTRY,
    INTERPOLATION_METHODS,
    guide_index,
    pchip_slopes,
)
from phong_table.model import SpectralPhong, specular_RGB
from phong_table.placement import PLACEMENT_METHODS, check_entries
from reference.errors import require

__all__ = [
    "OVERSHOOT_SAMPLES",
    "SpecularTable",
    "build_table",
    "check_interpolation",
    "increasing",
    "tabulate",
    "zero_below",
]

#: Points per interval at which :meth:`SpecularTable.overshoot` evaluates the interpolant.
OVERSHOOT_SAMPLES = 16


def check_interpolation(interpolation: str, entries: int) -> None:
    """Raise unless ``interpolation`` is registered and accepts a table of ``entries`` entries.

    Examples
    --------
    >>> check_interpolation("parabolic", 2)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: table: entries: parabolic interpolation needs entries >= 3, got 2
    """
    method = INTERPOLATION_METHODS.lookup(interpolation)
    least = method.min_entries
    require(
        entries >= least,
        f"table: entries: {interpolation} interpolation needs entries >= {least}, got {entries}",
    )


@dataclass(frozen=True, eq=False)
class SpecularTable:
    """A table of ``f_sp(t) = [f_rsp, f_gsp, f_bsp](t)``, Eq. (11), Wang et al., without ``f_att``.

    Attributes
    ----------
    nodes : ndarray, shape (m + 1,)
        Strictly increasing, ``t_0 = 0`` to ``t_m = 1``.
    values : ndarray, shape (m + 1, 3)
        ``f_sp`` at the nodes, linear display RGB.
    slopes : ndarray, shape (m + 1, 3)
        Monotone (PCHIP) slopes at the nodes.
    inv_width : ndarray, shape (m,)
        ``1/(t_{i+1} − t_i)``.
    cubic : ndarray, shape (m, 3, 3)
        The monotone cubic of each interval and channel in Horner form, ``f = v_i + s (c1 + s (c2
        + s c3))`` with ``s = (t − t_i)/(t_{i+1} − t_i)`` (what the kernel evaluates).
    guide : ndarray of int64, shape (16 m + 1,)
        Inverse-map index (``phong_table.interpolation.guide_index``).
    steps : int
        Bisection steps inside the widest cell of ``guide``.
    uniform : bool
        True when the nodes are ``q/m`` (O(1) lookup).
    an : float
        The average exponent, for the parabola in w.
    placement : str
        The placement key.
    segments : int or None
        ``p`` of an importance table.
    zero_below : float
        Every interpolation of the table is exactly 0 for ``t`` below this (:func:`zero_below`);
        -1 when there is no such run. The compiled shader skips the lookup there.

    Examples
    --------
    >>> from phong_table.scenes import constant_material
    >>> table = build_table(constant_material(2.0), 4, "uniform")
    >>> table.entries, table.values.shape
    (4, (5, 3))
    """

    nodes: np.ndarray
    values: np.ndarray
    slopes: np.ndarray
    inv_width: np.ndarray
    cubic: np.ndarray
    guide: np.ndarray
    steps: int
    uniform: bool
    an: float
    placement: str
    segments: int | None = None
    zero_below: float = -1.0

    @property
    def entries(self) -> int:
        """``m``, the number of intervals."""
        return self.nodes.size - 1

    def lookup(self, t, interpolation: str = "monotone") -> np.ndarray:
        """``f_sp(t)`` read from the table with a registered interpolation (NumPy reference).

        Parameters
        ----------
        t : array_like, shape (...,)
            Points in [0, 1].
        interpolation : str
            A key of ``INTERPOLATION_METHODS``.

        Returns
        -------
        ndarray, shape (..., 3)

        Examples
        --------
        >>> from phong_table.scenes import constant_material
        >>> model = constant_material(1.0)
        >>> table = build_table(model, 2, "uniform")
        >>> bool(np.allclose(table.lookup([0.3], "linear"), model.specular([0.3])))
        True
        """
        check_interpolation(interpolation, self.entries)
        t = np.clip(np.asarray(t, dtype=np.float64), 0.0, 1.0)
        method = INTERPOLATION_METHODS.lookup(interpolation)
        if interpolation == "monotone":
            return method.reference(self.nodes, self.values, t, self.an, slopes=self.slopes)
        return method.reference(self.nodes, self.values, t, self.an)

    def overshoot(self, interpolation: str = "monotone", samples: int = OVERSHOOT_SAMPLES) -> float:
        """How far the interpolant leaves the range of its interval's two values, in peaks.

        The largest ``max(f − max(v_i, v_{i+1}), min(v_i, v_{i+1}) − f)`` over ``samples`` points
        per interval and the three channels, divided by the table's peak ``max |values|``; 0 means
        the interpolant never leaves the range of the tabulated values.

        Examples
        --------
        >>> from phong_table.scenes import constant_material
        >>> table = build_table(constant_material(2000.0), 50, "importance")
        >>> table.overshoot("monotone"), table.overshoot("parabolic") > 1
        (0.0, True)
        """
        check_interpolation(interpolation, self.entries)
        s = (np.arange(samples) + 0.5) / samples
        t = (self.nodes[:-1, None] + s[None, :] * np.diff(self.nodes)[:, None]).ravel()
        f = self.lookup(t, interpolation)
        i = np.repeat(np.arange(self.entries), samples)
        low = np.minimum(self.values[i], self.values[i + 1])
        high = np.maximum(self.values[i], self.values[i + 1])
        excess = np.maximum(np.maximum(f - high, low - f), 0.0).max()
        peak = np.abs(self.values).max()
        return float(excess / peak) if peak > 0 else 0.0


def zero_below(nodes, values) -> float:
    """The ``t`` below which every interpolation of a table returns exactly 0.

    High exponents make ``t^n`` underflow to 0 over most of [0, 1], so the leading values are
    exactly 0. If ``values[0 .. z + 1]`` are all 0 (every channel), the interval ``[t_j, t_{j+1}]``
    with ``j + 1 <= z`` is interpolated from nodes ``j − 1 .. j + 2`` at most (the widest stencil,
    the parabola's), whose values and monotone slopes are 0: the result is 0 for ``t < t_z``.

    Returns
    -------
    float
        ``t_z``, or -1.0 when fewer than three leading values are 0 (no ``t`` qualifies).

    Examples
    --------
    >>> nodes = np.linspace(0.0, 1.0, 6)
    >>> zero_below(nodes, np.array([[0.0] * 3] * 4 + [[0.1] * 3, [1.0] * 3]))
    0.4
    >>> zero_below(nodes, np.ones((6, 3)))
    -1.0
    """
    nonzero = np.flatnonzero((np.asarray(values) != 0.0).any(axis=-1))
    first = int(nonzero[0]) if nonzero.size else len(nodes)
    z = first - 2
    return float(nodes[z]) if z >= 1 else -1.0


def increasing(nodes) -> bool:
    """Whether ``nodes`` rise strictly from 0 to 1 (what every table's nodes must do).

    The compiled twin is ``phong_table._kernels._increasing_kernel``.

    Examples
    --------
    >>> increasing(np.array([0.0, 0.5, 1.0])), increasing(np.array([0.0, 0.5, 0.5, 1.0]))
    (True, False)
    """
    return bool(nodes[0] == 0.0 and nodes[-1] == 1.0 and (np.diff(nodes) > 0).all())


def tabulate(nodes, C, n, cells_per_entry: int = GUIDE_CELLS_PER_ENTRY) -> tuple:
    """Everything a lookup needs at given nodes: values, slopes, widths, cubics and the index.

    Eq. (11), Wang et al. at the nodes (``phong_table.model.specular_RGB``), the monotone slopes
    (``pchip_slopes``), and the inverse-map index (``guide_index``). The compiled twin is
    ``phong_table._kernels.tabulate_kernel``.

    Parameters
    ----------
    nodes : ndarray, shape (m + 1,)
        Strictly increasing, from 0 to 1.
    C, n : ndarray, shapes (n_bands, 3) and (n_bands,)
        ``f_sp(t) = Σ_λ C(λ) t^{n(λ)}``.
    cells_per_entry : int
        Cells of the index per entry.

    Returns
    -------
    values, slopes : ndarray, shape (m + 1, 3)
    inv_width : ndarray, shape (m,)
    cubic : ndarray, shape (m, 3, 3)
        ``[c1, c2, c3]`` with ``f = v_i + s (c1 + s (c2 + s c3))`` on interval i.
    guide : ndarray of int64, shape (cells_per_entry · m + 1,)
    steps : int
        Bisection steps that resolve the widest cell of ``guide``.

    Examples
    --------
    >>> values, slopes, inv_width, cubic, guide, steps = tabulate(
    ...     np.array([0.0, 0.5, 1.0]), np.ones((1, 3)), np.array([2.0]), 1)
    >>> values[:, 0], cubic[1, 0]
    (array([0.  , 0.25, 1.  ]), array([ 0.375,  0.5  , -0.125]))
    """
    # Eq. (11), Wang et al.: the table holds f_sp at the nodes (Erratum E18: without f_att)
    values = specular_RGB(nodes, C, n)
    slopes = pchip_slopes(nodes, values)
    h = np.diff(nodes)[:, None]
    delta = np.diff(values, axis=0)
    hd0, hd1 = h * slopes[:-1], h * slopes[1:]
    # h00 = 2s³ − 3s² + 1, h10 = s³ − 2s² + s, h01 = −2s³ + 3s², h11 = s³ − s², collected by power
    cubic = np.stack([hd0, 3.0 * delta - 2.0 * hd0 - hd1, hd0 + hd1 - 2.0 * delta], axis=-1)
    guide = guide_index(nodes, cells_per_entry)
    # bisection steps for the widest cell, with the one-interval margins of the kernel's lookup
    m = nodes.size - 1
    widest = (np.minimum(guide[1:] + 1, m - 1) - np.maximum(guide[:-1] - 1, 0) + 1).max()
    steps = int(np.ceil(np.log2(max(int(widest), 1))))
    return values, slopes, 1.0 / np.diff(nodes), np.ascontiguousarray(cubic), guide, steps


def build_table(
    material: SpectralPhong,
    entries: int,
    placement: str = "error",
    segments: int | None = None,
    compiled: bool = False,
    t_range=None,
    t_density=None,
    interpolation: str | None = None,
) -> SpecularTable:
    """Tabulate the specular functions of a material: place nodes, evaluate, precompute lookups.

    Eq. (11), Wang et al. (the tabulated function) at the nodes of Eq. (16), Wang et al. or of a
    registered alternative.

    Parameters
    ----------
    material : SpectralPhong
        Material and light.
    entries : int
        ``m``, the number of intervals (the table has ``m + 1`` nodes), in [1, 1e6].
    placement : str
        A key of ``PLACEMENT_METHODS``: ``"uniform"``, ``"importance"`` or ``"error"``.
    segments : int, optional
        ``p`` for ``"importance"`` (must divide ``entries``; default ``entries``).
    compiled : bool
        Use the numba twins of the placement (where it has one) and of :func:`tabulate` (the
        timed path).
    t_range : (float, float), optional
        The range of ``t`` over the frame's lit pixels (``ShadingBuffer.t_range``), for the
        placements that read it (``error``: ``phong_table.placement.seen_interval``); the paper's
        placements ignore it. The table still covers [0, 1].
    t_density : ndarray, optional
        The frame's pixel density in ``t`` over ``t_range`` (``ShadingBuffer.t_density``), for
        the same placements (``error`` also equidistributes the pixels' RMS error).
    interpolation : str, optional
        The interpolation the table will be read with, for the placements that place for it
        (``error`` grades its nodes for the parabolas: ``phong_table.placement.ERROR_GRADING``).
        The table can still be read with any interpolation.

    Returns
    -------
    SpecularTable

    Raises
    ------
    SpecrefError
        Unknown placement, bad ``entries``, ``segments`` that do not divide ``entries`` or given to
        a placement without segments.

    Examples
    --------
    >>> from phong_table.scenes import constant_material
    >>> table = build_table(constant_material(3.0), 3, "importance")
    >>> table.nodes.round(4)
    array([0.    , 0.7598, 0.9036, 1.    ])
    >>> build_table(constant_material(3.0), 10, "importance", segments=3)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: importance table: segments: must divide entries = 10, got 3
    """
    method, m, p = _checked_placement(material, placement, entries, segments)
    frame = _frame_keywords(method, m, t_range, t_density, interpolation)
    place = (method.compiled or method.reference) if compiled else method.reference
    nodes = np.ascontiguousarray(place(material, m, p, **frame), dtype=np.float64)
    # the compiled build runs no NumPy array operation between its kernels (phong_table._kernels)
    require(
        _kernels._increasing_kernel(nodes) if compiled else increasing(nodes),
        f"{placement} table: nodes are not strictly increasing from 0 to 1 (m = {m}); use fewer "
        "entries",
    )
    return _tabulated(material, nodes, compiled, placement, p)


def _checked_placement(material, placement: str, entries, segments):
    """The placement's registry entry and ``(m, p)``, checked with the material and segments."""
    method = PLACEMENT_METHODS.lookup(placement)
    require(
        isinstance(material, SpectralPhong),
        f"build_table: material must be a SpectralPhong, got {type(material).__name__}",
    )
    require(
        segments is None or method.segments,
        f"{placement} table: segments: only the importance placement takes segments, got "
        f"{segments!r}",
    )
    m, p = check_entries(entries, segments, f"{placement} table")
    return method, m, p


def _frame_keywords(method, m: int, t_range, t_density, interpolation) -> dict:
    """The frame as the placement reads it: the range and pixel density of t, the interpolation."""
    seen = {}
    if method.t_range and t_range is not None:
        seen = {"t_range": t_range, "t_density": t_density}
    if method.interpolation and interpolation is not None:
        check_interpolation(interpolation, m)
        seen["interpolation"] = interpolation
    return seen


def _tabulated(material, nodes, compiled: bool, placement: str, p: int) -> SpecularTable:
    """Eq. (11), Wang et al. at the nodes, and what every lookup needs (NumPy or numba twins)."""
    make = _kernels.tabulate_kernel if compiled else tabulate
    # Eq. (11), Wang et al. at the nodes, one power per distinct exponent (the same sum)
    C, n = material.specular_weights_distinct, material.n_distinct
    values, slopes, inv_width, cubic, guide, steps = make(nodes, C, n, GUIDE_CELLS_PER_ENTRY)
    zero = _kernels._zero_below_kernel(nodes, values) if compiled else zero_below(nodes, values)
    return SpecularTable(
        nodes=nodes,
        values=values,
        slopes=slopes,
        inv_width=inv_width,
        cubic=cubic,
        guide=guide,
        steps=int(steps),
        uniform=placement == "uniform" or (placement == "importance" and p == 1),
        an=material.an,
        placement=placement,
        segments=p,
        zero_below=float(zero),
    )

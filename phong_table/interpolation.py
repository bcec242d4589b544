"""Reading a table of ``f_sp(t)`` between its nodes: linear, parabolic (in t or in w), monotone.

Wang et al. interpolate their table "parabolically" without naming the stencil or the coordinate.
specref offers both readings and two alternatives; :data:`INTERPOLATION_METHODS` maps the keys of
``--interp`` to them:

- ``linear``: the chord between the two nodes around ``t``;
- ``parabolic``: the literal reading, a 3-point Lagrange parabola **in t** through the node nearest
  to ``t`` and its two neighbours (the stencil is shifted inwards at the ends);
- ``parabolic_w``: the same parabola **in w = ir(t) = t^{an+1}** (Eq. (14), Wang et al.), the
  coordinate in which importance nodes with ``p = m`` are uniform; guarded against the underflow
  of ``t^{an+1}`` (Erratum E19);
- ``monotone``: the shape-preserving piecewise cubic Hermite interpolant of Fritsch & Carlson with
  the slopes of ``scipy.interpolate.PchipInterpolator`` (equal to it to 1e-12); every interval stays
  within its two tabulated values, so it never overshoots.

Each reference takes ``(nodes, values, t, an)`` and returns ``(..., 3)``; the compiled twins are the
pixel loops of ``phong_table._kernels.shade_table_kernel``, one per interpolation (the cubics and
parabolas packed once per call: ``_monotone_records``, ``_parabolic_records``,
``_parabolic_w_records``).

**Lookup.** The interval of ``t`` is ``i = searchsorted(nodes, t, "right") − 1`` clipped to
``[0, m − 1]``. The kernel finds it in O(1) for uniform tables (``i = ⌊t m⌋``) and, for other
tables, with an inverse-map index (:func:`guide_index`): ``K = 16 m`` uniform cells in t, each
storing the first and last interval it overlaps, then a fixed number of branch-free halvings
inside the cell, ``O(log(nodes per cell))``. Before either, the kernel tries the interval the
previous pixel found: pixels of a raster-ordered G-buffer see nearby ``t``, and on the scenes'
views most lookups end there, with one comparison.

References
----------
- F. N. Fritsch, R. E. Carlson, "Monotone Piecewise Cubic Interpolation", SIAM J. Numer. Anal.
  17(2), 1980.
- F. N. Fritsch, J. Butland, "A Method for Constructing Local Monotone Piecewise Cubic
  Interpolants", SIAM J. Sci. Stat. Comput. 5(2), 1984 (the weighted harmonic-mean slopes).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from phong_table import _kernels
from reference.registry import Method, Registry

__all__ = [
    "GUIDE_CELLS_PER_ENTRY",
    "INTERPOLATION_METHODS",
    "guide_index",
    "interpolate_linear",
    "interpolate_monotone",
    "interpolate_parabolic",
    "interpolate_parabolic_w",
    "interval_index",
    "pchip_slopes",
]

#: Cells of the inverse-map index per table entry (``K = 16 m``).
GUIDE_CELLS_PER_ENTRY = 16


def interval_index(nodes, t) -> np.ndarray:
    """Index ``i`` of the interval ``[t_i, t_{i+1}]`` that holds each ``t`` (binary search).

    Examples
    --------
    >>> interval_index(np.array([0.0, 0.5, 0.9, 1.0]), np.array([0.0, 0.5, 0.95, 1.0]))
    array([0, 1, 2, 2])
    """
    m = nodes.size - 1
    return np.clip(np.searchsorted(nodes, t, side="right") - 1, 0, m - 1)


def guide_index(nodes, cells_per_entry: int = GUIDE_CELLS_PER_ENTRY) -> np.ndarray:
    """The inverse-map index: the interval holding ``c/K`` for each cell edge, ``K = 16 m``.

    A ``t`` in cell ``c = ⌊t K⌋`` lies in an interval between ``guide[c]`` and ``guide[c + 1]``.

    Examples
    --------
    >>> guide_index(np.array([0.0, 0.9, 0.99, 1.0]), 1)
    array([0, 0, 0, 2])
    """
    K = cells_per_entry * (nodes.size - 1)
    return interval_index(nodes, np.arange(K + 1) / K).astype(np.int64)


def _prepare(nodes, values, t):
    nodes = np.asarray(nodes, dtype=np.float64)
    values = np.asarray(values, dtype=np.float64)
    t = np.asarray(t, dtype=np.float64)
    return nodes, values, t, interval_index(nodes, t)


def interpolate_linear(nodes, values, t, an=None) -> np.ndarray:
    """Linear interpolation of a table of the specular functions of Eq. (11), Wang et al.

    Parameters
    ----------
    nodes : ndarray, shape (m + 1,)
        Strictly increasing, from 0 to 1.
    values : ndarray, shape (m + 1, 3)
        ``f_sp`` at the nodes.
    t : array_like, shape (...,)
        Points in [0, 1].
    an : float, optional
        Unused.

    Returns
    -------
    ndarray, shape (..., 3)

    Examples
    --------
    >>> interpolate_linear(np.array([0.0, 0.5, 1.0]), np.array([[0.0] * 3, [0.25] * 3, [1.0] * 3]),
    ...                    np.array([0.75]))
    array([[0.625, 0.625, 0.625]])
    """
    nodes, values, t, i = _prepare(nodes, values, t)
    # the chord through (t_i, v_i) and (t_{i+1}, v_{i+1})
    s = ((t - nodes[i]) / (nodes[i + 1] - nodes[i]))[..., None]
    return values[i] + s * (values[i + 1] - values[i])


def _lagrange(x0, x1, x2, x, v0, v1, v2):
    """The 3-point Lagrange parabola through (x0, v0), (x1, v1), (x2, v2), evaluated at x."""
    l0 = (x - x1) * (x - x2) / ((x0 - x1) * (x0 - x2))
    l1 = (x - x0) * (x - x2) / ((x1 - x0) * (x1 - x2))
    l2 = (x - x0) * (x - x1) / ((x2 - x0) * (x2 - x1))
    return l0[..., None] * v0 + l1[..., None] * v1 + l2[..., None] * v2


def interpolate_parabolic(nodes, values, t, an=None) -> np.ndarray:
    """The literal parabolic interpolation: 3-point Lagrange in ``t`` around the nearest node.

    Wang et al., §5 ("parabolic interpolation"), read literally: the parabola in ``t`` through the
    node ``j`` nearest to ``t`` and its neighbours ``j ± 1`` (``j`` clipped to ``[1, m − 1]``). It
    is exact for quadratics, and overshoots where a wide interval meets a steep lobe (the first
    interval of an importance table).

    Parameters
    ----------
    nodes : ndarray, shape (m + 1,)
        Strictly increasing, from 0 to 1, ``m >= 2``.
    values : ndarray, shape (m + 1, 3)
        ``f_sp`` at the nodes (Eq. (11), Wang et al.).
    t : array_like, shape (...,)
        Points in [0, 1].
    an : float, optional
        Unused.

    Returns
    -------
    ndarray, shape (..., 3)

    Examples
    --------
    >>> nodes = np.array([0.0, 0.3, 0.7, 1.0])
    >>> interpolate_parabolic(nodes, np.stack([nodes**2] * 3, -1), np.array([0.5])).round(12)
    array([[0.25, 0.25, 0.25]])
    """
    nodes, values, t, i = _prepare(nodes, values, t)
    m = nodes.size - 1
    j = np.where(t - nodes[i] <= nodes[i + 1] - t, i, i + 1)
    j = np.clip(j, 1, m - 1)
    return _lagrange(
        nodes[j - 1], nodes[j], nodes[j + 1], t, values[j - 1], values[j], values[j + 1]
    )


def interpolate_parabolic_w(nodes, values, t, an: float = 0.0) -> np.ndarray:
    """Parabolic interpolation in ``w = ir(t) = t^{an+1}``, with an underflow guard.

    Eq. (14), Wang et al. gives ``w``; the stencil is the node nearest to ``t`` *in w* and its
    neighbours. Lagrange weights do not change when all ``w`` are scaled, so each stencil uses
    ``ŵ = exp((an+1)(ln t − ln t_top))`` relative to its top node, which keeps ``ŵ`` in [0, 1]
    where ``t^{an+1}`` itself underflows (``t < 0.7`` at ``an = 2000``). Where w cannot resolve
    the stencil (a node spacing below ``W_RESOLUTION = 1e-6`` of the stencil's w-span: the nodes
    crowd at ``w = 0``, or ``t^{an+1}`` underflowed), the parabola through nearly coincident points
    would have weights of order 1/spacing (1e66 on a uniform table at an = 222), so it is taken in
    ``t`` instead (Erratum E19).

    Parameters
    ----------
    nodes : ndarray, shape (m + 1,)
        Strictly increasing, from 0 to 1, ``m >= 2``.
    values : ndarray, shape (m + 1, 3)
        ``f_sp`` at the nodes.
    t : array_like, shape (...,)
        Points in [0, 1].
    an : float
        The average exponent (Eq. (13), Wang et al., Erratum E1), >= 0.

    Returns
    -------
    ndarray, shape (..., 3)

    Examples
    --------
    >>> nodes = np.sqrt(np.array([0.0, 0.25, 0.5, 0.75, 1.0]))  # uniform in w = t^2
    >>> values = np.stack([nodes**4] * 3, -1)  # = w^2, a parabola in w
    >>> interpolate_parabolic_w(nodes, values, np.array([0.8]), an=1.0).round(12)
    array([[0.4096, 0.4096, 0.4096]])
    """
    nodes, values, t, i = _prepare(nodes, values, t)
    m = nodes.size - 1
    a = an + 1.0

    def rescaled(x, log_top):
        # Eq. (14), Wang et al.: w = x^(an+1), divided by the top node's w
        with np.errstate(divide="ignore", over="ignore"):
            return np.where(x > 0.0, np.exp(a * (np.log(np.where(x > 0, x, 1.0)) - log_top)), 0.0)

    log_top = np.log(nodes[i + 1])
    w, w0 = rescaled(t, log_top), rescaled(nodes[i], log_top)
    j = np.where(w - w0 <= 1.0 - w, i, i + 1)
    j = np.clip(j, 1, m - 1)
    log_top = np.log(nodes[j + 1])
    y0, y1, y = rescaled(nodes[j - 1], log_top), rescaled(nodes[j], log_top), rescaled(t, log_top)
    in_w = np.minimum(y1 - y0, 1.0 - y1) >= _kernels.W_RESOLUTION
    x0 = np.where(in_w, y0, nodes[j - 1])
    x1 = np.where(in_w, y1, nodes[j])
    x2 = np.where(in_w, 1.0, nodes[j + 1])
    x = np.where(in_w, y, t)
    return _lagrange(x0, x1, x2, x, values[j - 1], values[j], values[j + 1])


def pchip_slopes(nodes, values) -> np.ndarray:
    """Node slopes of the monotone piecewise cubic Hermite interpolant (as SciPy's PCHIP).

    Interior slopes are the weighted harmonic mean of the neighbouring secants (Fritsch & Butland),
    0 where the secants differ in sign or vanish; end slopes use the one-sided three-point formula,
    set to 0 if its sign differs from the first secant's and limited to 3× the secant where the
    data turns. Written by hand because the table kernel needs them compiled-in; the test compares
    with ``scipy.interpolate.PchipInterpolator``.

    Parameters
    ----------
    nodes : ndarray, shape (m + 1,)
        Strictly increasing.
    values : ndarray, shape (m + 1, 3)
        Values.

    Returns
    -------
    ndarray, shape (m + 1, 3)

    Examples
    --------
    >>> pchip_slopes(np.array([0.0, 1.0, 2.0]), np.array([[0.0] * 3, [1.0] * 3, [2.0] * 3]))[1]
    array([1., 1., 1.])
    """
    x = np.asarray(nodes, dtype=np.float64)
    y = np.asarray(values, dtype=np.float64)
    h = np.diff(x)[:, None]
    delta = np.diff(y, axis=0) / h
    d = np.zeros_like(y)
    if x.size == 2:
        d[:] = delta
        return d
    # interior: weighted harmonic mean where the secants agree in sign
    w1 = 2.0 * h[1:] + h[:-1]
    w2 = h[1:] + 2.0 * h[:-1]
    agree = (np.sign(delta[1:]) == np.sign(delta[:-1])) & (delta[1:] != 0) & (delta[:-1] != 0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        harmonic = (w1 + w2) / (w1 / delta[:-1] + w2 / delta[1:])
    d[1:-1] = np.where(agree, harmonic, 0.0)
    # ends: one-sided three-point estimate, kept shape-preserving
    d[0] = _pchip_end_slope(h[0], h[1], delta[0], delta[1])
    d[-1] = _pchip_end_slope(h[-1], h[-2], delta[-1], delta[-2])
    return d


def _pchip_end_slope(h0, h1, m0, m1):
    d = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
    d = np.where(np.sign(d) != np.sign(m0), 0.0, d)
    turn = (np.sign(m0) != np.sign(m1)) & (np.abs(d) > np.abs(3.0 * m0))
    return np.where(turn, 3.0 * m0, d)


def interpolate_monotone(nodes, values, t, an=None, slopes=None) -> np.ndarray:
    """Monotone (shape-preserving) cubic Hermite interpolation: never overshoots.

    The PCHIP of Fritsch & Carlson, slopes from :func:`pchip_slopes`; on each interval the cubic is
    monotone, and the result is clamped to the interval's two values so that rounding cannot step
    outside them either (overshoot exactly 0).

    Parameters
    ----------
    nodes : ndarray, shape (m + 1,)
        Strictly increasing, from 0 to 1.
    values : ndarray, shape (m + 1, 3)
        ``f_sp`` at the nodes (Eq. (11), Wang et al.).
    t : array_like, shape (...,)
        Points in [0, 1].
    an : float, optional
        Unused.
    slopes : ndarray, shape (m + 1, 3), optional
        Precomputed :func:`pchip_slopes`.

    Returns
    -------
    ndarray, shape (..., 3)

    Examples
    --------
    >>> nodes = np.array([0.0, 0.5, 1.0])
    >>> interpolate_monotone(nodes, np.array([[0.0] * 3, [0.0] * 3, [1.0] * 3]), np.array([0.25]))
    array([[0., 0., 0.]])
    """
    nodes, values, t, i = _prepare(nodes, values, t)
    d = pchip_slopes(nodes, values) if slopes is None else slopes
    h = (nodes[i + 1] - nodes[i])[..., None]
    s = ((t - nodes[i]) / (nodes[i + 1] - nodes[i]))[..., None]
    # cubic Hermite basis on the interval
    h00 = (1.0 + 2.0 * s) * (1.0 - s) * (1.0 - s)
    h10 = s * (1.0 - s) * (1.0 - s)
    h01 = s * s * (3.0 - 2.0 * s)
    h11 = s * s * (s - 1.0)
    v0, v1 = values[i], values[i + 1]
    f = h00 * v0 + h10 * h * d[i] + h01 * v1 + h11 * h * d[i + 1]
    return np.clip(f, np.minimum(v0, v1), np.maximum(v0, v1))


def _example_inputs(rng):
    nodes = np.concatenate([[0.0], np.sort(rng.uniform(0.0, 1.0, 6)), [1.0]])
    return nodes, np.stack([nodes**5] * 3, axis=-1), rng.uniform(0.0, 1.0, 20), 4.0


@dataclass(frozen=True, kw_only=True)
class Interpolation(Method):
    """An interpolation of a specular table: ``reference(nodes, values, t, an) -> (..., 3)``.

    Parameters
    ----------
    code : int
        Its branch of ``shade_table_kernel`` (the compiled twin).
    min_entries : int
        The smallest table it accepts.
    order : int
        Its convergence order: error O(h^order) on smooth data.
    coordinate : {"t", "w"}
        The coordinate it interpolates in: ``t`` (any node set) or ``w = ir(t)``, in which only
        importance nodes with ``p = m`` are uniform.
    graded : bool
        Its stencil spans two intervals (the 3-point parabolas), so the error placement grades its
        nodes for it (``phong_table.placement.ERROR_GRADING``).
    """

    code: int
    min_entries: int
    order: int
    coordinate: str
    graded: bool


#: Interpolations by the keys of ``--interp``. Registration order is the order of Table 1's columns
#: and of the report: the paper's parabola first, its reading in w, then the alternatives.
INTERPOLATION_METHODS = Registry("interpolation", Interpolation)
INTERPOLATION_METHODS.register(
    Interpolation(
        "parabolic",
        interpolate_parabolic,
        None,
        "Eq. (11), Wang et al.",
        _example_inputs,
        code=_kernels.PARABOLIC,
        min_entries=3,
        order=3,
        coordinate="t",
        graded=True,
    )
)
INTERPOLATION_METHODS.register(
    Interpolation(
        "parabolic_w",
        interpolate_parabolic_w,
        None,
        "Eq. (14), Wang et al.",
        _example_inputs,
        code=_kernels.PARABOLIC_W,
        min_entries=3,
        order=3,
        coordinate="w",
        graded=True,
    )
)
INTERPOLATION_METHODS.register(
    Interpolation(
        "linear",
        interpolate_linear,
        None,
        "Eq. (11), Wang et al.",
        _example_inputs,
        code=_kernels.LINEAR,
        min_entries=1,
        order=2,
        coordinate="t",
        graded=False,
    )
)
INTERPOLATION_METHODS.register(
    Interpolation(
        "monotone",
        interpolate_monotone,
        None,
        "Eq. (11), Wang et al.",
        _example_inputs,
        code=_kernels.MONOTONE,
        min_entries=1,
        order=3,
        coordinate="t",
        graded=False,
    )
)

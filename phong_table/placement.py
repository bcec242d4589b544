"""Where to put the nodes of a table of ``f_sp(t)``: uniform, Wang's importance, and error-driven.

A table of ``m`` entries has ``m + 1`` nodes ``0 = t_0 < t_1 < ... < t_m = 1`` (the ``m`` intervals
of Eq. (16), Wang et al.). Every placement returns the nodes, strictly increasing, from 0 to 1; the
registry :data:`PLACEMENT_METHODS` maps the keys users type (``--placement``) to them.

- ``uniform``: ``t_q = q/m``.
- ``importance`` (:func:`table_importance_Wang`): Eqs. (12)-(16), Wang et al. The importance ratio
  ``ir(t) = t^{an+1}`` of the proxy ``t^{an}`` (``an`` the average exponent, Erratum E1) is split
  into ``p`` segments of equal weight, ``S_i = iir(i/p)``, and each segment into ``m/p`` equal
  intervals (Erratum E3).
- ``error`` (:func:`table_error`, ours): nodes that equidistribute the interpolation error of the
  *true* ``f_sp`` (all bands, all three channels), with a density floor.

The importance proxy ignores ``k_s``, the light and the spread of ``n(λ)``, and its first interval
``[0, S_1]`` has ``ir = 1/p`` of the weight whatever ``m`` is: with ``p = m`` and a bimodal ``n(λ)``
that interval never shrinks, so the table stops converging (see ``docs/phong-tables.md``).

**The error placement** (:func:`table_error`, ours). Its Notes derive the density: ``ρ ∝
|f^(k)|^{1/k}`` equidistributes the largest error of an interpolation of order ``k``.

**One density for three channels.** One node set serves the three channels and every
interpolation: the density is the larger of the normalised ``max_c |f_c''|^{1/2}`` and
``max_c |f_c'''|^{1/3}`` (``c`` over R, G, B; each channel's error is in the same display units),
which costs each interpolation at most half its own optimal nodes. A floor keeps intervals bounded
where the derivative vanishes (zero crossings of ``f^(k)``, ``n(λ) ≤ 1``):
``ρ = ρ_error/∫ρ_error + floor``.

**The seen range.** A view sees only part of [0, 1]: the scenes' near view, zoomed on the
highlight, sees ``t`` from about 0.78 to 1, and nodes below that are wasted on its pixels.
Given the frame's range ``[t_lo, t_hi]``, the density is equidistributed there
(:func:`fine_grid` mapped onto it) and each open side gets a margin interval and one more to
0 or 1 (:func:`place_seen`). The table is then exact only on the frame it was built for; in
Wang et al.'s use (editing spectra on a fixed view) that is the frame. The paper's placements
(``uniform``, ``importance``) do not read the range.

**The pixels' RMS.** The figure that matters is the RMS error over the frame's pixels, not the
largest error over ``t``: with ``p(t)`` the pixels' density in ``t`` (``t_density``,
:func:`pixel_density`), the mean square error is ``∫ p (c_k h^k f^(k))² dt = c_k² ∫ p
|f^(k)|² ρ^(−2k) dt``, which under ``∫ρ = m`` is smallest (a Lagrange multiplier) for ``ρ ∝
(p |f^(k)|²)^{1/(2k+1)}``. Pixels bunch where the view sees the highlight (the near view has
most of its pixels at ``t > 0.9``), where the max-norm density alone puts too few nodes. The
density is then the largest of the four normalised densities (``k = 2, 3``, pixel-weighted, and
max-norm at the weight :data:`ERROR_HEDGE`): the pixel-weighted ones lead, and the max-norm ones
take over only where they ask for more than twice as many nodes, which guards against a
histogram of few pixels (a small frame). ``tests/validation/studies/test_phong.py`` checks the
result against uniform and importance tables on measured materials.

**Grading for the parabola** (Erratum E85). The parabola of the interval around node ``j``
goes through ``t_{j-1}, t_j, t_{j+1}``; its error is ``|f^(3)| |(t - t_{j-1})(t - t_j)(t -
t_{j+1})|/6``, about ``h_{j-1} h_j^2`` rather than ``h^3`` where the two widths differ. Where
a narrow lobe (``n = 10^4`` in one band) meets the floor's wide intervals the widths jump by
~10^3 in one node and the parabola swings far below 0. For such interpolations the width
``w = M/(m ρ)`` is capped by a sweep each way at ``w(s) + g |t - s|`` (``g`` =
:data:`ERROR_GRADING`), so neighbouring widths differ by at most ``1/(1 - g)``. Linear
and monotone interpolation keep the ungraded nodes (grading cost the monotone table up to
3x at ``m = 200`` on such a lobe).

References
----------
- C.-M. Wang, J.-R. Chern, J. Lee, "An Efficient Spectral Rendering Technique for Phong Illumination
  Model".
- C. de Boor, *A Practical Guide to Splines*, rev. ed., 2001, ch. XII (equidistributing the error by
  node density ∝ |f^(k)|^(1/k)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from phong_table import _kernels
from phong_table.model import SpectralPhong, average_exponent_Wang
from reference.errors import require
from reference.registry import Method, Registry

__all__ = [
    "ERROR_DENSITY_FLOOR",
    "ERROR_GRADING",
    "ERROR_HEDGE",
    "MAX_ENTRIES",
    "PIXEL_DENSITY_CELLS",
    "PLACEMENT_METHODS",
    "check_density",
    "check_entries",
    "fine_grid",
    "importance_ratio_Wang",
    "inverse_importance_ratio_Wang",
    "pixel_density",
    "place_seen",
    "seen_interval",
    "table_error",
    "table_importance_Wang",
    "table_uniform",
]

#: Largest table size accepted (a million entries is already far past any error budget).
MAX_ENTRIES = 1_000_000
#: Uniform share added to the normalised error density of :func:`table_error`: at least
#: ``floor/(1 + floor)`` of the nodes are spread uniformly, so no interval exceeds
#: ``(1 + floor)/(floor · m)``.
ERROR_DENSITY_FLOOR = 0.1
#: Uniform cells over the seen range on which :func:`pixel_density` counts the frame's pixels.
PIXEL_DENSITY_CELLS = 64
#: Largest growth of the interval width per unit ``t`` (``|dw/dt|``) of :func:`table_error` for
#: the interpolations whose stencil spans two intervals (``Interpolation.graded``, the 3-point
#: parabolas): neighbouring intervals then differ by at most a factor ``1/(1 − g) = 2``. Without
#: it a lobe's narrow intervals meet the floor's wide ones in one step and the parabola through
#: them swings far below 0 (Erratum E85).
ERROR_GRADING = 0.5
#: Weight of the max-norm densities of :func:`table_error` when the pixels' density is given: they
#: hedge against a sparse or noisy pixel histogram and take over only where they ask for more
#: than ``1/ERROR_HEDGE`` times the pixel-weighted density.
ERROR_HEDGE = 0.5


def check_entries(entries, segments=None, where: str = "table") -> tuple[int, int | None]:
    """Validate a table size ``m`` and a segment count ``p`` (``p`` divides ``m``).

    Examples
    --------
    >>> check_entries(200, 20)
    (200, 20)
    >>> check_entries(200, 30)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: table: segments: must divide entries = 200, got 30
    """
    ok = isinstance(entries, int | np.integer) and not isinstance(entries, bool)
    require(
        ok and 1 <= entries <= MAX_ENTRIES,
        f"{where}: entries: must be an integer in [1, {MAX_ENTRIES}], got {entries!r}",
    )
    if segments is None:
        return int(entries), None
    ok = isinstance(segments, int | np.integer) and not isinstance(segments, bool)
    require(
        ok and 1 <= segments <= entries,
        f"{where}: segments: must be an integer in [1, entries = {entries}], got {segments!r}",
    )
    require(
        entries % segments == 0,
        f"{where}: segments: must divide entries = {entries}, got {segments}",
    )
    return int(entries), int(segments)


def table_uniform(model: SpectralPhong | None, entries: int, segments=None) -> np.ndarray:
    """Uniform nodes ``t_q = q/m``: the paper's baseline.

    Eq. (16), Wang et al., with ``p = 1`` (one segment spanning [0, 1]).

    Parameters
    ----------
    model : SpectralPhong or None
        Unused (the uniform table does not look at the material).
    entries : int
        ``m``, the number of intervals, >= 1.
    segments : None
        Not used by this placement.

    Returns
    -------
    ndarray, shape (m + 1,)

    Examples
    --------
    >>> table_uniform(None, 4)
    array([0.  , 0.25, 0.5 , 0.75, 1.  ])
    """
    m, _ = check_entries(entries, None)
    # Eq. (16), Wang et al. with p = 1: S_0 = 0, S_1 = 1, t_j = j/m
    return np.arange(m + 1, dtype=np.float64) / m


def importance_ratio_Wang(t, an: float) -> np.ndarray:
    """The importance ratio of the proxy ``t^{an}``: ``ir(t) = t^{an+1}``.

    Eq. (14), Wang et al.: Eq. (12), Wang et al. in closed form for the proxy ``f^app = t^{an}``
    of Eq. (13), Wang et al.

    Parameters
    ----------
    t : array_like
        Points in [0, 1].
    an : float
        The average exponent (Erratum E1), >= 0.

    Returns
    -------
    ndarray
        ``w`` in [0, 1]; it underflows to 0 for ``t^{an+1} < 1e-308`` (t < 0.7 at an = 2000).

    Examples
    --------
    >>> importance_ratio_Wang([0.0, 0.5, 1.0], 1.0)
    array([0.  , 0.25, 1.  ])
    """
    # Eq. (14), Wang et al.: ir(t) = ∫_0^t x^an dx / ∫_0^1 x^an dx = t^(an+1)
    return np.asarray(t, dtype=np.float64) ** (an + 1.0)


def inverse_importance_ratio_Wang(w, an: float) -> np.ndarray:
    """The inverse importance ratio ``iir(w) = w^{1/(an+1)}``.

    Eq. (15), Wang et al., with Erratum E4 (the paper prints ``a + 1`` for ``an + 1``).

    Examples
    --------
    >>> inverse_importance_ratio_Wang([0.0, 0.25, 1.0], 1.0)
    array([0. , 0.5, 1. ])
    """
    # Eq. (15), Wang et al. (Erratum E4): t = (an+1)-th root of w
    return np.asarray(w, dtype=np.float64) ** (1.0 / (an + 1.0))


def table_importance_Wang(model: SpectralPhong, entries: int, segments=None) -> np.ndarray:
    """Wang et al.'s importance-driven nodes: ``p`` equal-weight segments of ``m/p`` intervals.

    Eq. (16), Wang et al., on the segment ends of Eqs. (12)-(15), Wang et al., with Errata E1, E3
    and E4.

    Parameters
    ----------
    model : SpectralPhong
        The material; only its average exponent ``an`` is used (Eq. (13), Wang et al.).
    entries : int
        ``m``, the number of intervals.
    segments : int, optional
        ``p``, which must divide ``m``; default ``m`` (one interval per segment).

    Returns
    -------
    ndarray, shape (m + 1,)
        Strictly increasing nodes from 0 to 1.

    Notes
    -----
    With ``p = 1`` the nodes are exactly the uniform ones; with ``p = m`` and a constant exponent
    ``n`` they are ``t_q = (q/m)^{1/(n+1)}``.

    Examples
    --------
    >>> from phong_table.scenes import constant_material
    >>> table_importance_Wang(constant_material(1.0), 4).round(4)
    array([0.    , 0.5   , 0.7071, 0.866 , 1.    ])
    >>> table_importance_Wang(constant_material(1.0), 4, segments=2).round(4)
    array([0.    , 0.3536, 0.7071, 0.8536, 1.    ])
    """
    m, p = check_entries(entries, segments, "importance table")
    p = m if p is None else p
    an = average_exponent_Wang(model.n)
    # Eq. (15), Wang et al. (Erratum E4): segment ends S_i = iir(i/p), so W(S_i) = i/p
    S = inverse_importance_ratio_Wang(np.arange(p + 1) / p, an)
    # Eq. (16), Wang et al. (Erratum E3): t_{i·(m/p)+j} = S_i + j·(p/m)·(S_{i+1} − S_i)
    j = np.arange(m // p)
    t = S[:-1, None] + (j * p / m)[None, :] * (S[1:] - S[:-1])[:, None]
    return np.append(t.ravel(), 1.0)


def fine_grid(size: int = 256) -> np.ndarray:
    """The fine grid on which :func:`table_error` integrates its node density.

    ``size`` uniform points on [0, 1] and ``size`` points with ``1 − t`` geometric from 1e-9 to 1,
    merged: it resolves the lobe of ``t^n`` (width ~1/n near t = 1) for exponents up to ~1e8.

    Examples
    --------
    >>> g = fine_grid(8)
    >>> float(g[0]), float(g[-1]), bool((np.diff(g) > 0).all())
    (0.0, 1.0, True)
    """
    u = np.logspace(-9.0, 0.0, size)
    t = np.concatenate([np.linspace(0.0, 1.0, size), 1.0 - u, [0.0, 1.0]])
    return np.unique(np.clip(t, 0.0, 1.0))


_FINE_GRID = fine_grid()
_FINE_GRID.setflags(write=False)
_NO_CELLS = np.zeros(0)


def seen_interval(t_range, entries: int) -> tuple[float, float, int]:
    """The seen interval of :func:`table_error` before margins: ``(t_lo, t_hi, m_inner)``.

    A frame whose lit pixels see ``t`` in ``[t_lo, t_hi]`` (``ShadingBuffer.t_range``) needs the
    table there: ``m_inner`` intervals are equidistributed over the seen interval, and each side
    that stops short of 0 or 1 gets two more (:func:`place_seen`). Without a range (or with too
    few entries for the extra intervals, or a single ``t``) the whole of [0, 1] is seen.

    Examples
    --------
    >>> seen_interval(None, 8), seen_interval((0.9, 1.0), 8), seen_interval((0.2, 0.7), 8)
    ((0.0, 1.0, 8), (0.9, 1.0, 6), (0.2, 0.7, 4))
    >>> seen_interval((0.2, 0.7), 4)
    (0.0, 1.0, 4)
    """
    if t_range is None:
        return 0.0, 1.0, entries
    t_lo, t_hi = (float(x) for x in t_range)
    require(
        math.isfinite(t_lo) and math.isfinite(t_hi) and 0.0 <= t_lo <= t_hi <= 1.0,
        f"error table: t_range: must be 0 <= t_lo <= t_hi <= 1, got {t_range!r}",
    )
    inner = entries - 2 * (t_lo > 0.0) - 2 * (t_hi < 1.0)
    if inner < 2 or t_lo == t_hi:
        return 0.0, 1.0, entries
    return t_lo, t_hi, inner


def place_seen(place, entries: int, t_range) -> np.ndarray:
    """Nodes over the seen interval, a margin on each open side, then 0 and 1.

    ``place(t_lo, t_hi, m)`` returns ``m + 1`` nodes from ``t_lo`` to ``t_hi``. Below ``t_lo``
    (if > 0) come a node at ``t_lo − h``, with ``h`` the first seen interval's width, and 0; above
    ``t_hi`` (if < 1) likewise. The margin gives the slopes and parabolas at ``t_lo`` and ``t_hi``
    evenly spaced neighbours: PCHIP's slope and the 3-point parabola are first-order accurate only
    where neighbouring widths are alike, and a node whose other neighbour is 0 (or 1) is off by
    the whole of ``f`` there. Where a margin would reach 0 or 1, the seen interval is widened to
    0 or 1 instead (no end interval much narrower than its neighbour).

    Examples
    --------
    >>> line = lambda lo, hi, m: np.linspace(lo, hi, m + 1)
    >>> place_seen(line, 8, (0.5, 0.8)).round(3)       # four seen intervals, margins of 0.075
    array([0.   , 0.425, 0.5  , 0.575, 0.65 , 0.725, 0.8  , 0.875, 1.   ])
    >>> place_seen(line, 8, (0.5, 0.95)).round(3)      # 0.95 + 0.075 > 1: seen up to 1
    array([0.   , 0.417, 0.5  , 0.583, 0.667, 0.75 , 0.833, 0.917, 1.   ])
    """
    t_lo, t_hi, m = seen_interval(t_range, entries)
    # a gap to 0 or 1 narrower than the mean seen interval is taken at once (saves a placement)
    mean = (t_hi - t_lo) / m
    t_lo, t_hi = (0.0 if t_lo < mean else t_lo), (1.0 if 1.0 - t_hi < mean else t_hi)
    m = entries - 2 * (t_lo > 0.0) - 2 * (t_hi < 1.0)
    for _ in range(3):
        nodes = place(t_lo, t_hi, m)
        low = t_lo - (nodes[1] - nodes[0]) if t_lo > 0.0 else 0.0
        high = t_hi + (nodes[-1] - nodes[-2]) if t_hi < 1.0 else 1.0
        if (low > 0.0 or t_lo == 0.0) and (high < 1.0 or t_hi == 1.0):
            break
        # a margin reaches 0 or 1: the seen interval takes that end and the margin's intervals
        t_lo = t_lo if low > 0.0 else 0.0
        t_hi = t_hi if high < 1.0 else 1.0
        m = entries - 2 * (t_lo > 0.0) - 2 * (t_hi < 1.0)
    below = [0.0, low] if t_lo > 0.0 else []
    above = [high, 1.0] if t_hi < 1.0 else []
    return np.concatenate([below, nodes, above])


def pixel_density(t, t_range, cells: int = PIXEL_DENSITY_CELLS) -> np.ndarray | None:
    """The density of the frame's lit pixels in ``t``: a histogram over the seen range.

    ``cells`` uniform cells over ``t_range = (t_lo, t_hi)``; the values are pixels per unit ``t``
    divided by the number of lit pixels (``t > 0``), so they integrate to 1 over the range. None
    when no pixel is lit or the range is a single ``t``. :func:`table_error` weights the error by
    it, since the figure that matters is the RMS over the frame's pixels.

    Examples
    --------
    >>> pixel_density(np.array([0.0, 0.5, 0.6, 0.6, 0.9]), (0.5, 0.9), 4).round(6)
    array([2.5, 5. , 0. , 2.5])
    """
    if t_range is None or t_range[0] >= t_range[1]:
        return None
    t = np.asarray(t, dtype=np.float64)
    lit = t[t > 0.0]
    if lit.size == 0:
        return None
    edges = np.linspace(t_range[0], t_range[1], cells + 1)
    counts = np.histogram(np.clip(lit, t_range[0], t_range[1]), edges)[0]
    return counts / (lit.size * np.diff(edges))


def _pixel_weight(t_mid, t_range, t_density) -> np.ndarray:
    """:func:`pixel_density` at ``t_mid``: linear between cell centres, 0 outside the range."""
    if t_density is None:
        return np.zeros(0)
    t_lo, t_hi = t_range
    cells = np.asarray(t_density, dtype=np.float64)
    centres = t_lo + (np.arange(cells.size) + 0.5) * (t_hi - t_lo) / cells.size
    inside = (t_mid >= t_lo) & (t_mid <= t_hi)
    return np.interp(t_mid, centres, cells) * inside


def _fine_weights(t_lo, t_hi, t_range, t_density) -> tuple[np.ndarray, np.ndarray]:
    """The fine grid mapped onto ``[t_lo, t_hi]`` and :func:`_pixel_weight` at its midpoints.

    The compiled twin is ``phong_table._kernels._fine_weights_kernel``.
    """
    t_fine = t_lo + (t_hi - t_lo) * _FINE_GRID
    return t_fine, _pixel_weight(0.5 * (t_fine[1:] + t_fine[:-1]), t_range, t_density)


def table_error(
    model: SpectralPhong,
    entries: int,
    segments=None,
    floor: float = ERROR_DENSITY_FLOOR,
    t_range=None,
    t_density=None,
    interpolation: str | None = None,
) -> np.ndarray:
    """Nodes that equidistribute the interpolation error of the true specular functions (ours).

    Eq. (11), Wang et al. gives ``f_sp``; this placement replaces the proxy of Eqs. (12)-(13),
    Wang et al. by the derivatives of ``f_sp`` itself, over the range of ``t`` the frame sees.

    Parameters
    ----------
    model : SpectralPhong
        The material and light: ``f_sp(t) = Σ_λ C(λ) t^{n(λ)}``.
    entries : int
        ``m``, the number of intervals.
    segments : None
        Not used by this placement.
    floor : float
        Uniform share of the density, > 0 (:data:`ERROR_DENSITY_FLOOR`).
    t_range : (float, float), optional
        ``(t_lo, t_hi)``, the range of ``t`` over the frame's lit pixels
        (``phong_table.render.ShadingBuffer.t_range``); the nodes go there
        (:func:`seen_interval`). None: all of [0, 1].
    t_density : ndarray, shape (cells,), optional
        The frame's pixels per unit ``t`` over ``t_range`` (:func:`pixel_density`,
        ``ShadingBuffer.t_density``): the density also equidistributes the pixels' RMS error.
    interpolation : str, optional
        The interpolation the table will be read with (``INTERPOLATION_METHODS``): for one whose
        stencil spans two intervals (``Interpolation.graded``, the parabolas) the nodes are graded
        (:data:`ERROR_GRADING`). None: not graded (linear and monotone need no grading).

    Returns
    -------
    ndarray, shape (m + 1,)
        Strictly increasing nodes from 0 to 1, one node set for the three channels.

    Notes
    -----
    **Derivation.** Interpolating with a piecewise polynomial of order ``k`` (``k = 2`` for linear,
    ``k = 3`` for the parabola and for the monotone cubic, whose slopes are second-order accurate)
    leaves on an interval of width ``h`` around ``t`` an error ``e ≈ c_k h^k |f^(k)(t)|``. A node
    density ``ρ`` (nodes per unit ``t``, ``∫ρ = m``) gives ``h = 1/ρ``, so ``e(t) ≈ c_k
    |f^(k)(t)| / ρ(t)^k``. The largest error over [0, 1] is smallest when it is the same
    everywhere (equidistribution), i.e. when ``ρ ∝ |f^(k)|^{1/k}``, and then

    ``max e ≈ c_k (∫_0^1 |f^(k)|^{1/k} dt)^k / m^k``.

    For ``f = t^n`` the integral ``∫ (n(n−1)···)^{1/k} t^{(n−k)/k} dt ≈ k n^{1/k} · n^{(k−1)/k}/n``
    stays bounded as ``n`` grows (``≈ k``), so the error no longer depends on the exponent: this is
    why the placement converges where the uniform table (error ∝ ``n^k``) and the importance table
    (whose first interval does not shrink) do not.

    Each derivative's density is normalised, the largest taken and the floor added (module
    docstring: the channels, the floor, the seen range, the pixels' RMS, the grading for the
    parabola). The derivatives are evaluated at the midpoints of the fine grid, the density
    integrated there, and its cumulative inverted at ``q/m`` by linear interpolation; the
    compiled twin is ``phong_table._kernels.table_error_kernel``.

    Examples
    --------
    >>> from phong_table.scenes import constant_material
    >>> nodes = table_error(constant_material(500.0), 8)
    >>> nodes.round(3)
    array([0.   , 0.982, 0.99 , 0.994, 0.996, 0.997, 0.998, 0.999, 1.   ])
    """
    m, _ = check_entries(entries, None, "error table")
    require(np.isfinite(floor) and floor > 0, f"error table: floor: must be > 0, got {floor}")
    check_density(t_density, t_range)
    grading = _grading(interpolation)

    def place(t_lo, t_hi, m):
        t_fine, p = _fine_weights(t_lo, t_hi, t_range, t_density)
        return _error_nodes(model, m, floor, t_fine, p, grading)

    return place_seen(place, m, t_range)


def check_density(t_density, t_range) -> None:
    """Validate a ``t_density`` (:func:`pixel_density`) given to :func:`table_error`.

    Examples
    --------
    >>> check_density(np.array([0.5, 1.5]), (0.0, 1.0))
    >>> check_density(np.array([-1.0]), (0.0, 1.0))
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: error table: t_density: must be >= 0 (with a t_range), got [-1.]
    """
    if t_density is None:
        return
    density = np.asarray(t_density, dtype=np.float64)
    ok = t_range is not None and density.ndim == 1 and density.size > 0
    # compiled: no NumPy array operation in the compiled build (phong_table._kernels)
    if not (ok and _kernels._finite_nonnegative_kernel(density)):
        # formatted only on failure (the check runs on every table build)
        require(False, f"error table: t_density: must be >= 0 (with a t_range), got {density}")


def _grading(interpolation) -> float:
    """:data:`ERROR_GRADING` for an interpolation marked ``graded``, else 0 (no grading)."""
    if interpolation is None:
        return 0.0
    from phong_table.interpolation import INTERPOLATION_METHODS

    return ERROR_GRADING if INTERPOLATION_METHODS.lookup(interpolation).graded else 0.0


def _error_nodes(model: SpectralPhong, m: int, floor: float, t_fine, p, grading: float = 0.0):
    """``m + 1`` nodes over ``t_fine`` that equidistribute the error (table_error).

    ``p``: the pixel density at the fine grid's midpoints (empty: none).
    """
    t_lo, t_hi = t_fine[0], t_fine[-1]
    h = np.diff(t_fine)
    t_mid = 0.5 * (t_fine[1:] + t_fine[:-1])
    rho = np.zeros_like(t_mid)
    for k in (2, 3):
        f_k = np.abs(model.specular_derivative(t_mid, k)).max(axis=-1)
        # the largest error c_k h^k |f^(k)| is equidistributed by |f^(k)|^(1/k); the pixels'
        # mean square error Σ p (c_k h^k f^(k))² by (p |f^(k)|²)^(1/(2k+1)) (module docstring)
        densities = [(f_k ** (1.0 / k), ERROR_HEDGE if p.size else 1.0)]
        if p.size:
            densities.append(((p * f_k * f_k) ** (1.0 / (2 * k + 1)), 1.0))
        for rho_k, weight in densities:
            mass = (rho_k * h).sum()
            if mass > 0:
                rho = np.maximum(rho, weight * rho_k / mass)
    mass = (rho * h).sum()
    # the floor keeps its share of the nodes whatever the width of the seen interval
    rho = (rho / mass if mass > 0 else rho) + floor / (t_hi - t_lo)
    if grading > 0:
        rho = _graded(rho, t_fine, m, grading)
    cdf = np.concatenate([[0.0], np.cumsum(rho * h)])
    nodes = np.interp(cdf[-1] * np.arange(m + 1) / m, cdf, t_fine)
    nodes[0], nodes[-1] = t_lo, t_hi
    return nodes


def _graded(rho, t_fine, m, grading):
    """The density raised until neighbouring intervals differ in width by at most ``grading``.

    The width of the interval at ``t`` is ``w(t) = M/(m ρ(t))`` (``M = ∫ρ``); a sweep each way
    over the fine grid caps it at ``w(s) + grading·|t − s|`` (a lower envelope), so that
    ``|dw/dt| <= grading``: a node's two intervals differ by at most ``1/(1 − grading)``.
    """
    mass = float((rho * np.diff(t_fine)).sum())
    w = mass / (m * rho)
    t_mid = 0.5 * (t_fine[1:] + t_fine[:-1])
    for q in range(1, w.size):
        w[q] = min(w[q], w[q - 1] + grading * (t_mid[q] - t_mid[q - 1]))
    for q in range(w.size - 2, -1, -1):
        w[q] = min(w[q], w[q + 1] + grading * (t_mid[q + 1] - t_mid[q]))
    return mass / (m * w)


def _table_error_compiled(
    model: SpectralPhong,
    entries: int,
    segments=None,
    t_range=None,
    t_density=None,
    interpolation: str | None = None,
) -> np.ndarray:
    m, _ = check_entries(entries, None, "error table")
    check_density(t_density, t_range)
    grading = _grading(interpolation)
    # the same f_sp with one power per distinct exponent (SpectralPhong.n_distinct)
    C, n = model.specular_weights_distinct, model.n_distinct

    r_lo, r_hi = (0.0, 1.0) if t_range is None else (float(t_range[0]), float(t_range[1]))
    cells = _NO_CELLS if t_density is None else np.asarray(t_density, dtype=np.float64)
    t_lo, t_hi, _ = seen_interval(t_range, m)
    # place_seen with the error placement, in one compiled call
    return _kernels._place_seen_error_kernel(
        _FINE_GRID,
        t_lo,
        t_hi,
        m,
        r_lo,
        r_hi,
        cells,
        C,
        n,
        ERROR_DENSITY_FLOOR,
        ERROR_HEDGE,
        grading,
    )


def _example_inputs(rng):
    from phong_table.scenes import constant_material

    return constant_material(float(rng.uniform(1.0, 100.0))), 16, None


@dataclass(frozen=True, kw_only=True)
class Placement(Method):
    """A node placement: ``reference(model, entries, segments) -> nodes``.

    ``kernel`` (if any) is the numba twin of its density computation and ``compiled`` calls it with
    the reference's signature.

    Parameters
    ----------
    source : str
        Whose placement it is: the paper's, its baseline, or ours.
    segments : bool
        ``segments`` applies (the importance placement's p of Eq. (16), Wang et al.).
    t_range : bool
        It reads the frame's range of ``t`` (``t_range=``).
    interpolation : bool
        It places for the interpolation used (``interpolation=``).
    """

    source: str
    segments: bool
    t_range: bool = False
    interpolation: bool = False


#: Placements by the keys of ``--placement``. Registration order is the order of Table 1's rows and
#: of the report: the paper's placement, its uniform baseline, then ours.
PLACEMENT_METHODS = Registry("placement", Placement)
PLACEMENT_METHODS.register(
    Placement(
        "importance",
        table_importance_Wang,
        None,
        "Eq. (16), Wang et al.",
        _example_inputs,
        source="Wang et al.",
        segments=True,
    )
)
PLACEMENT_METHODS.register(
    Placement(
        "uniform",
        table_uniform,
        None,
        "Eq. (16), Wang et al.",
        _example_inputs,
        source="Wang et al. (baseline)",
        segments=False,
    )
)
PLACEMENT_METHODS.register(
    Placement(
        "error",
        table_error,
        _kernels.table_error_kernel,
        "Eq. (11), Wang et al.",
        _example_inputs,
        compiled=_table_error_compiled,
        source="ours",
        segments=False,
        t_range=True,
        interpolation=True,
    )
)

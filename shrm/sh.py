"""Real spherical harmonics to high order in float64: basis, projection of lat-long maps, synthesis.

§5.3, Herbert et al.: an environment is projected onto SH to order 100 before prefiltering. Herbert
et al. used 320-bit arithmetic for this (§7.3); that works around factorial overflow
(``(l + m)! > 1.8e308`` for l + m > 170) and is not needed. specref evaluates the normalized
associated Legendre functions

    λ_lm(x) = sqrt((2l+1)/(4π) (l-m)!/(l+m)!) P_l^m(x),    x = cos θ,

with the Condon–Shortley phase inside ``P_l^m``, by the three-term recurrences of Holmes &
Featherstone (2002), which contain no factorials:

- sectoral: ``λ_00 = 1/sqrt(4π)``, ``λ_mm = -sqrt((2m+1)/(2m)) sin θ λ_{m-1,m-1}``;
- column: ``λ_lm = a_lm (x λ_{l-1,m} - b_lm λ_{l-2,m})`` with
  ``a_lm = sqrt((4l²-1)/(l²-m²))``, ``b_lm = sqrt(((l-1)²-m²)/(4(l-1)²-1))``.

In plain float64 this is accurate to about 1e-13 at l = 100 and 1e-12 at l = 1000. It breaks only
where ``sin^m θ`` underflows the exponent range while ``λ_lm`` itself is not small, which first
happens near l ≈ 1930 (at sin θ ≈ 1/e, m ≈ 710). Above :data:`PLAIN_ORDER_LIMIT` specref switches
to the *scaled* recurrence: the same arithmetic, with the running values kept in
``[2^-200, 2^200]`` and a separate binary exponent (an extended-exponent number), as Holmes &
Featherstone's 10^-280 scaling does. Orders above :data:`SH_MAX_ORDER` are refused.

The real, orthonormal basis (``docs/conventions.md``), with ``(θ, φ)`` the lat-long angles of
``reference.envmap`` (y up, Mitsuba 3 orientation):

    Y_l0 = λ_l0(cos θ),  Y_lm = √2 λ_lm(cos θ) cos(mφ),  Y_l,-m = √2 λ_lm(cos θ) sin(mφ)   (m > 0)

stored at index ``l² + l + m``. Coefficients of C channels have shape ``(C, (L+1)²)``.

Projection of an ``H × W`` lat-long map uses its pixel rows θ_j = (j + ½)π/H, the nodes of Fejér's
first rule: an rFFT over φ per row, then the Legendre sum over θ with Fejér-1 weights. The rule
integrates polynomials in cos θ of degree < H exactly, so a map band-limited to L is projected
exactly when 2L < H. Three paths compute it (:data:`SH_BACKENDS`): ``numpy`` (the readable oracle),
``numba`` (its twin) and ``ducc0`` (``ducc0.sht``, whose ``F1`` geometry is this grid; we apply the
same Fejér-1 weights through its adjoint synthesis, so the three agree to rounding).

References
----------
- F. Herbert, J. Kirkenaer, O. Unter Ecker, "Achieving a Multi-spectral Virtual Reality", 2004.
- S. A. Holmes, W. E. Featherstone, "A unified approach to the Clenshaw summation and the recursive
  computation of very high degree and order normalised associated Legendre functions", J. Geodesy
  76, 279-299, 2002.
- L. Fejér, "Mechanische Quadraturen mit positiven Cotesschen Zahlen", Math. Z. 37, 1933.
- J. Waldvogel, "Fast construction of the Fejér and Clenshaw-Curtis quadrature rules", BIT 46, 2006.
- M. Reinecke, D. S. Seljebotn, "Libsharp - spherical harmonic transforms revisited", A&A 554, 2013
  (the algorithms behind ``ducc0.sht``).
"""

from __future__ import annotations

import functools

import numpy as np

from reference.envmap import check_latlong_shape, direction_to_latlong_uv
from reference.errors import require, require_choice
from reference.registry import Method, Registry

__all__ = [
    "PLAIN_ORDER_LIMIT",
    "SH_BACKENDS",
    "SH_KERNELS",
    "SH_MAX_ORDER",
    "check_order",
    "directions_to_theta_phi",
    "fejer1_weights",
    "latlong_ring_angles",
    "legendre_analysis",
    "legendre_recurrence_coefficients",
    "legendre_synthesis",
    "legendre_table",
    "n_coefficients",
    "order_of",
    "project_function",
    "project_latlong",
    "ring_cosines",
    "sh_basis",
    "sh_degrees_orders",
    "sh_evaluate",
    "sh_index",
    "synthesize_latlong",
]

#: Largest order evaluated with the plain float64 recurrence; above it the scaled one is used.
PLAIN_ORDER_LIMIT = 1800
#: Largest order specref accepts (tested against mpmath up to 2500).
SH_MAX_ORDER = 3000

_SCALE_BITS = 200
_BIG = 2.0**_SCALE_BITS
_SMALL = 2.0**-_SCALE_BITS


def check_order(order, where: str = "order", maximum: int = SH_MAX_ORDER) -> int:
    """Return ``order`` as an int after checking ``0 <= order <= maximum``.

    Raises
    ------
    SpecrefError
        Not an integer, negative, or above the limit.

    Examples
    --------
    >>> check_order(100)
    100
    >>> check_order(-1, "--order")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: --order: must be an integer in [0, 3000], got -1
    """
    ok = isinstance(order, int | np.integer) and not isinstance(order, bool)
    require(
        ok and 0 <= order <= maximum,
        f"{where}: must be an integer in [0, {maximum}], got {order!r}",
    )
    return int(order)


def n_coefficients(order: int) -> int:
    """Number of real SH coefficients up to order L: ``(L + 1)²``.

    Examples
    --------
    >>> n_coefficients(100)
    10201
    """
    return (int(order) + 1) ** 2


def order_of(n_coeffs: int, where: str = "coefficients") -> int:
    """The order L of a coefficient vector of length ``(L + 1)²``.

    Examples
    --------
    >>> order_of(9)
    2
    """
    L = round(np.sqrt(n_coeffs)) - 1
    require(
        L >= 0 and n_coeffs == (L + 1) ** 2,
        f"{where}: length {n_coeffs} is not (L+1)² for any order L",
    )
    return L


def sh_index(l, m):
    """Index of ``Y_lm`` in a coefficient vector: ``l² + l + m`` (``docs/conventions.md``).

    Examples
    --------
    >>> sh_index(0, 0), sh_index(1, -1), sh_index(1, 1), sh_index(2, -2)
    (0, 1, 3, 4)
    """
    return l * l + l + m


def sh_degrees_orders(order: int) -> tuple[np.ndarray, np.ndarray]:
    """Degree l and order m of every index up to ``order`` (inverse of :func:`sh_index`).

    Examples
    --------
    >>> l, m = sh_degrees_orders(1)
    >>> l, m
    (array([0, 1, 1, 1]), array([ 0, -1,  0,  1]))
    """
    index = np.arange(n_coefficients(order))
    l = np.floor(np.sqrt(index)).astype(np.int64)
    return l, index - l * l - l


def directions_to_theta_phi(directions) -> tuple[np.ndarray, np.ndarray]:
    """Polar angle θ from +y and azimuth φ of unit directions, in the lat-long convention.

    ``θ = π v`` and ``φ = 2π u`` with ``(u, v)`` of ``reference.envmap.direction_to_latlong_uv``.

    Examples
    --------
    >>> theta, phi = directions_to_theta_phi([[0.0, 0.0, -1.0], [1.0, 0.0, 0.0]])
    >>> theta.round(6), phi.round(6)
    (array([1.570796, 1.570796]), array([0.      , 1.570796]))
    """
    d = np.asarray(directions, dtype=np.float64)
    u, _ = direction_to_latlong_uv(d)
    # θ by atan2, accurate near the poles (acos(y) loses digits there)
    theta = np.arctan2(np.hypot(d[..., 0], d[..., 2]), d[..., 1])
    return theta, 2.0 * np.pi * u


def latlong_ring_angles(height: int) -> np.ndarray:
    """Row centres θ_j = (j + ½)π/H of a lat-long map: the Fejér-1 nodes.

    Examples
    --------
    >>> (latlong_ring_angles(4) / np.pi).round(3)
    array([0.125, 0.375, 0.625, 0.875])
    """
    return (np.arange(height) + 0.5) * np.pi / height


def fejer1_weights(n: int) -> np.ndarray:
    """Weights of Fejér's first quadrature rule on ``x_j = cos θ_j``, θ_j = (j + ½)π/n.

    ``∫_{-1}^{1} g(x) dx ≈ Σ_j w_j g(x_j)``, exact for polynomials of degree < n; the weights are
    positive and sum to 2:

        w_j = (2/n) (1 - 2 Σ_{k=1}^{⌊n/2⌋} cos(2k θ_j) / (4k² - 1))

    Parameters
    ----------
    n : int
        Number of nodes (the map height), >= 1.

    Returns
    -------
    ndarray, shape (n,)

    Examples
    --------
    >>> w = fejer1_weights(4)
    >>> w.round(6), round(float(w.sum()), 12)
    (array([0.264298, 0.735702, 0.735702, 0.264298]), 2.0)
    """
    require(int(n) >= 1, f"fejer1_weights: n must be >= 1, got {n}")
    theta = latlong_ring_angles(int(n))
    k = np.arange(1, n // 2 + 1)
    # Fejér's first rule: w_j = (2/n)(1 - 2 Σ_k cos(2kθ_j)/(4k²-1))
    series = np.cos(2.0 * np.outer(theta, k)) / (4.0 * k * k - 1.0)
    return (2.0 / n) * (1.0 - 2.0 * series.sum(axis=1))


def legendre_recurrence_coefficients(order: int) -> tuple[np.ndarray, np.ndarray]:
    """The column-recurrence coefficients a_lm, b_lm in the m-major triangular layout.

    Entry ``t(l, m) = m(2L + 3 - m)/2 + (l - m)``; ``a_mm = b_mm = 0``, ``a_{m+1,m} = sqrt(2m+3)``
    and ``b_{m+1,m} = 0``.

    Returns
    -------
    A, B : ndarray, shape ((L+1)(L+2)/2,)

    Examples
    --------
    >>> A, B = legendre_recurrence_coefficients(1)
    >>> A.round(4), B
    (array([0.    , 1.7321, 0.    ]), array([0., 0., 0.]))
    """
    L = int(order)
    A, B = [], []
    for m in range(L + 1):
        l = np.arange(m, L + 1, dtype=np.float64)
        a = np.zeros_like(l)
        b = np.zeros_like(l)
        # a_lm = sqrt((4l²-1)/(l²-m²)), b_lm = sqrt(((l-1)²-m²)/(4(l-1)²-1)) (Holmes & Featherstone)
        a[1:] = np.sqrt((4.0 * l[1:] ** 2 - 1.0) / (l[1:] ** 2 - m * m))
        b[2:] = np.sqrt(((l[2:] - 1.0) ** 2 - m * m) / (4.0 * (l[2:] - 1.0) ** 2 - 1.0))
        A.append(a)
        B.append(b)
    return np.concatenate(A), np.concatenate(B)


def ring_cosines(theta) -> tuple[np.ndarray, np.ndarray]:
    """``x = cos θ`` as ``sgn (1 - u)`` with ``u = 1 - |cos θ|`` computed without cancellation.

    ``u = 2 sin²(θ/2)`` in the northern hemisphere and ``2 cos²(θ/2)`` in the southern one, so
    ``x p = sgn (p - u p)`` stays exact near the poles, where ``cos θ`` itself is not
    representable (θ = 1e-6 gives 1 - cos θ = 5e-13 with a relative error of 2e-4).

    Examples
    --------
    >>> sgn, u = ring_cosines(np.array([1e-6, np.pi]))
    >>> sgn, u
    (array([ 1., -1.]), array([5.e-13, 0.e+00]))
    """
    theta = np.asarray(theta, dtype=np.float64)
    north = theta <= np.pi / 2
    u = np.where(north, 2.0 * np.sin(0.5 * theta) ** 2, 2.0 * np.cos(0.5 * theta) ** 2)
    return np.where(north, 1.0, -1.0), u


def _scaled_for(order: int, method: str) -> bool:
    require_choice(method, ("auto", "plain", "scaled"), "Legendre recurrence")
    return method == "scaled" or (method == "auto" and order > PLAIN_ORDER_LIMIT)


def legendre_table(order: int, theta, method: str = "auto", orders=None) -> np.ndarray:
    """Normalized associated Legendre functions λ_lm(cos θ) for 0 <= m <= l <= L.

    Eq. (3), Ramamoorthi & Hanrahan 2001 (the θ part of the real basis).

    Holmes & Featherstone's sectoral and column recurrences (module docstring); the readable NumPy
    oracle, vectorized over θ. ``method="scaled"`` carries a binary exponent beside each running
    value so that ``sin^m θ`` never underflows (extended-exponent arithmetic); ``"plain"`` is the
    textbook float64 recurrence; ``"auto"`` uses plain up to :data:`PLAIN_ORDER_LIMIT`.

    Parameters
    ----------
    order : int
        L, in [0, :data:`SH_MAX_ORDER`].
    theta : array_like, shape (N,)
        Polar angles in [0, π].
    method : {"auto", "plain", "scaled"}
    orders : sequence of int, optional
        Keep only the blocks of these orders m (default all), for large L.

    Returns
    -------
    ndarray, shape ((L+1)(L+2)/2, N)
        m-major layout: the block of order m holds l = m..L (only the kept blocks).

    Examples
    --------
    >>> legendre_table(1, [0.0, np.pi / 2]).round(6)   # λ_00, λ_10, λ_11
    array([[ 0.282095,  0.282095],
           [ 0.488603,  0.      ],
           [-0.      , -0.345494]])
    """
    L = check_order(order)
    scaled = _scaled_for(L, method)
    theta = np.atleast_1d(np.asarray(theta, dtype=np.float64))
    sgn, u = ring_cosines(theta)
    sin_theta = np.sin(theta)
    A, B = legendre_recurrence_coefficients(L)
    N = theta.size
    keep = set(range(L + 1)) if orders is None else {int(m) for m in orders}
    out = np.empty((sum(L + 1 - m for m in keep), N))
    row = 0
    p = np.full(N, 1.0 / np.sqrt(4.0 * np.pi))
    e = np.zeros(N, dtype=np.int64)
    t0 = 0
    for m in range(L + 1):
        if m > 0:
            # Sectoral recurrence: λ_mm = -sqrt((2m+1)/(2m)) sin θ λ_{m-1,m-1}
            p = -np.sqrt((2.0 * m + 1.0) / (2.0 * m)) * sin_theta * p
            if scaled:
                tiny = (p != 0.0) & (np.abs(p) < _SMALL)
                p = np.where(tiny, p * _BIG, p)
                e = np.where(tiny, e - _SCALE_BITS, e)
        if m not in keep:
            t0 += L + 1 - m
            continue
        p1, p2, e_col = p, np.zeros(N), e
        out[row] = np.ldexp(p1, e_col) if scaled else p1
        for l in range(m + 1, L + 1):
            t = t0 + l - m
            # Column recurrence: λ_lm = a_lm (x λ_{l-1,m} - b_lm λ_{l-2,m}), x p = sgn (p - u p)
            p1, p2 = A[t] * (sgn * (p1 - u * p1) - B[t] * p2), p1
            if scaled:
                big = np.abs(p1) > _BIG
                if big.any():
                    p1 = np.where(big, p1 * _SMALL, p1)
                    p2 = np.where(big, p2 * _SMALL, p2)
                    e_col = np.where(big, e_col + _SCALE_BITS, e_col)
            out[row + l - m] = np.ldexp(p1, e_col) if scaled else p1
        t0 += L + 1 - m
        row += L + 1 - m
    return out


def _table_blocks(order: int, table: np.ndarray) -> list[np.ndarray]:
    """Split an m-major table into its blocks, block m of shape (L+1-m, N)."""
    starts = np.cumsum([0] + [order + 1 - m for m in range(order + 1)])
    return [table[starts[m] : starts[m + 1]] for m in range(order + 1)]


@functools.lru_cache(maxsize=8)
def _ring_table(order: int, height: int, method: str) -> tuple[np.ndarray, ...]:
    """Legendre blocks on the rings of an ``height``-row map, cached (a property of the grid)."""
    table = legendre_table(order, latlong_ring_angles(height), method)
    table.setflags(write=False)
    return tuple(_table_blocks(order, table))


#: Cache the ring table only below this many float64 values (64 MB).
_RING_CACHE_VALUES = 8_000_000


def legendre_analysis(order: int, theta, w, F_cos, F_sin, method: str = "auto") -> np.ndarray:
    """The Legendre sum of the projection: ``c_lm = Σ_j w_j √2 λ_lm(θ_j) F_m(θ_j)``.

    Eq. (4), Ramamoorthi & Hanrahan 2001 (``L_lm = ∫ L Y_lm dω``), by Fejér-1 quadrature over
    the rings θ_j after the φ integral per ring (the ``√2`` is 1 for m = 0).

    Parameters
    ----------
    order : int
        L.
    theta, w : ndarray, shape (H,)
        Ring angles and θ-quadrature weights (for ``∫ g(θ) sin θ dθ``).
    F_cos, F_sin : ndarray, shape (L+1, H, C)
        ``∫ f(θ_j, φ) cos(mφ) dφ`` and ``∫ f(θ_j, φ) sin(mφ) dφ`` per ring.
    method : {"auto", "plain", "scaled"}
        The recurrence, as in :func:`legendre_table`.

    Returns
    -------
    ndarray, shape (C, (L+1)²)

    Examples
    --------
    >>> H = 4; theta = latlong_ring_angles(H); w = fejer1_weights(H)
    >>> F = np.zeros((2, H, 1)); F[0, :, 0] = 2 * np.pi   # f = 1: ∫ cos(0φ) dφ = 2π
    >>> legendre_analysis(1, theta, w, F, np.zeros_like(F)).round(6) + 0.0  # √(4π) Y_00
    array([[3.544908, 0.      , 0.      , 0.      ]])
    """
    L = int(order)
    H = len(theta)
    C = F_cos.shape[2]
    if (
        method == "auto"
        and L <= PLAIN_ORDER_LIMIT
        and (L + 1) * (L + 2) // 2 * H <= _RING_CACHE_VALUES
    ):
        same_grid = np.array_equal(theta, latlong_ring_angles(H))
        blocks = _ring_table(L, H, method) if same_grid else None
    else:
        blocks = None
    if blocks is None:
        blocks = _table_blocks(L, legendre_table(L, theta, method))
    out = np.zeros((C, (L + 1) ** 2))
    for m in range(L + 1):
        l = np.arange(m, L + 1)
        # Fejér-1 quadrature over the rings: Σ_j w_j λ_lm(θ_j) F_m(θ_j)
        lam_w = blocks[m] * w
        if m == 0:
            out[:, l * l + l] = (lam_w @ F_cos[0]).T
        else:
            out[:, l * l + l + m] = np.sqrt(2.0) * (lam_w @ F_cos[m]).T
            out[:, l * l + l - m] = np.sqrt(2.0) * (lam_w @ F_sin[m]).T
    return out


def legendre_synthesis(order: int, theta, coeffs, method: str = "auto"):
    """Ring Fourier amplitudes of ``Σ c_lm Y_lm``: ``Σ_m G_cos cos(mφ) + G_sin sin(mφ)`` per ring.

    Eq. (2), Ramamoorthi & Hanrahan 2001 (``L(θ, φ) = Σ L_lm Y_lm(θ, φ)``), summed over l per m.

    Parameters
    ----------
    order : int
        L.
    theta : ndarray, shape (H,)
        Ring angles.
    coeffs : ndarray, shape (C, (L+1)²)
    method : {"auto", "plain", "scaled"}

    Returns
    -------
    G_cos, G_sin : ndarray, shape (L+1, H, C)

    Examples
    --------
    >>> c = np.zeros((1, 4)); c[0, 0] = np.sqrt(4 * np.pi)   # f = 1
    >>> G_cos, G_sin = legendre_synthesis(1, latlong_ring_angles(2), c)
    >>> G_cos[0, :, 0].round(12)
    array([1., 1.])
    """
    L = int(order)
    theta = np.asarray(theta, dtype=np.float64)
    H = theta.size
    C = coeffs.shape[0]
    blocks = _table_blocks(L, legendre_table(L, theta, method))
    G_cos = np.zeros((L + 1, H, C))
    G_sin = np.zeros((L + 1, H, C))
    for m in range(L + 1):
        l = np.arange(m, L + 1)
        # Eq. (2), Ramamoorthi & Hanrahan 2001: Σ_l c_lm Y_lm, per ring and per m
        if m == 0:
            G_cos[0] = blocks[0].T @ coeffs[:, l * l + l].T
        else:
            G_cos[m] = np.sqrt(2.0) * blocks[m].T @ coeffs[:, l * l + l + m].T
            G_sin[m] = np.sqrt(2.0) * blocks[m].T @ coeffs[:, l * l + l - m].T
    return G_cos, G_sin


def sh_basis(order: int, directions, method: str = "auto") -> np.ndarray:
    """Real orthonormal SH ``Y_lm`` at unit directions (lat-long angles, ``docs/conventions.md``).

    Eq. (3), Ramamoorthi & Hanrahan 2001 (the real basis), to any order by the normalized
    recurrence, with the Condon–Shortley phase.

    Parameters
    ----------
    order : int
        L.
    directions : array_like, shape (..., 3)
        Unit directions, y up.
    method : {"auto", "plain", "scaled"}

    Returns
    -------
    ndarray, shape (..., (L+1)²)

    Examples
    --------
    >>> Y = sh_basis(1, [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    >>> Y.round(6)   # Y_1,-1 = -c x, Y_10 = c y, Y_11 = c z with c = sqrt(3/4π)
    array([[ 0.282095, -0.488603,  0.      , -0.      ],
           [ 0.282095,  0.      ,  0.488603,  0.      ],
           [ 0.282095,  0.      ,  0.      ,  0.488603]])
    """
    L = check_order(order)
    d = np.asarray(directions, dtype=np.float64)
    shape = d.shape[:-1]
    theta, phi = directions_to_theta_phi(d.reshape(-1, 3))
    blocks = _table_blocks(L, legendre_table(L, theta, method))
    out = np.empty((theta.size, n_coefficients(L)))
    for m in range(L + 1):
        l = np.arange(m, L + 1)
        # Real SH: Y_l0 = λ_l0; Y_lm = √2 λ_lm cos(mφ); Y_l,-m = √2 λ_lm sin(mφ)
        if m == 0:
            out[:, l * l + l] = blocks[0].T
        else:
            out[:, l * l + l + m] = np.sqrt(2.0) * blocks[m].T * np.cos(m * phi)[:, None]
            out[:, l * l + l - m] = np.sqrt(2.0) * blocks[m].T * np.sin(m * phi)[:, None]
    return out.reshape(*shape, -1)


def _as_coeffs(coeffs, where: str = "coefficients") -> tuple[np.ndarray, int, bool]:
    c = np.asarray(coeffs, dtype=np.float64)
    single = c.ndim == 1
    c = np.atleast_2d(c)
    require(c.ndim == 2, f"{where}: expected shape (C, (L+1)²), got {c.shape}")
    require(np.isfinite(c).all(), f"{where}: must be finite, found NaN or inf")
    return c, order_of(c.shape[1], where), single


def sh_evaluate(coeffs, directions, backend: str = "numpy", method: str = "auto") -> np.ndarray:
    """Synthesis at arbitrary directions: ``f(ω) = Σ_lm c_lm Y_lm(ω)`` (cube-map texels, normals).

    Eq. (2), Ramamoorthi & Hanrahan 2001.

    Parameters
    ----------
    coeffs : array_like, shape (C, (L+1)²) or ((L+1)²,)
    directions : array_like, shape (..., 3)
        Unit directions.
    backend : {"numpy", "numba", "ducc0"}
        ``numpy`` evaluates the basis in chunks (the oracle), ``numba`` runs the recurrence per
        direction, ``ducc0`` uses ``ducc0.sht.synthesis_general`` (NUFFT, accuracy 1e-12).
    method : {"auto", "plain", "scaled"}

    Returns
    -------
    ndarray, shape (..., C) (or (...,) for 1-D coefficients)

    Examples
    --------
    >>> c = np.zeros(4); c[2] = 1.0                       # Y_10 = sqrt(3/4π) y
    >>> sh_evaluate(c, [[0.0, 1.0, 0.0], [0.0, -1.0, 0.0]]).round(6)
    array([ 0.488603, -0.488603])
    """
    c, L, single = _as_coeffs(coeffs)
    SH_BACKENDS.lookup(backend)
    d = np.asarray(directions, dtype=np.float64)
    require(d.shape[-1:] == (3,), f"sh_evaluate: directions must be (..., 3), got {d.shape}")
    shape = d.shape[:-1]
    d = d.reshape(-1, 3)
    C = c.shape[0]
    if backend == "numba":
        from shrm._kernels import sh_evaluate_kernel

        theta, phi = directions_to_theta_phi(d)
        A, B = legendre_recurrence_coefficients(L)
        out = np.zeros((d.shape[0], C))
        sh_evaluate_kernel(
            L,
            *ring_cosines(theta),
            np.sin(theta),
            phi,
            A,
            B,
            np.ascontiguousarray(c.T),
            _scaled_for(L, method),
            out,
        )
    elif backend == "ducc0":
        out = _evaluate_ducc0(c, L, d)
    else:
        out = np.empty((d.shape[0], C))
        chunk = max(1, 4_000_000 // n_coefficients(L))
        for start in range(0, d.shape[0], chunk):
            # Eq. (2), Ramamoorthi & Hanrahan 2001: f(ω) = Σ c_lm Y_lm(ω)
            out[start : start + chunk] = sh_basis(L, d[start : start + chunk], method) @ c.T
    out = out.reshape(*shape, C)
    return out[..., 0] if single else out


# ducc0 stores complex a_lm (m >= 0) at m(2L+1-m)/2 + l; these convert to and from our real layout.
def _real_to_ducc0(c: np.ndarray, L: int) -> np.ndarray:
    l, m = sh_degrees_orders(L)
    pos = m >= 0
    alm = np.zeros((c.shape[0], (L + 1) * (L + 2) // 2), dtype=np.complex128)
    index = m[pos] * (2 * L + 1 - m[pos]) // 2 + l[pos]
    zero = m[pos] == 0
    real = np.where(zero[None, :], c[:, pos], c[:, pos] / np.sqrt(2.0))
    neg = np.where(zero, 0, l[pos] * l[pos] + l[pos] - m[pos])
    imag = np.where(zero[None, :], 0.0, -c[:, neg] / np.sqrt(2.0))
    alm[:, index] = real + 1j * imag
    return alm


def _ducc0_to_real(alm: np.ndarray, L: int) -> np.ndarray:
    l, m = sh_degrees_orders(L)
    index = np.abs(m) * (2 * L + 1 - np.abs(m)) // 2 + l
    a = alm[:, index]
    # c_l0 = Re a_l0; c_lm = √2 Re a_lm; c_l,-m = -√2 Im a_lm (ducc0 includes the CS phase)
    return np.where(m == 0, a.real, np.where(m > 0, np.sqrt(2.0) * a.real, -np.sqrt(2.0) * a.imag))


def _evaluate_ducc0(c, L, d):
    import ducc0

    theta, phi = directions_to_theta_phi(d)
    loc = np.ascontiguousarray(np.stack([theta, phi], axis=-1))
    alm = _real_to_ducc0(c, L)
    out = np.empty((d.shape[0], c.shape[0]))
    for channel in range(c.shape[0]):  # ducc0 transforms one spin-0 map per call
        out[:, channel] = ducc0.sht.synthesis_general(
            alm=alm[channel : channel + 1], spin=0, lmax=L, loc=loc, epsilon=1e-12
        )[0]
    return out


def _check_map(image, where: str) -> np.ndarray:
    image = np.asarray(image)
    if image.ndim == 2:
        image = image[..., None]
    require(image.ndim == 3, f"{where}: expected an (H, W, C) lat-long map, got {image.shape}")
    check_latlong_shape(image.shape, where)
    require(np.isfinite(image).all(), f"{where}: radiance must be finite, found NaN or inf")
    return image


def _ring_fourier(image: np.ndarray, L: int) -> tuple[np.ndarray, np.ndarray]:
    """Per ring: ∫ f cos(mφ) dφ and ∫ f sin(mφ) dφ for m <= L, by rFFT, shape (L+1, H, C)."""
    W = image.shape[1]
    spectrum = np.fft.rfft(image, axis=1)[:, : L + 1, :]
    # Pixel centres at φ_i = 2π(i + ½)/W: shift the DFT by e^{-imπ/W}; ∫ ... dφ ≈ (2π/W) Σ_i
    m = np.arange(L + 1)
    F = spectrum * ((2.0 * np.pi / W) * np.exp(-1j * m * np.pi / W))[None, :, None]
    F = np.moveaxis(F, 1, 0)
    return np.ascontiguousarray(F.real), np.ascontiguousarray(-F.imag)


def _project_numpy(image, L, w, method):
    """Projection path (NumPy rFFT and Legendre sum).

    Eq. (4), Ramamoorthi & Hanrahan 2001: ``c_lm = Σ_j w_j ∫ f Y_lm dφ``.

    Examples
    --------
    >>> _project_numpy(np.ones((4, 8, 1)), 1, fejer1_weights(4), "auto")[0, 0].round(6)
    np.float64(3.544908)
    """
    F_cos, F_sin = _ring_fourier(image, L)
    return legendre_analysis(L, latlong_ring_angles(image.shape[0]), w, F_cos, F_sin, method)


def _project_numba(image, L, w, method):
    """Projection path (numba kernel).

    Eq. (4), Ramamoorthi & Hanrahan 2001: ``c_lm = Σ_j w_j ∫ f Y_lm dφ``.

    Examples
    --------
    >>> _project_numba(np.ones((4, 8, 1)), 1, fejer1_weights(4), "auto")[0, 0].round(6)
    np.float64(3.544908)
    """
    from shrm._kernels import legendre_analysis_kernel

    F_cos, F_sin = _ring_fourier(image, L)
    theta = latlong_ring_angles(image.shape[0])
    A, B = legendre_recurrence_coefficients(L)
    out = np.zeros(((L + 1) ** 2, image.shape[2]))
    legendre_analysis_kernel(
        L, *ring_cosines(theta), np.sin(theta), w, A, B, F_cos, F_sin, _scaled_for(L, method), out
    )
    return np.ascontiguousarray(out.T)


def _project_ducc0(image, L, w, method):
    """Projection path (ducc0 adjoint synthesis).

    Eq. (4), Ramamoorthi & Hanrahan 2001: ``c_lm = Σ_j w_j ∫ f Y_lm dφ``.

    Examples
    --------
    >>> _project_ducc0(np.ones((4, 8, 1)), 1, fejer1_weights(4), "auto")[0, 0].round(6)
    np.float64(3.544908)
    """
    import ducc0

    W, C = image.shape[1:]
    # The same quadrature as the NumPy path: ring weights w_j (2π/W) through the adjoint synthesis.
    ringfactor = w * (2.0 * np.pi / W)
    alm = np.empty((C, (L + 1) * (L + 2) // 2), dtype=np.complex128)
    for channel in range(C):  # ducc0 transforms one spin-0 map per call
        alm[channel] = ducc0.sht.experimental.adjoint_synthesis_2d(
            map=np.ascontiguousarray(image[None, :, :, channel], dtype=np.float64),
            spin=0,
            lmax=L,
            geometry="F1",
            phi0=np.pi / W,
            ringfactor=ringfactor,
        )[0]
    return _ducc0_to_real(alm, L)


#: Quadrature weights over θ for a lat-long map of height H (for ∫ g(θ) sin θ dθ).
QUADRATURE_WEIGHTS = {
    "fejer1": fejer1_weights,
    "solid_angle": lambda H: (
        np.cos(np.arange(H) * np.pi / H) - np.cos(np.arange(1, H + 1) * np.pi / H)
    ),
}


def project_latlong(
    image,
    order: int,
    window=None,
    backend: str = "numpy",
    weights: str = "fejer1",
    method: str = "auto",
    where: str = "environment map",
) -> np.ndarray:
    """SH coefficients of a lat-long map: ``c_lm = ∫ f Y_lm dω`` by Fejér-1 quadrature.

    Eq. (4), Ramamoorthi & Hanrahan 2001; §5.3, Herbert et al. Rows sit at θ_j = (j + ½)π/H, the
    nodes of Fejér's first rule, which integrates polynomials in cos θ of degree < H exactly: a map
    band-limited to order L is projected exactly when 2L < H. ``weights="solid_angle"`` uses the
    exact pixel solid angles instead (a midpoint rule, round-trip error about 5e-4; not the
    default). Each channel is transformed, all channels at once on the NumPy and numba paths.

    Parameters
    ----------
    image : array_like, shape (H, W, C) or (H, W)
        Linear values, finite, ``W = 2H``.
    order : int
        L, in [0, min(:data:`SH_MAX_ORDER`, W/2 - 1)].
    window : str or callable, optional
        A window spec of ``shrm.windows`` (``"gaussian"``, ``"hanning:100"``...) applied to the
        coefficients; None or ``"none"`` keeps them.
    backend : {"numpy", "numba", "ducc0"}
    weights : {"fejer1", "solid_angle"}
    method : {"auto", "plain", "scaled"}
        Legendre recurrence (ignored by ducc0).
    where : str
        Name for messages (the file).

    Returns
    -------
    ndarray, shape (C, (L+1)²)

    Raises
    ------
    SpecrefError
        Not a 2:1 map, non-finite values, bad order, backend, weights or window.

    Examples
    --------
    >>> image = np.ones((8, 16, 1))
    >>> project_latlong(image, 2)[0, :4].round(6) + 0.0    # √(4π) Y_00 only
    array([3.544908, 0.      , 0.      , 0.      ])
    """
    image = _check_map(image, where)
    H, W, _ = image.shape
    L = check_order(order, f"{where}: order", min(SH_MAX_ORDER, W // 2 - 1))
    method_entry = SH_BACKENDS.lookup(backend)
    require_choice(weights, QUADRATURE_WEIGHTS, "quadrature weights")
    w = QUADRATURE_WEIGHTS[weights](H)
    coeffs = method_entry.reference(np.asarray(image, dtype=np.float64), L, w, method)
    if window is not None and window != "none":
        from shrm.windows import apply_window

        coeffs = apply_window(coeffs, window)
    return coeffs


def project_function(
    f, order: int, height: int | None = None, backend: str = "numpy"
) -> np.ndarray:
    """SH coefficients of a function of direction, sampled on a Fejér-1 lat-long grid.

    Eq. (4), Ramamoorthi & Hanrahan 2001. The default grid has ``H = 2L + 2`` rows, so a function
    band-limited to L is projected exactly (BRDF slices, SHRM texels).

    Parameters
    ----------
    f : callable
        ``f(directions (..., 3)) -> (...,) or (..., C)``.
    order : int
        L.
    height : int, optional
        Grid rows (default 2L + 2).
    backend : {"numpy", "numba", "ducc0"}

    Returns
    -------
    ndarray, shape (C, (L+1)²)

    Examples
    --------
    >>> project_function(lambda d: d[..., 1], 1).round(6)  # y = sqrt(4π/3) Y_10
    array([[0.      , 0.      , 2.046653, 0.      ]])
    """
    from reference.envmap import latlong_pixel_directions

    L = check_order(order)
    H = 2 * L + 2 if height is None else int(height)
    values = np.asarray(f(latlong_pixel_directions(H, 2 * H)), dtype=np.float64)
    if values.ndim == 2:
        values = values[..., None]
    return project_latlong(values, L, backend=backend, where="project_function")


def synthesize_latlong(
    coeffs, height: int, backend: str = "numpy", method: str = "auto"
) -> np.ndarray:
    """Values of ``Σ c_lm Y_lm`` at the pixel centres of a ``height × 2·height`` lat-long map.

    Eq. (2), Ramamoorthi & Hanrahan 2001: a Legendre sum per ring, then an inverse rFFT over φ.

    Parameters
    ----------
    coeffs : array_like, shape (C, (L+1)²) or ((L+1)²,)
    height : int
        H, with 2H > 2L (so that every m < W/2).
    backend : {"numpy", "numba", "ducc0"}
    method : {"auto", "plain", "scaled"}

    Returns
    -------
    ndarray, shape (H, 2H, C) (or (H, 2H) for 1-D coefficients)

    Examples
    --------
    >>> c = np.zeros(4); c[0] = np.sqrt(4 * np.pi)
    >>> synthesize_latlong(c, 2).round(12)
    array([[1., 1., 1., 1.],
           [1., 1., 1., 1.]])
    """
    c, L, single = _as_coeffs(coeffs)
    SH_BACKENDS.lookup(backend)
    H = int(height)
    W = 2 * H
    require(H >= 1 and L < H, f"synthesize_latlong: height must exceed the order {L}, got {H}")
    theta = latlong_ring_angles(H)
    if backend == "ducc0":
        import ducc0

        alm = _real_to_ducc0(c, L)
        out = np.empty((H, W, c.shape[0]))
        for channel in range(c.shape[0]):  # one spin-0 map per call
            out[..., channel] = ducc0.sht.synthesis_2d(
                alm=alm[channel : channel + 1],
                spin=0,
                lmax=L,
                geometry="F1",
                ntheta=H,
                nphi=W,
                phi0=np.pi / W,
            )[0]
    else:
        if backend == "numba":
            from shrm._kernels import legendre_synthesis_kernel

            A, B = legendre_recurrence_coefficients(L)
            G_cos = np.zeros((L + 1, H, c.shape[0]))
            G_sin = np.zeros_like(G_cos)
            legendre_synthesis_kernel(
                L,
                *ring_cosines(theta),
                np.sin(theta),
                A,
                B,
                np.ascontiguousarray(c.T),
                _scaled_for(L, method),
                G_cos,
                G_sin,
            )
        else:
            G_cos, G_sin = legendre_synthesis(L, theta, c, method)
        # Inverse rFFT, pixel centres at φ_i = 2π(i + ½)/W: X_m = (W/2)(G_cos - i G_sin) e^{imπ/W}
        m = np.arange(L + 1)
        X = np.zeros((H, W // 2 + 1, c.shape[0]), dtype=np.complex128)
        Z = (G_cos - 1j * G_sin) * np.exp(1j * m * np.pi / W)[:, None, None]
        X[:, : L + 1] = np.moveaxis(Z, 0, 1) * (W / 2.0)
        X[:, 0] *= 2.0
        out = np.fft.irfft(X, n=W, axis=1)
    return out[..., 0] if single else out


#: The projection paths: ``reference`` is ``project(image (H, W, C), L, w (H,), method)``.
SH_BACKENDS = Registry("SH backend")
SH_BACKENDS.register(
    Method(
        "numpy",
        _project_numpy,
        None,
        "Eq. (4), Ramamoorthi & Hanrahan 2001",
        extra={"description": "rFFT over φ, Legendre sum over θ in NumPy (the oracle)"},
    )
)
SH_BACKENDS.register(
    Method(
        "numba",
        _project_numba,
        None,
        "Eq. (4), Ramamoorthi & Hanrahan 2001",
        extra={"description": "rFFT over φ, Legendre recurrence and sum in one numba kernel"},
    )
)
SH_BACKENDS.register(
    Method(
        "ducc0",
        _project_ducc0,
        None,
        "Eq. (4), Ramamoorthi & Hanrahan 2001",
        extra={"description": "ducc0.sht adjoint synthesis on the F1 grid, Fejér-1 ring weights"},
    )
)


def _example_table_inputs(rng):
    return 12, rng.uniform(0.0, np.pi, 7)


def _example_analysis_inputs(rng):
    H, L = 16, 6
    return (
        L,
        latlong_ring_angles(H),
        fejer1_weights(H),
        rng.normal(size=(L + 1, H, 2)),
        rng.normal(size=(L + 1, H, 2)),
    )


def _example_synthesis_inputs(rng):
    return 6, latlong_ring_angles(10), rng.normal(size=(2, 49))


def _example_evaluate_inputs(rng):
    d = rng.normal(size=(9, 3))
    return rng.normal(size=(2, 64)), d / np.linalg.norm(d, axis=-1, keepdims=True)


#: Readable NumPy functions and their numba twins (tests check each pair).
SH_KERNELS = Registry("SH kernel")


def _register_kernels():
    from shrm import _kernels as k

    SH_KERNELS.register(
        Method(
            "legendre_table",
            legendre_table,
            k.legendre_table_kernel,
            "Eq. (3), Ramamoorthi & Hanrahan 2001",
            _example_table_inputs,
        )
    )
    SH_KERNELS.register(
        Method(
            "legendre_analysis",
            legendre_analysis,
            k.legendre_analysis_kernel,
            "Eq. (4), Ramamoorthi & Hanrahan 2001",
            _example_analysis_inputs,
        )
    )
    SH_KERNELS.register(
        Method(
            "legendre_synthesis",
            legendre_synthesis,
            k.legendre_synthesis_kernel,
            "Eq. (2), Ramamoorthi & Hanrahan 2001",
            _example_synthesis_inputs,
        )
    )
    SH_KERNELS.register(
        Method(
            "sh_evaluate",
            sh_evaluate,
            k.sh_evaluate_kernel,
            "Eq. (2), Ramamoorthi & Hanrahan 2001",
            _example_evaluate_inputs,
        )
    )


_register_kernels()

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
``reference.geometry.envmap`` (y up, Mitsuba 3 orientation):

    Y_l0 = λ_l0(cos θ),  Y_lm = √2 λ_lm(cos θ) cos(mφ),  Y_l,-m = √2 λ_lm(cos θ) sin(mφ)   (m > 0)

stored at index ``l² + l + m``. Coefficients of C channels have shape ``(C, (L+1)²)``.

Projection onto this basis and synthesis on lat-long grids live in ``shrm.transform``;
:func:`sh_evaluate` synthesizes at arbitrary directions.

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

from reference.errors import require, require_choice
from reference.geometry.envmap import direction_to_latlong_uv

__all__ = [
    "PLAIN_ORDER_LIMIT",
    "SH_MAX_ORDER",
    "check_order",
    "directions_to_theta_phi",
    "fejer1_weights",
    "latlong_ring_angles",
    "legendre_recurrence_coefficients",
    "legendre_table",
    "n_coefficients",
    "order_of",
    "ring_cosines",
    "sh_basis",
    "sh_degrees_orders",
    "sh_evaluate",
    "sh_index",
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

    ``θ = π v`` and ``φ = 2π u`` with ``(u, v)`` of
    ``reference.geometry.envmap.direction_to_latlong_uv``.

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


@functools.lru_cache(maxsize=16)
def _fejer1_weights_cached(n: int) -> np.ndarray:
    theta = latlong_ring_angles(n)
    k = np.arange(1, n // 2 + 1)
    # Fejér's first rule: w_j = (2/n)(1 - 2 Σ_k cos(2kθ_j)/(4k²-1))
    series = np.cos(2.0 * np.outer(theta, k)) / (4.0 * k * k - 1.0)
    w = (2.0 / n) * (1.0 - 2.0 * series.sum(axis=1))
    w.setflags(write=False)
    return w


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
    return _fejer1_weights_cached(int(n)).copy()


@functools.lru_cache(maxsize=16)
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
    m = np.concatenate([np.full(L + 1 - k, k) for k in range(L + 1)]).astype(np.float64)
    l = np.concatenate([np.arange(k, L + 1) for k in range(L + 1)]).astype(np.float64)
    A, B = np.zeros_like(l), np.zeros_like(l)
    with np.errstate(divide="ignore", invalid="ignore"):
        # a_lm = sqrt((4l²-1)/(l²-m²)), b_lm = sqrt(((l-1)²-m²)/(4(l-1)²-1)) (Holmes & Featherstone)
        a = np.sqrt((4.0 * l**2 - 1.0) / (l**2 - m**2))
        b = np.sqrt(((l - 1.0) ** 2 - m**2) / (4.0 * (l - 1.0) ** 2 - 1.0))
    A = np.where(l >= m + 1, a, 0.0)
    B = np.where(l >= m + 2, b, 0.0)
    for array in (A, B):
        array.setflags(write=False)
    return A, B


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


def legendre_table(
    order: int, theta, method: str = "auto", orders=None, backend: str = "numpy"
) -> np.ndarray:
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
    backend : {"numpy", "numba"}
        ``numba`` runs the twin kernel.

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
    N = theta.size
    keep = set(range(L + 1)) if orders is None else {int(m) for m in orders}
    if backend == "numba":
        from shrm._kernels import legendre_table_kernel

        A, B = legendre_recurrence_coefficients(L)
        mask = np.zeros(L + 1, dtype=np.bool_)
        mask[sorted(keep)] = True
        out = np.empty((sum(L + 1 - m for m in keep), N))
        legendre_table_kernel(L, *ring_cosines(theta), np.sin(theta), A, B, scaled, mask, out)
        return out
    require_choice(backend, ("numpy", "numba"), "Legendre backend")
    blocks = [block for _, block in _legendre_blocks(L, theta, scaled, keep)]
    return np.concatenate(blocks) if blocks else np.empty((0, N))


def _legendre_blocks(L: int, theta: np.ndarray, scaled: bool, keep=None):
    """Yield ``(m, block)`` with block[l - m, j] = λ_lm(θ_j), l = m..L, for the orders in ``keep``.

    Holmes & Featherstone's sectoral and column recurrences, vectorized over θ (see
    :func:`legendre_table`).
    """
    sgn, u = ring_cosines(theta)
    sin_theta = np.sin(theta)
    A, B = legendre_recurrence_coefficients(L)
    N = theta.size
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
        if keep is not None and m not in keep:
            t0 += L + 1 - m
            continue
        block = np.empty((L + 1 - m, N))
        p1, p2, e_col = p, np.zeros(N), e
        block[0] = np.ldexp(p1, e_col) if scaled else p1
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
            block[l - m] = np.ldexp(p1, e_col) if scaled else p1
        t0 += L + 1 - m
        yield m, block


def _table_blocks(order: int, table: np.ndarray) -> list[np.ndarray]:
    """Split an m-major table into its blocks, block m of shape (L+1-m, N)."""
    starts = np.cumsum([0] + [order + 1 - m for m in range(order + 1)])
    return [table[starts[m] : starts[m + 1]] for m in range(order + 1)]


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
    require_choice(backend, ("numpy", "numba", "ducc0"), "SH backend")
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
        out = np.zeros((d.shape[0], C))
        chunk = max(1, 8_000_000 // (L + 1))
        scaled = _scaled_for(L, method)
        for start in range(0, d.shape[0], chunk):
            theta, phi = directions_to_theta_phi(d[start : start + chunk])
            acc = out[start : start + chunk]
            for m, block in _legendre_blocks(L, theta, scaled):
                l = np.arange(m, L + 1)
                # Eq. (2), Ramamoorthi & Hanrahan 2001: f(ω) = Σ_m Σ_l c_lm Y_lm(ω), per order m
                if m == 0:
                    acc += block.T @ c[:, l * l + l].T
                else:
                    acc += (
                        np.sqrt(2.0) * np.cos(m * phi)[:, None] * (block.T @ c[:, l * l + l + m].T)
                    )
                    acc += (
                        np.sqrt(2.0) * np.sin(m * phi)[:, None] * (block.T @ c[:, l * l + l - m].T)
                    )
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

"""Radially symmetric lobes and their Legendre coefficients (§5.4, Herbert et al.).

A lobe K depends only on the angle γ between a lookup direction n and an incident direction ω,
``K(ω · n)``. By the Funk–Hecke theorem, convolving a function on the sphere with it scales each SH
degree by (Eq. (7), Ramamoorthi & Hanrahan 2001, with ``Λ_l = sqrt(4π/(2l+1)) A_l``)

    Λ_l = 2π ∫_{-1}^{1} K(t) P_l(t) dt,

computed here by Gauss–Legendre quadrature, not by the Gaussian approximation ``exp(-l²/2s)`` of a
Phong lobe. :mod:`shrm.prefilter` applies the Λ_l to an environment.

Lobes (:data:`PREFILTER_KERNELS`, spec strings for ``--kernel``):

- ``lambert``: the clamped cosine ``max(t, 0)``; E is the irradiance and ``Λ_l = Â_l`` of
  Ramamoorthi & Hanrahan (closed form in :func:`lambert_Lambda_closed_form`).
- ``phong:S``: the normalized Phong lobe ``(s + 1)/(2π) max(t, 0)^s`` (Λ_0 = 1).
- ``table:FILE``: any radially symmetric lobe tabulated over the angle γ in [0, π] (radians, two
  columns ``angle_rad,value``), linear in γ between samples and 0 beyond the last angle.

The order adapts to the lobe (:func:`adaptive_order`): the smallest L whose truncated tail is
below ``tol`` in relative L2 norm, ``sqrt(Σ_{l>L} (2l+1) Λ_l² / Σ_l (2l+1) Λ_l²)`` (the total from
Parseval, ``Σ_l (2l+1) Λ_l² = 8π² ∫ K² dt``), so a Lambert map does not pay for order 100.

References
----------
- F. Herbert, J. Kirkenaer, O. Unter Ecker, "Achieving a Multi-spectral Virtual Reality", 2004.
- R. Ramamoorthi, P. Hanrahan, "An Efficient Representation for Irradiance Environment Maps",
  SIGGRAPH 2001.
"""

from __future__ import annotations

import csv
import functools
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reference.errors import SpecrefError, require
from reference.registry import Method, ParametricMethod, Registry
from shrm.sh import check_order

__all__ = [
    "DEFAULT_TOL",
    "PREFILTER_KERNELS",
    "RadialKernel",
    "adaptive_order",
    "kernel_lambert",
    "kernel_phong",
    "kernel_table",
    "lambert_Lambda_closed_form",
    "legendre_P",
    "parse_kernel",
    "phong_Lambda_gaussian",
    "truncation_tail",
]

#: Default tolerance of the adaptive order (relative L2 tail of the kernel's Legendre series).
DEFAULT_TOL = 1e-2


def legendre_P(order: int, t) -> np.ndarray:
    """Legendre polynomials ``P_l(t)``, l = 0..L, by Bonnet's recurrence.

    Returns
    -------
    ndarray, shape (L+1, ...)

    Examples
    --------
    >>> legendre_P(2, [1.0, 0.5])
    array([[ 1.   ,  1.   ],
           [ 1.   ,  0.5  ],
           [ 1.   , -0.125]])
    """
    t = np.asarray(t, dtype=np.float64)
    P = np.empty((int(order) + 1, *t.shape))
    P[0] = 1.0
    if order >= 1:
        P[1] = t
    for l in range(2, int(order) + 1):
        # Bonnet: l P_l = (2l-1) t P_{l-1} - (l-1) P_{l-2}
        P[l] = ((2 * l - 1) * t * P[l - 1] - (l - 1) * P[l - 2]) / l
    return P


@dataclass(frozen=True)
class RadialKernel:
    """A radially symmetric lobe ``K(γ)`` over the angle γ from the lookup direction.

    Attributes
    ----------
    name : str
        Its spec (``"lambert"``, ``"phong:32"``, ``"table:lobe.csv"``).
    profile : callable
        ``K(gamma)`` for angles in [0, π], vectorized.
    segments : ndarray
        Angles at which K may have kinks; the quadrature integrates piece by piece.
    power : tuple or None
        ``(s, scale)`` when ``K = scale · max(cos γ, 0)^s`` (the fast brute-force path).
    table : tuple or None
        ``(angles, values)`` of a tabulated lobe.
    """

    name: str
    profile: object
    segments: np.ndarray
    power: tuple | None = None
    table: tuple | None = None
    _cache: dict = field(default_factory=dict, compare=False, repr=False)

    def Lambda(self, order: int) -> np.ndarray:
        """Λ_l = 2π ∫ K(γ) P_l(cos γ) sin γ dγ for l = 0..L, by Gauss–Legendre per segment.

        Eq. (7), Ramamoorthi & Hanrahan 2001 (the Funk–Hecke factor of a radially symmetric
        kernel). The node count grows with L and is doubled once to check convergence.
        """
        L = check_order(order, f"kernel {self.name}: order")
        if L not in self._cache:
            n = L + 64 + int(4 * np.sqrt(self.power[0] if self.power else 0.0))
            a = self._quadrature(L, n)
            b = self._quadrature(L, 2 * n)
            require(
                np.abs(a - b).max() <= 1e-12 * max(np.abs(b).max(), 1e-300),
                f"kernel {self.name}: Λ_l quadrature did not converge",
            )
            b.setflags(write=False)
            self._cache[L] = b
        return self._cache[L]

    def _quadrature(self, L: int, n: int) -> np.ndarray:
        from scipy.special import roots_legendre

        # scipy's nodes agree with numpy's leggauss to 2e-16 and take milliseconds, where
        # leggauss's dense eigensolver takes seconds at the ~1000 nodes of order 511
        x, w = roots_legendre(n)
        total = np.zeros(L + 1)
        for g0, g1 in zip(self.segments[:-1], self.segments[1:], strict=True):
            gamma = 0.5 * (g1 - g0) * x + 0.5 * (g1 + g0)
            weight = 0.5 * (g1 - g0) * w * np.sin(gamma) * self.profile(gamma)
            # Λ_l = 2π ∫ K(γ) P_l(cos γ) sin γ dγ
            total += 2.0 * np.pi * (legendre_P(L, np.cos(gamma)) @ weight)
        return total

    def squared_norm(self) -> float:
        """``Σ_l (2l+1) Λ_l² = 8π² ∫ K(t)² dt`` (Parseval), by Gauss–Legendre per segment."""
        x, w = np.polynomial.legendre.leggauss(256)
        total = 0.0
        for g0, g1 in zip(self.segments[:-1], self.segments[1:], strict=True):
            gamma = 0.5 * (g1 - g0) * x + 0.5 * (g1 + g0)
            total += float(np.sum(0.5 * (g1 - g0) * w * np.sin(gamma) * self.profile(gamma) ** 2))
        return 8.0 * np.pi**2 * total


@functools.lru_cache(maxsize=1)
def kernel_lambert() -> RadialKernel:
    """The clamped cosine ``K = max(cos γ, 0)``: E is the irradiance.

    Eq. (8), Ramamoorthi & Hanrahan 2001 (its Λ_l are the Â_l).

    Examples
    --------
    >>> kernel_lambert().Lambda(2).round(6)          # π, 2π/3, π/4
    array([3.141593, 2.094395, 0.785398])
    """
    return RadialKernel(
        "lambert",
        lambda g: np.maximum(np.cos(g), 0.0),
        np.array([0.0, np.pi / 2]),
        power=(1.0, 1.0),
    )


@functools.lru_cache(maxsize=64)
def kernel_phong(s: float) -> RadialKernel:
    """The normalized Phong lobe ``(s+1)/(2π) max(cos γ, 0)^s`` (Λ_0 = 1).

    Eq. (7), Ramamoorthi & Hanrahan 2001 gives the convolution with it.

    Examples
    --------
    >>> kernel_phong(32).Lambda(2).round(6)
    array([1.      , 0.970588, 0.914286])
    """
    s = float(s)
    require(np.isfinite(s) and 0 <= s <= 1e5, f"kernel phong:{s:g}: exponent must be in [0, 1e5]")
    scale = (s + 1.0) / (2.0 * np.pi)
    # cos^s γ ≈ exp(−s γ²/2): a lobe of width 1/√s. Above s = 256 the quadrature is split at
    # 2^j/√s so that its nodes follow the lobe (a single segment missed it at s = 1e5)
    edges = [0.0, np.pi / 2]
    if s > 256:
        edges = [0.0, *(2.0**j / np.sqrt(s) for j in range(-1, 12) if 2.0**j / np.sqrt(s) < 1.5)]
        edges.append(np.pi / 2)
    return RadialKernel(
        f"phong:{s:g}",
        lambda g: scale * np.maximum(np.cos(g), 0.0) ** s,
        np.array(edges),
        power=(s, scale),
    )


def kernel_table(path) -> RadialKernel:
    """A tabulated lobe over angle (radians) from a two-column CSV.

    Eq. (7), Ramamoorthi & Hanrahan 2001 gives the convolution with it.

    The file has a header row and columns ``angle_rad, value``; angles strictly increase from 0
    and stay within [0, π]; values are finite and >= 0. K is linear in γ between samples and 0
    beyond the last angle.

    Raises
    ------
    SpecrefError
        Unreadable file, or a table that is not a function of angle in [0, π].

    Examples
    --------
    >>> kernel_table("/nonexistent.csv")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent.csv: kernel table: file not found
    """
    path = Path(path)
    require(path.is_file(), f"{path}: kernel table: file not found")
    try:
        rows = [r for r in csv.reader(path.read_text().splitlines()) if r and r[0].strip()]
    except (OSError, UnicodeDecodeError) as error:
        raise SpecrefError(
            f"{path}: kernel table: cannot read ({error.__class__.__name__})"
        ) from None
    data = []
    for number, row in enumerate(rows, start=1):
        try:
            data.append([float(row[0]), float(row[1])])
        except (ValueError, IndexError):
            require(number == 1, f"{path}: kernel table: row {number} is not two numbers: {row}")
    table = np.asarray(data)
    require(
        table.ndim == 2 and len(table) >= 2,
        f"{path}: kernel table: needs >= 2 rows of angle_rad,value",
    )
    angles, values = table[:, 0], table[:, 1]
    require(np.isfinite(table).all(), f"{path}: kernel table: values must be finite")
    require(
        angles[0] == 0.0 and (np.diff(angles) > 0).all() and angles[-1] <= np.pi,
        f"{path}: kernel table: angles must increase from 0 to at most π radians, got "
        f"[{angles.min():g}, {angles.max():g}]",
    )
    require((values >= 0).all(), f"{path}: kernel table: values must be >= 0")
    last = angles[-1]

    def profile(g):
        return np.where(g <= last, np.interp(g, angles, values), 0.0)

    segments = angles if last == np.pi else np.append(angles, np.pi)
    return RadialKernel(f"table:{path}", profile, segments, table=(angles, values))


#: Prefilter kernels by spec name; ``reference(param) -> RadialKernel``.
PREFILTER_KERNELS = Registry("kernel")
PREFILTER_KERNELS.register(
    Method("lambert", kernel_lambert, None, "Eq. (8), Ramamoorthi & Hanrahan 2001")
)
PREFILTER_KERNELS.register(
    ParametricMethod("phong", kernel_phong, None, "Eq. (7), Ramamoorthi & Hanrahan 2001", param="S")
)
PREFILTER_KERNELS.register(
    ParametricMethod(
        "table", kernel_table, None, "Eq. (7), Ramamoorthi & Hanrahan 2001", param="FILE"
    )
)


def parse_kernel(spec) -> RadialKernel:
    """A :class:`RadialKernel` from a spec: ``lambert``, ``phong:S`` or ``table:FILE``.

    Raises
    ------
    SpecrefError
        Unknown kernel, a missing or bad parameter.

    Examples
    --------
    >>> parse_kernel("phong:8").name
    'phong:8'
    >>> parse_kernel("ward")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: unknown kernel 'ward'; allowed: lambert, phong, table
    """
    if isinstance(spec, RadialKernel):
        return spec
    name, _, param = str(spec).partition(":")
    entry = PREFILTER_KERNELS.lookup(name)
    if not isinstance(entry, ParametricMethod):
        require(not param, f"kernel {name!r} takes no parameter, got {spec!r}")
        return entry.reference()
    require(param, f"kernel {name!r} needs a parameter: {name}:{entry.param}")
    if name == "phong":
        try:
            exponent = float(param)
        except ValueError:
            raise SpecrefError(f"kernel {spec!r}: the exponent must be a number") from None
        return entry.reference(exponent)
    return entry.reference(param)


def lambert_Lambda_closed_form(order: int) -> np.ndarray:
    """``Â_l`` of the clamped cosine in closed form, Eq. (8), Ramamoorthi & Hanrahan 2001.

    ``Â_0 = π``, ``Â_1 = 2π/3``, ``Â_l = 0`` for odd l > 1, and for even l
    ``Â_l = 2π (-1)^{l/2-1} / ((l+2)(l-1)) · l! / (2^l ((l/2)!)²)``, with the last factor by its
    product form (no factorials).

    Examples
    --------
    >>> lambert_Lambda_closed_form(4).round(6)
    array([ 3.141593,  2.094395,  0.785398,  0.      , -0.1309  ])
    """
    L = int(order)
    out = np.zeros(L + 1)
    out[0] = np.pi
    if L >= 1:
        out[1] = 2.0 * np.pi / 3.0
    binom = 1.0  # l! / (2^l ((l/2)!)²), updated for even l
    for l in range(2, L + 1, 2):
        binom *= (l - 1.0) / l
        # Eq. (8), Ramamoorthi & Hanrahan 2001
        out[l] = 2.0 * np.pi * (-1.0) ** (l // 2 - 1) / ((l + 2.0) * (l - 1.0)) * binom
    return out


def phong_Lambda_gaussian(s: float, order: int) -> np.ndarray:
    """The Gaussian approximation ``Λ_l ≈ exp(-l²/(2s))`` of the normalized Phong lobe.

    Ramamoorthi & Hanrahan 2002 (§4, the Phong BRDF in frequency space); kept to chart its error
    against the exact :meth:`RadialKernel.Lambda` (Eq. (7), Ramamoorthi & Hanrahan 2001).

    Examples
    --------
    >>> phong_Lambda_gaussian(32, 2).round(6)
    array([1.      , 0.984496, 0.939413])
    """
    l = np.arange(int(order) + 1)
    return np.exp(-(l**2) / (2.0 * s))


def truncation_tail(kernel, order: int) -> float:
    """Relative L2 norm of a kernel's Legendre series beyond order L.

    ``sqrt(Σ_{l>L} (2l+1) Λ_l² / Σ_l (2l+1) Λ_l²)``, the total by Parseval.

    Examples
    --------
    >>> round(truncation_tail("lambert", 2), 3)
    0.088
    """
    k = parse_kernel(kernel)
    Lam = k.Lambda(order)
    partial = float(np.sum((2 * np.arange(order + 1) + 1) * Lam**2))
    total = k.squared_norm()
    return float(np.sqrt(max(total - partial, 0.0) / total))


def adaptive_order(kernel, tol: float = DEFAULT_TOL, maximum: int = 1000) -> int:
    """The smallest order L with :func:`truncation_tail` below ``tol``.

    "Model no more than a scene needs": a Lambert map at tol 1e-2 needs order 14, not 100.

    Raises
    ------
    SpecrefError
        ``tol`` not in (0, 1), or no order up to ``maximum`` reaches it.

    Examples
    --------
    >>> adaptive_order("lambert", 1e-2), adaptive_order("phong:32", 1e-2)
    (14, 17)
    """
    require(0 < tol < 1, f"--tol: must be in (0, 1), got {tol}")
    k = parse_kernel(kernel)
    L = 16
    while True:
        Lam = k.Lambda(L)
        total = k.squared_norm()
        partial = np.cumsum((2 * np.arange(L + 1) + 1) * Lam**2)
        tail = np.sqrt(np.maximum(total - partial, 0.0) / total)
        below = np.nonzero(tail < tol)[0]
        if below.size:
            return int(below[0])
        require(
            maximum > L,
            f"kernel {k.name}: no order up to {maximum} reaches --tol {tol:g}; raise the tolerance",
        )
        L = min(2 * L, maximum)

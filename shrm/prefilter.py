"""Frequency-space prefiltering with radially symmetric kernels (§5.4, Herbert et al.).

Prefiltering convolves the environment L with a kernel K that depends only on the angle between the
lookup direction n and the incident direction ω:

    E(n) = ∫ L(ω) K(ω · n) dω.

By the Funk–Hecke theorem this scales each SH degree: ``E_lm = Λ_l L_lm`` (Eq. (7), Ramamoorthi &
Hanrahan 2001, where ``Λ_l = sqrt(4π/(2l+1)) A_l``), with the exact Legendre projection of the lobe

    Λ_l = 2π ∫_{-1}^{1} K(t) P_l(t) dt,

computed here by Gauss–Legendre quadrature (not the Gaussian approximation ``exp(-l²/2s)`` of a
Phong lobe, which is 9-10 % off per texel). The angular-domain convolution is quadratic per texel;
the frequency-space one is a product per coefficient (§5.4, Herbert et al.).

Kernels (:data:`PREFILTER_KERNELS`, spec strings for ``--kernel``):

- ``lambert``: the clamped cosine ``max(t, 0)``; E is the irradiance and ``Λ_l = Â_l`` of
  Ramamoorthi & Hanrahan (closed form in :func:`lambert_Lambda_closed_form`).
- ``phong:S``: the normalized Phong lobe ``(s + 1)/(2π) max(t, 0)^s`` (Λ_0 = 1).
- ``table:FILE``: any radially symmetric lobe tabulated over the angle γ in [0, π] (radians, two
  columns ``angle_rad,value``), linear in γ between samples and 0 beyond the last angle.

The order adapts to the kernel (:func:`adaptive_order`): the smallest L whose truncated tail is
below ``tol`` in relative L2 norm, ``sqrt(Σ_{l>L} (2l+1) Λ_l² / Σ_l (2l+1) Λ_l²)`` (the total from
Parseval, ``Σ_l (2l+1) Λ_l² = 8π² ∫ K² dt``), so a Lambert map does not pay for order 100.

The oracle is the brute-force angular convolution, :func:`prefilter_bruteforce`: per output
direction, ``Σ_p L_p K(ω_p · n) w_p`` over all map pixels with the same Fejér-1 weights as the
projection, so the two differ only by the truncation of K's Legendre series (exactly, by the
addition theorem).

References
----------
- F. Herbert, J. Kirkenaer, O. Unter Ecker, "Achieving a Multi-spectral Virtual Reality", 2004.
- R. Ramamoorthi, P. Hanrahan, "An Efficient Representation for Irradiance Environment Maps",
  SIGGRAPH 2001.
- R. Ramamoorthi, P. Hanrahan, "Frequency Space Environment Map Rendering", SIGGRAPH 2002.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reference.errors import SpecrefError, require, require_choice
from reference.registry import Method, Registry
from shrm.sh import (
    SH_MAX_ORDER,
    check_order,
    fejer1_weights,
    order_of,
    project_latlong,
    sh_degrees_orders,
    sh_evaluate,
    synthesize_latlong,
)

__all__ = [
    "BRUTEFORCE_METHODS",
    "DEFAULT_TOL",
    "PREFILTER_KERNELS",
    "PrefilterResult",
    "RadialKernel",
    "adaptive_order",
    "kernel_lambert",
    "kernel_phong",
    "kernel_table",
    "lambert_Lambda_closed_form",
    "legendre_P",
    "parse_kernel",
    "phong_Lambda_gaussian",
    "prefilter_bruteforce",
    "prefilter_coefficients",
    "prefilter_environment",
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
        x, w = np.polynomial.legendre.leggauss(n)
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
    return RadialKernel(
        f"phong:{s:g}",
        lambda g: scale * np.maximum(np.cos(g), 0.0) ** s,
        np.array([0.0, np.pi / 2]),
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
    Method(
        "phong", kernel_phong, None, "Eq. (7), Ramamoorthi & Hanrahan 2001", extra={"param": "S"}
    )
)
PREFILTER_KERNELS.register(
    Method(
        "table", kernel_table, None, "Eq. (7), Ramamoorthi & Hanrahan 2001", extra={"param": "FILE"}
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
    if "param" not in entry.extra:
        require(not param, f"kernel {name!r} takes no parameter, got {spec!r}")
        return entry.reference()
    require(param, f"kernel {name!r} needs a parameter: {name}:{entry.extra['param']}")
    if name == "phong":
        try:
            return entry.reference(float(param))
        except ValueError:
            raise SpecrefError(f"kernel {spec!r}: the exponent must be a number") from None
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


def prefilter_coefficients(coeffs, Lambda) -> np.ndarray:
    """Frequency-space convolution: ``E_lm = Λ_l L_lm``, Eq. (7), Ramamoorthi & Hanrahan 2001.

    Parameters
    ----------
    coeffs : array_like, shape (C, (L+1)²)
    Lambda : array_like, shape (L'+1,) or (C, L'+1), L' >= L
        One factor per degree, or one row per channel (a per-band Phong exponent).

    Returns
    -------
    ndarray, shape (C, (L+1)²)

    Examples
    --------
    >>> prefilter_coefficients(np.ones((1, 4)), np.array([1.0, 0.5]))
    array([[1. , 0.5, 0.5, 0.5]])
    """
    c = np.atleast_2d(np.asarray(coeffs, dtype=np.float64))
    L = order_of(c.shape[1])
    Lam = np.asarray(Lambda, dtype=np.float64)
    require(Lam.shape[-1] > L, f"prefilter: Λ has {Lam.shape[-1]} degrees, need {L + 1}")
    l, _ = sh_degrees_orders(L)
    # Eq. (7), Ramamoorthi & Hanrahan 2001: E_lm = Λ_l L_lm
    return c * Lam[..., l]


@dataclass(frozen=True)
class PrefilterResult:
    """A prefiltered environment: the values and how they were made.

    Attributes
    ----------
    values : ndarray
        ``(6, S, S, C)`` for a cube map, ``(H, 2H, C)`` for lat-long.
    format : str
        ``"cube"`` or ``"latlong"``.
    order : int
        The SH order used.
    kernel : str
        The kernel spec.
    Lambda : ndarray, shape (order+1,)
        The degree factors.
    tail : float
        :func:`truncation_tail` at ``order``.
    """

    values: np.ndarray
    format: str
    order: int
    kernel: str
    Lambda: np.ndarray
    tail: float


def prefilter_environment(
    image,
    kernel,
    order: int | None = None,
    tol: float = DEFAULT_TOL,
    output: str = "cube",
    size: int = 64,
    height: int | None = None,
    backend: str = "ducc0",
    where: str = "environment map",
) -> PrefilterResult:
    """Prefilter a lat-long environment in frequency space and sample it as a cube or lat-long map.

    §5.4, Herbert et al.: project (Fejér-1, order L), scale by Λ_l (Eq. (7), Ramamoorthi &
    Hanrahan 2001), synthesize at the output texels.

    Parameters
    ----------
    image : array_like, shape (H, W, C)
        Linear radiance, finite and >= 0, W = 2H.
    kernel : str or RadialKernel
        ``lambert``, ``phong:S`` or ``table:FILE``.
    order : int, optional
        Fixed order; default :func:`adaptive_order` at ``tol``.
    tol : float
        Tolerance of the adaptive order.
    output : {"cube", "latlong"}
    size : int
        Cube face size.
    height : int, optional
        Lat-long output height (default 2L + 2, at least 16).
    backend : {"ducc0", "numba", "numpy"}
        Projection and synthesis path.
    where : str
        Name for messages.

    Returns
    -------
    PrefilterResult

    Examples
    --------
    >>> r = prefilter_environment(np.ones((32, 64, 1)), "lambert", output="latlong")
    >>> r.order, r.values.shape, round(float(r.values.mean()), 6)    # E = π under L = 1
    (14, (30, 60, 1), 3.141593)
    """
    from reference.cubemap import cubemap_texel_directions

    image = np.asarray(image, dtype=np.float64)
    require(
        image.ndim == 3 and np.isfinite(image).all(),
        f"{where}: expected a finite (H, W, C) map, got shape {image.shape}",
    )
    require((image >= 0).all(), f"{where}: radiance must be >= 0, found {image.min():g}")
    require_choice(output, ("cube", "latlong"), "prefilter output format")
    k = parse_kernel(kernel)
    L = adaptive_order(k, tol) if order is None else check_order(order, f"{where}: order")
    L = min(L, image.shape[1] // 2 - 1, SH_MAX_ORDER)
    coeffs = prefilter_coefficients(
        project_latlong(image, L, backend=backend, where=where), k.Lambda(L)
    )
    if output == "cube":
        d = cubemap_texel_directions(size)
        values = sh_evaluate(coeffs, d, backend=backend)
    else:
        H = max(2 * L + 2, 16) if height is None else int(height)
        values = synthesize_latlong(coeffs, max(H, L + 1), backend=backend)
    return PrefilterResult(values, output, L, k.name, k.Lambda(L), truncation_tail(k, L))


def prefilter_bruteforce(image, kernel, directions, backend: str = "numba") -> np.ndarray:
    """The angular-domain oracle: ``E(n) = Σ_p L_p K(ω_p · n) w_p`` over every map pixel.

    Eq. (7), Ramamoorthi & Hanrahan 2001 in the angular domain (quadratic per texel, §5.4,
    Herbert et al.), with the Fejér-1 weights of the projection ``w_p = w_j 2π/W``.

    Parameters
    ----------
    image : array_like, shape (H, W, C)
        Lat-long radiance.
    kernel : str or RadialKernel
    directions : array_like, shape (..., 3)
        Unit lookup directions (cube texels, normals).
    backend : {"numba", "numpy"}

    Returns
    -------
    ndarray, shape (..., C)

    Examples
    --------
    >>> E = prefilter_bruteforce(np.ones((64, 128, 1)), "lambert", [[0.0, 1.0, 0.0]])
    >>> E.round(3)                                  # π under uniform unit radiance
    array([[3.142]])
    """
    from reference.envmap import latlong_pixel_directions

    image = np.asarray(image, dtype=np.float64)
    require(image.ndim == 3, f"prefilter_bruteforce: expected (H, W, C), got {image.shape}")
    require_choice(backend, ("numba", "numpy"), "brute-force backend")
    k = parse_kernel(kernel)
    H, W, C = image.shape
    omega = latlong_pixel_directions(H, W).reshape(-1, 3)
    w = np.repeat(fejer1_weights(H) * (2.0 * np.pi / W), W)
    radiance = image.reshape(-1, C)
    n = np.asarray(directions, dtype=np.float64)
    shape = n.shape[:-1]
    n = np.ascontiguousarray(n.reshape(-1, 3))
    out = np.zeros((n.shape[0], C))
    if backend == "numba":
        from shrm import _kernels

        if k.power is not None:
            _kernels.prefilter_bruteforce_power_kernel(
                n, omega, w, radiance, k.power[0], k.power[1], out
            )
        else:
            angles, values = k.table
            _kernels.prefilter_bruteforce_table_kernel(n, omega, w, radiance, angles, values, out)
    else:
        chunk = max(1, 2_000_000 // omega.shape[0])
        for start in range(0, n.shape[0], chunk):
            t = np.clip(n[start : start + chunk] @ omega.T, -1.0, 1.0)
            # Eq. (7), Ramamoorthi & Hanrahan 2001, angular domain: Σ_p L_p K(ω_p · n) w_p
            if k.power is not None:
                s, scale = k.power
                K = np.where(t > 0.0, scale * np.maximum(t, 0.0) ** s, 0.0)
            else:
                K = k.profile(np.arccos(t))
            out[start : start + chunk] = (K * w) @ radiance
    return out.reshape(*shape, C)


def _example_bruteforce_inputs(kernel_spec):
    def make(rng):
        d = rng.normal(size=(5, 3))
        return rng.random((8, 16, 2)), kernel_spec, d / np.linalg.norm(d, axis=-1, keepdims=True)

    return make


def _register_bruteforce():
    from shrm import _kernels

    BRUTEFORCE_METHODS.register(
        Method(
            "power",
            prefilter_bruteforce,
            _kernels.prefilter_bruteforce_power_kernel,
            "Eq. (7), Ramamoorthi & Hanrahan 2001",
            _example_bruteforce_inputs("phong:7.5"),
        )
    )
    BRUTEFORCE_METHODS.register(
        Method(
            "table",
            prefilter_bruteforce,
            _kernels.prefilter_bruteforce_table_kernel,
            "Eq. (7), Ramamoorthi & Hanrahan 2001",
            None,
        )
    )


#: The brute-force oracle: NumPy reference and numba kernels (power lobes, tabulated lobes).
BRUTEFORCE_METHODS = Registry("brute-force prefilter")
_register_bruteforce()

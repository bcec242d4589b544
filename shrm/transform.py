"""Projection of lat-long maps onto real SH and synthesis on lat-long grids (§5.3, Herbert et al.).

Rows of an ``H × W`` lat-long map sit at θ_j = (j + ½)π/H, the nodes of Fejér's first rule, which
integrates polynomials in cos θ of degree < H exactly: projection is an rFFT over φ per row, then
the Legendre sum over θ with Fejér-1 weights, so a map band-limited to L is projected exactly when
2L < H. Three paths compute it (:data:`SH_BACKENDS`): ``numpy`` (the readable oracle), ``numba``
(its twin) and ``ducc0`` (``ducc0.sht``, whose ``F1`` geometry is this grid; we apply the same
Fejér-1 weights as its ring factors, so the three agree to rounding). Synthesis is the reverse: a
Legendre sum per ring, then an inverse rFFT. The basis, its layout and the recurrences are in
``shrm.sh``.

References
----------
- F. Herbert, J. Kirkenaer, O. Unter Ecker, "Achieving a Multi-spectral Virtual Reality", 2004.
- L. Fejér, "Mechanische Quadraturen mit positiven Cotesschen Zahlen", Math. Z. 37, 1933.
- M. Reinecke, D. S. Seljebotn, "Libsharp - spherical harmonic transforms revisited", A&A 554, 2013
  (the algorithms behind ``ducc0.sht``).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from reference.errors import require, require_choice
from reference.geometry.envmap import check_latlong_shape
from reference.registry import Method, Registry
from shrm.sh import (
    SH_MAX_ORDER,
    _as_coeffs,
    _ducc0_to_real,
    _legendre_blocks,
    _real_to_ducc0,
    _scaled_for,
    _table_blocks,
    check_order,
    fejer1_weights,
    latlong_ring_angles,
    legendre_recurrence_coefficients,
    legendre_table,
    ring_cosines,
    sh_evaluate,
)

__all__ = [
    "QUADRATURE_WEIGHTS",
    "SH_BACKENDS",
    "SH_KERNELS",
    "ducc0_ring_analysis",
    "legendre_analysis",
    "legendre_synthesis",
    "project_function",
    "project_latlong",
    "synthesize_latlong",
]


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
    small = (L + 1) * (L + 2) // 2 * H <= _RING_CACHE_VALUES
    if method == "auto" and small and np.array_equal(theta, latlong_ring_angles(H)):
        blocks = enumerate(_ring_table(L, H, method))
    else:  # streamed block by block: O(L H) memory at any order
        blocks = _legendre_blocks(L, np.asarray(theta, dtype=np.float64), _scaled_for(L, method))
    out = np.zeros((C, (L + 1) ** 2))
    for m, block in blocks:
        l = np.arange(m, L + 1)
        # Fejér-1 quadrature over the rings: Σ_j w_j λ_lm(θ_j) F_m(θ_j)
        lam_w = block * w
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
    G_cos = np.zeros((L + 1, H, C))
    G_sin = np.zeros((L + 1, H, C))
    for m, block in _legendre_blocks(L, theta, _scaled_for(L, method)):
        l = np.arange(m, L + 1)
        # Eq. (2), Ramamoorthi & Hanrahan 2001: Σ_l c_lm Y_lm, per ring and per m
        if m == 0:
            G_cos[0] = block.T @ coeffs[:, l * l + l].T
        else:
            G_cos[m] = np.sqrt(2.0) * block.T @ coeffs[:, l * l + l + m].T
            G_sin[m] = np.sqrt(2.0) * block.T @ coeffs[:, l * l + l - m].T
    return G_cos, G_sin


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
    """Projection path (ducc0: one FFT pass for all channels, a Legendre transform per channel).

    Eq. (4), Ramamoorthi & Hanrahan 2001: ``c_lm = Σ_j w_j ∫ f Y_lm dφ``, with the same Fejér-1
    ring weights ``w_j 2π/W`` as the NumPy path (``ringfactor``), pixel centres at
    ``φ_i = 2π(i + ½)/W`` (``phi0 = π/W``). The channels are read in place as strided maps.

    Examples
    --------
    >>> _project_ducc0(np.ones((4, 8, 1)), 1, fejer1_weights(4), "auto")[0, 0].round(6)
    np.float64(3.544908)
    """
    return ducc0_ring_analysis(image, L, latlong_ring_angles(image.shape[0]), w)


def ducc0_ring_analysis(image, L: int, theta, w) -> np.ndarray:
    """The projection sum over the given rings with ducc0 (all rows of a map, or a row block).

    Eq. (4), Ramamoorthi & Hanrahan 2001: ``map2leg`` with the rings' own geometry (``ringfactor``
    ``w_j 2π/W``, ``phi0 = π/W``), then ``leg2alm`` at their θ_j, one channel per call.

    Examples
    --------
    >>> theta, w = latlong_ring_angles(4), fejer1_weights(4)
    >>> ducc0_ring_analysis(np.ones((4, 8, 1)), 1, theta, w)[0, 0].round(6)
    np.float64(3.544908)
    """
    import ducc0

    H, W, C = image.shape
    maps = np.asarray(image, dtype=np.float64).reshape(H * W, C).T  # (C, H·W) strided view
    leg = ducc0.sht.experimental.map2leg(
        map=maps,
        nphi=np.full(H, W, dtype=np.uint64),
        phi0=np.full(H, np.pi / W),
        ringstart=(np.arange(H) * W).astype(np.uint64),
        ringfactor=w * (2.0 * np.pi / W),
        mmax=L,
    )
    alm = np.empty((C, (L + 1) * (L + 2) // 2), dtype=np.complex128)
    for channel in range(C):  # ducc0's Legendre transform takes one spin-0 component per call
        alm[channel] = ducc0.sht.experimental.leg2alm(
            leg=leg[channel : channel + 1], lmax=L, theta=theta
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
    from reference.geometry.envmap import latlong_pixel_directions

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


@dataclass(frozen=True, kw_only=True)
class SHBackend(Method):
    """A projection path, ``project(image (H, W, C), L, w (H,), method)``, and how it computes."""

    description: str


#: The projection paths by the keys of ``--backend``.
SH_BACKENDS = Registry("SH backend", SHBackend)
for _name, _project, _description in (
    ("numpy", _project_numpy, "rFFT over φ, Legendre sum over θ in NumPy (the oracle)"),
    ("numba", _project_numba, "rFFT over φ, Legendre recurrence and sum in one numba kernel"),
    ("ducc0", _project_ducc0, "ducc0.sht adjoint synthesis on the F1 grid, Fejér-1 ring weights"),
):
    SH_BACKENDS.register(
        SHBackend(
            _name, _project, None, "Eq. (4), Ramamoorthi & Hanrahan 2001", description=_description
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

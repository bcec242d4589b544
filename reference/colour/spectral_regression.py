"""Camera RGB → reflectance spectra by polynomial regression on a target (Herbert et al., §4).

Herbert et al. expand an HDR panorama to 31 or more bands with "polynomial equations of the 5th
order that map RGB plus the higher order terms to the wavelengths of the measured target patches".
specref implements that regression:

- **Features** (:data:`REGRESSION_FEATURES`): ``polynomial`` — every monomial ``R^a G^b B^c`` with
  ``1 <= a + b + c <= d``, d = 1…5 (3, 9, 19, 34, 55 terms; no constant, so black stays black);
  ``root_polynomial`` — Finlayson et al.'s root-polynomials, the ``(a + b + c)``-th root of each
  monomial of degree ``<= d``, d = 1…4 (3, 6, 13, 22 distinct terms), which scale linearly with
  exposure.
- **Losses** (:data:`REGRESSION_LOSSES`, erratum E44). With the feature columns scaled to unit
  RMS over the target (the scale is then folded into ``W``), for the n target spectra S:

  - ``colorimetric`` (the default, :data:`DEFAULT_LOSS`): what ΔE94 measures, plus a spectral
    term, ``W = argmin (1/n)·Σ_i [Σ_L ||G_iL r_i||² + (β/b)·||r_i||²] + λ·||W||²`` with the
    residuals ``r_i = Wᵀx_i − s_i``; ``G_iL`` (3 × b) is ΔE94 linearised at patch i's
    spectrum under the capture illuminant and under A (:func:`delta_E94_jacobian`), so
    ``||G_iL r||`` is ΔE94 to first order in the spectral error r; the spectral term (b bands)
    keeps the spectra near the target's where the eye does not constrain them (√β is the ΔE94
    that a spectral RMS error of 1 costs).
    λ and β are chosen by k-fold cross-validation (:data:`CV_FOLDS` folds of a shuffle with seed
    :data:`CV_SEED`) from :data:`COLORIMETRIC_RIDGE_GRID` × :data:`SPECTRAL_WEIGHT_GRID`,
    minimizing the :data:`CV_PERCENTILE`-th percentile of the held-out ΔE94 under both lights
    (the targets are a peak and a mean, under two lights).
  - ``spectral``: ridge least squares on the spectra, ``W = argmin (1/n)·||X W − S||² + λ·||W||²``,
    λ from :data:`RIDGE_GRID` (0 and 10^-12 … 10^0 in half decades) by the same cross-validation,
    minimizing the held-out spectral RMS.
- **Augmentation** (erratum E44): ``fit_regression(augment=...)`` adds extra patches made from
  the target's (``reference.colour.spectral_target.product_augmentation``: the products of pairs of
  its patches, for a synthetic target whose camera is known), weighing ``a·n`` in total against the
  n patches' ``n``; ``a`` is chosen from :data:`AUGMENT_WEIGHT_GRID` with λ and β by the same
  cross-validation, each fold's extra patches made from the other folds' patches and scored on the
  fold's own patches only.
- **Exposure** (erratum E41): HDR texels are brighter than any target patch. A polynomial is
  applied to ``RGB / s`` and the result multiplied by ``s``, with ``s = max(1, max(R, G, B))``:
  texels inside the target's range are mapped as fitted, brighter ones keep their chromaticity.
  Root-polynomials are homogeneous of degree 1, so for them this changes nothing.
- **Model files** (:func:`save_regression`, :func:`load_regression`): JSON, written atomically.
  The format is documented in ``docs/spectral-environments.md``.

The spectra are *reflectance-like*: camera RGB is normalized so that the perfect white diffuser
under the capture illuminant is (1, 1, 1), and the model maps it to the target's reflectance. A
spectral panorama is relit by multiplying by the chosen illuminant (erratum E42).

References
----------
- F. Herbert et al., "Multispectral Virtual Reality", 2004, §4.
- G. D. Finlayson, M. Mackiewicz, A. Hurlbert, "Color Correction Using Root-Polynomial
  Regression", IEEE Transactions on Image Processing 24(5), 2015.
- A. E. Hoerl, R. W. Kennard, "Ridge Regression", Technometrics 12(1), 1970.
- CIE 116-1995, "Industrial colour-difference evaluation" (ΔE94); CIE 15:2004 (CIELAB).
- M. A. Woodbury, "Inverting modified matrices", Memorandum Report 42, Princeton, 1950.
"""

from __future__ import annotations

import functools
import itertools
import json
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import NamedTuple

import numpy as np

from reference.errors import SpecrefError, format_allowed, require
from reference.registry import Registry

__all__ = [
    "AUGMENT_WEIGHT_GRID",
    "COLORIMETRIC_RIDGE_GRID",
    "CV_FOLDS",
    "CV_PERCENTILE",
    "CV_SEED",
    "DEFAULT_LOSS",
    "MAX_RIDGE",
    "NONNEGATIVE_STRENGTH",
    "PIXELS_PER_BLOCK",
    "REGRESSION_FEATURES",
    "REGRESSION_LOSSES",
    "RELIT_ILLUMINANT",
    "RIDGE_GRID",
    "SPECTRAL_WEIGHT_GRID",
    "SpectralRegression",
    "delta_E94_jacobian",
    "feature_exponents",
    "feature_names",
    "features_RGB",
    "fit_regression",
    "load_regression",
    "model_XYZ_weights",
    "project_nonnegative",
    "save_regression",
    "spectralize_blocks",
    "spectralize_rows",
]

#: Pixels spectralized per block by default (whole rows, at least one): 2^17 pixels make 21 MB
#: of float32 output and ~66 MB of float64 features and spectra, large enough for an efficient
#: matrix product, small beside a panorama (64 rows of a 2k panorama, 10 of a 12k one).
PIXELS_PER_BLOCK = 1 << 17

#: Cross-validation folds and the seed of their shuffle.
CV_FOLDS = 5
CV_SEED = 20040101
#: Ridge strengths tried by cross-validation (relative to unit-RMS feature columns).
RIDGE_GRID = (0.0, *(10.0 ** (k / 2.0) for k in range(-24, 1)))
#: Largest ridge strength accepted from a user.
MAX_RIDGE = 1.0
#: Ridge strengths λ of the colorimetric loss tried by cross-validation (unit-RMS features, ΔE94²).
COLORIMETRIC_RIDGE_GRID = (1e-5, 1e-4, 1e-3, 1e-2, 1e-1)
#: Weights β of the spectral term of the colorimetric loss tried by cross-validation.
SPECTRAL_WEIGHT_GRID = (1e2, 1e3, 1e4, 1e5)
#: The colorimetric loss's cross-validated criterion: this percentile of held-out ΔE94.
CV_PERCENTILE = 95.0
#: The augmentation's total weight against the target's patches (0: none), by CV (erratum E44).
AUGMENT_WEIGHT_GRID = (0.0, 1.0, 2.0, 4.0)
#: The light a spectral panorama is relit under in the held-out targets (erratum E44); the
#: colorimetric loss measures ΔE94 under it beside the capture illuminant.
RELIT_ILLUMINANT = "A"
#: Model-file format tag and version (3: ``augmentation``; 2: ``loss`` and ``spectral_weight``;
#: version 1 files, all fitted with the spectral loss, and version 2 files are still read).
FORMAT = "specref-spectral-regression"
FORMAT_VERSION = 3
_READABLE_VERSIONS = (1, 2, 3)

#: Losses of :func:`fit_regression` by key (module docstring).
REGRESSION_LOSSES = Registry("regression losses", str)
REGRESSION_LOSSES.register("ΔE94 (capture illuminant and A) plus β · spectral", "colorimetric")
REGRESSION_LOSSES.register("spectral least squares", "spectral")
#: The loss `specref env fit` and the shipped model use (erratum E44).
DEFAULT_LOSS = "colorimetric"

#: Feature families by key: the range of degrees each allows.
REGRESSION_FEATURES = Registry("regression features", range)
REGRESSION_FEATURES.register(range(1, 6), "polynomial")
REGRESSION_FEATURES.register(range(1, 5), "root_polynomial")


def feature_exponents(kind: str, degree: int) -> np.ndarray:
    """Exponents of R, G, B of each feature: ``feature = R^e0 · G^e1 · B^e2``.

    Finlayson, Mackiewicz & Hurlbert 2015: the polynomial and the root-polynomial terms.

    Parameters
    ----------
    kind : {"polynomial", "root_polynomial"}
    degree : int
        1…5 for polynomials, 1…4 for root-polynomials.

    Returns
    -------
    ndarray, shape (n_features, 3)
        Exponents (fractions for root-polynomials), ordered by degree, then lexicographically.

    Examples
    --------
    >>> [len(feature_exponents("polynomial", d)) for d in range(1, 6)]
    [3, 9, 19, 34, 55]
    >>> [len(feature_exponents("root_polynomial", d)) for d in range(1, 5)]
    [3, 6, 13, 22]
    """
    degrees = REGRESSION_FEATURES.lookup(kind)
    require(
        isinstance(degree, int | np.integer) and degree in degrees,
        f"{kind} degree must be an integer in {degrees[0]}…{degrees[-1]}, got {degree!r}",
    )
    seen: list[tuple] = []
    for j in range(1, int(degree) + 1):
        for combo in itertools.combinations_with_replacement(range(3), j):
            a = tuple(combo.count(c) for c in range(3))
            # Finlayson et al. 2015, root-polynomials: the j-th root of a degree-j monomial
            e = tuple(Fraction(x, j) for x in a) if kind == "root_polynomial" else a
            if e not in seen:
                seen.append(e)
    return np.array([[float(x) for x in e] for e in seen])


def feature_names(kind: str, degree: int) -> list[str]:
    """Readable names of the features, e.g. ``R*G^2`` or ``(R*G)^(1/2)``.

    Examples
    --------
    >>> feature_names("root_polynomial", 2)
    ['R', 'G', 'B', '(R*G)^(1/2)', '(R*B)^(1/2)', '(G*B)^(1/2)']
    """
    names = []
    for e in feature_exponents(kind, degree):
        if kind == "root_polynomial":
            j = Fraction(1, 1)
            fractions = [Fraction(x).limit_denominator(12) for x in e]
            j = max(f.denominator for f in fractions)
            parts = [
                c + (f"^{int(f * j)}" if f * j > 1 else "")
                for c, f in zip("RGB", fractions, strict=True)
                if f
            ]
            body = "*".join(parts)
            names.append(body if j == 1 else f"({body})^(1/{j})")
        else:
            parts = [
                c + (f"^{int(x)}" if x > 1 else "") for c, x in zip("RGB", e, strict=True) if x
            ]
            names.append("*".join(parts))
    return names


def features_RGB(RGB, kind: str, degree: int) -> np.ndarray:
    """The feature matrix of RGB values: every monomial (or root-monomial) up to ``degree``.

    Finlayson, Mackiewicz & Hurlbert 2015: the polynomial and the root-polynomial terms.

    Parameters
    ----------
    RGB : array_like, shape (..., 3)
        Linear camera RGB, finite and >= 0.
    kind, degree
        As in :func:`feature_exponents`.

    Returns
    -------
    ndarray, shape (..., n_features)

    Examples
    --------
    >>> features_RGB([2.0, 3.0, 1.0], "polynomial", 2)
    array([2., 3., 1., 4., 6., 2., 9., 3., 1.])
    >>> features_RGB([4.0, 1.0, 0.0], "root_polynomial", 2)
    array([4., 1., 0., 2., 0., 0.])
    """
    RGB = np.asarray(RGB, dtype=np.float64)
    X_T = _features_T(RGB.reshape(-1, 3), kind, degree)
    return X_T.T.reshape(*RGB.shape[:-1], X_T.shape[0])


@functools.lru_cache(maxsize=16)
def _feature_terms(kind: str, degree: int) -> tuple:
    """Each feature as ``((channel, exponent as a Fraction), ...)`` over its channels in use."""
    return tuple(
        tuple((c, Fraction(x).limit_denominator(12)) for c, x in enumerate(e) if x > 0)
        for e in feature_exponents(kind, degree)
    )


def _features_T(RGB, kind: str, degree: int, out=None) -> np.ndarray:
    """Features of ``(N, 3)`` RGB as an ``(n_features, N)`` array (rows contiguous, for speed).

    Each feature is a product of per-channel powers ``x^f``, computed once per channel and
    exponent: integer powers by repeated products, 1/2, 1/4, 3/4 by square roots, 1/3 and 2/3 by
    cube roots, so no feature costs more than two products.
    """
    channels = [np.ascontiguousarray(RGB[:, c]) for c in range(3)]
    table: dict = {}

    def power(c: int, f: Fraction) -> np.ndarray:
        if (c, f) not in table:
            x = channels[c]
            if f == 1:
                value = x
            elif f.denominator == 1:
                value = power(c, f - 1) * x
            elif f in (Fraction(1, 2), Fraction(1, 4)):
                value = np.sqrt(power(c, 2 * f))
            elif f == Fraction(3, 4):
                value = power(c, Fraction(1, 2)) * power(c, Fraction(1, 4))
            elif f in (Fraction(1, 3), Fraction(2, 3)):
                value = np.cbrt(x) if f.numerator == 1 else power(c, Fraction(1, 3)) ** 2
            else:
                value = np.power(x, float(f))
            table[(c, f)] = value
        return table[(c, f)]

    terms = _feature_terms(kind, degree)
    out = np.empty((len(terms), len(RGB))) if out is None else out
    for i, term in enumerate(terms):
        # Finlayson et al. 2015: a term is the product of the channel powers
        factors = [power(c, f) for c, f in term]
        if len(factors) == 1:
            out[i] = factors[0]
        else:
            np.multiply(factors[0], factors[1], out=out[i])
            if len(factors) == 3:
                out[i] *= factors[2]
    table.clear()  # power() refers to itself: a cycle that would hold every block's arrays
    channels.clear()
    return out


@dataclass(frozen=True, eq=False)
class SpectralRegression:
    """A fitted RGB → spectrum regression: ``S = s · (features(RGB / s) @ coefficients)``.

    Herbert et al., §4 (the 5th-order polynomial from camera RGB to the target's spectra).

    Parameters
    ----------
    kind : str
        A key of :data:`REGRESSION_FEATURES`.
    degree : int
    coefficients : ndarray, shape (n_features, n_bands)
    wavelengths_nm : ndarray, shape (n_bands,)
    ridge : float
        The ridge strength used (relative to unit-RMS feature columns).
    illuminant : str
        The capture illuminant (the camera's white is the white diffuser under it).
    camera : str
        Whose sensitivities made the RGB.
    training_set : str
        The target's name.
    cv : dict
        The cross-validation: ``{"folds": k, "seed": ..., "grid": [...], "rms": [...]}`` for the
        spectral loss; ``{"folds", "seed", "criterion", "ridge_grid", "spectral_weight_grid",
        "scores"}`` (scores[i][j] for ridge i, weight j) for the colorimetric one (None when
        nothing was chosen).
    loss : str
        A key of :data:`REGRESSION_LOSSES`: how the coefficients were fitted.
    spectral_weight : float or None
        β of the colorimetric loss (None for the spectral loss).
    augmentation : dict or None
        ``{"method", "weight", "patches"}`` when the target was augmented (erratum E44; weight 0
        when cross-validation declined it), None otherwise.

    Examples
    --------
    >>> model = SpectralRegression("polynomial", 1, np.eye(3), np.array([450.0, 550.0, 650.0]))
    >>> model.predict([[0.2, 0.5, 4.0]])                 # B > 1: applied to RGB / 4, times 4
    array([[0.2, 0.5, 4. ]])
    """

    kind: str
    degree: int
    coefficients: np.ndarray
    wavelengths_nm: np.ndarray
    ridge: float = 0.0
    illuminant: str = "D65"
    camera: str = ""
    training_set: str = ""
    cv: dict | None = None
    loss: str = "spectral"
    spectral_weight: float | None = None
    augmentation: dict | None = None

    def __post_init__(self):
        REGRESSION_LOSSES.lookup(self.loss)
        n_features = len(feature_exponents(self.kind, self.degree))
        coefficients = np.asarray(self.coefficients, dtype=np.float64)
        wavelengths = np.asarray(self.wavelengths_nm, dtype=np.float64)
        require(
            coefficients.shape == (n_features, wavelengths.size),
            f"regression: coefficients must be ({n_features}, {wavelengths.size}), got "
            f"{coefficients.shape}",
        )
        require(np.isfinite(coefficients).all(), "regression: coefficients must be finite")
        object.__setattr__(self, "coefficients", coefficients)
        object.__setattr__(self, "wavelengths_nm", wavelengths)
        # the float32 copy for spectralizing (spectralize_rows)
        object.__setattr__(self, "_coefficients32", coefficients.astype(np.float32))

    @property
    def n_bands(self) -> int:
        """Number of bands of the spectra."""
        return self.wavelengths_nm.size

    def predict(self, RGB) -> np.ndarray:
        """Spectra of camera RGB, shape ``(..., n_bands)`` (module docstring: exposure, E41)."""
        RGB = np.asarray(RGB, dtype=np.float64)
        flat = RGB.reshape(-1, 3)
        S = self._predict_flat(flat, np.empty((self.coefficients.shape[0], len(flat))))
        return S.reshape(*RGB.shape[:-1], self.n_bands)

    def _predict_flat(self, flat, X_T, S=None) -> np.ndarray:
        """Spectra of ``(N, 3)`` RGB, with the ``(n_features, N)`` buffer ``X_T`` (and ``S``).

        The arithmetic is in the buffers' precision: float64, or float32 throughout (features
        and product) when ``flat`` and ``X_T`` are float32 (:func:`spectralize_rows`).
        """
        C = self._coefficients32 if X_T.dtype == np.float32 else self.coefficients
        if self.kind == "root_polynomial":
            # homogeneous of degree 1: the exposure rule of E41 would change nothing
            _features_T(flat, self.kind, self.degree, X_T)
            return np.matmul(X_T.T, C, out=S)
        # Erratum E41: s = max(1, max RGB); S = s · f(RGB / s)
        s = np.maximum(flat.max(axis=-1, keepdims=True), 1.0)
        _features_T(flat / s, self.kind, self.degree, X_T)
        S = np.matmul(X_T.T, C, out=S)
        S *= s
        return S


def _check_target(RGB, spectra) -> tuple[np.ndarray, np.ndarray]:
    RGB = np.asarray(RGB, dtype=np.float64)
    spectra = np.asarray(spectra, dtype=np.float64)
    require(RGB.ndim == 2 and RGB.shape[1] == 3, f"target RGB must be (n, 3), got {RGB.shape}")
    require(
        spectra.ndim == 2 and spectra.shape[0] == RGB.shape[0],
        f"target: {RGB.shape[0]} RGB patches but {spectra.shape[0]} spectra",
    )
    require(
        np.isfinite(RGB).all() and (RGB >= 0).all(),
        "target RGB must be finite and >= 0 (found NaN, inf or negative values)",
    )
    require(np.isfinite(spectra).all(), "target spectra must be finite")
    return RGB, spectra


def _ridge_solutions(X, S, ridges):
    """Ridge solutions for each λ from one SVD: ``W = V diag(σ / (σ² + nλ)) Uᵀ S``."""
    U, sigma, Vt = np.linalg.svd(X, full_matrices=False)
    UtS = U.T @ S
    n = X.shape[0]
    for lam in ridges:
        # Hoerl & Kennard 1970: the ridge solution of (1/n)||XW - S||² + λ||W||²
        with np.errstate(divide="ignore", invalid="ignore"):
            d = np.where(sigma > sigma[0] * 1e-13, sigma / (sigma**2 + n * lam), 0.0)
        yield Vt.T @ (d[:, None] * UtS)


def delta_E94_jacobian(spectra, weights) -> np.ndarray:
    """ΔE94 linearised at each spectrum: ``ΔE94(s, s + r) ≈ ||G r||`` for small spectral errors r.

    CIE 116-1995 (ΔE94: ``ΔL/S_L``, ``ΔC/S_C``, ``ΔH/S_H`` with ``S_L = 1``,
    ``S_C = 1 + 0.045 C``, ``S_H = 1 + 0.015 C`` of the reference) of CIE 15:2004 CIELAB, the
    white the perfect diffuser under the weights' light; rows ``(ΔL, ΔC, ΔH)``.

    Parameters
    ----------
    spectra : array_like, shape (n, b)
        The reference spectra (reflectances on the weights' grid).
    weights : ndarray, shape (b, 3)
        Tristimulus band weights (``reference.colour.colorimetry.band_weights``), Y = 1 for the
        white.

    Returns
    -------
    ndarray, shape (n, 3, b)

    Examples
    --------
    >>> from reference.colour.colorimetry import band_weights
    >>> from reference.colour.spectra import GRID_41, spectrum_from_dataset
    >>> import colour
    >>> from reference.colour.colorimetry import XYZ_to_Lab, white_XYZ
    >>> W = band_weights(GRID_41, spectrum_from_dataset("illuminant", "D65"))
    >>> s = np.linspace(0.2, 0.6, 41)[None]
    >>> r = 1e-4 * np.cos(np.arange(41))[None]
    >>> Lab = [XYZ_to_Lab(x @ W, white_XYZ(W)) for x in (s, s + r)]
    >>> exact = colour.delta_E(*Lab, method="CIE 1994")[0]
    >>> linear = np.linalg.norm(delta_E94_jacobian(s, W)[0] @ r[0])
    >>> bool(abs(linear / exact - 1) < 1e-3)
    True
    """
    S = np.asarray(spectra, dtype=np.float64)
    white = weights.sum(axis=0)
    t = (S @ weights) / white
    # CIE 15:2004: f(t) = t^(1/3) above (6/29)³, linear below; Lab from f of X/Xn, Y/Yn, Z/Zn
    delta = 6.0 / 29.0
    above = t > delta**3
    f = np.where(above, np.cbrt(np.maximum(t, 0.0)), t / (3 * delta**2) + 4.0 / 29.0)
    df = np.where(above, 1.0 / (3.0 * np.maximum(f, 1e-300) ** 2), 1.0 / (3 * delta**2)) / white
    J = np.zeros((len(S), 3, 3))  # ∂(L, a, b)/∂(X, Y, Z)
    J[:, 0, 1] = 116.0 * df[:, 1]
    J[:, 1, 0], J[:, 1, 1] = 500.0 * df[:, 0], -500.0 * df[:, 1]
    J[:, 2, 1], J[:, 2, 2] = 200.0 * df[:, 1], -200.0 * df[:, 2]
    a, b = 500.0 * (f[:, 0] - f[:, 1]), 200.0 * (f[:, 1] - f[:, 2])
    C, h = np.hypot(a, b), np.arctan2(b, a)
    # CIE 116-1995: ΔC = cos h Δa + sin h Δb, ΔH = −sin h Δa + cos h Δb, over S_L, S_C, S_H
    R = np.zeros((len(S), 3, 3))
    R[:, 0, 0] = 1.0
    R[:, 1, 1], R[:, 1, 2] = np.cos(h) / (1 + 0.045 * C), np.sin(h) / (1 + 0.045 * C)
    R[:, 2, 1], R[:, 2, 2] = -np.sin(h) / (1 + 0.015 * C), np.cos(h) / (1 + 0.015 * C)
    return (R @ J) @ weights.T


#: Patches per block when the colorimetric normal equations are summed (memory ~ block · k² · 8 B).
TERMS_BLOCK = 2048


def _colorimetric_terms(X, S, G) -> tuple[np.ndarray, ...]:
    """The sums the colorimetric normal equations are made of (module docstring).

    ``Σ_i (x_i x_iᵀ) ⊗ (G_iᵀG_i)`` as a ``(k·b, k·b)`` matrix, ``Σ_i x_i ⊗ G_iᵀG_i s_i`` as
    ``(k, b)``, ``XᵀX`` and ``XᵀS``: summed over blocks of patches, never as the ``(n·m, k·b)``
    matrix of the loss rows. Sums of two sets of patches weigh them (:func:`_colorimetric_solve`).
    """
    n, b = S.shape
    k = X.shape[1]
    # x xᵀ and GᵀG are symmetric: sum their upper triangles only, then mirror (4× fewer flops)
    p, q = np.triu_indices(k)
    a, c = np.triu_indices(b)
    upper = np.zeros((p.size, a.size))
    GtGS = np.zeros((k, b))
    for start in range(0, n, TERMS_BLOCK):
        block = slice(start, start + TERMS_BLOCK)
        x, g, s = X[block], G[block], S[block]
        GtG = np.einsum("imb,imc->ibc", g, g)
        upper += (x[:, p] * x[:, q]).T @ GtG[:, a, c]
        GtGS += x.T @ np.einsum("ibc,ic->ib", GtG, s)
    full = np.empty((k, k, b, b))
    for first, second in ((p, q), (q, p)):
        full[first[:, None], second[:, None], a[None], c[None]] = upper
        full[first[:, None], second[:, None], c[None], a[None]] = upper
    # (p, q, a, c) -> (p, a, q, c): the Kronecker layout of vec W (feature-major)
    ZtZ = full.transpose(0, 2, 1, 3).reshape(k * b, k * b)
    return ZtZ, GtGS, X.T @ X, X.T @ S


def _colorimetric_solve(terms, n: int, b: int, grid):
    """Solutions ``W`` for each ``(λ, β)`` of ``grid`` from :func:`_colorimetric_terms` (n patches).

    ``H vec W = r`` with ``H = (1/n)[Σ (x xᵀ) ⊗ (GᵀG) + (β/b) XᵀX ⊗ I] + λI`` and
    ``r = (1/n)[Σ x ⊗ GᵀG s + (β/b) XᵀS]``.
    """
    import scipy.linalg

    ZtZ, GtGS, XtX, XtS = terms
    k = XtX.shape[0]
    spectral = np.kron(XtX, np.eye(b))
    for ridge, weight in grid:
        H = (ZtZ + spectral * (weight / b)) / n
        H[np.diag_indices_from(H)] += ridge
        rhs = ((GtGS + XtS * (weight / b)) / n).reshape(-1)
        try:  # H is symmetric positive definite when λ > 0 or the patches determine W
            W = scipy.linalg.cho_solve(scipy.linalg.cho_factor(H, check_finite=False), rhs)
        except np.linalg.LinAlgError:
            W = np.linalg.lstsq(H, rhs, rcond=None)[0]
        yield W.reshape(k, b)


def _colorimetric_solutions(X, S, G, grid):
    """Colorimetric-loss solutions ``W`` for each ``(λ, β)`` of ``grid`` (module docstring).

    The normal equations ``(ZᵀZ + (β/(nb))·XᵀX ⊗ I + λI) vec W = r``, ``Z`` the rows
    ``x_i ⊗ g_ij / √n`` of the ``m = 3·lights`` rows ``g_ij`` of ``G_i``, have ``k·b`` unknowns;
    when ``n·m < k·b`` the Woodbury identity (Woodbury 1950) solves them through an
    ``(n·m) × (n·m)`` system, the ``XᵀX ⊗ I + λI`` part being diagonal in the eigenvectors of
    ``XᵀX``; otherwise they are solved as they stand (:func:`_colorimetric_solve`).
    """
    n, b = S.shape
    k, m = X.shape[1], G.shape[1]
    if k * b <= n * m:  # fewer unknowns than loss rows: the normal equations themselves
        yield from _colorimetric_solve(_colorimetric_terms(X, S, G), n, b, grid)
        return
    eigenvalues, Q = np.linalg.eigh(X.T @ X)
    eigenvalues = np.maximum(eigenvalues, 0.0)
    Xq = X @ Q  # features in the eigenbasis of XᵀX
    Gflat = G.reshape(n * m, b)
    GG = (Gflat @ Gflat.T).reshape(n, m, n, m)
    GS = np.einsum("imb,ib->im", G, S)
    for ridge, weight in grid:
        c = weight / (n * b)
        d = np.maximum(c * eigenvalues + ridge, 1e-300)  # D = Q diag(d) Qᵀ ⊗ I

        def D_inv(U, d=d):  # U: (k, b) in the original basis
            return Q @ ((Q.T @ U) / d[:, None])

        def Z_of(U):  # (n, m): x_iᵀ U g_ij / √n
            return np.einsum("ib,imb->im", X @ U, G) / np.sqrt(n)

        def Zt_of(V):  # (k, b): Σ_ij x_i ⊗ g_ij v_ij / √n
            return X.T @ np.einsum("im,imb->ib", V, G) / np.sqrt(n)

        rhs = Zt_of(GS / np.sqrt(n)) + c * (X.T @ S)
        K = (Xq / d) @ Xq.T / n  # Z D⁻¹ Zᵀ = Kx[i, i'] · (g_ij · g_i'j')
        system = (K[:, None, :, None] * GG).reshape(n * m, n * m)
        system[np.diag_indices_from(system)] += 1.0
        y = D_inv(rhs)
        correction = np.linalg.solve(system, Z_of(y).reshape(-1)).reshape(n, m)
        yield y - D_inv(Zt_of(correction))


def _loss_jacobians(spectra, wavelengths, illuminant):
    """``(n, 3·lights, b)``: :func:`delta_E94_jacobian` under the capture illuminant and A."""
    from reference.colour.colorimetry import band_weights
    from reference.colour.spectra import SpectralGrid, spectrum_from_dataset

    step = float(wavelengths[1] - wavelengths[0]) if wavelengths.size > 1 else 0.0
    uniform = step > 0 and np.allclose(np.diff(wavelengths), step)
    require(
        uniform,
        "colorimetric loss: the target's wavelengths must be a uniform grid (or use the "
        "spectral loss)",
    )
    grid = SpectralGrid(float(wavelengths[0]), float(wavelengths[-1]), step)
    lights = dict.fromkeys((illuminant, RELIT_ILLUMINANT))
    return np.concatenate(
        [
            delta_E94_jacobian(spectra, band_weights(grid, spectrum_from_dataset("illuminant", L)))
            for L in lights
        ],
        axis=1,
    ), [band_weights(grid, spectrum_from_dataset("illuminant", L)) for L in lights]


def _delta_E94(truth, estimate, weights) -> np.ndarray:
    import colour

    from reference.colour.colorimetry import XYZ_to_Lab

    white = weights.sum(axis=0)
    Lab_1, Lab_2 = XYZ_to_Lab(truth @ weights, white), XYZ_to_Lab(estimate @ weights, white)
    return np.asarray(colour.delta_E(Lab_1, Lab_2, method="CIE 1994"))


def fit_regression(
    RGB,
    spectra,
    wavelengths_nm,
    kind: str = "polynomial",
    degree: int = 5,
    ridge: float | None = None,
    illuminant: str = "D65",
    camera: str = "",
    training_set: str = "",
    loss: str = DEFAULT_LOSS,
    spectral_weight: float | None = None,
    augment=None,
    augment_weight: float | None = None,
) -> SpectralRegression:
    """Fit the regression of a target's spectra on its camera RGB (λ, β by cross-validation).

    Herbert et al., §4; Finlayson et al. 2015 for the root-polynomial features; the losses in
    the module docstring (the colorimetric one: CIE 116-1995 ΔE94, erratum E44).

    Parameters
    ----------
    RGB : array_like, shape (n, 3)
        Camera RGB of the patches, white diffuser = 1; finite, >= 0.
    spectra : array_like, shape (n, n_bands)
        Their reflectances on ``wavelengths_nm``.
    wavelengths_nm : array_like, shape (n_bands,)
    kind, degree
        As in :func:`feature_exponents`.
    ridge : float, optional
        A fixed ridge strength in [0, :data:`MAX_RIDGE`]; None chooses it by cross-validation.
    illuminant : str
        The capture illuminant (colour-science key; the colorimetric loss measures ΔE94 under it
        and under :data:`RELIT_ILLUMINANT`). Recorded in the model, as are:
    camera, training_set : str
    loss : str
        A key of :data:`REGRESSION_LOSSES`. The colorimetric loss needs a uniform grid within
        360–780 nm.
    spectral_weight : float, optional
        β of the colorimetric loss, > 0; None chooses it by cross-validation.
    augment : callable, optional
        ``augment(train, held) -> (RGB, spectra)``: extra patches made from the patches of index
        ``train``, none of them a look-alike of the patches ``held`` (None for the final fit);
        its ``name`` is recorded. Only a target whose camera is known can be augmented
        (``reference.colour.spectral_target.product_augmentation``, erratum E44).
    augment_weight : float, optional
        The extra patches' total weight against the target's (0: none); None chooses it from
        :data:`AUGMENT_WEIGHT_GRID` by the same cross-validation.

    Returns
    -------
    SpectralRegression

    Raises
    ------
    SpecrefError
        Patch counts differ, negative or NaN RGB, degree or ridge out of range.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> RGB = rng.uniform(0, 1, (40, 3))
    >>> model = fit_regression(RGB, RGB[:, ::-1], [450.0, 550.0, 650.0], degree=2, loss="spectral")
    >>> model.predict([[0.2, 0.5, 0.9]]).round(3)
    array([[0.9, 0.5, 0.2]])
    """
    RGB, spectra, wavelengths = _check_fit_target(RGB, spectra, wavelengths_nm, ridge)
    X, scale = _unit_rms_features(RGB, kind, degree)
    _check_loss_options(loss, spectral_weight, augment, augment_weight)
    target = _Target(kind, degree, X, scale, spectra, wavelengths, illuminant, loss, augment)
    grid = _search_grid(target, ridge, spectral_weight, augment_weight)
    return _fitted_model(target, _choose(target, grid), camera, training_set)


def _check_fit_target(RGB, spectra, wavelengths_nm, ridge):
    """The target's RGB, spectra and wavelengths as float64 arrays, checked; a fixed λ checked."""
    RGB, spectra = _check_target(RGB, spectra)
    wavelengths = np.asarray(wavelengths_nm, dtype=np.float64)
    require(
        wavelengths.shape == (spectra.shape[1],),
        f"target: {spectra.shape[1]} spectral values per patch but {wavelengths.size} wavelengths",
    )
    if ridge is not None:
        require(
            np.isfinite(ridge) and 0.0 <= ridge <= MAX_RIDGE,
            f"ridge strength must be in [0, {MAX_RIDGE:g}], got {ridge!r}",
        )
    return RGB, spectra, wavelengths


def _unit_rms_features(RGB, kind: str, degree: int) -> tuple[np.ndarray, np.ndarray]:
    """The target's features ``X / scale``, columns scaled to unit RMS, and ``scale``."""
    X = features_RGB(RGB, kind, degree)
    require(
        RGB.shape[0] >= CV_FOLDS * 2,
        f"target: at least {CV_FOLDS * 2} patches needed, got {RGB.shape[0]}",
    )
    # Feature columns scaled to unit RMS, so that one λ grid suits every degree
    scale = np.sqrt((X**2).mean(axis=0))
    scale = np.where(scale > 0, scale, 1.0)
    return X / scale, scale


#: The largest spectral weight β of the colorimetric loss (:func:`fit_regression`).
MAX_SPECTRAL_WEIGHT = 1e6


def _check_loss_options(loss: str, spectral_weight, augment, augment_weight) -> None:
    """Check the loss key, β (colorimetric loss only) and a (with an augmentation only)."""
    REGRESSION_LOSSES.lookup(loss)
    if spectral_weight is not None:
        # β weighs the spectral misfit against ΔE's: beyond 1e6 either term is lost in the other,
        # and at 1e308 the normal equations overflow
        require(
            loss == "colorimetric"
            and np.isfinite(spectral_weight)
            and 0 < spectral_weight <= MAX_SPECTRAL_WEIGHT,
            f"--spectral-weight: β (colorimetric loss only) must be in (0, "
            f"{MAX_SPECTRAL_WEIGHT:g}], got {spectral_weight!r}",
        )
    require(
        augment_weight is None
        or (augment is not None and np.isfinite(augment_weight) and augment_weight >= 0),
        f"augmentation weight (with an augmentation only) must be >= 0, got {augment_weight!r}",
    )


@dataclass(frozen=True, eq=False)
class _Target:
    """A target as the fit sees it: unit-RMS features, spectra, the loss and the augmentation."""

    kind: str
    degree: int
    X: np.ndarray  # (n, k): the features over ``scale``
    scale: np.ndarray  # (k,)
    spectra: np.ndarray  # (n, b)
    wavelengths: np.ndarray  # (b,)
    illuminant: str
    loss: str
    augment: Callable | None
    # the colorimetric loss's Jacobians (n, 3·lights, b) and the lights' band weights
    G: np.ndarray | None = field(init=False, default=None)
    lights: list | None = field(init=False, default=None)

    def __post_init__(self):
        if self.colorimetric:
            G, lights = _loss_jacobians(self.spectra, self.wavelengths, self.illuminant)
            object.__setattr__(self, "G", G)
            object.__setattr__(self, "lights", lights)

    @property
    def colorimetric(self) -> bool:
        """Whether the loss is the colorimetric one (module docstring)."""
        return self.loss == "colorimetric"


class _Grid(NamedTuple):
    """What cross-validation chooses from: λ, β (colorimetric loss; else None) and a."""

    ridges: tuple
    betas: tuple | None
    augment_weights: tuple

    @property
    def points(self):
        """The λ of each point (spectral loss), or its (λ, β) (colorimetric loss)."""
        if self.betas is None:
            return self.ridges
        return [(r, w) for r in self.ridges for w in self.betas]


class _Choice(NamedTuple):
    """The chosen λ, β (None for the spectral loss) and a, with the cross-validation's record."""

    ridge: float
    spectral_weight: float | None
    augment_weight: float
    cv: dict | None


def _search_grid(target: _Target, ridge, spectral_weight, augment_weight) -> _Grid:
    """The grid of λ, β and a to cross-validate; a value given is a grid of one."""
    if target.augment is None:
        weights = (0.0,)
    else:
        weights = AUGMENT_WEIGHT_GRID if augment_weight is None else (float(augment_weight),)
    if not target.colorimetric:
        return _Grid(RIDGE_GRID if ridge is None else (float(ridge),), None, weights)
    ridges = COLORIMETRIC_RIDGE_GRID if ridge is None else (float(ridge),)
    betas = SPECTRAL_WEIGHT_GRID if spectral_weight is None else (float(spectral_weight),)
    return _Grid(ridges, betas, weights)


def _augmentation_rows(target: _Target, train, held):
    """Features and spectra of the augmentation made from ``train`` (and its loss terms)."""
    RGB_e, S_e = target.augment(train, held)
    RGB_e, S_e = _check_target(RGB_e, S_e)
    X_e = features_RGB(RGB_e, target.kind, target.degree) / target.scale
    if not target.colorimetric:
        return X_e, S_e, None
    G_e = _loss_jacobians(S_e, target.wavelengths, target.illuminant)[0]
    return X_e, S_e, _colorimetric_terms(X_e, S_e, G_e)


def _solutions(target: _Target, train, extra, a, grid):
    """The solutions over ``grid`` on the patches ``train`` plus the extra ones at weight a."""
    X, spectra, G = target.X, target.spectra, target.G
    if not (a > 0 and extra is not None and len(extra[0])):
        if target.colorimetric:
            return _colorimetric_solutions(X[train], spectra[train], G[train], grid)
        return _ridge_solutions(X[train], spectra[train], grid)
    # E44: the n_e extra patches weigh a·n_t in total against the n_t patches' n_t, the
    # weights scaled to a mean of 1 over the N = n_t + n_e rows
    n_t, n_e = len(train), len(extra[0])
    N = n_t + n_e
    w_t = N / (n_t * (1.0 + a))
    w_e = a * n_t / n_e * w_t
    if target.colorimetric:
        own = _colorimetric_terms(X[train], spectra[train], G[train])
        terms = [w_t * t + w_e * e for t, e in zip(own, extra[2], strict=True)]
        return _colorimetric_solve(terms, N, spectra.shape[1], grid)
    root = np.sqrt(np.concatenate([np.full(n_t, w_t), np.full(n_e, w_e)]))[:, None]
    Xw = np.concatenate([X[train], extra[0]]) * root
    return _ridge_solutions(Xw, np.concatenate([spectra[train], extra[1]]) * root, grid)


def _cv_scores(target: _Target, grid: _Grid) -> np.ndarray:
    """Held-out scores, shape (augmentation weights, points): ΔE94 percentile or spectral RMS."""
    X, spectra = target.X, target.spectra
    points, weights = grid.points, grid.augment_weights
    folds = np.array_split(np.random.default_rng(CV_SEED).permutation(len(X)), CV_FOLDS)
    # k-fold cross-validation over augmentation weight × grid; the folds' held-out patches
    # are the target's own, the augmentation is made from the other folds' (E44)
    errors = [[[] for _ in points] for _ in weights]
    sq = np.zeros((len(weights), len(points)))
    for held in folds:
        train = np.setdiff1d(np.arange(len(X)), held)
        augmented = target.augment is not None and max(weights) > 0
        extra = _augmentation_rows(target, train, held) if augmented else None
        for i, a in enumerate(weights):
            estimates = np.array([X[held] @ W for W in _solutions(target, train, extra, a, points)])
            if target.colorimetric:
                # the CV_PERCENTILE-th percentile of held-out ΔE94, both lights: every grid
                # point's estimates in one ΔE94 call per light (row by row, the same values)
                truth = np.broadcast_to(spectra[held], estimates.shape)
                for Wl in target.lights:
                    dE = _delta_E94(truth.reshape(-1, truth.shape[-1]),
                                    estimates.reshape(-1, truth.shape[-1]), Wl)  # fmt: skip
                    for j, row in enumerate(dE.reshape(len(points), -1)):
                        errors[i][j].append(row)
            else:
                for j, P in enumerate(estimates):
                    sq[i, j] += ((P - spectra[held]) ** 2).sum()
    if target.colorimetric:
        return np.array(
            [[np.percentile(np.concatenate(e), CV_PERCENTILE) for e in row] for row in errors]
        )
    return np.sqrt(sq / spectra.size)  # held-out spectral RMS


def _choose(target: _Target, grid: _Grid) -> _Choice:
    """λ, β and a: the grid's point of least held-out score, or its only point."""
    points, weights = grid.points, grid.augment_weights
    if len(points) * len(weights) == 1:
        if target.colorimetric:
            return _Choice(*points[0], weights[0], None)
        return _Choice(float(points[0]), None, weights[0], None)
    scores = _cv_scores(target, grid)
    i, j = np.unravel_index(int(np.argmin(scores)), scores.shape)
    cv = {"folds": CV_FOLDS, "seed": CV_SEED}
    if target.colorimetric:
        ridge, spectral_weight = points[j]
        cv |= {
            "criterion": f"percentile {CV_PERCENTILE:g} of ΔE94 under "
            + " and ".join(dict.fromkeys((target.illuminant, RELIT_ILLUMINANT))),
            "ridge_grid": list(grid.ridges),
            "spectral_weight_grid": list(grid.betas),
            "scores": scores[i].reshape(len(grid.ridges), len(grid.betas)).tolist(),
        }
    else:
        ridge, spectral_weight = float(points[j]), None
        cv |= {"grid": list(points), "rms": scores[i].tolist()}
    if target.augment is not None:
        cv |= {
            "augment_weight_grid": list(weights),
            "augment_scores": scores.min(axis=1).tolist(),
        }
    return _Choice(ridge, spectral_weight, weights[i], cv)


def _fitted_model(target: _Target, choice: _Choice, camera, training_set) -> SpectralRegression:
    """The fit on every patch at the chosen λ, β and a, as a model in RGB's own scale."""
    ridge, spectral_weight, a, cv = choice
    everything = np.arange(len(target.X))
    extra = _augmentation_rows(target, everything, None) if a > 0 else None
    chosen = [(float(ridge), float(spectral_weight))] if target.colorimetric else [float(ridge)]
    (W,) = _solutions(target, everything, extra, a, chosen)
    augmentation = None
    if target.augment is not None:
        augmentation = {
            "method": getattr(target.augment, "name", "custom"),
            "weight": float(a),
            "patches": 0 if extra is None else len(extra[0]),
        }
    return SpectralRegression(
        target.kind,
        int(target.degree),
        W / target.scale[:, None],
        target.wavelengths,
        float(ridge),
        target.illuminant,
        camera,
        training_set,
        cv,
        target.loss,
        None if spectral_weight is None else float(spectral_weight),
        augmentation,
    )


def save_regression(model: SpectralRegression, path) -> Path:
    """Write a model file (JSON, atomically; format in ``docs/spectral-environments.md``).

    Examples
    --------
    >>> import tempfile, os
    >>> model = SpectralRegression("polynomial", 1, np.eye(3), np.array([450.0, 550.0, 650.0]))
    >>> with tempfile.TemporaryDirectory() as d:
    ...     back = load_regression(save_regression(model, os.path.join(d, "m.json")))
    >>> bool(np.array_equal(back.coefficients, model.coefficients))
    True
    """
    from reference.files import write_text_atomic

    document = {
        "format": FORMAT,
        "version": FORMAT_VERSION,
        "features": model.kind,
        "degree": model.degree,
        "feature_names": feature_names(model.kind, model.degree),
        "wavelengths_nm": model.wavelengths_nm.tolist(),
        "coefficients": model.coefficients.tolist(),
        "loss": model.loss,
        "ridge": model.ridge,
        "spectral_weight": model.spectral_weight,
        "cross_validation": model.cv,
        "augmentation": model.augmentation,
        "illuminant": model.illuminant,
        "camera": model.camera,
        "training_set": model.training_set,
    }
    return write_text_atomic(path, json.dumps(document, indent=1) + "\n")


#: The keys of a model file, by its version.
_MODEL_KEYS = {
    1: ("features", "degree", "coefficients", "wavelengths_nm", "ridge", "illuminant", "camera",
        "training_set"),
}  # fmt: skip
_MODEL_KEYS[2] = (*_MODEL_KEYS[1], "loss", "spectral_weight")
_MODEL_KEYS[3] = (*_MODEL_KEYS[2], "augmentation")


def _is_number(value, kind) -> bool:
    # JSON numbers; a whole number for int; booleans are not numbers here
    allowed = int if kind is int else (int, float)
    return isinstance(value, allowed) and not isinstance(value, bool) and math.isfinite(value)


def _model_array(document: dict, key: str, ndim: int) -> np.ndarray:
    # a model file's array, its shape and finiteness named by key (the path is added by the caller)
    what = "a list of numbers" if ndim == 1 else "a list of rows of numbers, all of one length"
    value = document[key]
    rows = value if ndim == 2 and isinstance(value, list) else [value] if ndim == 1 else []
    for i, row in enumerate(rows):  # the first entry that is not a number, or a ragged row
        where = f"{key}[{i}]" if ndim == 2 else key
        if not isinstance(row, list):
            break
        require(
            ndim == 1 or len(row) == len(rows[0]),
            f"{where}: has {len(row)} values, {key}[0] has {len(rows[0])}; rows are of one length",
        )
        for j, number in enumerate(row):
            require(
                _is_number(number, float),
                f"{where}[{j}]: must be a finite number, got {number!r:.40}",
            )
    try:
        array = np.array(value, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        array = np.empty((0,))
    require(
        array.ndim == ndim and array.size > 0 and not isinstance(value, str),
        f"{key}: must be {what}, got {value!r:.40}",
    )
    require(bool(np.isfinite(array).all()), f"{key}: must be finite numbers")
    require(ndim == 2 or bool((np.diff(array) > 0).all()), f"{key}: must increase")
    return array


def load_regression(path, wavelengths_nm=None) -> SpectralRegression:
    """Read a model file; with ``wavelengths_nm``, require the model's grid to be that grid.

    Raises
    ------
    SpecrefError
        Missing or malformed file, another grid than ``wavelengths_nm``.

    Examples
    --------
    >>> load_regression("/nonexistent.json")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent.json: file not found
    """
    path = Path(path)
    require(path.is_file(), f"{path}: file not found")
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
        require(
            isinstance(document, dict) and document.get("format") == FORMAT,
            f"{path}: not a {FORMAT} file",
        )
        version = document.get("version")
        require(
            version in _READABLE_VERSIONS,
            f"{path}: {FORMAT} version {version!r}; this specref reads versions "
            f"{', '.join(map(str, _READABLE_VERSIONS))} (refit with `specref env fit`)",
        )
        missing = [key for key in _MODEL_KEYS[version] if key not in document]
        if missing:
            raise SpecrefError(
                f"{path}: missing key {missing[0]!r}; a version {version} model file holds "
                f"{', '.join(_MODEL_KEYS[version])}"
            )
        weight = document["spectral_weight"] if version >= 2 else None
        require(
            isinstance(document["features"], str) and _is_number(document["degree"], int),
            f"{path}: features, degree: must be a name ({format_allowed(REGRESSION_FEATURES)}) "
            f"and a whole number, got {document['features']!r:.30}, {document['degree']!r:.30}",
        )
        for key in ("ridge", "spectral_weight"):
            value = document.get(key)
            require(
                _is_number(value, float) or (key == "spectral_weight" and value is None),
                f"{path}: {key}: must be a number, got {value!r:.40}",
            )
        model = SpectralRegression(
            document["features"],
            document["degree"],
            _model_array(document, "coefficients", 2),
            _model_array(document, "wavelengths_nm", 1),
            float(document["ridge"]),
            str(document["illuminant"]),
            str(document["camera"]),
            str(document["training_set"]),
            document.get("cross_validation"),
            str(document["loss"]) if version >= 2 else "spectral",  # version 1: spectral only
            None if weight is None else float(weight),
            document["augmentation"] if version >= 3 else None,
        )
    except SpecrefError as error:
        raise SpecrefError(f"{path}: {error}".replace(f"{path}: {path}: ", f"{path}: ")) from None
    except (ValueError, KeyError, TypeError) as error:
        raise SpecrefError(f"{path}: malformed model file ({error.__class__.__name__})") from None
    if wavelengths_nm is not None:
        wl = np.asarray(wavelengths_nm, dtype=np.float64)
        require(
            model.wavelengths_nm.shape == wl.shape and np.allclose(model.wavelengths_nm, wl),
            f"{path}: model grid {model.wavelengths_nm[0]:g}-{model.wavelengths_nm[-1]:g} nm, "
            f"{model.n_bands} bands; expected {wl[0]:g}-{wl[-1]:g} nm, {wl.size} bands",
        )
    return model


#: μ of :func:`project_nonnegative`'s fallback: how much the colour outweighs the spectrum's shape
#: (in units of the weights' largest value). At 10³ a spectrum of peak 4 gave up 3·10⁻⁴ in XYZ for
#: a closer shape; at 10⁶ the colour is kept to ~10⁻⁹.
NONNEGATIVE_STRENGTH = 1e6


def project_nonnegative(spectra, weights, strength: float = NONNEGATIVE_STRENGTH):
    """Spectra with negative values replaced by the nearest non-negative ones of the same colour.

    A regression's prediction can go negative (a polynomial is not bounded below); a spectrum
    cannot. Each spectrum ``s`` with a value below zero becomes

    ``s' = argmin_{s' >= 0} ||s' − s||² + (μ/w)² ||Wᵀ (s' − s)||²``

    with ``W`` the ``(n, 3)`` XYZ weights, ``w`` their largest value and ``μ`` = ``strength``.
    All rows are first solved at once with the colour held exactly, fixing the bands that go
    negative at zero until none does (an active-set iteration); a row whose Karush-Kuhn-Tucker
    conditions then hold is the exact solution (checked against SLSQP). The others (a band that
    should be freed again, or a colour no non-negative spectrum has) are solved one by one by
    non-negative least squares on the stacked system (Lawson & Hanson 1974,
    ``scipy.optimize.nnls``), which keeps the colour where it can and moves it as little as the
    constraint allows where it cannot. Our choice, erratum E106.

    Parameters
    ----------
    spectra : array_like, shape (N, n)
    weights : array_like, shape (n, 3)
        XYZ per band (e.g. ``band_weights`` under the capture illuminant).
    strength : float

    Returns
    -------
    projected : ndarray, shape (N, n), float64
        Rows without a negative value are returned unchanged.
    changed : dict
        ``values``: negative values replaced, ``pixels``: spectra projected, ``min``: the most
        negative value found (0 if none).

    Examples
    --------
    >>> W = np.array([[0.1, 0, 0.6], [0.3, 0.2, 0.9], [0.2, 0.7, 0.1], [0.6, 0.6, 0],
    ...               [0.5, 0.1, 0]])
    >>> s = np.array([[0.3, 0.5, 0.2, 0.4, 0.4], [0.4, -0.05, 0.7, 0.5, 0.6]])
    >>> p, changed = project_nonnegative(s, W)
    >>> p[1].round(4), changed
    (array([0.3266, 0.    , 0.6902, 0.4958, 0.5936]), {'values': 1, 'pixels': 1, 'min': -0.05})
    >>> bool(np.array_equal(p[0], s[0])), bool(np.abs(p @ W - s @ W).max() < 1e-6)
    (True, True)
    """
    from scipy.optimize import nnls

    S = np.array(spectra, dtype=np.float64)
    W = np.asarray(weights, dtype=np.float64)
    negative = S < 0.0
    rows = np.flatnonzero(negative.any(axis=1))
    changed = {
        "values": int(negative.sum()),
        "pixels": int(rows.size),
        "min": float(S.min()) if rows.size else 0.0,
    }
    if not rows.size:
        return S, changed
    # first, all rows at once: the exact-colour solution on a shrinking set of free bands
    solved, optimal = _project_active_set(S[rows], W)
    S[rows] = solved
    scale = strength / np.abs(W).max()
    A = np.vstack([np.eye(S.shape[1]), scale * W.T])
    for i in rows[~optimal]:
        # Lawson & Hanson 1974: non-negative least squares on [I; μ/w Wᵀ] s' ≈ [s; μ/w Wᵀ s]
        S[i], _ = nnls(A, np.concatenate([spectra[i], scale * (W.T @ spectra[i])]))
    return S, changed


def _project_active_set(S, W, iterations: int = 16) -> tuple[np.ndarray, np.ndarray]:
    """``min ||x − s||²`` s.t. ``Wᵀx = Wᵀs``, ``x >= 0``: many rows at once, and which are sure.

    The bands that go negative are fixed at zero and the others solved again,
    ``x_F = s_F + W_F λ`` with ``(W_Fᵀ W_F) λ = Wᵀs − W_Fᵀ s_F``, until none goes negative. A row
    is certainly optimal when its zero bands' multipliers ``ν = −s − Wλ`` are all >= 0 (the
    Karush-Kuhn-Tucker conditions of the problem); the others (a band that should be freed
    again, a colour no non-negative spectrum has) are returned for :func:`project_nonnegative`'s
    one-by-one NNLS.
    """
    target = S @ W
    free = np.ones(S.shape, dtype=bool)
    X = np.maximum(S, 0.0)
    lam = np.zeros((len(S), 3))
    for _ in range(iterations):
        WF = W[None] * free[..., None]  # (N, n, 3)
        G = np.einsum("nbi,nbj->nij", WF, WF)
        r = target - np.einsum("nb,nbi->ni", S * free, WF)
        solvable = np.abs(np.linalg.det(G)) > 1e-12 * np.abs(W).max() ** 6
        lam[solvable] = np.linalg.solve(G[solvable], r[solvable][..., None])[..., 0]
        X = np.where(free, S + lam @ W.T, 0.0)
        negative = X < 0.0
        if not negative.any():
            break
        free &= ~negative
    nu = -(S + lam @ W.T)  # the multipliers of the bands held at zero
    optimal = solvable & (X >= 0.0).all(axis=1) & ((nu >= -1e-12) | free).all(axis=1)
    optimal &= np.abs(X @ W - target).max(axis=1) <= 1e-9 * (1.0 + np.abs(target).max(axis=1))
    return np.maximum(X, 0.0), optimal


def spectralize_blocks(model: SpectralRegression, RGB, rows_per_block: int | None = None):
    """Spectralize an image block of rows by block: yields ``(row0, spectra float32)``.

    Herbert et al., §4 (the panorama expanded to n bands). Each block is one feature expansion
    and one matrix product, as :meth:`SpectralRegression.predict` but in float32 arithmetic
    (erratum E45: within ``(n_features + 7)·2⁻²⁴·Σ|x_i c_i|`` of the float64 prediction), so the
    memory in use is bounded by a block, never by the whole output; an out-of-core or distributed
    writer consumes the blocks. :func:`spectralize_rows` reads the rows from a file as it goes.

    Parameters
    ----------
    model : SpectralRegression
    RGB : array_like, shape (H, W, 3)
        Linear camera RGB (white diffuser = 1), finite, >= 0.
    rows_per_block : int, optional
        Default: as many rows as hold :data:`PIXELS_PER_BLOCK` pixels (at least one).

    Yields
    ------
    row0 : int
    spectra : ndarray, shape (rows, W, n_bands), float32
        A view of a buffer that the next block overwrites: write or copy it before asking for
        the next block.

    Raises
    ------
    SpecrefError
        Not (H, W, 3), NaN, inf or negative RGB.

    Examples
    --------
    >>> model = SpectralRegression("polynomial", 1, np.eye(3), np.array([450.0, 550.0, 650.0]))
    >>> [(row0, block.shape, block.dtype.name) for row0, block in
    ...  spectralize_blocks(model, np.ones((3, 6, 3)), rows_per_block=2)]   # shapes only
    [(0, (2, 6, 3), 'float32'), (2, (1, 6, 3), 'float32')]
    """
    RGB = np.asarray(RGB)
    require(
        RGB.ndim == 3 and RGB.shape[2] == 3, f"spectralize: expected (H, W, 3), got {RGB.shape}"
    )
    return spectralize_rows(model, lambda a, b: RGB[a:b], *RGB.shape[:2], rows_per_block)


def model_XYZ_weights(model: SpectralRegression) -> np.ndarray:
    """``(n_bands, 3)`` XYZ weights of the model's bands under its capture illuminant.

    Examples
    --------
    >>> from reference.colour.spectra import GRID_41
    >>> model = SpectralRegression("polynomial", 1, np.ones((3, 41)), GRID_41.wavelengths_nm)
    >>> model_XYZ_weights(model).shape
    (41, 3)
    """
    from reference.colour.colorimetry import band_weights
    from reference.colour.spectra import SpectralGrid, spectrum_from_dataset

    w = model.wavelengths_nm
    step = float(w[1] - w[0]) if w.size > 1 else 0.0
    require(
        step > 0 and np.allclose(np.diff(w), step),
        "regression: the model's wavelengths must be a uniform grid",
    )
    grid = SpectralGrid(float(w[0]), float(w[-1]), step)
    return band_weights(grid, spectrum_from_dataset("illuminant", model.illuminant))


def _count_projected(total: dict | None, found: dict) -> None:
    """Add :func:`project_nonnegative`'s ``changed`` to a running ``total`` (None: not kept)."""
    if total is None:
        return
    total["values"] = total.get("values", 0) + found["values"]
    total["pixels"] = total.get("pixels", 0) + found["pixels"]
    total["min"] = min(total.get("min", 0.0), found["min"])


def spectralize_rows(
    model: SpectralRegression,
    read_rows,
    height: int,
    width: int,
    rows_per_block=None,
    where=None,
    projected: dict | None = None,
):
    """Spectralize rows that ``read_rows(row0, row1)`` supplies, block by block, in order.

    Herbert et al., §4. The streaming form of :func:`spectralize_blocks`: ``read_rows`` returns
    ``(row1 - row0, width, >= 3)`` RGB (extra channels ignored), e.g. a file's row window
    (:func:`reference.images.spectral.open_panorama_rows`), so neither the input nor the output is
    ever held whole. ``where`` names the input in error messages. Yields as
    :func:`spectralize_blocks` does. Spectra with a negative value are projected onto
    non-negative ones of the same colour under the model's illuminant
    (:func:`project_nonnegative`, erratum E106); ``projected``, when given, receives the count
    (``values``, ``pixels``, ``min``).

    Examples
    --------
    >>> model = SpectralRegression("polynomial", 1, np.eye(3), np.array([450.0, 550.0, 650.0]))
    >>> calls = []
    >>> def read(a, b):
    ...     calls.append((a, b)); return np.ones((b - a, 4, 3))
    >>> [block.shape[0] for _, block in spectralize_rows(model, read, 5, 4, 2)], calls
    ([2, 2, 1], [(0, 2), (2, 4), (4, 5)])
    """
    default = max(1, PIXELS_PER_BLOCK // max(width, 1))
    rows = default if rows_per_block is None else int(rows_per_block)
    require(rows >= 1, f"spectralize: rows per block must be >= 1, got {rows}")
    rows = min(rows, max(height, 1))
    where = "spectralize" if where is None else str(where)
    # float32 buffers reused by every block (fresh ones would cost a page fault per page each
    # time); float32 arithmetic halves the product's time and memory traffic (erratum E45)
    RGB32 = np.empty((rows * width, 3), np.float32)
    X_T = np.empty((model.coefficients.shape[0], rows * width), np.float32)
    S32 = np.empty((rows * width, model.n_bands), np.float32)
    weights = None  # the XYZ weights, made when a block first needs them
    for row0 in range(0, height, rows):
        block = read_rows(row0, min(row0 + rows, height))[..., :3]
        n = block.shape[0] * block.shape[1]
        with np.errstate(over="ignore"):  # beyond float32: inf, refused just below
            np.copyto(RGB32[:n], block.reshape(-1, 3), casting="unsafe")
        require(
            np.isfinite(RGB32[:n]).all() and (RGB32[:n] >= 0).all(),
            f"{where}: RGB must be finite and >= 0 (rows {row0}-{row0 + len(block) - 1})",
        )
        spectra = model._predict_flat(RGB32[:n], X_T[:, :n], S32[:n])
        # erratum E106: no negative radiance, the colour kept. One reduction first: most blocks of
        # a real capture have no negative value, and the per-row test took a third of a block's time
        if spectra.min() < 0.0:
            negative = (spectra < 0.0).any(axis=1)
            weights = model_XYZ_weights(model) if weights is None else weights
            spectra[negative], found = project_nonnegative(spectra[negative], weights)
            _count_projected(projected, found)
        yield row0, spectra.reshape(*block.shape[:2], model.n_bands)

"""RGB → spectrum upsampling of environment maps (colour.recovery; Herbert et al.'s regression).

Herbert et al. (§4) expand HDR panoramas to 31-41 bands with a fitted polynomial; specref offers
that regression and two published methods from colour-science, by key
(:data:`UPSAMPLING_METHODS`):

- ``mallett2019`` (default): Mallett & Yuksel's spectral primary decomposition for sRGB. A
  spectrum is the linear combination ``R b_r(λ) + G b_g(λ) + B b_b(λ)`` of three non-negative
  basis spectra that sum to 1 at every wavelength, so it is linear (HDR values > 1 scale exactly),
  non-negative for non-negative RGB, and a **white texel (R = G = B = v) becomes the flat spectrum
  v** in every band (to 1e-5, the precision of the published basis). It is the default because it is
  exact on white, linear and fast (one matrix product per map).
- ``regression``: Herbert et al.'s method (§4): a regression from RGB to the spectra of a camera
  target (``reference.colour.spectral_regression``). The shipped model (``reference/data/
  spectral_regression_sRGB.json``, fitted by ``validation/precompute/spectral_regression.py``) takes
  linear sRGB: Finlayson's root-polynomials of degree 4, fitted on a synthetic target (the sRGB
  "camera" of the reflectances in ``reference.colour.spectral_target``); it is linear in exposure.
  ``specref env fit`` fits models for other cameras.
- ``jakob2019``: Jakob & Hanika's sigmoid-polynomial model, as Mitsuba 3 and pbrt-v4 use it for RGB
  emitters and environment maps. The model represents reflectances in [0, 1]; like those renderers
  (Mitsuba 3 ``src/emitters/envmap.cpp``, pbrt-v4 ``RGBIlluminantSpectrum``: ``scale = 2 * max``),
  a texel is divided by **twice** its largest component m, so the shape is fitted to a colour whose
  largest component is ½ (a smoother spectrum than at 1), and the spectrum is multiplied by 2m
  (erratum E80). A white texel becomes a flat spectrum to 0.1 % (½ is the sigmoid at 0; the sRGB
  white and D65 integrated at 5 nm differ slightly). The
  coefficients come from a 64³ table per largest component, Mitsuba's and pbrt's resolution
  (``reference.colour.jakob2019``: generated once, one to four minutes, and cached), interpolated by
  colour-science's ``LUT3D_Jakob2019``, so a 1k map takes seconds; ``lut_size=None`` fits each
  colour with colour-science instead (about 0.5 s each, for a few colours).

The RGB is linear in the map's colourspace (sRGB primaries for both methods). Both methods recover
*reflectance-like* spectra: R = G = B maps to a flat spectrum, whose colour under the equal-energy
weights is illuminant E, not the sRGB white. Environment maps hold *radiance*, so
:func:`RGB_to_radiance_spectra` multiplies the recovered spectrum by the colourspace's white
illuminant (D65 for sRGB), normalized to Y = 1, as Mitsuba 3 and pbrt-v4 do for RGB emitters: a
white texel of value v becomes ``v · D65(λ) / Y(D65)``, whose XYZ is v times the D65 white, so it
displays as sRGB (v, v, v).

References
----------
- I. Mallett, C. Yuksel, "Spectral Primary Decomposition for Rendering with sRGB Reflectance",
  EGSR 2019.
- W. Jakob, J. Hanika, "A Low-Dimensional Function Space for Efficient Spectral Upsampling",
  Computer Graphics Forum 38(2), 2019.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from reference.colour.jakob2019 import DEFAULT_TABLE_SIZE, table_Jakob2019
from reference.colour.spectra import SpectralGrid
from reference.data import data_path
from reference.errors import require
from reference.registry import Method, Registry

__all__ = [
    "DEFAULT_UPSAMPLING",
    "UPSAMPLING_METHODS",
    "RGB_to_radiance_spectra",
    "RGB_to_spectra",
    "RGB_to_spectra_Jakob2019",
    "RGB_to_spectra_Mallett2019",
    "RGB_to_spectra_regression",
    "default_regression",
    "load_upsampling_model",
]

#: The default RGB → spectrum method.
DEFAULT_UPSAMPLING = "mallett2019"


def _mallett_basis(grid: SpectralGrid) -> np.ndarray:
    import colour

    basis = colour.recovery.MSDS_BASIS_FUNCTIONS_sRGB_MALLETT2019
    wl = grid.wavelengths_nm
    return np.stack(
        [np.interp(wl, basis.wavelengths, basis.values[:, i]) for i in range(3)]
    )  # (3, n_bands)


def RGB_to_spectra_Mallett2019(RGB, grid: SpectralGrid) -> np.ndarray:
    """Spectra of linear sRGB values by Mallett & Yuksel's primaries: ``S = RGB @ B``.

    Eq. (4), Mallett & Yuksel 2019 (the spectrum as a convex combination of three basis spectra),
    resampled linearly onto ``grid``.

    Parameters
    ----------
    RGB : array_like, shape (..., 3)
        Linear sRGB, >= 0 (any magnitude).
    grid : SpectralGrid

    Returns
    -------
    ndarray, shape (..., n_bands)

    Examples
    --------
    >>> from reference.colour.spectra import GRID_41
    >>> S = RGB_to_spectra_Mallett2019([[2.0, 2.0, 2.0]], GRID_41)
    >>> bool(np.allclose(S, 2.0, atol=1e-4))
    True
    """
    RGB = np.asarray(RGB, dtype=np.float64)
    return RGB @ _mallett_basis(grid)


def RGB_to_spectra_Jakob2019(
    RGB, grid: SpectralGrid, lut_size: int | None = DEFAULT_TABLE_SIZE
) -> np.ndarray:
    """Spectra of linear sRGB values by Jakob & Hanika's sigmoid polynomials, scaled as Mitsuba 3.

    Eq. (3), Jakob & Hanika 2019: ``S(λ) = sigmoid(c0 λ² + c1 λ + c2)``. A texel is divided by
    ``2m`` (m its largest component), its shape fitted there, and multiplied by ``2m``, as Mitsuba 3
    and pbrt-v4 do (module docstring; erratum E80).

    Parameters
    ----------
    RGB : array_like, shape (..., 3)
        Linear sRGB, >= 0.
    grid : SpectralGrid
    lut_size : int or None
        The coefficient table's resolution (``reference.colour.jakob2019.table_Jakob2019``, default
        64, as Mitsuba 3 and pbrt-v4; generated once and cached). None: fit each distinct colour
        (chromaticity quantized to 1/64 of the largest component) with
        ``colour.recovery.find_coefficients_Jakob2019`` (about 0.5 s each; for a few colours).

    Returns
    -------
    ndarray, shape (..., n_bands)

    Examples
    --------
    >>> from reference.colour.spectra import GRID_41
    >>> S = RGB_to_spectra_Jakob2019([[2.0, 2.0, 2.0]], GRID_41, lut_size=None)   # white: flat
    >>> round(float(S.min()), 6), round(float(S.max()), 6)
    (2.0, 2.0)
    """
    import colour

    RGB = np.asarray(RGB, dtype=np.float64)
    # Erratum E80: scale by twice the largest component (Mitsuba 3, pbrt-v4)
    scale = 2.0 * RGB.max(axis=-1, keepdims=True)
    half = RGB / np.where(scale > 0, scale, 1.0)
    if lut_size is not None:
        coefficients = table_Jakob2019(int(lut_size)).RGB_to_coefficients(half.reshape(-1, 3))
        coefficients = coefficients.reshape(*RGB.shape[:-1], 3)
    else:
        from colour.recovery import find_coefficients_Jakob2019

        quantized = np.round(half * 128.0) / 128.0
        flat = quantized.reshape(-1, 3)
        unique, inverse = np.unique(flat, axis=0, return_inverse=True)
        space = colour.RGB_COLOURSPACES["sRGB"]
        fitted = np.stack(
            [find_coefficients_Jakob2019(colour.RGB_to_XYZ(c, space))[0] for c in unique]
        )
        coefficients = fitted[inverse.ravel()].reshape(*RGB.shape[:-1], 3)
    lam = grid.wavelengths_nm
    # Eq. (3), Jakob & Hanika 2019: x = c0 λ² + c1 λ + c2, S = ½ + x / (2 sqrt(1 + x²))
    x = (coefficients[..., 0:1] * lam + coefficients[..., 1:2]) * lam + coefficients[..., 2:3]
    return (0.5 + x / (2.0 * np.sqrt(1.0 + x * x))) * scale


#: The shipped regression model (linear sRGB → reflectance on the 41-band grid).
DEFAULT_REGRESSION_MODEL = data_path("spectral_regression_sRGB.json")


@functools.lru_cache(maxsize=1)
def default_regression():
    """The shipped :class:`~.spectral_regression.SpectralRegression` (linear sRGB input).

    Examples
    --------
    >>> model = default_regression()
    >>> model.kind, model.degree, model.camera, model.n_bands
    ('root_polynomial', 4, 'sRGB', 41)
    """
    from reference.colour.spectral_regression import load_regression

    return load_regression(DEFAULT_REGRESSION_MODEL)


def load_upsampling_model(path, grid: SpectralGrid):
    """A regression model file for upsampling onto ``grid`` (cached by path and modification time).

    Herbert et al., §4. The model's wavelengths must cover the grid's range (the spectra are
    resampled linearly onto it, :func:`RGB_to_spectra_regression`).

    Raises
    ------
    SpecrefError
        Missing or malformed file; a model of another grid: ``<file>: model grid 450-650 nm, 3
        bands; does not cover the scene grid 380-780 nm``.

    Examples
    --------
    >>> from reference.colour.spectra import GRID_31
    >>> load_upsampling_model(DEFAULT_REGRESSION_MODEL, GRID_31).n_bands
    41
    """
    path = Path(path)
    require(path.is_file(), f"{path}: file not found")
    model = _load_model(str(path.resolve()), path.stat().st_mtime_ns)
    wl = model.wavelengths_nm
    require(
        wl[0] <= grid.start_nm + 1e-9 and wl[-1] >= grid.end_nm - 1e-9,
        f"{path}: model grid {wl[0]:g}-{wl[-1]:g} nm, {wl.size} bands; does not cover the scene "
        f"grid {grid.start_nm:g}-{grid.end_nm:g} nm",
    )
    return model


@functools.lru_cache(maxsize=8)
def _load_model(path: str, mtime_ns: int):
    from reference.colour.spectral_regression import load_regression

    return load_regression(path)


def RGB_to_spectra_regression(RGB, grid: SpectralGrid, model=None) -> np.ndarray:
    """Spectra of linear sRGB values by the shipped camera-target regression (Herbert et al., §4).

    Herbert et al., §4: polynomial terms of RGB times fitted coefficients (the shipped model uses
    Finlayson's root-polynomials, erratum E43), resampled linearly onto ``grid``.

    Parameters
    ----------
    RGB : array_like, shape (..., 3)
        Linear sRGB, >= 0 (any magnitude: the root-polynomials scale with exposure).
    grid : SpectralGrid
    model : SpectralRegression or path, optional
        Another model (a file of ``specref env fit``, :func:`load_upsampling_model`); default the
        shipped one.

    Returns
    -------
    ndarray, shape (..., n_bands)

    Examples
    --------
    >>> from reference.colour.colorimetry import band_weights, spectra_to_RGB_matrix
    >>> from reference.colour.spectra import GRID_41, spectrum_from_dataset
    >>> S = RGB_to_spectra_regression([[0.2, 0.4, 0.8]], GRID_41)
    >>> M = spectra_to_RGB_matrix(band_weights(GRID_41, spectrum_from_dataset("illuminant", "D65")))
    >>> (S @ M).round(2)                                                # the round trip
    array([[0.2, 0.4, 0.8]])
    """
    if model is None:
        model = default_regression()
    elif not hasattr(model, "predict"):
        model = load_upsampling_model(model, grid)
    S = model.predict(np.asarray(RGB, dtype=np.float64))
    negative = (S < 0.0).any(axis=-1)
    if negative.any():  # erratum E106: no negative spectrum, the colour kept
        from reference.colour.spectral_regression import model_XYZ_weights, project_nonnegative

        S[negative] = project_nonnegative(S[negative], model_XYZ_weights(model))[0]
    wl = grid.wavelengths_nm
    if wl.shape == model.wavelengths_nm.shape and np.array_equal(wl, model.wavelengths_nm):
        return S
    index = np.interp(wl, model.wavelengths_nm, np.arange(model.n_bands))
    lo = np.floor(index).astype(int)
    hi = np.minimum(lo + 1, model.n_bands - 1)
    t = index - lo
    return S[..., lo] * (1.0 - t) + S[..., hi] * t


@dataclass(frozen=True, kw_only=True)
class Upsampler(Method):
    """An RGB → spectrum method.

    Parameters
    ----------
    exact : bool
        The spectrum renders back to its RGB by construction (the fits); the regression is a
        least-squares model and reproduces RGB only to within its fit
        (docs/spectral-environments.md).
    """

    exact: bool


#: RGB → spectrum methods by key.
UPSAMPLING_METHODS = Registry("RGB upsampling", Upsampler)
UPSAMPLING_METHODS.register(
    Upsampler(
        "mallett2019",
        RGB_to_spectra_Mallett2019,
        None,
        "Eq. (4), Mallett & Yuksel 2019",
        exact=True,
    )
)
UPSAMPLING_METHODS.register(
    Upsampler(
        "jakob2019", RGB_to_spectra_Jakob2019, None, "Eq. (3), Jakob & Hanika 2019", exact=True
    )
)
UPSAMPLING_METHODS.register(
    Upsampler("regression", RGB_to_spectra_regression, None, "§4, Herbert et al.", exact=False)
)


def RGB_to_spectra(
    RGB, grid: SpectralGrid, method: str = DEFAULT_UPSAMPLING, model=None
) -> np.ndarray:
    """Spectra of linear sRGB values by a registered method (default ``mallett2019``).

    Eq. (4), Mallett & Yuksel 2019 by default. ``model`` (a regression model or its file) is for
    ``method="regression"`` only.

    Raises
    ------
    SpecrefError
        Unknown method, negative or non-finite RGB, a model for another method.

    Examples
    --------
    >>> from reference.colour.spectra import GRID_31
    >>> RGB_to_spectra(np.ones((2, 2, 3)), GRID_31).shape
    (2, 2, 31)
    """
    entry = UPSAMPLING_METHODS.lookup(method)
    RGB = np.asarray(RGB, dtype=np.float64)
    require(RGB.shape[-1:] == (3,), f"RGB_to_spectra: expected (..., 3), got {RGB.shape}")
    require(np.isfinite(RGB).all() and (RGB >= 0).all(), "RGB_to_spectra: RGB must be finite, >= 0")
    if model is None:
        return entry.reference(RGB, grid)
    require(
        method == "regression", f"RGB_to_spectra: a model file is for 'regression', not {method!r}"
    )
    return entry.reference(RGB, grid, model)


def RGB_to_radiance_spectra(
    RGB,
    grid: SpectralGrid,
    method: str = DEFAULT_UPSAMPLING,
    colourspace: str = "sRGB",
    model=None,
) -> np.ndarray:
    """Spectral radiance of linear RGB radiance: the upsampled spectrum times the white illuminant.

    Eq. (4), Mallett & Yuksel 2019 by default, times ``D(λ) / Y(D)`` with D the colourspace's white
    illuminant (module docstring), so that XYZ (equal-energy weights) reproduces the RGB's XYZ.

    Examples
    --------
    >>> from reference.colour.colorimetry import band_weights, spectra_to_RGB_matrix
    >>> from reference.colour.spectra import GRID_41
    >>> S = RGB_to_radiance_spectra([[1.0, 1.0, 1.0]], GRID_41)       # a white texel
    >>> (S @ spectra_to_RGB_matrix(band_weights(GRID_41, None))).round(2)
    array([[1., 1., 1.]])
    """
    import colour

    from reference.colour.colorimetry import band_weights
    from reference.colour.spectra import resample_spectrum, spectrum_from_dataset

    space = colour.RGB_COLOURSPACES[colourspace]
    illuminant = spectrum_from_dataset("illuminant", space.whitepoint_name)
    D = resample_spectrum(illuminant, grid, extrapolation="constant")
    D = D / (D @ band_weights(grid, None)[:, 1])
    return RGB_to_spectra(RGB, grid, method, model) * D

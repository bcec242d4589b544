"""Spectra to XYZ, display RGB and Lab: band weights with the light folded in; Eq. (9), Wang et al.

specref turns a spectrum sampled on a grid into tristimulus values with one matrix product,
``XYZ = R @ W`` (Eq. (4), Wang et al., in matrix form), where ``W`` has shape ``(n_bands, 3)``. For
a surface under a known light, ``W`` carries the light: it holds the ASTM E2022 tristimulus
weighting factors for that light and grid, with the weights of wavelengths outside the grid folded
into the end bands as ASTM E308 does (colour-science computes both). These reproduce
``colour.sd_to_XYZ(..., method="ASTM E308")`` exactly on the same 10 nm data, and they integrate the
light's spectral lines: point-sampling illuminant × CMF at 10 nm misses FL2's mercury lines
(``band_weights_point_sampled`` keeps that method, to show the failure).

Scale convention: ``W`` is normalised so that a perfect white diffuser (R = 1 in every band) under
the light has Y = 1. colour-science's ``sd_to_XYZ`` returns Y = 100; divide by 100 at that boundary.
Radiance spectra with no light folded in use the weights of the equal-energy light E.

The spectra-to-RGB matrix of Eq. (9), Wang et al. is ``W @ M_XYZ_to_RGB.T``: it maps a spectrum
straight to linear display RGB.

References
----------
- C.-M. Wang, J.-R. Chern, J. Lee, "An Efficient Spectral Rendering Technique for Phong Illumination
Model".
- ASTM E2022-16, Standard Practice for Calculation of Weighting Factors for Tristimulus Integration.
- ASTM E308-15, Standard Practice for Computing the Colors of Objects by Using the CIE System.
- CIE 015:2018, Colorimetry, 4th ed.
"""

from __future__ import annotations

import functools
import hashlib
import itertools
import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from reference.colour.spectra import (
    DEFAULT_GRID,
    SpectralGrid,
    Spectrum,
    spectrum_from_dataset,
    spectrum_to_colour_sd,
)
from reference.errors import require, require_choice
from reference.registry import Method, Registry

__all__ = [
    "BAND_WEIGHT_METHODS",
    "DEFAULT_OBSERVER",
    "OBSERVERS",
    "XYZ_to_Lab",
    "XYZ_to_RGB_matrix",
    "XYZ_to_display_RGB",
    "band_weights",
    "band_weights_ASTM_E308",
    "band_weights_point_sampled",
    "delta_E_00",
    "display_RGB_to_XYZ",
    "spectra_to_RGB_matrix",
    "spectra_to_XYZ",
    "spectral_channel_weights",
    "white_XYZ",
]

#: Standard observers available from colour-science.
OBSERVERS = ("CIE 1931 2 Degree Standard Observer", "CIE 1964 10 Degree Standard Observer")
DEFAULT_OBSERVER = OBSERVERS[0]

# ASTM E308 works on the practice range 360-780 nm.
_PRACTICE_START_NM, _PRACTICE_END_NM = 360.0, 780.0


def _check_grid_for_weights(grid: SpectralGrid) -> None:
    require(
        grid.start_nm >= _PRACTICE_START_NM and grid.end_nm <= _PRACTICE_END_NM,
        f"band weights: grid {grid.label} must lie within the ASTM E308 practice range 360-780 nm",
    )
    offset = (grid.start_nm - _PRACTICE_START_NM) / grid.step_nm
    require(
        float(grid.step_nm).is_integer() and abs(offset - round(offset)) < 1e-9,
        f"band weights: grid {grid.label} must have an integer step (nm) and start on 360 + k·step",
    )


def _illuminant_sd(illuminant: Spectrum | None):
    """The colour-science SpectralDistribution for a light; None means the equal-energy light E."""
    if illuminant is None:
        illuminant = spectrum_from_dataset("illuminant", "E")
    return spectrum_to_colour_sd(illuminant)


def band_weights_ASTM_E308(
    grid: SpectralGrid = DEFAULT_GRID,
    illuminant: Spectrum | None = None,
    observer: str = DEFAULT_OBSERVER,
) -> np.ndarray:
    """Tristimulus weights with the light folded in (ASTM E2022 factors, E308 end-band folding).

    Eq. (4), Wang et al. (the discrete tristimulus sum), with the CMFs and the light integrated over
    each band by ASTM E2022's Lagrange weights instead of point-sampled.

    Parameters
    ----------
    grid : SpectralGrid
        Uniform grid inside 360-780 nm with an integer step, starting on 360 + k·step (380-780/10
        and 400-700/10 qualify).
    illuminant : Spectrum, optional
        The light's relative spectral power at any sampling; None is the equal-energy light E (use
        it for radiance spectra with no light folded in).
    observer : str
        Colour-matching functions, one of :data:`OBSERVERS`.

    Returns
    -------
    ndarray, shape (n_bands, 3)
        ``W`` such that ``XYZ = R @ W`` for a reflectance ``R`` on the grid, with Y = 1 for R = 1.

    Notes
    -----
    colour-science computes the E2022 factors on the 360-780 nm practice range at the grid's step;
    the factors of bands outside the grid are added to the first and last grid bands
    (``adjust_tristimulus_weighting_factors_ASTME308``), which amounts to extrapolating R as
    constant.

    Examples
    --------
    >>> from reference.colour.spectra import GRID_41
    >>> W = band_weights_ASTM_E308(GRID_41, spectrum_from_dataset("illuminant", "D65"))
    >>> W.shape, round(float(W[:, 1].sum()), 12)
    ((41, 3), 1.0)
    """
    import colour
    from colour.colorimetry import (
        adjust_tristimulus_weighting_factors_ASTME308,
        tristimulus_weighting_factors_ASTME2022,
    )

    _check_grid_for_weights(grid)
    require_choice(observer, OBSERVERS, "observer")
    step = int(grid.step_nm)
    # The CMFs on the practice range at 1 nm, as colour.sd_to_XYZ_ASTME308 uses them.
    cmfs = colour.MSDS_CMFS[observer].copy().trim(colour.SpectralShape(360, 780, 1))
    illuminant_sd = _illuminant_sd(illuminant).copy().align(cmfs.shape)
    # ASTM E2022 weighting factors on 360-780 at the grid step (Y = 100 for a perfect white).
    W = tristimulus_weighting_factors_ASTME2022(
        cmfs, illuminant_sd, colour.SpectralShape(360, 780, step)
    )
    # ASTM E308: fold the factors outside the grid into its end bands.
    W = adjust_tristimulus_weighting_factors_ASTME308(
        W,
        colour.SpectralShape(360, 360 + step * (W.shape[0] - 1), step),
        colour.SpectralShape(grid.start_nm, grid.end_nm, step),
    )
    return np.ascontiguousarray(W / 100.0)


def band_weights_point_sampled(
    grid: SpectralGrid = DEFAULT_GRID,
    illuminant: Spectrum | None = None,
    observer: str = DEFAULT_OBSERVER,
) -> np.ndarray:
    """Tristimulus weights from point samples of light × CMF at the grid nodes (the naive method).

    Eq. (4), Wang et al., literally: ``W_b = k S(λ_b) cmf(λ_b) Δλ``. Kept to show where it fails:
    spectral lines between nodes (FL2's mercury lines) are missed, by about 4 ΔE00 mean on the
    ColorChecker.

    Parameters
    ----------
    grid : SpectralGrid
        Any uniform grid inside 360-830 nm.
    illuminant : Spectrum, optional
        The light; None is the equal-energy light E.
    observer : str
        One of :data:`OBSERVERS`.

    Returns
    -------
    ndarray, shape (n_bands, 3)
        With Y = 1 for R = 1.

    Examples
    --------
    >>> from reference.colour.spectra import GRID_31
    >>> W = band_weights_point_sampled(GRID_31, spectrum_from_dataset("illuminant", "A"))
    >>> W.shape, round(float(W[:, 1].sum()), 12)
    ((31, 3), 1.0)
    """
    import colour

    require_choice(observer, OBSERVERS, "observer")
    cmfs = colour.MSDS_CMFS[observer]
    wl = grid.wavelengths_nm
    cmf = np.stack([np.interp(wl, cmfs.wavelengths, cmfs.values[:, i]) for i in range(3)], axis=-1)
    light = _illuminant_sd(illuminant)
    S = np.interp(wl, light.wavelengths, light.values)
    # Eq. (4), Wang et al.: W_b = S(λ_b) cmf(λ_b) Δλ, normalised to Y = 1 for a perfect white
    W = S[:, None] * cmf * grid.step_nm
    return np.ascontiguousarray(W / W[:, 1].sum())


#: Band-weight methods, keyed by the names scene files and the CLI use.
BAND_WEIGHT_METHODS = Registry("band-weight method")
BAND_WEIGHT_METHODS.register(
    Method(
        "astm_e308",
        band_weights_ASTM_E308,
        None,
        "Eq. (4), Wang et al. (ASTM E2022/E308 weights)",
        lambda rng: (DEFAULT_GRID, None),
    )
)
BAND_WEIGHT_METHODS.register(
    Method(
        "point",
        band_weights_point_sampled,
        None,
        "Eq. (4), Wang et al. (point samples)",
        lambda rng: (DEFAULT_GRID, None),
    )
)

_WEIGHTS_CACHE: dict[tuple, np.ndarray] = {}


def _spectrum_key(spectrum: Spectrum | None) -> str:
    if spectrum is None:
        return "E"
    digest = hashlib.sha1(spectrum.wavelengths_nm.tobytes() + spectrum.values.tobytes())
    return digest.hexdigest()


def band_weights(
    grid: SpectralGrid = DEFAULT_GRID,
    illuminant: Spectrum | None = None,
    method: str = "astm_e308",
    observer: str = DEFAULT_OBSERVER,
) -> np.ndarray:
    """Tristimulus weights ``W`` (``XYZ = R @ W``) by a registered method, cached by content.

    Parameters
    ----------
    grid : SpectralGrid
        The spectral grid.
    illuminant : Spectrum, optional
        The light folded into the weights; None is the equal-energy light E.
    method : str
        A key of :data:`BAND_WEIGHT_METHODS`: ``"astm_e308"`` (default) or ``"point"``.
    observer : str
        One of :data:`OBSERVERS`.

    Returns
    -------
    ndarray, shape (n_bands, 3)
        Read-only; Y = 1 for a perfect white diffuser.

    Examples
    --------
    >>> from reference.colour.spectra import GRID_41
    >>> W = band_weights(GRID_41, spectrum_from_dataset("illuminant", "FL2"))
    >>> spectra_to_XYZ(np.ones(41), W).round(4)
    array([0.9915, 1.    , 0.6732])
    """
    entry = BAND_WEIGHT_METHODS.lookup(method)
    key = (method, grid, _spectrum_key(illuminant), observer)
    if key not in _WEIGHTS_CACHE:
        W = entry.reference(grid, illuminant, observer)
        W.setflags(write=False)
        _WEIGHTS_CACHE[key] = W
    return _WEIGHTS_CACHE[key]


#: Rows (pixels) per worker below which :func:`spectra_to_XYZ` stays on the calling thread: a
#: smaller block costs less than handing it to another thread.
ROWS_PER_THREAD = 1 << 16


#: Default worker count of :func:`spectra_to_XYZ`: two, or one on a one-core machine.
XYZ_THREADS = max(1, min(2, os.cpu_count() or 1))


@functools.lru_cache(maxsize=4)
def _row_workers(threads: int) -> ThreadPoolExecutor:
    return ThreadPoolExecutor(max_workers=threads, thread_name_prefix="specref-XYZ")


def spectra_to_XYZ(
    spectra, weights: np.ndarray, out=None, threads: int | None = None
) -> np.ndarray:
    """Tristimulus values of spectra on a grid.

    Eq. (4), Wang et al., as a matrix product with band weights. float32 spectra stay float32 (the
    weights are rounded to float32; a 41-band sum keeps ~1e-7 relative error), anything else is
    computed in float64. Large inputs are split into contiguous blocks of rows, one NumPy matrix
    product per block on up to ``threads`` threads (:data:`XYZ_THREADS`); each
    product keeps whatever BLAS threading the process set (the Makefile sets one thread, and
    ``docs/dependencies.md`` says why). The product is memory-bound: a second thread reads the
    input at nearly twice the rate, while ``np.copyto`` of the same bytes gains little from it.

    Parameters
    ----------
    spectra : array_like, shape (..., n_bands)
        Reflectance factors (or radiance relative to the light in ``weights``).
    weights : ndarray, shape (n_bands, 3)
        From :func:`band_weights`.
    out : ndarray, shape (..., 3), optional
        C-contiguous output of the computation dtype.
    threads : int, optional
        Workers for inputs of at least 2 × :data:`ROWS_PER_THREAD` rows; 1 computes in the calling
        thread.

    Returns
    -------
    ndarray, shape (..., 3)
        XYZ with Y = 1 for a perfect white diffuser.

    Examples
    --------
    >>> from reference.colour.spectra import GRID_31
    >>> W = band_weights(GRID_31, None)
    >>> spectra_to_XYZ(np.full((2, 31), 0.5), W).round(3)
    array([[0.5, 0.5, 0.5],
           [0.5, 0.5, 0.5]])
    >>> spectra_to_XYZ(np.full((2, 31), 0.5, np.float32), W).dtype
    dtype('float32')
    """
    spectra = np.asarray(spectra)
    dtype = np.float32 if spectra.dtype == np.float32 else np.float64
    spectra = np.ascontiguousarray(spectra, dtype=dtype)
    weights = np.asarray(weights, dtype=dtype)
    require(
        weights.ndim == 2 and weights.shape[1] == 3,
        f"spectra_to_XYZ: weights must be (n_bands, 3), got {weights.shape}",
    )
    require(
        spectra.shape[-1:] == weights.shape[:1],
        f"spectra_to_XYZ: spectra have {spectra.shape[-1:]} bands but the weights have "
        f"{weights.shape[0]}",
    )
    shape = (*spectra.shape[:-1], 3)
    if out is None:
        out = np.empty(shape, dtype=dtype)
    require(
        out.shape == shape and out.dtype == dtype and out.flags.c_contiguous,
        f"spectra_to_XYZ: out must be a C-contiguous {np.dtype(dtype).name} array {shape}, "
        f"got {out.dtype} {out.shape}",
    )
    rows, XYZ = spectra.reshape(-1, weights.shape[0]), out.reshape(-1, 3)
    threads = XYZ_THREADS if threads is None else int(threads)
    require(threads >= 1, f"spectra_to_XYZ: threads must be >= 1, got {threads}")
    blocks = max(1, min(threads, rows.shape[0] // ROWS_PER_THREAD))
    # Eq. (4), Wang et al.: X = k Σ_λ φ(λ) x̄(λ), with k and the light inside W
    if blocks == 1:
        np.matmul(rows, weights, out=XYZ)
        return out
    edges = np.linspace(0, rows.shape[0], blocks + 1).astype(int)
    jobs = [
        _row_workers(blocks).submit(np.matmul, rows[a:b], weights, out=XYZ[a:b])
        for a, b in itertools.pairwise(edges)
    ]
    for job in jobs:
        job.result()
    return out


def white_XYZ(weights: np.ndarray) -> np.ndarray:
    """XYZ of the perfect white diffuser under the weights' light (Y = 1).

    Examples
    --------
    >>> from reference.colour.spectra import GRID_41
    >>> white_XYZ(band_weights(GRID_41, spectrum_from_dataset("illuminant", "D65"))).round(4)
    array([0.9505, 1.    , 1.0888])
    """
    return weights.sum(axis=0)


def XYZ_to_RGB_matrix(
    colourspace: str = "sRGB",
    white_XYZ_in=None,
    chromatic_adaptation: str | None = None,
) -> np.ndarray:
    """The 3×3 matrix from XYZ to a colourspace's linear RGB, optionally with chromatic adaptation.

    Parameters
    ----------
    colourspace : str
        A key of ``colour.RGB_COLOURSPACES`` (``"sRGB"``, ``"Display P3"``, ``"Adobe RGB (1998)"``,
        ...).
    white_XYZ_in : array_like, shape (3,), optional
        White of the XYZ input (the scene light's white), needed only with ``chromatic_adaptation``.
    chromatic_adaptation : str, optional
        None (colorimetric: the display shows the XYZ as they are) or a colour-science transform
        (``"Bradford"``, ``"CAT02"``, ``"Von Kries"``) adapting ``white_XYZ_in`` to the colourspace
        white.

    Returns
    -------
    ndarray, shape (3, 3)
        ``RGB = M @ XYZ``.

    Examples
    --------
    >>> XYZ_to_RGB_matrix("sRGB").round(4)[0]
    array([ 3.2406, -1.5372, -0.4986])
    """
    import colour

    require_choice(colourspace, list(colour.RGB_COLOURSPACES), "colourspace")
    space = colour.RGB_COLOURSPACES[colourspace]
    M = np.asarray(space.matrix_XYZ_to_RGB, dtype=np.float64)
    if chromatic_adaptation is None:
        return M
    require_choice(
        chromatic_adaptation, list(colour.CHROMATIC_ADAPTATION_TRANSFORMS), "chromatic adaptation"
    )
    require(white_XYZ_in is not None, "XYZ_to_RGB_matrix: chromatic adaptation needs white_XYZ_in")
    white_out = colour.xy_to_XYZ(space.whitepoint)
    white_in = np.asarray(white_XYZ_in, dtype=np.float64) / float(white_XYZ_in[1])
    A = colour.adaptation.matrix_chromatic_adaptation_VonKries(
        white_in, white_out, transform=chromatic_adaptation
    )
    return M @ A


def XYZ_to_display_RGB(
    XYZ, colourspace: str = "sRGB", white_XYZ_in=None, chromatic_adaptation=None
):
    """Linear display RGB from XYZ (Y = 1 scale); see :func:`XYZ_to_RGB_matrix`.

    Eq. (5), Wang et al.

    Parameters
    ----------
    XYZ : array_like, shape (..., 3)
        Tristimulus values, Y = 1 for the white diffuser.
    colourspace, white_XYZ_in, chromatic_adaptation
        As in :func:`XYZ_to_RGB_matrix`.

    Returns
    -------
    ndarray, shape (..., 3)
        Linear RGB, unclipped.

    Examples
    --------
    >>> XYZ_to_display_RGB([0.95047, 1.0, 1.08883]).round(3)
    array([1., 1., 1.])
    """
    M = XYZ_to_RGB_matrix(colourspace, white_XYZ_in, chromatic_adaptation)
    # Eq. (5), Wang et al.: [R G B] = [X Y Z] · XYZtoRGB
    return np.asarray(XYZ, dtype=np.float64) @ M.T


def display_RGB_to_XYZ(RGB, colourspace: str = "sRGB") -> np.ndarray:
    """XYZ from linear display RGB, the inverse of :func:`XYZ_to_display_RGB` without adaptation.

    Examples
    --------
    >>> display_RGB_to_XYZ([1.0, 1.0, 1.0]).round(4)
    array([0.9505, 1.    , 1.089 ])
    """
    M = XYZ_to_RGB_matrix(colourspace)
    return np.asarray(RGB, dtype=np.float64) @ np.linalg.inv(M).T


def spectra_to_RGB_matrix(
    weights: np.ndarray, colourspace: str = "sRGB", chromatic_adaptation: str | None = None
) -> np.ndarray:
    """The spectra-to-RGB matrix: band weights times the XYZ-to-RGB matrix.

    Eq. (9), Wang et al.

    Parameters
    ----------
    weights : ndarray, shape (n_bands, 3)
        From :func:`band_weights` (light folded in).
    colourspace : str
        Target colourspace.
    chromatic_adaptation : str, optional
        As in :func:`XYZ_to_RGB_matrix`; the source white is the light's white.

    Returns
    -------
    ndarray, shape (n_bands, 3)
        ``RGB = spectra @ M``; each column is a channel's row ``w`` of Eq. (11), Wang et al.

    Examples
    --------
    >>> from reference.colour.spectra import GRID_41
    >>> W = band_weights(GRID_41, spectrum_from_dataset("illuminant", "D65"))
    >>> (np.ones(41) @ spectra_to_RGB_matrix(W)).round(3)
    array([1., 1., 1.])
    """
    M = XYZ_to_RGB_matrix(colourspace, white_XYZ(weights), chromatic_adaptation)
    # Eq. (9), Wang et al.: Spectra-to-RGB = [x̄ ȳ z̄](λ) · XYZtoRGB
    return np.ascontiguousarray(weights @ M.T)


def XYZ_to_Lab(XYZ, white=None) -> np.ndarray:
    """CIELAB from XYZ on specref's Y = 1 scale, through colour-science.

    Parameters
    ----------
    XYZ : array_like, shape (..., 3)
        Tristimulus values, Y = 1 for the white diffuser.
    white : array_like, shape (3,), optional
        Reference white XYZ (Y = 1 scale); default D65's.

    Returns
    -------
    ndarray, shape (..., 3)
        L* in [0, 100], a*, b*.

    Examples
    --------
    >>> XYZ_to_Lab([0.95047, 1.0, 1.08883]).round(3)
    array([100.,   0.,   0.])
    """
    import colour

    white = np.array([0.95047, 1.0, 1.08883]) if white is None else np.asarray(white, float)
    return colour.XYZ_to_Lab(np.asarray(XYZ, dtype=np.float64), colour.XYZ_to_xy(white))


def delta_E_00(Lab_1, Lab_2) -> np.ndarray:
    """CIEDE2000 colour difference, through colour-science.

    Examples
    --------
    >>> float(delta_E_00([50.0, 2.6772, -79.7751], [50.0, 0.0, -82.7485])).__round__(4)
    2.0425
    """
    import colour

    return colour.delta_E(np.asarray(Lab_1, float), np.asarray(Lab_2, float), method="CIE 2000")


def spectral_channel_weights(wavelengths_nm, where: str = "spectral channels") -> np.ndarray:
    """Equal-energy weights ``W`` (``XYZ = bands @ W``) for an image's evenly spaced bands.

    A spectral image's bands hold relative radiance normalised with the equal-energy light
    (docs/render-outputs.md), so its XYZ is ``bands @ W`` with ``W = band_weights(grid, None)``:
    ASTM E308 where it tabulates the grid, else point sampling.

    Parameters
    ----------
    wavelengths_nm : array_like, shape (B,)
        The bands' centres, evenly spaced.
    where : str
        What the message of a refusal names (a file).

    Returns
    -------
    ndarray, shape (B, 3)

    Examples
    --------
    >>> W = spectral_channel_weights(np.arange(380.0, 781.0, 10.0))
    >>> W.shape, round(float(W[:, 1].sum()), 6)
    ((41, 3), 1.0)
    >>> spectral_channel_weights([400.0, 410.0, 430.0], "a.exr")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: a.exr: spectral channels must be evenly spaced, got [400.0, ...
    """
    from reference.colour.spectra import SpectralGrid
    from reference.errors import SpecrefError

    wavelengths = np.asarray(wavelengths_nm, dtype=np.float64)
    steps = np.diff(wavelengths)
    require(
        wavelengths.size >= 2 and np.allclose(steps, steps[0]),
        f"{where}: spectral channels must be evenly spaced, got {wavelengths.tolist()}",
    )
    grid = SpectralGrid(float(wavelengths[0]), float(wavelengths[-1]), float(steps[0]))
    try:
        return band_weights(grid, None, "astm_e308")
    except SpecrefError:  # a grid that ASTM E308 does not tabulate
        return band_weights(grid, None, "point")

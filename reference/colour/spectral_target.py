"""Synthetic camera targets: camera RGB of reflectance sets that colour-science ships.

A user without a measured target (Herbert et al. measured a 576-patch camera target, §4) gets one
from a camera's spectral sensitivities and reflectance sets that colour-science ships
(erratum E40):

- **Training** (:data:`TRAINING_SET`): the 190 training spectra of rawtoaces
  (``colour.characterisation.read_training_data_rawtoaces_v1``), the only general-purpose
  reflectance collection in colour-science, with every *look-alike* of a held-out patch removed.
  A look-alike is within 0.03 spectral RMS (41 bands) or ΔE94 2.0 (D65, CIE 1931 2°) of any patch
  of :data:`HELD_OUT_SETS` or of the other ColorChecker measurements (BabelColor Average,
  ISO 17321-1, PMC); rawtoaces holds several ColorChecker-like patches, and a held-out figure on a
  patch the model was trained on would measure memory, not recovery.
- **Held out** (:data:`HELD_OUT_SETS`): ColorChecker N Ohta (the chart of the section's targets),
  the CIE 2024 test colour samples and the NIST CQS 9.0 samples (Munsell papers). The design never
  sees them.
- **A further test set** (:data:`OTHER_TEST_SET`, erratum E44): the 99 colour evaluation samples
  of CIE 224:2017 (colour fidelity index; real objects chosen to cover colour space uniformly)
  minus those with a look-alike in the training set (same thresholds), measured after every
  design choice was made, to check that a choice did not fit the sets above.
- **Every set** (:data:`EVALUATION_SETS`): the above, the other ColorChecker measurements
  (BabelColor Average, ISO 17321-1, PMC: their look-alikes are out of training too), the CIE 1995
  test colour samples and NIST CQS 7.4, and the 18 Nix Spectro 2 measurements that specref ships
  (:data:`MEASURED_SET`, 400-700 nm, constant beyond); the last three minus the patches with a
  training look-alike, as the CIE 2017 samples.
- **Cameras** (:data:`CAMERAS`): colour-science's ``MSDS_CAMERA_SENSITIVITIES`` (Nikon 5100 and
  Sigma SD Merrill, NPL measurements), and ``sRGB``: the CIE 1931 2° observer through the XYZ →
  linear sRGB matrix, i.e. the RGB of the sRGB-encoded maps scenes use.

Camera RGB is integrated on the 5 nm grid 380–780 nm (:data:`FINE_GRID`) and normalized so that the
perfect white diffuser under the capture illuminant is (1, 1, 1); the target spectra are the same
reflectances on the 10 nm grid.

References
----------
- F. Herbert et al., "Multispectral Virtual Reality", 2004, §4.
- Academy of Motion Picture Arts and Sciences, rawtoaces, training spectra (190 patches).
- W. Davis, Y. Ohno, "Color quality scale", Optical Engineering 49(3), 2010 (the VS samples).
"""

from __future__ import annotations

import functools

import numpy as np

from reference.colour.spectra import GRID_41, SpectralGrid
from reference.errors import SpecrefError, require
from reference.registry import Registry

__all__ = [
    "CAMERAS",
    "DEFAULT_AUGMENTATION",
    "EVALUATION_SETS",
    "FINE_GRID",
    "HELD_OUT_SETS",
    "MEASURED_SET",
    "OTHER_TEST_SET",
    "TARGET_AUGMENTATIONS",
    "TRAINING_SET",
    "camera_RGB",
    "camera_noise",
    "product_augmentation",
    "product_patches",
    "read_target",
    "reflectance_set",
]

#: Integration grid of camera responses.
FINE_GRID = SpectralGrid(380.0, 780.0, 5.0)
#: Name of the training set (recorded in model files).
TRAINING_SET = "rawtoaces-190 minus look-alikes"


def _colour_sets():
    import colour

    checkers = colour.SDS_COLOURCHECKERS
    return {
        "ColorChecker N Ohta": checkers["ColorChecker N Ohta"],
        "CIE 2024 TCS": colour.quality.SDS_TCS["CIE 2024"],
        "NIST CQS 9.0": colour.quality.SDS_VS["NIST CQS 9.0"],
        "BabelColor Average": checkers["BabelColor Average"],
        "ISO 17321-1": checkers["ISO 17321-1"],
        "PMC": checkers["PMC"],
    }


#: The CIE 2017 colour evaluation samples without a training look-alike (module docstring).
OTHER_TEST_SET = "CIE 2017 TCS minus training look-alikes"
#: The Nix Spectro 2 measurements specref ships, without a training look-alike.
MEASURED_SET = "physicallybased Nix minus training look-alikes"
# Sets evaluated without their training look-alikes: name -> source set.
_FILTERED_SETS = {
    OTHER_TEST_SET: "CIE 2017 TCS",
    "CIE 1995 TCS minus training look-alikes": "CIE 1995 TCS",
    "NIST CQS 7.4 minus training look-alikes": "NIST CQS 7.4",
    MEASURED_SET: "physicallybased Nix",
}
#: Reflectance sets never used in training (and whose look-alikes are removed from training).
HELD_OUT_SETS = ("ColorChecker N Ohta", "CIE 2024 TCS", "NIST CQS 9.0")
# Further sets whose look-alikes are removed: the other ColorChecker measurements.
_LOOKALIKE_SETS = (*HELD_OUT_SETS, "BabelColor Average", "ISO 17321-1", "PMC")
#: Every reflectance set a fit is evaluated on (module docstring): none is read by the fitting.
EVALUATION_SETS = (*_LOOKALIKE_SETS, *_FILTERED_SETS)
# Look-alike thresholds (erratum E40).
_LOOKALIKE_RMS = 0.03
_LOOKALIKE_DELTA_E94 = 2.0


def _on_fine_grid(sds) -> tuple[list[str], np.ndarray]:
    wl = FINE_GRID.wavelengths_nm
    labels = list(sds)
    values = np.stack(
        [np.interp(wl, sds[k].wavelengths, sds[k].values) for k in labels]
    )  # (n, 81); constant beyond a set's ends (all sets here cover 380-780 nm)
    return labels, values


def _lab_D65(spectra_41: np.ndarray) -> np.ndarray:
    from reference.colour.colorimetry import XYZ_to_Lab, band_weights, white_XYZ
    from reference.colour.spectra import spectrum_from_dataset

    W = band_weights(GRID_41, spectrum_from_dataset("illuminant", "D65"))
    return XYZ_to_Lab(spectra_41 @ W, white_XYZ(W))


def _has_lookalike(values: np.ndarray, references: np.ndarray) -> np.ndarray:
    """Per spectrum (5 nm): within 0.03 spectral RMS or ΔE94 2.0 (D65) of a reference (E40)."""
    import colour

    coarse, ref = values[:, ::2], references[:, ::2]
    # squared distances as |a|² + |b|² − 2a·b: no (n, m, bands) array for thousands of spectra
    sq = (coarse**2).sum(1)[:, None] + (ref**2).sum(1)[None] - 2.0 * coarse @ ref.T
    rms = np.sqrt(np.maximum(sq, 0.0) / coarse.shape[1]).min(axis=1)
    lab, lab_ref = _lab_D65(coarse), _lab_D65(ref)
    dE = colour.delta_E(lab[:, None], lab_ref[None], method="CIE 1994").min(axis=1)
    return (rms < _LOOKALIKE_RMS) | (dE < _LOOKALIKE_DELTA_E94)


@functools.cache
def _cie2017_samples() -> tuple[tuple[str, ...], np.ndarray]:
    """CIE 224:2017's 99 colour evaluation samples, as colour-science ships them (5 nm)."""
    import colour

    msds = colour.quality.cfi2017.load_TCS_CIE2017(colour.SpectralShape(380, 780, 5))
    values = np.asarray(msds.values, dtype=np.float64).T.copy()
    values.setflags(write=False)
    return tuple(msds.labels), values


@functools.cache
def _source_set(name: str) -> tuple[tuple[str, ...], np.ndarray]:
    """A source of :data:`_FILTERED_SETS` on :data:`FINE_GRID`, every patch."""
    import colour

    if name == "CIE 2017 TCS":
        return _cie2017_samples()
    if name == "physicallybased Nix":
        from reference.colour.spectra import resample_spectrum, spectrum_from_csv
        from reference.data import measured_spectra_folder

        paths = sorted(measured_spectra_folder().glob("*__nix_export.csv"))
        labels = tuple(p.name.split("__")[0] for p in paths)
        values = np.stack(
            [
                resample_spectrum(spectrum_from_csv(p), FINE_GRID, extrapolation="constant")
                for p in paths
            ]
        )
        return labels, values
    sds = {"CIE 1995 TCS": colour.quality.SDS_TCS["CIE 1995"]}
    sds["NIST CQS 7.4"] = colour.quality.SDS_VS["NIST CQS 7.4"]
    labels, values = _on_fine_grid(sds[name])
    return tuple(labels), values


@functools.cache
def _reflectance_set(name: str) -> tuple[tuple[str, ...], np.ndarray]:
    if name == TRAINING_SET:
        from colour.characterisation import read_training_data_rawtoaces_v1

        msds = read_training_data_rawtoaces_v1()
        labels = list(msds.labels)
        values = np.stack(
            [
                np.interp(FINE_GRID.wavelengths_nm, msds.wavelengths, msds.values[:, i])
                for i in range(len(labels))
            ]
        )
        refs = [_on_fine_grid(_colour_sets()[other])[1] for other in _LOOKALIKE_SETS]
        keep = ~_has_lookalike(values, np.concatenate(refs))
        labels = [label for label, k in zip(labels, keep, strict=True) if k]
        values = values[keep]
    elif name in _FILTERED_SETS:
        all_labels, values = _source_set(_FILTERED_SETS[name])
        keep = ~_has_lookalike(values, _reflectance_set(TRAINING_SET)[1])
        labels = [label for label, k in zip(all_labels, keep, strict=True) if k]
        values = values[keep]
    else:
        sets = _colour_sets()
        require(
            name in sets,
            f"unknown reflectance set {name!r}; allowed: {', '.join(sets)}, {TRAINING_SET}, "
            f"{', '.join(_FILTERED_SETS)}",
        )
        labels, values = _on_fine_grid(sets[name])
    values.setflags(write=False)
    return tuple(labels), values


def reflectance_set(name: str, grid: SpectralGrid = FINE_GRID) -> tuple[list[str], np.ndarray]:
    """Labels and reflectances: :data:`TRAINING_SET`, :data:`OTHER_TEST_SET` or a held-out set.

    Parameters
    ----------
    name : str
    grid : SpectralGrid
        :data:`FINE_GRID` (5 nm) or ``GRID_41`` (10 nm, every second sample).

    Returns
    -------
    labels : list of str
    spectra : ndarray, shape (n, n_bands)

    Examples
    --------
    >>> labels, spectra = reflectance_set("ColorChecker N Ohta", GRID_41)
    >>> len(labels), spectra.shape
    (24, (24, 41))
    >>> len(reflectance_set(TRAINING_SET)[0]), len(reflectance_set(OTHER_TEST_SET)[0])
    (156, 87)
    """
    require(grid in (FINE_GRID, GRID_41), f"reflectance_set: grid must be 5 or 10 nm, got {grid}")
    labels, values = _reflectance_set(name)
    return list(labels), values if grid == FINE_GRID else values[:, ::2]


def _sensitivities(camera: str) -> np.ndarray:
    import colour

    wl = FINE_GRID.wavelengths_nm
    if camera == "sRGB":
        cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
        xyz = np.stack([np.interp(wl, cmfs.wavelengths, cmfs.values[:, i]) for i in range(3)], 1)
        return xyz @ colour.RGB_COLOURSPACES["sRGB"].matrix_XYZ_to_RGB.T
    msds = colour.MSDS_CAMERA_SENSITIVITIES[camera]
    return np.stack([np.interp(wl, msds.wavelengths, msds.values[:, i]) for i in range(3)], 1)


#: Cameras by key: colour-science's measured sensitivities, and the sRGB "camera".
CAMERAS = Registry("camera", functools.partial)
for _camera in ("Nikon 5100 (NPL)", "Sigma SDMerill (NPL)", "sRGB"):
    CAMERAS.register(functools.partial(_sensitivities, _camera), _camera)


def camera_RGB(reflectances, camera: str, illuminant: str = "D65") -> np.ndarray:
    """Camera RGB of reflectances under an illuminant, the white diffuser at (1, 1, 1).

    ``RGB_c = Σ_λ R(λ) E(λ) s_c(λ) / Σ_λ E(λ) s_c(λ)`` on the 5 nm grid; negative values (only the
    sRGB "camera" of saturated colours has them) are clipped to 0.

    Parameters
    ----------
    reflectances : array_like, shape (..., 81)
        On :data:`FINE_GRID`.
    camera : str
        A key of :data:`CAMERAS`.
    illuminant : str
        A colour-science illuminant key.

    Returns
    -------
    ndarray, shape (..., 3)

    Examples
    --------
    >>> camera_RGB(np.ones(81), "Nikon 5100 (NPL)").round(6)
    array([1., 1., 1.])
    """
    return np.maximum(_camera_response(reflectances, camera, illuminant), 0.0)


def _camera_response(reflectances, camera: str, illuminant: str) -> np.ndarray:
    """:func:`camera_RGB` before negative values are clipped."""
    from reference.colour.spectra import resample_spectrum, spectrum_from_dataset

    s = CAMERAS.lookup(camera)()
    E = resample_spectrum(spectrum_from_dataset("illuminant", illuminant), FINE_GRID)
    R = np.asarray(reflectances, dtype=np.float64)
    require(R.shape[-1] == FINE_GRID.n_bands, f"camera_RGB: expected (..., 81), got {R.shape}")
    response = E[:, None] * s
    return R @ response / response.sum(axis=0)


def camera_noise(RGB, rng: np.random.Generator, multiplicative=0.005, additive=0.001):
    """Camera RGB with Gaussian noise: ``RGB · (1 + m·N) + a·N'``, clipped to >= 0.

    Examples
    --------
    >>> noisy = camera_noise(np.full((1000, 3), 0.5), np.random.default_rng(0))
    >>> round(float(noisy.std()), 4)
    0.0027
    """
    RGB = np.asarray(RGB, dtype=np.float64)
    noisy = RGB * (1.0 + multiplicative * rng.standard_normal(RGB.shape))
    return np.maximum(noisy + additive * rng.standard_normal(RGB.shape), 0.0)


def product_patches(reflectances, avoid=None) -> np.ndarray:
    """Every product ``R_i · R_j`` (i < j) of the reflectances, less the look-alikes of ``avoid``.

    A product is the reflectance of a transparent layer of double-pass transmittance ``R_j``
    over an opaque ``R_i``: a physically realizable reflectance, darker and more saturated than
    both. They extend a training set of n patches by n(n − 1)/2 patches where it is thin (the
    saturated colours that a regression otherwise reaches only by extrapolation); erratum E44.

    Parameters
    ----------
    reflectances : array_like, shape (n, 81)
        On :data:`FINE_GRID`.
    avoid : array_like, shape (m, 81), optional
        Spectra whose look-alikes (E40's thresholds) are left out.

    Returns
    -------
    ndarray, shape (k, 81)

    Examples
    --------
    >>> R = np.stack([np.full(81, 0.5), np.linspace(0.2, 0.8, 81), np.full(81, 0.9)])
    >>> product_patches(R).shape, float(product_patches(R)[0, 0])
    ((3, 81), 0.1)
    >>> product_patches(R, avoid=np.full((1, 81), 0.45)).shape   # 0.5 × 0.9 is left out
    (2, 81)
    """
    R = np.asarray(reflectances, dtype=np.float64)
    require(R.ndim == 2 and R.shape[1] == FINE_GRID.n_bands, f"expected (n, 81), got {R.shape}")
    i, j = np.triu_indices(len(R), 1)
    products = R[i] * R[j]
    if avoid is not None and len(avoid):
        products = products[~_has_lookalike(products, np.asarray(avoid, dtype=np.float64))]
    return products


def product_augmentation(
    reflectances, camera: str, illuminant: str = "D65", noise_rng=None, grid: SpectralGrid = GRID_41
):
    """The augmentation that ``fit_regression(augment=...)`` takes: products of training patches.

    ``augment(train, held)`` returns the camera RGB and spectra (on ``grid``) of
    :func:`product_patches` of the patches ``train`` of ``reflectances``, less the look-alikes of
    every held-out set, of the other ColorChecker measurements, of CIE 224:2017's 99 samples
    (:data:`OTHER_TEST_SET` is drawn from them) and of the patches ``held`` (a
    cross-validation fold's held-out patches: the fold must not see their look-alikes either).
    With ``noise_rng`` the RGB gets :func:`camera_noise`. Erratum E44.

    Parameters
    ----------
    reflectances : array_like, shape (n, 81)
        The target's reflectances on :data:`FINE_GRID`.
    camera, illuminant : str
        As in :func:`camera_RGB`.
    noise_rng : numpy.random.Generator, optional
    grid : SpectralGrid
        The grid of the spectra returned (:data:`FINE_GRID` or ``GRID_41``).

    Returns
    -------
    callable
        With ``name`` ``"products"``.

    Examples
    --------
    >>> _, R = reflectance_set(TRAINING_SET)
    >>> RGB, spectra = product_augmentation(R[:20], "Nikon 5100 (NPL)")(np.arange(20), None)
    >>> RGB.shape[1], spectra.shape[1], len(RGB) <= 190
    (3, 41, True)
    """
    R = np.asarray(reflectances, dtype=np.float64)
    require(
        grid in (FINE_GRID, GRID_41), f"product_augmentation: grid must be 5 or 10 nm, got {grid}"
    )
    require(R.ndim == 2 and R.shape[1] == FINE_GRID.n_bands, f"expected (n, 81), got {R.shape}")
    i, j, products, response, usable = _all_products(R.tobytes(), len(R), camera, illuminant)

    def augment(train, held=None):
        inside = np.zeros(len(R), dtype=bool)
        inside[np.asarray(train)] = True
        pick = usable & inside[i] & inside[j]  # the products of the patches `train`, in order
        P, RGB = products[pick], response[pick]
        if held is not None and len(held):
            other = ~_has_lookalike(P, R[np.asarray(held)])
            P, RGB = P[other], RGB[other]
        if noise_rng is not None:
            RGB = camera_noise(RGB, noise_rng)
        return RGB, P if grid == FINE_GRID else P[:, ::2]

    augment.name = "products"
    return augment


@functools.lru_cache(maxsize=4)
def _all_products(data: bytes, n: int, camera: str, illuminant: str):
    """Every product of ``n`` reflectances (``data``: their float64 bytes) and what is usable.

    Returns the pair indices ``i < j``, the products, their camera response and a mask: not a
    look-alike of a held-out set, another ColorChecker measurement or a CIE 2017 sample, and
    recorded by the camera (no channel below 0: a product outside the sRGB "camera"'s gamut
    would teach the clipped RGB). Cached, so that every fold and fit of a study shares them.
    """
    R = np.frombuffer(data, dtype=np.float64).reshape(n, FINE_GRID.n_bands)
    i, j = np.triu_indices(n, 1)
    products = product_patches(R)  # the pairs (i, j) in this order
    references = np.concatenate(
        [_on_fine_grid(_colour_sets()[s])[1] for s in _LOOKALIKE_SETS] + [_cie2017_samples()[1]]
    )
    response = _camera_response(products, camera, illuminant)
    usable = ~_has_lookalike(products, references) & (response >= 0).all(axis=1)
    for array in (i, j, products, response, usable):
        array.setflags(write=False)
    return i, j, products, response, usable


#: How a synthetic target may be augmented, by key (``specref env fit --augment``; E44).
TARGET_AUGMENTATIONS = Registry("target augmentation", object)
TARGET_AUGMENTATIONS.register(product_augmentation, "products")
TARGET_AUGMENTATIONS.register(None, "none")
#: The augmentation of ``specref env fit`` and the report (its weight by cross-validation); the
#: shipped sRGB model is fitted without it (``validation.precompute.spectral_regression``).
DEFAULT_AUGMENTATION = "products"


def _read_csv(path) -> tuple[list[str], list[list[str]]]:
    import csv
    from pathlib import Path

    path = Path(path)
    require(path.is_file(), f"{path}: file not found")
    try:
        with open(path, newline="", encoding="utf-8") as handle:
            rows = [r for r in csv.reader(handle) if r and not r[0].lstrip().startswith("#")]
    except (UnicodeDecodeError, csv.Error) as error:  # a binary or non-UTF-8 file
        raise SpecrefError(f"{path}: not a UTF-8 CSV text file ({error})") from None
    require(len(rows) >= 2, f"{path}: expected a header row and at least one patch")
    return [h.strip() for h in rows[0]], rows[1:]


def _columns(path, header, rows, names) -> np.ndarray:
    index = [header.index(n) for n in names]
    try:
        return np.array([[float(r[i]) for i in index] for r in rows])
    except (ValueError, IndexError):
        raise SpecrefError(f"{path}: non-numeric or missing values in {', '.join(names)}") from None


#: Reflectances a target file may hold: [0, 1] with room for measurement noise and the slight
#: excess of fluorescent or glossy patches (ours, E104); -0.5 or 5.0 is a wrong file or unit.
REFLECTANCE_RANGE = (-0.05, 1.5)

#: The largest camera RGB a target file may hold: the white diffuser is 1, so ten times it is no
#: patch of a reflective target (8-bit counts, 0-255, are a wrong unit; 1e308 was fitted).
MAX_TARGET_RGB = 10.0


def read_target(path, spectra_path=None, grid: SpectralGrid = GRID_41):
    r"""Read a measured camera target: RGB of the patches and their reflectances on ``grid``.

    Herbert et al., §4 (a camera target with measured spectra). Format (CSV, ``#`` comments):
    a header row, then one row per patch. The RGB columns are named ``R``, ``G``, ``B`` (linear
    camera RGB, white diffuser = 1); the spectral columns are named by their wavelength in nm
    (``380``, ``385nm``…), reflectance in [0, 1]. Either one file holds both, or ``path`` holds
    the RGB and ``spectra_path`` the spectra, rows in the same order. The spectra are resampled
    linearly onto ``grid``, which their wavelengths must cover.

    Returns
    -------
    RGB : ndarray, shape (n, 3)
    spectra : ndarray, shape (n, n_bands)

    Raises
    ------
    SpecrefError
        Missing columns, patch counts that differ, a grid that does not cover ``grid``,
        RGB that is NaN or outside [0, :data:`MAX_TARGET_RGB`], reflectances outside
        :data:`REFLECTANCE_RANGE`.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     path = os.path.join(d, "t.csv")
    ...     _ = open(path, "w").write("R,G,B,400,700\n0.5,0.5,0.5,0.5,0.5\n")
    ...     RGB, spectra = read_target(path, grid=SpectralGrid(400.0, 700.0, 100.0))
    >>> RGB, spectra
    (array([[0.5, 0.5, 0.5]]), array([[0.5, 0.5, 0.5, 0.5]]))
    """
    import re

    header, rows = _read_csv(path)
    missing = [c for c in "RGB" if c not in header]
    require(not missing, f"{path}: no column {', '.join(missing)} (expected R, G, B)")
    RGB = _columns(path, header, rows, list("RGB"))
    spectra_file = path if spectra_path is None else spectra_path
    if spectra_path is not None:
        header, rows = _read_csv(spectra_path)
    pattern = re.compile(r"^(\d+(?:\.\d+)?)\s*(?:nm)?$")
    columns = [h for h in header if pattern.match(h)]
    require(columns, f"{spectra_file}: no spectral columns (named by wavelength in nm: 380, 390nm)")
    wavelengths = np.array([float(pattern.match(h).group(1)) for h in columns])
    values = _columns(spectra_file, header, rows, columns)
    require(
        len(RGB) == len(values),
        f"{spectra_file}: {len(values)} spectra for {len(RGB)} RGB patches in {path}",
    )
    bad = ~(np.isfinite(RGB) & (RGB >= 0) & (RGB <= MAX_TARGET_RGB)).all(axis=1)
    require(
        not bad.any(),
        f"{path}: patch {int(np.argmax(bad)) + 1}: RGB must be finite and in "
        f"[0, {MAX_TARGET_RGB:g}] (linear camera RGB, white diffuser = 1)",
    )
    low, high = REFLECTANCE_RANGE
    bad = ~(np.isfinite(values) & (values >= low) & (values <= high)).all(axis=1)
    require(
        not bad.any(),
        f"{spectra_file}: patch {int(np.argmax(bad)) + 1}: reflectances must be finite and in "
        f"[{low:g}, {high:g}] (measurement noise allowed around [0, 1])",
    )
    require(
        (np.diff(wavelengths) > 0).all()
        and wavelengths[0] <= grid.wavelengths_nm[0]
        and wavelengths[-1] >= grid.wavelengths_nm[-1],
        f"{spectra_file}: spectra on {wavelengths[0]:g}-{wavelengths[-1]:g} nm do not cover the "
        f"scene grid {grid.label}",
    )
    spectra = np.stack([np.interp(grid.wavelengths_nm, wavelengths, v) for v in values])
    return RGB, spectra

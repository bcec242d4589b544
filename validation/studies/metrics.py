"""Error metrics shared by tests, benchmarks and the report.

- :func:`delta_E_stats`: mean, standard deviation, 90th percentile and maximum of ΔE values, as in
Table 1,
  Ferwerda.
- :func:`colorchecker_delta_E`: ΔE00 of specref's spectral core on the ColorChecker against
colour-science's
  5 nm computation (the physical truth), per patch.
"""

from __future__ import annotations

import numpy as np

from reference.colour.colorimetry import XYZ_to_Lab, band_weights, delta_E_00, spectra_to_XYZ
from reference.colour.spectra import (
    SpectralGrid,
    make_spectrum,
    resample_spectrum,
    spectrum_from_dataset,
)
from reference.errors import require

__all__ = ["COLORCHECKER", "colorchecker_delta_E", "colorchecker_truth", "delta_E_stats"]

#: The ColorChecker measurement set used for accuracy figures (5 nm, 380-780 nm).
COLORCHECKER = "ColorChecker N Ohta"


def delta_E_stats(delta_E) -> dict:
    """Summary statistics of colour differences.

    Parameters
    ----------
    delta_E : array_like, shape (n,)
        Colour differences.

    Returns
    -------
    dict
        ``mean``, ``std`` (population), ``p90`` (90th percentile, linear interpolation) and ``max``.

    Examples
    --------
    >>> {k: round(v, 3) for k, v in delta_E_stats([0.0, 1.0, 2.0, 3.0]).items()}
    {'mean': 1.5, 'std': 1.118, 'p90': 2.7, 'max': 3.0}
    """
    d = np.asarray(delta_E, dtype=np.float64).ravel()
    require(d.size > 0, "delta_E_stats: no values")
    return {
        "mean": float(d.mean()),
        "std": float(d.std()),
        "p90": float(np.percentile(d, 90)),
        "max": float(d.max()),
    }


def colorchecker_truth(illuminant: str) -> tuple[dict, np.ndarray, np.ndarray]:
    """The 5 nm truth on the ColorChecker: colour-science's ``sd_to_XYZ`` (CIE 1931 2°), Y = 1.

    Parameters
    ----------
    illuminant : str
        A colour-science illuminant key.

    Returns
    -------
    patches : dict
        Patch name to colour-science ``SpectralDistribution`` (5 nm, 380-780 nm).
    XYZ : ndarray, shape (24, 3)
        Truth per patch.
    white : ndarray, shape (3,)
        The perfect white diffuser under the light (Y = 1).

    Examples
    --------
    >>> _, XYZ, white = colorchecker_truth("D65")
    >>> XYZ.shape, white.round(4)
    ((24, 3), array([0.9505, 1.    , 1.089 ]))
    """
    import colour

    sd_light = spectrum_from_dataset("illuminant", illuminant).meta["colour_sd"]
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    patches = colour.SDS_COLOURCHECKERS[COLORCHECKER]
    first = next(iter(patches.values()))
    unit = colour.SpectralDistribution(np.ones(first.values.size), first.wavelengths)
    white = colour.sd_to_XYZ(unit, cmfs, sd_light) / 100.0
    XYZ = np.array([colour.sd_to_XYZ(sd, cmfs, sd_light) / 100.0 for sd in patches.values()])
    return dict(patches), XYZ, white


def colorchecker_delta_E(
    grid: SpectralGrid, illuminant: str, method: str = "astm_e308"
) -> np.ndarray:
    """ΔE00 per ColorChecker patch: specref's band weights on ``grid`` against the 5 nm truth.

    The truth is ``colour.sd_to_XYZ`` on the native 5 nm N Ohta data (CIE 1931 2°), in Lab relative
    to the true white under the light. specref's value subsamples each patch onto ``grid`` and
    applies :func:`~reference.colour.colorimetry.band_weights` with ``method``; its Lab uses the
    same true white, so a method that gets the white wrong (point sampling under FL2) is charged for
    it.

    Parameters
    ----------
    grid : SpectralGrid
        The spectral grid.
    illuminant : str
        A colour-science illuminant key (``"D65"``, ``"A"``, ``"D50"``, ``"FL2"``, ...).
    method : str
        A band-weight method (``"astm_e308"`` or ``"point"``).

    Returns
    -------
    ndarray, shape (24,)
        ΔE00 per patch, in the dataset's order.

    Examples
    --------
    >>> from reference.colour.spectra import GRID_41
    >>> float(colorchecker_delta_E(GRID_41, "D65").mean()) < 0.03
    True
    """
    light = spectrum_from_dataset("illuminant", illuminant)
    W = band_weights(grid, light, method)
    patches, truth, white = colorchecker_truth(illuminant)
    out = []
    for (name, sd), XYZ_true in zip(patches.items(), truth, strict=True):
        R = resample_spectrum(make_spectrum(sd.wavelengths, sd.values, name), grid)
        XYZ = spectra_to_XYZ(R, W)
        out.append(float(delta_E_00(XYZ_to_Lab(XYZ, white), XYZ_to_Lab(XYZ_true, white))))
    return np.asarray(out)

"""Fit the default RGB → spectrum regression, shipped as package data (reference/data/).

The "camera" is linear sRGB (the CIE 1931 2° observer through the XYZ → sRGB matrix,
``reference.colour.spectral_target.CAMERAS["sRGB"]``), the capture illuminant D65 (the sRGB white),
the target the training set of ``reference.colour.spectral_target`` (rawtoaces-190 minus the
look-alikes of every held-out set), the features Finlayson's root-polynomials of degree 4, the
colorimetric loss (ΔE94 under D65 and A plus a spectral term, erratum E44) with the ridge strength
and the spectral weight chosen by 5-fold cross-validation
(``reference.colour.spectral_regression``). It is what the ``regression`` key of
``reference.colour.upsampling.UPSAMPLING_METHODS`` uses. It is fitted on the training patches alone,
without the products that ``specref env fit`` adds by default: for this "camera" their
cross-validated gain did not carry to the held-out sets (erratum E44).

Run: ``.venv/bin/python -m validation.precompute.spectral_regression`` (a few seconds).
"""

from __future__ import annotations

from pathlib import Path

from reference.colour.spectra import GRID_41
from reference.colour.spectral_regression import fit_regression, save_regression
from reference.colour.spectral_target import TRAINING_SET, camera_RGB, reflectance_set

OUT = Path(__file__).resolve().parents[2] / "reference" / "data" / "spectral_regression_sRGB.json"


def main() -> Path:
    """Fit and write the default model; return its path."""
    _, spectra = reflectance_set(TRAINING_SET)
    model = fit_regression(
        camera_RGB(spectra, "sRGB", "D65"),
        spectra[:, ::2],
        GRID_41.wavelengths_nm,
        "root_polynomial",
        4,
        illuminant="D65",
        camera="sRGB",
        training_set=TRAINING_SET,
    )
    return save_regression(model, OUT)


if __name__ == "__main__":
    main()

"""Colour science: spectra, colorimetry, RGB → spectrum upsampling and the spectral regression.

- :mod:`~reference.colour.spectra` — spectral grids, spectrum sources (colour-science datasets, CSV
  files, arrays) and resampling.
- :mod:`~reference.colour.colorimetry` — band weights (Eq. (9), Wang et al.; ASTM E308), XYZ, RGB,
  Lab and ΔE00.
- :mod:`~reference.colour.upsampling` — RGB → spectrum (``UPSAMPLING_METHODS``: Mallett 2019,
  Jakob–Hanika 2019 via :mod:`~reference.colour.jakob2019`, and the regression).
- :mod:`~reference.colour.spectral_regression`, :mod:`~reference.colour.spectral_target` — the
  camera-RGB → spectrum regression of Herbert et al. §4 and its synthetic training targets.

Herbert et al.'s §4 lives here rather than in ``shrm`` because the scene renderer that every paper
uses upsamples RGB environment maps and textures through ``UPSAMPLING_METHODS``, of which the
regression is one entry, and the spectral image readers spectralize camera RGB with it.
"""

from __future__ import annotations

from reference.colour import (
    colorimetry,
    jakob2019,
    spectra,
    spectral_regression,
    spectral_target,
    upsampling,
)
from reference.colour.colorimetry import *  # noqa: F403
from reference.colour.jakob2019 import *  # noqa: F403
from reference.colour.spectra import *  # noqa: F403
from reference.colour.spectral_regression import *  # noqa: F403
from reference.colour.spectral_target import *  # noqa: F403
from reference.colour.upsampling import *  # noqa: F403

__all__ = sorted(
    {
        *spectra.__all__,
        *colorimetry.__all__,
        *jakob2019.__all__,
        *spectral_regression.__all__,
        *spectral_target.__all__,
        *upsampling.__all__,
    }
)

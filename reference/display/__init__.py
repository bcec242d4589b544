"""Displays: encodings, the display model, calibration and its files, instruments, ICC profiles.

- :mod:`~reference.display.encodings` — display encodings (sRGB, gamma, Herbert's L*-linear curve).
- :mod:`~reference.display.model` — the display characterization of Eq. (1), Ferwerda (luminance
  falloff with viewing angle, screen flare, measurement files).
- :mod:`~reference.display.spectral`, :mod:`~reference.display.instruments` — the spectral display
  and the simulated instruments that measure it.
- :mod:`~reference.display.calibration` — calibration to any white and curve (Herbert et al. §6);
  :mod:`~reference.display.calibration_files`, :mod:`~reference.display.cgats`,
  :mod:`~reference.display.icc` — its ``.cal``, ``.ti3``, ``.cube``, JSON and ICC outputs.
- :mod:`~reference.display.pipeline` — images through Eq. (1), Ferwerda per pixel.

Herbert et al.'s §6 lives here with Ferwerda's display model because both papers calibrate and
characterize the display, and scene files state the calibration that ``specref render`` applies.
"""

from __future__ import annotations

from reference.display import (
    calibration,
    calibration_files,
    cgats,
    encodings,
    icc,
    instruments,
    model,
    pipeline,
    spectral,
)
from reference.display.calibration import *  # noqa: F403
from reference.display.calibration_files import *  # noqa: F403
from reference.display.cgats import *  # noqa: F403
from reference.display.encodings import *  # noqa: F403
from reference.display.icc import *  # noqa: F403
from reference.display.instruments import *  # noqa: F403
from reference.display.model import *  # noqa: F403
from reference.display.pipeline import *  # noqa: F403
from reference.display.spectral import *  # noqa: F403

__all__ = sorted(
    {
        *encodings.__all__,
        *model.__all__,
        *spectral.__all__,
        *instruments.__all__,
        *calibration.__all__,
        *cgats.__all__,
        *calibration_files.__all__,
        *icc.__all__,
        *pipeline.__all__,
    }
)

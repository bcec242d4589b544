"""Images on disk: PNG, OpenEXR and Radiance HDR; spectral images; Zarr panoramas by row blocks.

- :mod:`~reference.images.formats` — PNG, EXR (spectral layout of Fichet et al. 2021) and HDR.
- :mod:`~reference.images.spectral` — spectral EXR, 41-band TIFF and Zarr outputs; panoramas read by
  row windows.
- :mod:`~reference.images.zarr_store` — spectral panoramas as Zarr stores of row-band chunks.
"""

from __future__ import annotations

from reference.images import formats, spectral, zarr_store
from reference.images.formats import *  # noqa: F403
from reference.images.spectral import *  # noqa: F403
from reference.images.zarr_store import *  # noqa: F403

__all__ = sorted({*formats.__all__, *spectral.__all__, *zarr_store.__all__})

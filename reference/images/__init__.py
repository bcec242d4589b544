"""Images on disk: PNG, OpenEXR and Radiance HDR; spectral images; Zarr panoramas by row blocks.

- :mod:`~reference.images.formats` — PNG, EXR (spectral layout of Fichet et al. 2021) and HDR.
- :mod:`~reference.images.spectral` — spectral EXR, 41-band TIFF and Zarr outputs; panoramas read by
  row windows.
- :mod:`~reference.images.zarr_store` — spectral panoramas as Zarr stores of row-band chunks.
"""

from __future__ import annotations

from reference.images.formats import (
    MAX_IMAGE_PIXELS,
    channel_wavelengths_nm,
    exr_write_error,
    read_exr,
    read_hdr,
    read_image,
    read_png,
    spectral_channel_names,
    write_exr,
    write_png,
)
from reference.images.spectral import (
    SPECTRAL_FORMATS,
    PanoramaRows,
    convert_to_zarr,
    open_panorama_rows,
    read_environment_file,
    read_spectral_tiff,
    spectralize_file,
    write_spectral_blocks,
)
from reference.images.zarr_store import (
    ZARR_COMPRESSIONS,
    ZarrImage,
    check_chunk_fits,
    map_zarr_blocks,
    open_zarr_image,
    rows_per_chunk_for,
    write_zarr_blocks,
    write_zarr_image,
    zarr_to_cubemap,
)

__all__ = [
    "MAX_IMAGE_PIXELS",
    "SPECTRAL_FORMATS",
    "ZARR_COMPRESSIONS",
    "PanoramaRows",
    "ZarrImage",
    "channel_wavelengths_nm",
    "check_chunk_fits",
    "convert_to_zarr",
    "exr_write_error",
    "map_zarr_blocks",
    "open_panorama_rows",
    "open_zarr_image",
    "read_environment_file",
    "read_exr",
    "read_hdr",
    "read_image",
    "read_png",
    "read_spectral_tiff",
    "rows_per_chunk_for",
    "spectral_channel_names",
    "spectralize_file",
    "write_exr",
    "write_png",
    "write_spectral_blocks",
    "write_zarr_blocks",
    "write_zarr_image",
    "zarr_to_cubemap",
]

"""Spectral panoramas on disk: multi-channel float EXR and 41-component float TIFF, written by rows.

Herbert et al. (§4) store the spectral panorama "as a 41 component floating-point TIFF file".
specref writes that (through tifffile) and, beside it, the spectral OpenEXR layout of Fichet et al.
(erratum E43):

- **EXR**: one FLOAT channel per band, named ``S0.<wavelength>nm`` with a comma as the decimal
  separator (``S0.550,000000nm``, :func:`reference.images.spectral_channel_names`); scanlines are
  written block by block (``OpenEXR.OutputFile.writePixels``).
- **TIFF**: one page, ``(H, W, n_bands)`` float32, contiguous (chunky) samples, uncompressed;
  the ImageDescription tag holds JSON ``{"specref": "spectral", "wavelengths_nm": [...]}``.
  Rows are written through a memory map (``tifffile.memmap``), so the output is never held whole.

Both are written to a temporary file beside the destination, synced and renamed into place (the
writers need a path, so :func:`reference.images.atomic_write`'s open handle does not serve).
:func:`read_environment_file` reads ``.exr``, ``.hdr`` and these TIFFs for the scene reader and
``specref sh``.

References
----------
- F. Herbert et al., "Multispectral Virtual Reality", 2004, §4.
- A. Fichet, R. Pacanowski, A. Wilkie, "An OpenEXR Layout for Spectral Images", JCGT 10(3), 2021.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import Path

import numpy as np

from reference.errors import SpecrefError, require
from reference.images import (
    atomic_path,
    exr_write_error,
    read_exr,
    read_hdr,
    spectral_channel_names,
)

__all__ = [
    "SPECTRAL_FORMATS",
    "read_environment_file",
    "read_spectral_tiff",
    "spectralize_file",
    "write_spectral_blocks",
]

#: Output formats of spectral panoramas by file suffix.
SPECTRAL_FORMATS = (".exr", ".tif", ".tiff")
# Suffixes of 8-bit images that are refused as panoramas (they are not HDR).
_LDR_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".gif", ".webp")


def _write_exr_blocks(path: Path, height, width, names, blocks) -> None:
    import Imath
    import OpenEXR

    header = OpenEXR.Header(width, height)
    header["channels"] = {n: Imath.Channel(Imath.PixelType(Imath.PixelType.FLOAT)) for n in names}
    out = OpenEXR.OutputFile(str(path), header)
    try:
        for _row0, block in blocks:
            out.writePixels(
                {n: np.ascontiguousarray(block[..., i]).tobytes() for i, n in enumerate(names)},
                block.shape[0],
            )
    finally:
        out.close()


def _write_tiff_blocks(path: Path, height, width, wavelengths, blocks) -> None:
    import tifffile

    description = json.dumps({"specref": "spectral", "wavelengths_nm": list(wavelengths)})
    image = tifffile.memmap(
        str(path),
        shape=(height, width, len(wavelengths)),
        dtype=np.float32,
        photometric="minisblack",
        planarconfig="contig",
        description=description,
    )
    for row0, block in blocks:
        image[row0 : row0 + block.shape[0]] = block
        image.flush()
    del image


def write_spectral_blocks(
    path, height: int, width: int, wavelengths_nm, blocks: Iterable[tuple[int, np.ndarray]]
) -> Path:
    """Write a spectral image from row blocks ``(row0, (rows, W, n_bands) float32)``, atomically.

    Parameters
    ----------
    path : str or Path
        ``.exr`` or ``.tif``/``.tiff`` (module docstring for the layouts).
    height, width : int
    wavelengths_nm : array_like, shape (n_bands,)
    blocks : iterable
        Consecutive blocks from row 0, e.g. from
        :func:`reference.spectral_regression.spectralize_blocks`.

    Raises
    ------
    SpecrefError
        Another suffix.

    Examples
    --------
    >>> import tempfile, os
    >>> blocks = [(0, np.ones((1, 4, 2), np.float32)), (1, np.zeros((1, 4, 2), np.float32))]
    >>> with tempfile.TemporaryDirectory() as d:
    ...     path = write_spectral_blocks(os.path.join(d, "p.tif"), 2, 4, [500.0, 600.0], blocks)
    ...     image, names = read_spectral_tiff(path)
    >>> image[:, 0, 0], names
    (array([1., 0.]), ['S0.500,000000nm', 'S0.600,000000nm'])
    """
    path = Path(path)
    suffix = path.suffix.lower()
    require(
        suffix in SPECTRAL_FORMATS,
        f"{path}: unsupported spectral image type {suffix!r}; allowed: .exr, .tif, .tiff",
    )
    wavelengths = [float(w) for w in np.asarray(wavelengths_nm, dtype=np.float64)]
    with atomic_path(path, suffix) as tmp:
        if suffix == ".exr":
            try:
                _write_exr_blocks(tmp, height, width, spectral_channel_names(wavelengths), blocks)
            except (RuntimeError, OSError) as error:
                # OpenEXR's scanline writer reports a full disk as text, with no errno.
                if getattr(error, "errno", None) is not None:
                    raise
                raise exr_write_error(path, error) from None
        else:
            _write_tiff_blocks(tmp, height, width, wavelengths, blocks)
    return path


def read_spectral_tiff(path) -> tuple[np.ndarray, list[str]]:
    """Read a spectral float TIFF: ``(H, W, n_bands)`` float64 and its spectral channel names.

    The wavelengths come from the JSON ImageDescription that :func:`write_spectral_blocks` writes;
    a TIFF without them, or one of integers (8 or 16 bits: not HDR), is refused.

    Raises
    ------
    SpecrefError
        Missing, unreadable, integer or unlabelled file.

    Examples
    --------
    >>> read_spectral_tiff("/nonexistent.tif")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent.tif: file not found
    """
    import tifffile

    path = Path(path)
    require(path.is_file(), f"{path}: file not found")
    try:
        with tifffile.TiffFile(str(path)) as tif:
            page = tif.pages[0]
            description = page.description
            image = page.asarray()
    except Exception as error:  # tifffile raises TiffFileError, ValueError and others
        raise SpecrefError(f"{path}: cannot read TIFF image ({error.__class__.__name__})") from None
    require(
        image.dtype.kind == "f",
        f"{path}: {image.dtype.itemsize * 8}-bit integer TIFF, not HDR; linearize it and save "
        "as float (.hdr, .exr or a float TIFF)",
    )
    try:
        wavelengths = json.loads(description)["wavelengths_nm"]
    except (ValueError, KeyError, TypeError):
        raise SpecrefError(
            f"{path}: no wavelengths in the TIFF ImageDescription (expected JSON "
            '{"wavelengths_nm": [...]}, as specref env spectralize writes)'
        ) from None
    image = np.asarray(image, dtype=np.float64)
    if image.ndim == 2:
        image = image[..., None]
    require(
        image.shape[2] == len(wavelengths),
        f"{path}: {image.shape[2]} samples per pixel but {len(wavelengths)} wavelengths",
    )
    return image, spectral_channel_names(wavelengths)


def read_environment_file(path) -> tuple[np.ndarray, list[str]]:
    """Read a lat-long map, RGB or spectral: ``.exr``, ``.hdr`` or a spectral float ``.tif``.

    Returns
    -------
    image : ndarray, shape (H, W, C)
    names : list of str
        ``R, G, B`` (and ``A``...) or spectral names (``S0.550,000000nm``).

    Raises
    ------
    SpecrefError
        Unknown type; 8-bit images (not HDR: the message says how to linearize).

    Examples
    --------
    >>> read_environment_file("sky.png")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: sky.png: an 8-bit image is not HDR; merge bracketed exposures
    into a linear Radiance .hdr or OpenEXR .exr (or linearize it, e.g. sRGB decoding, and save as
    float)
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix in _LDR_SUFFIXES:
        raise SpecrefError(
            f"{path}: an 8-bit image is not HDR; merge bracketed exposures into a linear Radiance "
            ".hdr or OpenEXR .exr (or linearize it, e.g. sRGB decoding, and save as float)"
        )
    if suffix == ".exr":
        return read_exr(path)
    if suffix in (".hdr", ".rgbe", ".pic"):
        return read_hdr(path), ["R", "G", "B"]
    if suffix in (".tif", ".tiff"):
        return read_spectral_tiff(path)
    if suffix == ".zarr":  # a chunked store (reference.zarr_images), read whole here
        from reference.zarr_images import open_zarr_image

        store = open_zarr_image(path)
        return store.read(), store.channels
    raise SpecrefError(
        f"{path}: unsupported environment map type {suffix!r}; allowed: .exr, .hdr, .tif, .zarr"
    )


def spectralize_file(panorama, model, out, rows_per_block: int | None = None) -> dict:
    """Expand an HDR panorama to a spectral panorama on disk, row block by row block.

    Herbert et al., §4 (the panorama expanded to 41 bands and stored as a float TIFF). The input
    is read whole (it is 3 channels); the output (``n_bands`` float32 channels) never is: each
    block of rows is spectralized and written before the next (erratum E43 for the formats).

    Parameters
    ----------
    panorama : str or Path
        ``.hdr`` or RGB ``.exr``, linear camera RGB in the model's camera space.
    model : SpectralRegression
    out : str or Path
        ``.exr`` or ``.tif``/``.tiff``.
    rows_per_block : int, optional
        Default: :data:`reference.spectral_regression.PIXELS_PER_BLOCK` pixels' worth of rows.

    Returns
    -------
    dict
        ``out``, ``height``, ``width``, ``bands``, ``blocks``.

    Raises
    ------
    SpecrefError
        8-bit or unreadable input, not RGB, NaN or negative values, unsupported output type.

    Examples
    --------
    >>> spectralize_file("pano.jpg", None, "out.exr")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: pano.jpg: an 8-bit image is not HDR; merge bracketed exposures
    into a linear Radiance .hdr or OpenEXR .exr (or linearize it, e.g. sRGB decoding, and save as
    float)
    """
    from reference.spectral_regression import spectralize_blocks

    image, names = read_environment_file(panorama)
    require(
        names[:3] == ["R", "G", "B"],
        f"{panorama}: channels {', '.join(names[:5])}; spectralize needs an RGB panorama",
    )
    suffix = Path(out).suffix.lower()
    require(
        suffix in SPECTRAL_FORMATS,
        f"{out}: unsupported spectral image type {suffix!r}; allowed: .exr, .tif, .tiff",
    )
    RGB = image[..., :3]
    require(np.isfinite(RGB).all(), f"{panorama}: RGB must be finite, found NaN or inf")
    require((RGB >= 0).all(), f"{panorama}: RGB must be >= 0, found {RGB.min():g}")
    height, width = RGB.shape[:2]
    rows = rows_per_block
    count = [0]

    def counted():
        for item in spectralize_blocks(model, RGB, rows):
            count[0] += 1
            yield item

    write_spectral_blocks(out, height, width, model.wavelengths_nm, counted())
    return {
        "out": str(out),
        "height": height,
        "width": width,
        "bands": model.n_bands,
        "blocks": count[0],
    }

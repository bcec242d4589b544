"""Spectral panoramas on disk: multi-channel float EXR and 41-component float TIFF, written by rows.

Herbert et al. (§4) store the spectral panorama "as a 41 component floating-point TIFF file".
specref writes that (through tifffile) and, beside it, the spectral OpenEXR layout of Fichet et al.
(erratum E43):

- **EXR**: one FLOAT channel per band, named ``S0.<wavelength>nm`` with a comma as the decimal
  separator (``S0.550,000000nm``, :func:`reference.images.formats.spectral_channel_names`);
  scanlines are written block by block (``OpenEXR.OutputFile.writePixels``).
- **TIFF**: one page, ``(H, W, n_bands)`` float32, contiguous (chunky) samples, uncompressed;
  the ImageDescription tag holds JSON ``{"specref": "spectral", "wavelengths_nm": [...]}``.
  Rows are written through a memory map (``tifffile.memmap``), so the output is never held whole.
- **Zarr** (``.zarr``, ``reference.images.zarr_store``): row-band chunks of every band, written
  chunk
  by chunk; read by row windows too (:func:`open_panorama_rows`).

Both are written to a temporary file beside the destination, synced and renamed into place (the
writers need a path, so :func:`reference.files.atomic_write`'s open handle does not serve).
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

from reference.errors import SpecrefError, require, require_positive_int
from reference.files import atomic_path
from reference.geometry.envmap import check_latlong_shape
from reference.images.formats import exr_write_error, read_exr, read_hdr, spectral_channel_names
from reference.images.zarr_store import open_zarr_image, rows_per_chunk_for, write_zarr_blocks

__all__ = [
    "SPECTRAL_FORMATS",
    "PanoramaRows",
    "convert_to_zarr",
    "open_panorama_rows",
    "read_environment_file",
    "read_spectral_tiff",
    "spectralize_file",
    "write_spectral_blocks",
]

#: Output formats of spectral panoramas by file suffix.
SPECTRAL_FORMATS = (".exr", ".tif", ".tiff", ".zarr")
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


def _in_order(blocks, path):
    # the blocks of write_spectral_blocks, checked to be consecutive from row 0
    row = 0
    for row0, block in blocks:
        require(row0 == row, f"{path}: a block at row {row0}; expected row {row}")
        row += block.shape[0]
        yield block


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
        :func:`reference.colour.spectral_regression.spectralize_blocks`.

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
        f"{path}: unsupported spectral image type {suffix!r}; allowed: .exr, .tif, .tiff, .zarr",
    )
    wavelengths = [float(w) for w in np.asarray(wavelengths_nm, dtype=np.float64)]
    if suffix == ".zarr":  # a Zarr store is written atomically by its own writer
        return write_zarr_blocks(
            path, height, width, spectral_channel_names(wavelengths), _in_order(blocks, path)
        )
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
    if suffix == ".zarr":  # a chunked store (reference.images.zarr_store), read whole here
        store = open_zarr_image(path)
        return store.read(), store.channels
    raise SpecrefError(
        f"{path}: unsupported environment map type {suffix!r}; allowed: .exr, .hdr, .tif, .zarr"
    )


class PanoramaRows:
    """A panorama opened for reading by row windows: ``read(row0, row1)``, ``(rows, W, C)`` float64.

    What :func:`open_panorama_rows` returns; ``height``, ``width``, ``names`` (channel names as
    :func:`read_environment_file` gives them), ``streamed`` (False when the file's layout forces a
    whole read: compressed TIFF, old-style RLE or rotated Radiance files). Use it as a context
    manager, so the file is closed.
    """

    def __init__(self, path, height, width, names, read, close=None, streamed=True):
        if not (height > 0 and width > 0):  # OpenEXR's writer aborts the process on 0 rows
            if close is not None:
                close()
            raise SpecrefError(f"{path}: an image of {height} × {width} pixels; nothing to read")
        self.path, self.height, self.width, self.names = Path(path), height, width, names
        self.streamed = streamed
        self._read, self._close = read, close

    def read(self, row0: int, row1: int, dtype=np.float64) -> np.ndarray:
        """Rows ``row0 <= y < row1`` (top to bottom), ``(row1 - row0, W, C)`` of ``dtype``.

        ``float32`` (what the files hold) reads without a float64 copy: half the memory.
        """
        require(
            0 <= row0 < row1 <= self.height,
            f"{self.path}: rows {row0}-{row1} outside 0-{self.height}",
        )
        return self._read(row0, row1, np.dtype(dtype))

    def close(self) -> None:
        """Close the file."""
        if self._close is not None:
            self._close()
            self._close = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _whole(path, image, names) -> PanoramaRows:
    return PanoramaRows(
        path,
        image.shape[0],
        image.shape[1],
        names,
        lambda a, b, dtype: np.asarray(image[a:b], dtype=dtype),
        streamed=False,
    )


def _open_exr_rows(path: Path) -> PanoramaRows:
    """OpenEXR by scanline windows (``InputFile.channels(names, FLOAT, y0, y1)``)."""
    import Imath
    import OpenEXR

    from reference.images.formats import _WAVELENGTH_CHANNEL

    require(path.is_file(), f"{path}: file not found")
    try:
        # the header through the current bindings (the legacy InputFile.header() crashes on
        # some attributes, e.g. previews), the scanline windows through the legacy reader
        with OpenEXR.File(str(path), header_only=True) as opened:
            header = opened.header()
            (x0, y0), (x1, y1) = (np.asarray(v, int) for v in header["dataWindow"])
            names = [channel.name for channel in header["channels"]]
        handle = OpenEXR.InputFile(str(path))
    except Exception as error:  # the bindings raise OSError, RuntimeError and others
        raise SpecrefError(
            f"{path}: cannot read OpenEXR image ({error.__class__.__name__})"
        ) from None
    require(names, f"{path}: OpenEXR file has no channels")
    width, height = int(x1 - x0 + 1), int(y1 - y0 + 1)
    spectral = {n: _WAVELENGTH_CHANNEL.search(n) for n in names}
    if names and all(spectral.values()):
        names.sort(key=lambda n: float(spectral[n].group(1).replace(",", ".")))
    else:
        order = {"R": 0, "G": 1, "B": 2, "A": 3}
        position = {n: i for i, n in enumerate(names)}
        names.sort(key=lambda n: (order.get(n, 4), position[n]))
    FLOAT = Imath.PixelType(Imath.PixelType.FLOAT)

    def read(row0, row1, dtype):
        out = np.empty((row1 - row0, width, len(names)), dtype=dtype)
        try:
            # every channel in one call: the window's scanline blocks are decompressed once, not
            # once per channel (41× the work for a spectral file)
            window = handle.channels(names, FLOAT, int(y0) + row0, int(y0) + row1 - 1)
            for c, data in enumerate(window):
                out[..., c] = np.frombuffer(data, np.float32).reshape(row1 - row0, width)
        except Exception as error:  # truncated or corrupt scanlines
            raise SpecrefError(
                f"{path}: cannot read OpenEXR rows {row0}-{row1 - 1} ({error.__class__.__name__})"
            ) from None
        return out

    return PanoramaRows(path, height, width, names, read, handle.close)


def _hdr_scanline_end(buffer, p: int, width: int) -> int | None:
    """End of the Radiance scanline starting at ``p`` (flat or new-style RLE), None if old RLE."""
    if 8 <= width < 0x8000 and buffer[p] == 2 and buffer[p + 1] == 2 and buffer[p + 2] < 128:
        p += 4
        # new-style RLE: four channels of runs, count > 128 is a run of one byte
        for _channel in range(4):
            x = 0
            while x < width:
                count = buffer[p]
                if count > 128:
                    x, p = x + count - 128, p + 2
                else:
                    x, p = x + count, p + 1 + count
        return p
    if buffer[p] == 1 and buffer[p + 1] == 1 and buffer[p + 2] == 1:
        return None
    return p + 4 * width


def _open_hdr_rows(path: Path) -> PanoramaRows:
    """Radiance RGBE by scanlines: find each block's bytes, decode them with imagecodecs."""
    import imagecodecs

    require(path.is_file(), f"{path}: file not found")
    handle = open(path, "rb")  # noqa: SIM115 (closed by PanoramaRows.close)
    header = b""
    while not header.endswith(b"\n\n"):
        line = handle.readline(4096)
        if not line or len(header) > 65536:
            handle.close()
            raise SpecrefError(f"{path}: cannot read Radiance HDR image (no header end)")
        header += line
    resolution = handle.readline(256).split()
    if len(resolution) != 4 or resolution[0] != b"-Y" or resolution[2] != b"+X":
        handle.close()  # a rotated or flipped file: decoded whole
        return _whole(path, read_hdr(path), ["R", "G", "B"])
    try:
        height, width = int(resolution[1]), int(resolution[3])
    except ValueError:
        handle.close()
        raise SpecrefError(f"{path}: cannot read Radiance HDR image (resolution)") from None
    state = {"buffer": b"", "row": 0}
    worst = 4 + 4 * width + 4 * (width // 128 + 1)  # a scanline's most bytes (RLE or flat)

    def read(row0, row1, dtype):
        require(row0 == state["row"], f"{path}: Radiance rows are read in order, from row 0")
        buffer, p = state["buffer"], 0
        for row in range(row0, row1):
            if len(buffer) - p < worst:  # keep at least one whole scanline ahead
                buffer += handle.read(max(1 << 18, worst))
            try:
                end = _hdr_scanline_end(buffer, p, width) if len(buffer) - p >= 4 else p + worst
            except IndexError:  # a run that goes past the end of the file
                end = len(buffer) + 1
            if end is None:
                raise SpecrefError(f"{path}: old-style RLE scanlines; re-save it (e.g. pfstools)")
            require(end <= len(buffer), f"{path}: truncated Radiance HDR image (row {row})")
            p = end
        block = header + f"-Y {row1 - row0} +X {width}\n".encode() + buffer[:p]
        state["buffer"], state["row"] = buffer[p:], row1
        try:
            image = imagecodecs.rgbe_decode(block)
        except Exception as error:  # imagecodecs.RgbeError and others
            raise SpecrefError(
                f"{path}: cannot read Radiance HDR rows {row0}-{row1 - 1} "
                f"({error.__class__.__name__})"
            ) from None
        return np.asarray(image, dtype=dtype).reshape(row1 - row0, width, 3)

    return PanoramaRows(path, height, width, ["R", "G", "B"], read, handle.close)


def _open_tiff_rows(path: Path) -> PanoramaRows:
    """A float TIFF by rows through a memory map (uncompressed), else read whole."""
    import tifffile

    require(path.is_file(), f"{path}: file not found")
    try:
        image = tifffile.memmap(str(path), mode="r")
        with tifffile.TiffFile(str(path)) as tif:
            description = tif.pages[0].description
    except ValueError:  # compressed or tiled: no memory map
        image, names = read_spectral_tiff(path)
        return _whole(path, image, names)
    except Exception as error:  # tifffile raises TiffFileError and others
        raise SpecrefError(f"{path}: cannot read TIFF image ({error.__class__.__name__})") from None
    require(
        image.dtype.kind == "f",
        f"{path}: {image.dtype.itemsize * 8}-bit integer TIFF, not HDR; linearize it and save "
        "as float (.hdr, .exr or a float TIFF)",
    )
    image = image[..., None] if image.ndim == 2 else image
    try:
        names = spectral_channel_names(json.loads(description)["wavelengths_nm"])
    except (ValueError, KeyError, TypeError):
        require(
            image.shape[2] == 3,
            f"{path}: no wavelengths in the TIFF ImageDescription and not RGB "
            f"({image.shape[2]} samples)",
        )
        names = ["R", "G", "B"]
    require(
        image.shape[2] == len(names),
        f"{path}: {image.shape[2]} samples per pixel but {len(names)} wavelengths",
    )
    return PanoramaRows(
        path, image.shape[0], image.shape[1], names, lambda a, b, dtype: np.array(image[a:b], dtype)
    )


def _open_zarr_rows(path: Path) -> PanoramaRows:
    """A Zarr store (``reference.images.zarr_store``) by row windows: only the chunks they touch."""
    store = open_zarr_image(path)
    height, width, _ = store.shape

    def read(row0, row1, dtype):
        return np.asarray(store.array[row0:row1], dtype=dtype)

    return PanoramaRows(path, height, width, store.channels, read)


def open_panorama_rows(path) -> PanoramaRows:
    """Open a panorama for reading by row windows, never holding it whole (where the file allows).

    ``.exr``: OpenEXR scanline windows; ``.hdr``: Radiance scanlines found one by one (flat or
    new-style RLE) and decoded a block at a time by imagecodecs, bit for bit as
    :func:`reference.images.formats.read_hdr` (rows in order); ``.tif``: a memory map of an
    uncompressed float TIFF (RGB without a description, or spectral as :func:`write_spectral_blocks`
    writes); ``.zarr``: the chunks of a store (``reference.images.zarr_store``) that a window
    touches. Rotated Radiance files and compressed TIFFs are read whole (``streamed`` is False).

    Raises
    ------
    SpecrefError
        Unknown type, 8-bit images, missing or unreadable files.

    Examples
    --------
    >>> import tempfile, os
    >>> from reference.images.formats import write_exr
    >>> with tempfile.TemporaryDirectory() as d:
    ...     path = write_exr(os.path.join(d, "p.exr"), np.ones((4, 8, 3)))
    ...     with open_panorama_rows(path) as rows:
    ...         (rows.height, rows.width, rows.names), rows.read(1, 3).shape
    ((4, 8, ['R', 'G', 'B']), (2, 8, 3))
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".exr":
        return _open_exr_rows(path)
    if suffix in (".hdr", ".rgbe", ".pic"):
        return _open_hdr_rows(path)
    if suffix in (".tif", ".tiff"):
        return _open_tiff_rows(path)
    if suffix == ".zarr":
        return _open_zarr_rows(path)
    read_environment_file(path)  # the one-line refusals of 8-bit and unknown types
    raise AssertionError("unreachable")  # pragma: no cover


def spectralize_file(panorama, model, out, rows_per_block: int | None = None) -> dict:
    """Expand an HDR panorama to a spectral panorama on disk, row block by row block.

    Herbert et al., §4 (the panorama expanded to 41 bands and stored as a float TIFF). Neither
    the input nor the output is held whole: each block of rows is read from the panorama
    (:func:`open_panorama_rows`), spectralized and written before the next (erratum E43 for the
    formats). A NaN, inf or negative value stops the command and leaves no output.

    Parameters
    ----------
    panorama : str or Path
        ``.hdr``, RGB ``.exr`` or an RGB ``.zarr`` store, linear camera RGB in the model's
        camera space.
    model : SpectralRegression
    out : str or Path
        ``.exr``, ``.tif``/``.tiff`` or ``.zarr`` (written chunk by chunk).
    rows_per_block : int, optional
        Default: :data:`reference.colour.spectral_regression.PIXELS_PER_BLOCK` pixels' worth of
        rows.

    Returns
    -------
    dict
        ``out``, ``height``, ``width``, ``bands``, ``blocks``, ``streamed`` (False when the
        input's layout forced a whole read, :func:`open_panorama_rows`), ``projected``: the
        negative values replaced, the pixels they were in and the most negative value (erratum
        E106; a file's header is written before its rows, so the count is here, not in it).

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
    from reference.colour.spectral_regression import spectralize_rows

    suffix = Path(out).suffix.lower()
    with open_panorama_rows(panorama) as rows:
        require(
            rows.names[:3] == ["R", "G", "B"],
            f"{panorama}: channels {', '.join(rows.names[:5])}; spectralize needs an RGB panorama",
        )
        require(
            suffix in SPECTRAL_FORMATS,
            f"{out}: unsupported spectral image type {suffix!r}; allowed: .exr, .tif, .tiff, .zarr",
        )
        count, projected = [0], {"values": 0, "pixels": 0, "min": 0.0}

        def counted():
            blocks = spectralize_rows(
                model, rows.read, rows.height, rows.width, rows_per_block, panorama, projected
            )
            for item in blocks:
                count[0] += 1
                yield item

        write_spectral_blocks(out, rows.height, rows.width, model.wavelengths_nm, counted())
    return {
        "out": str(out),
        "height": rows.height,
        "width": rows.width,
        "bands": model.n_bands,
        "blocks": count[0],
        "streamed": rows.streamed,
        "projected": projected,
    }


#: Reads per chunk of rows in :func:`convert_to_zarr`: the reader's own buffers are this much
#: smaller than a chunk.
READ_WINDOWS_PER_CHUNK = 4


def convert_to_zarr(
    source, out, rows_per_chunk: int | None = None, compression: str = "blosc-lz4"
) -> dict:
    """Convert a panorama file (``.exr``, ``.hdr``, spectral ``.tif``) to a Zarr store, streamed.

    The source is read a chunk of rows at a time (:func:`open_panorama_rows`: OpenEXR scanline
    windows, Radiance scanlines, a memory-mapped TIFF) and each chunk is written as it is read
    (``write_zarr_blocks``), so the resident memory is a few chunks whatever the panorama's size:
    one float32 chunk buffer, reused, filled :data:`READ_WINDOWS_PER_CHUNK` windows at a time, and
    the compressor's output and working copy (about four chunks,
    :data:`~reference.images.zarr_store.CHUNK_BYTES` each by default; docs/scale-out.md). Files
    that cannot be read by rows (compressed TIFF, rotated Radiance; ``streamed`` False in the
    summary) are read whole. Nothing is left at ``out`` when a chunk holds NaN or infinity.

    Returns a summary: the shape, ``rows_per_chunk``, ``chunks``, the compression and its ratio,
    and ``streamed``.

    Examples
    --------
    >>> import tempfile, os
    >>> from reference.images.formats import write_exr
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = write_exr(os.path.join(d, "m.exr"), np.ones((4, 8, 3), dtype=np.float32))
    ...     info = convert_to_zarr(os.path.join(d, "m.exr"), os.path.join(d, "m.zarr"), 2)
    >>> info["chunks"], info["channels"], info["compression"], info["streamed"]
    (2, 3, 'blosc-lz4', True)
    """
    require(
        Path(out).resolve() != Path(source).resolve(),
        f"{out}: the output is the input; write the store to another path",
    )
    with open_panorama_rows(source) as rows:
        height, width, n = rows.height, rows.width, len(rows.names)
        check_latlong_shape((height, width, n), str(source))
        if rows_per_chunk is None:
            rows_per_chunk = rows_per_chunk_for(width, n, height)
        rows_per_chunk = min(
            require_positive_int(rows_per_chunk, "rows per chunk", 1 << 20), height
        )

        def chunks():
            # one chunk buffer, reused, filled a quarter chunk at a time (the store's float32):
            # the reader's temporaries stay a fraction of a chunk
            buffer = np.empty((rows_per_chunk, width, n), np.float32)
            step = max(1, rows_per_chunk // READ_WINDOWS_PER_CHUNK)
            for row0 in range(0, height, rows_per_chunk):
                row1 = min(row0 + rows_per_chunk, height)
                for a in range(row0, row1, step):
                    b = min(a + step, row1)
                    window = buffer[a - row0 : b - row0]
                    window[...] = rows.read(a, b, np.float32)
                    require(
                        np.isfinite(window).all(),
                        f"{source}: radiance must be finite, found NaN or inf (rows {a}-{b - 1})",
                    )
                    # as scenes and sh project do: a store of radiance holds none below zero
                    require(
                        bool((window >= 0).all()),
                        f"{source}: radiance must be >= 0, found {float(window.min()):g} "
                        f"(rows {a}-{b - 1})",
                    )
                yield buffer[: row1 - row0]

        write_zarr_blocks(
            out, height, width, rows.names, chunks(), rows_per_chunk, compression=compression
        )
    stored = sum(f.stat().st_size for f in Path(out).rglob("*") if f.is_file())
    return {
        "out": str(out),
        "height": height,
        "width": width,
        "channels": n,
        "rows_per_chunk": rows_per_chunk,
        "chunks": -(-height // rows_per_chunk),
        "compression": compression,
        "ratio": height * width * n * 4 / max(stored, 1),
        "streamed": rows.streamed,
    }

"""Spectral panoramas out of core: Zarr stores of row-band chunks, read as Dask arrays.

Herbert et al.'s panoramas reach 12k×6k at 41 float32 bands: 11.8 GB, more than a machine should
hold for one map. specref stores them as Zarr (v3) arrays and streams every operation over bands of
rows, so memory stays bounded by a few chunks whatever the map's size.

Layout of a store ``NAME.zarr`` (a folder), documented in ``docs/scale-out.md``:

- one array, shape ``(H, W, C)`` float32, lat-long rows top (θ = 0) to bottom, ``W = 2H``;
- chunks ``(rows_per_chunk, W, C)``: every band of a band of rows in one chunk, so a streamed
  operation reads each chunk once, in row order; by default about 21.5 MB of float32 per chunk
  (:func:`rows_per_chunk_for`);
- compression (:data:`ZARR_COMPRESSIONS`): ``blosc-lz4`` (level 5, byte shuffle; the default),
  ``zstd`` (level 3, no shuffle) or ``none``. On a spectral panorama blosc-lz4 reads back faster
  than zstd at about the same size (``make bench``, group ``scaleout-zarr-read``, shown in the
  report; erratum E48);
- attributes: ``{"specref": "spectral-panorama", "channels": [...], "wavelengths_nm": [...] or
  null, "rows_per_chunk": n}``; the channel names are the spectral OpenEXR names
  (``S0.550,000000nm``) or ``R, G, B``.

A store is written into a temporary folder beside the destination and renamed into place, so a
reader never sees half a store. :func:`open_zarr_image` validates the shape, band count and grid
before any pixel is read.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import tempfile
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from reference.errors import SpecrefError, format_allowed, require, require_positive_int
from reference.files import (
    check_output_store,
    output_error,
    remove_stale_temporaries,
    temporary_prefix,
)
from reference.geometry.cubemap import latlong_blocks_to_cubemap
from reference.images.formats import channel_wavelengths_nm

__all__ = [
    "ZARR_COMPRESSIONS",
    "ZarrImage",
    "check_chunk_fits",
    "map_zarr_blocks",
    "open_zarr_image",
    "rows_per_chunk_for",
    "write_zarr_blocks",
    "write_zarr_image",
    "zarr_to_cubemap",
]

#: Compressors of spectral Zarr stores, by name (the codec list zarr writes).
ZARR_COMPRESSIONS = {
    "zstd": lambda: [_codecs().ZstdCodec(level=3)],
    "blosc-lz4": lambda: [_codecs().BloscCodec(cname="lz4", clevel=5, shuffle="shuffle")],
    "none": lambda: None,
}

#: Target bytes of a float32 chunk: 64 rows of a 2048 × 41 map (21.5 MB). Of 5.4, 21.5 and 43 MB
#: chunks, the first two read about equally fast with every compression and the last slower
#: (``make bench``, group ``scaleout-zarr-read``, shown in the report); the larger of the two means
#: fewer chunks. A 12k-wide map gets 11 rows per chunk.
CHUNK_BYTES = 64 * 2048 * 41 * 4


def rows_per_chunk_for(width: int, channels: int, height: int | None = None) -> int:
    """Rows per chunk of a ``W × C`` float32 map: :data:`CHUNK_BYTES` worth, one to ``height``.

    Examples
    --------
    >>> rows_per_chunk_for(2048, 41), rows_per_chunk_for(12000, 41), rows_per_chunk_for(64, 3, 32)
    (64, 11, 32)
    """
    rows = max(1, round(CHUNK_BYTES / (width * channels * 4)))
    return rows if height is None else min(rows, height)


def check_chunk_fits(
    rows: int, width: int, channels: int, where: str, available=None, copies: int = 1
) -> int:
    """Refuse a chunk whose float64 working copies would not fit in half the available memory.

    A streamed operation holds about one chunk as float64 (plus its input as float32), up to three
    when the next chunk is read ahead (``copies=3``: the caller's last block, this one and the
    next); chunks larger than half the memory that is free now would swap or fail. The message
    says how many rows would fit.

    Examples
    --------
    >>> check_chunk_fits(64, 2048, 41, "m.zarr", available=8 << 30)
    64
    >>> check_chunk_fits(6000, 12000, 41, "m.zarr", available=8 << 30)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: m.zarr: rows per chunk: 6000 rows of 12000 × 41 float64 need ...
    GB; half the free memory (4.3 GB) holds 1091 rows
    """
    if available is None:
        import psutil

        available = psutil.virtual_memory().available
    row_bytes = width * channels * 8 * copies
    need = rows * row_bytes
    fits = max(1, int(available / 2 // row_bytes))
    held = f"{copies} copies of " if copies > 1 else ""
    require(
        need <= available / 2,
        f"{where}: rows per chunk: {held}{rows} rows of {width} × {channels} float64 need "
        f"{need / 1e9:.1f} GB; half the free memory ({available / 2e9:.1f} GB) holds {fits} rows",
    )
    return rows


def _codecs():
    import zarr.codecs

    return zarr.codecs


@dataclass(frozen=True)
class ZarrImage:
    """An opened spectral Zarr store: its array (lazy), channels, grid and chunking."""

    path: Path
    array: object
    channels: list
    rows_per_chunk: int

    @property
    def shape(self) -> tuple[int, int, int]:
        """``(H, W, C)``."""
        return tuple(self.array.shape)

    @property
    def wavelengths_nm(self) -> np.ndarray | None:
        """Band centres in nm, or None for an RGB store."""
        return channel_wavelengths_nm(self.channels)

    def row_blocks(
        self, rows: int | None = None, prefetch: bool = True
    ) -> Iterator[tuple[int, np.ndarray]]:
        """``(first_row, block)`` in row order; ``block`` is float64 ``(rows, W, C)``.

        With ``prefetch`` a reader thread reads, decompresses and converts the next block while
        the caller works on this one (Zarr's codecs and NumPy's cast release the GIL): two blocks
        are held at once, three while the caller lets go of its last one; the blocks are the same
        either way.

        Examples
        --------
        >>> import tempfile, os
        >>> with tempfile.TemporaryDirectory() as d:
        ...     image = np.arange(5 * 10, dtype=np.float32).reshape(5, 10, 1)
        ...     z = open_zarr_image(write_zarr_image(os.path.join(d, "m.zarr"), image, ["Y"],
        ...                                          rows_per_chunk=2))
        ...     [(start, block.shape[0], block.dtype.name) for start, block in z.row_blocks()]
        [(0, 2, 'float64'), (2, 2, 'float64'), (4, 1, 'float64')]
        """
        rows = rows or self.rows_per_chunk
        height, width, n = self.shape
        check_chunk_fits(rows, width, n, str(self.path), copies=3 if prefetch else 1)
        starts = range(0, height, rows)

        def read(start: int) -> tuple[int, np.ndarray]:
            return start, np.asarray(self.array[start : start + rows], dtype=np.float64)

        if not prefetch:
            yield from map(read, starts)
            return
        from concurrent.futures import ThreadPoolExecutor

        with ThreadPoolExecutor(1, thread_name_prefix="zarr-read") as reader:
            pending = reader.submit(read, starts[0])
            for start in starts[1:]:
                block = pending.result()
                pending = reader.submit(read, start)  # read the next block during this one
                yield block
            yield pending.result()

    def to_dask(self):
        """The store as a ``dask.array`` with the store's chunks (nothing read yet)."""
        import dask.array as da

        return da.from_zarr(self.array)

    def read(self) -> np.ndarray:
        """The whole image in memory, float64 (for small maps only)."""
        return np.asarray(self.array[...], dtype=np.float64)


def _check_channels(channels, n_channels: int, where: str) -> list[str]:
    channels = [str(c) for c in channels]
    require(
        len(channels) == n_channels,
        f"{where}: {len(channels)} channel names for {n_channels} channels",
    )
    return channels


@contextlib.contextmanager
def _atomic_folder(path: Path):
    """A temporary folder beside ``path``, renamed to ``path`` on success (else removed)."""
    path = check_output_store(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        remove_stale_temporaries(path)
        tmp = Path(tempfile.mkdtemp(prefix=temporary_prefix(path), dir=path.parent))
    except OSError as exc:
        raise (output_error(path, exc) or SpecrefError(f"{path}: cannot write ({exc})")) from None
    try:
        yield tmp
        if path.exists():  # replace an old store: move it aside, move the new one in, drop it
            old = Path(tempfile.mkdtemp(prefix=temporary_prefix(path), dir=path.parent))
            os.replace(path, old / "store")
            os.replace(tmp, path)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(tmp, path)
    except OSError as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        raise (output_error(path, exc) or SpecrefError(f"{path}: cannot write ({exc})")) from None
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def write_zarr_blocks(
    path,
    height: int,
    width: int,
    channels,
    blocks: Iterable[np.ndarray],
    rows_per_chunk: int | None = None,
    compression: str = "blosc-lz4",
) -> Path:
    """Write a panorama given as row blocks (in order) to a Zarr store, atomically.

    Parameters
    ----------
    path : str or Path
        The store (a folder, by convention ``*.zarr``).
    height, width : int
        ``H`` and ``W = 2H``.
    channels : list of str
        Channel names (spectral OpenEXR names or ``R, G, B``).
    blocks : iterable of ndarray, shape (rows, W, C)
        Consecutive row blocks covering ``H`` rows; any block height.
    rows_per_chunk : int, optional
        Chunk height (at most the image's height); default :func:`rows_per_chunk_for`.
    compression : str
        A key of :data:`ZARR_COMPRESSIONS`.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     image = np.arange(4 * 8 * 2, dtype=np.float32).reshape(4, 8, 2)
    ...     _ = write_zarr_blocks(os.path.join(d, "m.zarr"), 4, 8, ["R", "G"],
    ...                           [image[:3], image[3:]], rows_per_chunk=2)
    ...     z = open_zarr_image(os.path.join(d, "m.zarr"))
    ...     z.shape, z.channels, bool((z.read() == image).all())
    ((4, 8, 2), ['R', 'G'], True)
    """
    import zarr

    path = Path(path)
    height = require_positive_int(height, f"{path}: height", 1 << 20)
    width = require_positive_int(width, f"{path}: width", 1 << 21)
    if rows_per_chunk is None:
        rows_per_chunk = rows_per_chunk_for(width, len(channels), height)
    rows_per_chunk = require_positive_int(rows_per_chunk, f"{path}: rows per chunk", 1 << 20)
    rows_per_chunk = min(rows_per_chunk, height)
    require(
        compression in ZARR_COMPRESSIONS,
        f"{path}: unknown compression {compression!r}; "
        f"allowed: {format_allowed(ZARR_COMPRESSIONS)}",
    )
    channels = list(channels)
    n = len(channels)
    check_chunk_fits(rows_per_chunk, width, n, str(path))
    attributes = _store_attributes(channels, rows_per_chunk)
    with _atomic_folder(path) as tmp:
        array = zarr.create_array(
            store=str(tmp),
            shape=(height, width, n),
            chunks=(rows_per_chunk, width, n),
            dtype="float32",
            compressors=ZARR_COMPRESSIONS[compression](),
            attributes=attributes,
            zarr_format=3,
        )
        _write_row_blocks(array, blocks, rows_per_chunk, path)
    return path


def _store_attributes(channels: list[str], rows_per_chunk: int) -> dict:
    """A store's attributes (module docstring): its kind, channels, grid and chunk height."""
    wavelengths = channel_wavelengths_nm(channels)
    return {
        "specref": "spectral-panorama",
        "channels": channels,
        "wavelengths_nm": None if wavelengths is None else [float(w) for w in wavelengths],
        "rows_per_chunk": rows_per_chunk,
    }


def _write_row_blocks(array, blocks: Iterable[np.ndarray], rows_per_chunk: int, path) -> None:
    """Write consecutive row blocks into ``array`` as whole chunks; check they cover its rows."""
    height, width, n = array.shape
    row = 0
    pending = np.empty((0, width, n), dtype=np.float32)
    for block in blocks:
        block = np.asarray(block, dtype=np.float32)
        require(
            block.ndim == 3 and block.shape[1:] == (width, n),
            f"{path}: a row block of shape {block.shape}; expected (rows, {width}, {n})",
        )
        pending = np.concatenate([pending, block]) if len(pending) else block
        # write whole chunks as they fill, so no chunk is written twice
        full = (len(pending) // rows_per_chunk) * rows_per_chunk
        if full:
            require(row + full <= height, f"{path}: more than {height} rows given")
            array[row : row + full] = pending[:full]
            row += full
            pending = pending[full:]
        if len(pending) and row + len(pending) == height:  # the last rows: no need to wait
            array[row:height] = pending
            row, pending = height, pending[:0]
        if len(pending) and np.may_share_memory(pending, block):
            pending = pending.copy()  # the rest waits; the caller may reuse its block's buffer
    if len(pending):
        require(row + len(pending) <= height, f"{path}: more than {height} rows given")
        array[row : row + len(pending)] = pending
        row += len(pending)
    require(row == height, f"{path}: {row} rows given for a {height}-row image")


def write_zarr_image(path, image, channels, **kwargs) -> Path:
    """Write an in-memory ``(H, W, C)`` image as a Zarr store (:func:`write_zarr_blocks`).

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = write_zarr_image(os.path.join(d, "m.zarr"), np.ones((2, 4, 1)), ["Y"])
    ...     open_zarr_image(os.path.join(d, "m.zarr")).shape
    (2, 4, 1)
    """
    image = np.asarray(image)
    require(image.ndim == 3, f"{path}: expected an (H, W, C) image, got shape {image.shape}")
    channels = _check_channels(channels, image.shape[2], str(path))
    rows = kwargs.get("rows_per_chunk")
    if rows is None:
        rows = rows_per_chunk_for(image.shape[1], image.shape[2], image.shape[0])
    rows = require_positive_int(rows, f"{path}: rows per chunk", 1 << 20)
    blocks = (image[i : i + rows] for i in range(0, image.shape[0], rows))
    return write_zarr_blocks(path, image.shape[0], image.shape[1], channels, blocks, **kwargs)


def open_zarr_image(path, n_channels: int | None = None, wavelengths_nm=None) -> ZarrImage:
    """Open a spectral Zarr store and check it before any pixel is read.

    Parameters
    ----------
    path : str or Path
        The store.
    n_channels : int, optional
        The band count the caller needs.
    wavelengths_nm : array_like, optional
        The grid the caller needs (band centres, nm; 1e-6 nm tolerance).

    Raises
    ------
    SpecrefError
        Not a specref Zarr store; a shape that is not ``(H, 2H, C)``; another band count or grid;
        chunks that do not hold whole rows of all bands.

    Examples
    --------
    >>> open_zarr_image("/nonexistent/map.zarr")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent/map.zarr: Zarr store not found
    """
    import zarr

    path = Path(path)
    require(path.exists(), f"{path}: Zarr store not found")
    try:
        array = zarr.open_array(str(path), mode="r")
    except Exception as exc:  # zarr raises several types for a folder that is not a store
        raise SpecrefError(f"{path}: not a Zarr array ({type(exc).__name__}: {exc})") from None
    attrs = dict(array.attrs)
    require(
        attrs.get("specref") == "spectral-panorama",
        f"{path}: not a specref panorama store (attribute specref != 'spectral-panorama')",
    )
    require(array.ndim == 3, f"{path}: shape {array.shape}; expected (H, W, C)")
    height, width, n = array.shape
    require(width == 2 * height, f"{path}: shape {array.shape}; a lat-long map has W = 2H")
    channels = _check_channels(attrs.get("channels", []), n, str(path))
    chunks = array.chunks
    require(
        chunks[1:] == (width, n),
        f"{path}: chunks {chunks}; a panorama store holds whole rows of every band per chunk",
    )
    if n_channels is not None:
        require(n == n_channels, f"{path}: {n} channels; expected {n_channels}")
    if wavelengths_nm is not None:
        have = channel_wavelengths_nm(channels)
        want = np.asarray(wavelengths_nm, dtype=float)
        same = have is not None and have.shape == want.shape and np.allclose(have, want, atol=1e-6)
        require(
            same,
            f"{path}: wavelengths_nm: the store's grid "
            f"{json.dumps(None if have is None else [float(have[0]), float(have[-1]), len(have)])} "
            f"(first, last, count) is not the scene's ({float(want[0])}, {float(want[-1])}, "
            f"{len(want)})",
        )
    return ZarrImage(path, array, channels, int(chunks[0]))


def map_zarr_blocks(source, out, function, channels=None, **kwargs) -> Path:
    """Apply a per-pixel ``function(block) -> block`` to a store, streamed into a new store.

    ``function`` maps ``(rows, W, C)`` float64 to ``(rows, W, C')`` (for example the colour
    management ``block * illuminant`` or spectra → XYZ); it sees one chunk at a time, so the
    result equals ``function(whole image)`` for any per-pixel function, bit for bit.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     image = np.ones((4, 8, 2), dtype=np.float32)
    ...     _ = write_zarr_image(os.path.join(d, "a.zarr"), image, ["R", "G"], rows_per_chunk=2)
    ...     _ = map_zarr_blocks(os.path.join(d, "a.zarr"), os.path.join(d, "b.zarr"),
    ...                         lambda b: 3 * b)
    ...     float(open_zarr_image(os.path.join(d, "b.zarr")).read().max())
    3.0
    """
    src = open_zarr_image(source)
    height, width, _ = src.shape
    first = np.asarray(function(np.asarray(src.array[:1], dtype=np.float64)))
    require(
        first.ndim == 3 and first.shape[:2] == (1, width),
        f"{source}: the function must keep rows and columns, got {first.shape}",
    )
    names = list(channels) if channels is not None else src.channels
    require(
        len(names) == first.shape[2], f"{out}: {len(names)} names for {first.shape[2]} channels"
    )
    kwargs.setdefault("rows_per_chunk", src.rows_per_chunk)
    blocks = (function(block) for _, block in src.row_blocks())
    return write_zarr_blocks(out, height, width, names, blocks, **kwargs)


def zarr_to_cubemap(path, size: int = 64, backend: str = "numba") -> np.ndarray:
    """:func:`~reference.geometry.cubemap.latlong_to_cubemap` of a Zarr panorama, streamed by rows.

    The store's chunks are read in row order (float64, the next read ahead) and gathered by
    :func:`~reference.geometry.cubemap.latlong_blocks_to_cubemap`; equal, bit for bit, to
    ``latlong_to_cubemap`` of the store read whole.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     path = write_zarr_image(os.path.join(d, "m.zarr"), np.ones((8, 16, 2)), ["R", "G"],
    ...                             rows_per_chunk=3)
    ...     cube = zarr_to_cubemap(path, 4)
    >>> cube.shape, float(cube.min()), float(cube.max())
    ((6, 4, 4, 2), 1.0, 1.0)
    """
    store = open_zarr_image(path)
    return latlong_blocks_to_cubemap(store.row_blocks(), store.shape[0], size, backend)

"""Image I/O: PNG (imageio), OpenEXR (OpenEXR), Radiance HDR (imagecodecs).

Every writer goes through :func:`reference.files.atomic_write` or
:func:`reference.files.atomic_path`: the data go to a temporary file in the destination folder,
which is synced and renamed into place, so an interrupted run never leaves a half-written file.

Readers return float64 arrays ``(H, W, C)`` with row 0 at the top and refuse unreadable files with a
one-line :class:`~reference.errors.SpecrefError` that names the file.

Spectral OpenEXR files follow the layout of Fichet, Pacanowski & Wilkie (2021): one channel per
band, named ``S0.<wavelength>nm`` with a comma as the decimal separator (``S0.550,000000nm``). The
reader accepts any channel names that end in a wavelength in nm.

References
----------
- A. Fichet, R. Pacanowski, A. Wilkie, "An OpenEXR Layout for Spectral Images", JCGT 10(3), 2021.
- G. Ward, "Real Pixels", Graphics Gems II, 1991 (the RGBE encoding of Radiance ``.hdr`` files).
"""

from __future__ import annotations

import errno
import os
import re
from pathlib import Path

import numpy as np

from reference.errors import SpecrefError, require
from reference.files import WRITE_ERRORS, atomic_path, write_bytes_atomic

__all__ = [
    "MAX_IMAGE_PIXELS",
    "channel_wavelengths_nm",
    "exr_write_error",
    "read_exr",
    "read_hdr",
    "read_image",
    "read_png",
    "spectral_channel_names",
    "write_exr",
    "write_png",
]

#: Largest image (pixels) that specref reads or writes; larger inputs are refused as absurd.
MAX_IMAGE_PIXELS = 16384 * 16384


def write_png(path, image, text: dict | None = None) -> Path:
    """Write an 8-bit PNG atomically (imageio), with optional text chunks.

    Parameters
    ----------
    path : str or Path
        Destination.
    image : ndarray, shape (H, W) or (H, W, 3|4)
        uint8 values, or floats in [0, 1] that are quantized with round-half-up.
    text : dict of str, optional
        ``tEXt`` chunks (key → value): the render's settings, read back by
        ``imageio.v3.immeta`` or Pillow's ``Image.text``.

    Returns
    -------
    Path

    Examples
    --------
    >>> import tempfile, os
    >>> import imageio.v3 as iio
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = write_png(os.path.join(d, "a.png"), np.zeros((2, 3, 3)), {"specref": "N=8"})
    ...     read_png(p).shape, iio.immeta(p)["specref"]
    ((2, 3, 3), 'N=8')
    """
    import imageio.v3 as iio
    from PIL.PngImagePlugin import PngInfo

    from reference.display.encodings import to_8bit

    image = np.asarray(image)
    if image.dtype != np.uint8:
        image = to_8bit(image)
    info = PngInfo()
    for key, value in (text or {}).items():
        info.add_text(str(key), str(value))
    data = iio.imwrite("<bytes>", image, extension=".png", pnginfo=info)
    return write_bytes_atomic(path, data)


def read_png(path) -> np.ndarray:
    """Read a PNG (or another image imageio reads without plugins) as float64 in [0, 1], (H, W, C).

    A PNG keeps its bit depth (8 or 16 bits a channel; a palette is expanded to RGB).

    Examples
    --------
    >>> read_png("/nonexistent.png")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent.png: file not found
    """
    import imageio.v3 as iio

    path = Path(path)
    require(path.is_file(), f"{path}: file not found")
    try:
        image = _png_decode(path) if _is_png(path) else iio.imread(path, plugin="pillow")
    except SpecrefError:
        raise
    except Exception as error:  # the decoders raise many kinds; all mean "not a readable image"
        raise SpecrefError(f"{path}: cannot read image ({error.__class__.__name__})") from None
    image = np.asarray(image)
    scale = float(np.iinfo(image.dtype).max) if image.dtype.kind in "ui" else 1.0
    image = image.astype(np.float64) / scale
    return image[..., None] if image.ndim == 2 else image


_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _is_png(path: Path) -> bool:
    with open(path, "rb") as f:
        return f.read(8) == _PNG_SIGNATURE


def _png_decode(path: Path) -> np.ndarray:
    """A PNG at its own bit depth (Pillow reads 16-bit colour PNGs as 8 bits), size checked."""
    import imagecodecs

    data = path.read_bytes()
    # IHDR: width and height, big-endian, right after the signature and the chunk's header
    width, height = int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")
    require(
        0 < width * height <= MAX_IMAGE_PIXELS,
        f"{path}: {width} × {height} pixels; at most {MAX_IMAGE_PIXELS} are read",
    )
    return imagecodecs.png_decode(data)


def spectral_channel_names(wavelengths_nm) -> list[str]:
    """Channel names of the spectral OpenEXR layout (Fichet et al. 2021): ``S0.550,000000nm``.

    Examples
    --------
    >>> spectral_channel_names([380.0, 555.5])
    ['S0.380,000000nm', 'S0.555,500000nm']
    """
    return [f"S0.{w:.6f}".replace(".", ",").replace("S0,", "S0.") + "nm" for w in wavelengths_nm]


_WAVELENGTH_CHANNEL = re.compile(r"(\d+(?:[.,]\d+)?)\s*nm$")


def channel_wavelengths_nm(names) -> np.ndarray | None:
    """Wavelengths (nm) named by spectral channel names, or None if any name has no wavelength.

    Accepts the spectral OpenEXR layout (``S0.550,000000nm``) and plain ``550nm`` names, as
    :func:`read_exr` does when it sorts them.

    Examples
    --------
    >>> channel_wavelengths_nm(["S0.380,000000nm", "S0.555,500000nm"])
    array([380. , 555.5])
    >>> channel_wavelengths_nm(["R", "G", "B"]) is None
    True
    """
    found = [_WAVELENGTH_CHANNEL.search(str(name)) for name in names]
    if not found or not all(found):
        return None
    return np.array([float(m.group(1).replace(",", ".")) for m in found])


def write_exr(
    path, image, channels: list[str] | None = None, half: bool = False, attributes=None
) -> Path:
    """Write a linear float image as OpenEXR atomically.

    Parameters
    ----------
    path : str or Path
        Destination.
    image : ndarray, shape (H, W, C) or (H, W)
        Linear values.
    channels : list of str, optional
        Channel names; default ``R, G, B`` for 3 channels, ``Y`` for 1, and required otherwise (use
        :func:`spectral_channel_names` for spectral images).
    half : bool
        Store 16-bit half floats instead of 32-bit floats.
    attributes : dict of str to str, optional
        Extra string attributes of the header (``reference.scene.metadata.exr_attributes``).

    Returns
    -------
    Path

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = write_exr(os.path.join(d, "a.exr"), np.full((2, 2, 3), 0.25))
    ...     image, names = read_exr(p)
    ...     image[0, 0], names
    (array([0.25, 0.25, 0.25]), ['R', 'G', 'B'])
    """
    import OpenEXR

    image = np.asarray(image, dtype=np.float64)
    if image.ndim == 2:
        image = image[..., None]
    require(image.ndim == 3, f"{path}: EXR image must be (H, W, C), got shape {image.shape}")
    n = image.shape[2]
    if channels is None:
        require(n in (1, 3), f"{path}: name the {n} channels of this EXR image")
        channels = ["Y"] if n == 1 else ["R", "G", "B"]
    require(len(channels) == n, f"{path}: {len(channels)} channel names for {n} channels")
    dtype = np.float16 if half else np.float32
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    header.update({str(k): str(v) for k, v in (attributes or {}).items()})
    data = {
        name: np.ascontiguousarray(image[..., i].astype(dtype)) for i, name in enumerate(channels)
    }
    path = Path(path)
    # OpenEXR writes by file name, so write a temporary name beside the target and rename it.
    with atomic_path(path, ".exr") as tmp:
        try:
            with OpenEXR.File(header, data) as handle:
                handle.write(str(tmp))
        except RuntimeError as error:
            raise exr_write_error(path, error) from None
        # OpenEXR may lose a small file's data on a full disk without an error: read it back.
        _check_exr_written(tmp, path)
    return path


def exr_write_error(path, error: Exception) -> SpecrefError:
    """The one-line error for OpenEXR's exception (no errno) while writing ``path``.

    OpenEXR reports the file system's refusals as text ("... No space left on device").

    Examples
    --------
    >>> exr_write_error("a.exr", RuntimeError("Failed to write. No space left on device."))
    SpecrefError('a.exr: cannot write (no space left on the device)')
    """
    text = str(error)
    reason = WRITE_ERRORS[errno.ENOSPC] if "No space left" in text else f"OpenEXR: {text}"
    return SpecrefError(f"{path}: cannot write ({reason})")


def _check_exr_written(tmp, path) -> None:
    """Raise a one-line SpecrefError for ``path`` unless the EXR at ``tmp`` reads back whole."""
    try:
        with open(tmp, "rb") as handle:
            os.fsync(handle.fileno())
        read_exr(tmp)
    except (SpecrefError, OSError):
        stat = os.statvfs(Path(tmp).parent)
        full = stat.f_bavail == 0
        reason = WRITE_ERRORS[errno.ENOSPC] if full else "the written file does not read back"
        raise SpecrefError(f"{path}: cannot write ({reason})") from None


def read_exr_parts(path, read, **options):
    """Open an OpenEXR file, return ``read(handle)``; a missing or unreadable file is one line.

    The one place that opens EXR files for reading: :func:`read_exr` reads the pixels,
    ``reference.scene.metadata.read_exr_metadata`` the header (``header_only=True``).

    Parameters
    ----------
    path : str or Path
        The file.
    read : callable
        Takes the open ``OpenEXR.File`` and returns what the caller needs.
    **options
        Passed to ``OpenEXR.File`` (``separate_channels``, ``header_only``).

    Raises
    ------
    SpecrefError
        Missing or unreadable file.

    Examples
    --------
    >>> read_exr_parts("/nonexistent.exr", lambda handle: handle.header())
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent.exr: file not found
    """
    import OpenEXR

    path = Path(path)
    require(path.is_file(), f"{path}: file not found")
    try:
        with OpenEXR.File(str(path), **options) as handle:
            return read(handle)
    except Exception as error:  # the bindings raise RuntimeError and others for bad files
        raise SpecrefError(
            f"{path}: cannot read OpenEXR image ({error.__class__.__name__})"
        ) from None


def read_exr(path) -> tuple[np.ndarray, list[str]]:
    """Read an OpenEXR file (scanline or tiled; the top mip level) as float64.

    Channels are returned in the order R, G, B, A when present; channels whose names end in a
    wavelength (``S0.550,000000nm``, ``550nm``) are returned sorted by wavelength; anything else in
    file order.

    Parameters
    ----------
    path : str or Path
        The file.

    Returns
    -------
    image : ndarray, shape (H, W, C)
    names : list of str

    Raises
    ------
    SpecrefError
        Missing or unreadable file.

    Examples
    --------
    >>> read_exr("/nonexistent.exr")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent.exr: file not found
    """
    path = Path(path)
    channels = read_exr_parts(
        path,
        lambda handle: {name: np.asarray(ch.pixels) for name, ch in handle.channels().items()},
        separate_channels=True,
    )
    require(channels, f"{path}: OpenEXR file has no channels")
    names = list(channels)
    spectral = {n: _WAVELENGTH_CHANNEL.search(n) for n in names}
    if all(spectral.values()):
        names.sort(key=lambda n: float(spectral[n].group(1).replace(",", ".")))
    else:
        order = {"R": 0, "G": 1, "B": 2, "A": 3}
        position = {n: i for i, n in enumerate(names)}
        names.sort(key=lambda n: (order.get(n, 4), position[n]))
    shapes = {channels[n].shape for n in names}
    require(len(shapes) == 1, f"{path}: channels have different sizes {sorted(shapes)}")
    image = np.stack([channels[n].astype(np.float64) for n in names], axis=-1)
    require(image.shape[0] * image.shape[1] <= MAX_IMAGE_PIXELS, f"{path}: image too large")
    return image, names


def read_hdr(path) -> np.ndarray:
    """Read a Radiance RGBE ``.hdr`` file as float64 RGB (imagecodecs).

    RGBE decodes as ``m · 2^(e - 136)`` per channel (no +0.5 offset), as FreeImage and Mitsuba 3 do.

    Parameters
    ----------
    path : str or Path
        The file.

    Returns
    -------
    ndarray, shape (H, W, 3)

    Raises
    ------
    SpecrefError
        Missing or unreadable file.

    Examples
    --------
    >>> read_hdr("/nonexistent.hdr")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent.hdr: file not found
    """
    import imagecodecs

    path = Path(path)
    require(path.is_file(), f"{path}: file not found")
    data = path.read_bytes()
    try:
        image = imagecodecs.rgbe_decode(data)
    except Exception as error:  # imagecodecs.RgbeError and others
        raise SpecrefError(
            f"{path}: cannot read Radiance HDR image ({error.__class__.__name__})"
        ) from None
    image = np.asarray(image, dtype=np.float64)
    require(
        image.ndim == 3 and image.shape[2] == 3, f"{path}: expected an RGB image, got {image.shape}"
    )
    return image


def read_image(path) -> np.ndarray:
    """Read ``.exr``, ``.hdr`` or ``.png`` by extension as float64 ``(H, W, C)``.

    Raises
    ------
    SpecrefError
        Unknown extension, missing or unreadable file.

    Examples
    --------
    >>> read_image("photo.gif")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: photo.gif: unsupported image type '.gif'; allowed: .exr, .hdr,
    .png
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".exr":
        return read_exr(path)[0]
    if suffix in (".hdr", ".rgbe", ".pic"):
        return read_hdr(path)
    if suffix == ".png":
        return read_png(path)
    raise SpecrefError(f"{path}: unsupported image type {suffix!r}; allowed: .exr, .hdr, .png")

"""Atomic file writes, and image I/O: PNG (imageio), OpenEXR (OpenEXR), Radiance HDR (imagecodecs).

Every writer goes through :func:`atomic_write`: the data go to a temporary file in the destination
folder, which is flushed, synced and renamed into place, so an interrupted run never leaves a
half-written file.

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

import contextlib
import errno
import os
import re
import tempfile
from pathlib import Path

import numpy as np

from reference.errors import SpecrefError, require

__all__ = [
    "MAX_IMAGE_PIXELS",
    "atomic_path",
    "atomic_write",
    "channel_wavelengths_nm",
    "check_output_folder",
    "exr_write_error",
    "output_error",
    "read_exr",
    "read_hdr",
    "read_image",
    "read_json",
    "read_png",
    "spectral_channel_names",
    "write_bytes_atomic",
    "write_exr",
    "write_png",
    "write_text_atomic",
]

#: Largest image (pixels) that specref reads or writes; larger inputs are refused as absurd.
MAX_IMAGE_PIXELS = 16384 * 16384

# The process umask, read once at import: mkstemp creates files 0600, and a finished output should
# get the permissions an ordinary open() would give it.
_UMASK = os.umask(0o022)
os.umask(_UMASK)


def _new_file_permissions(tmp) -> None:
    """Give a temporary file the permissions of a newly created ordinary file (0666 & ~umask)."""
    os.chmod(tmp, 0o666 & ~_UMASK)


#: Errors of the file system that mean "this output cannot be written here", by errno, with what the
#: one-line message says about them.
_WRITE_ERRORS = {
    errno.EISDIR: "is a folder; give a file name",
    errno.ENOTDIR: "a part of the path is a file, not a folder",
    errno.EEXIST: "a part of the path is a file, not a folder",
    errno.EACCES: "permission denied",
    errno.EPERM: "permission denied",
    errno.EROFS: "read-only file system",
    errno.ENOSPC: "no space left on the device",
    errno.EDQUOT: "disk quota exceeded",
    errno.EFBIG: "file too large for the file system",
}


def output_error(path, error: OSError) -> SpecrefError | None:
    """The one-line :class:`SpecrefError` for an OSError met while writing ``path``, if it is one.

    Every writer (:func:`atomic_write`, :func:`write_exr`) turns the file system's refusals (a
    folder where a file should be, a file where a folder should be, no permission, a full disk)
    into this message, so no command shows a traceback for them.

    Returns
    -------
    SpecrefError or None
        None when ``error`` is not a refusal to write (the caller re-raises it).

    Examples
    --------
    >>> import errno
    >>> output_error("out/a.exr", OSError(errno.ENOSPC, "No space left on device"))
    SpecrefError('out/a.exr: cannot write (no space left on the device)')
    >>> output_error("a.exr", OSError(errno.EIO, "I/O error")) is None
    True
    """
    reason = _WRITE_ERRORS.get(getattr(error, "errno", None))
    if reason is None:
        return None
    return SpecrefError(f"{path}: cannot write ({reason})")


@contextlib.contextmanager
def _write_errors(path):
    """Turn the file system's refusals to write ``path`` into one-line SpecrefErrors."""
    try:
        yield
    except OSError as error:
        translated = output_error(path, error)
        if translated is None:
            raise
        raise translated from None


@contextlib.contextmanager
def atomic_write(path, mode: str = "wb"):
    """Open a temporary file beside ``path``; on success, sync it and rename it to ``path``.

    On an exception the temporary file is removed and ``path`` is untouched. When the file system
    refuses the write (see :func:`output_error`) the error is a one-line :class:`SpecrefError`.

    Parameters
    ----------
    path : str or Path
        Destination; its folder is created if missing.
    mode : str
        ``"wb"`` or ``"w"``.

    Yields
    ------
    file object
        The temporary file, opened in ``mode``.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = os.path.join(d, "out.txt")
    ...     with atomic_write(p, "w") as f:
    ...         _ = f.write("done")
    ...     open(p).read()
    'done'
    """
    path = Path(path)
    with _write_errors(path):
        require(not path.is_dir(), f"{path}: cannot write ({_WRITE_ERRORS[errno.EISDIR]})")
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
        try:
            _new_file_permissions(tmp)
            with os.fdopen(fd, mode) as handle:
                yield handle
                handle.flush()
                os.fsync(handle.fileno())
            os.replace(tmp, path)
        except BaseException:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp)
            raise


@contextlib.contextmanager
def atomic_path(path, suffix: str = ""):
    """Yield a temporary file name beside ``path``; on success, sync it and rename it to ``path``.

    For writers that take a file name rather than a file object (OpenEXR, tifffile). As in
    :func:`atomic_write`, an exception removes the temporary file and leaves ``path`` untouched,
    and the file system's refusals become one-line :class:`SpecrefError` (:func:`output_error`).

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     with atomic_path(os.path.join(d, "a.bin")) as tmp:
    ...         _ = open(tmp, "wb").write(b"xy")
    ...     sorted(os.listdir(d))
    ['a.bin']
    """
    path = Path(path)
    with _write_errors(path):
        require(not path.is_dir(), f"{path}: cannot write ({_WRITE_ERRORS[errno.EISDIR]})")
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix, dir=path.parent)
        os.close(fd)
        tmp = Path(name)
        try:
            yield tmp
            with open(tmp, "rb+") as handle:
                os.fsync(handle.fileno())
            _new_file_permissions(tmp)
            os.replace(tmp, path)
        except BaseException:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp)
            raise


def read_json(path, kind: str = "JSON"):
    """Read a JSON file; a missing or malformed one is a one-line :class:`SpecrefError`.

    Parameters
    ----------
    path : str or Path
    kind : str
        What the file should be, for the message (``"JSON display file"``).

    Examples
    --------
    >>> read_json("/nonexistent.json", "JSON display file")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent.json: file not found
    """
    import json

    path = Path(path)
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise SpecrefError(f"{path}: file not found") from None
    except (OSError, ValueError) as error:
        raise SpecrefError(f"{path}: not a {kind} ({error})") from None


def check_output_folder(folder) -> Path:
    """Create ``folder`` if needed and prove that a file can be written in it; return it.

    Commands that write many files into a folder call this before any work, so an unwritable
    folder (a file of that name, a read-only file system, a full disk) is refused in one line
    before the first frame rather than after it.

    Raises
    ------
    SpecrefError
        One line naming the folder and the reason (:func:`output_error`).

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     check_output_folder(os.path.join(d, "frames")).is_dir()
    True
    """
    folder = Path(folder)
    with _write_errors(folder):
        require(not folder.is_file(), f"{folder}: cannot write ({_WRITE_ERRORS[errno.ENOTDIR]})")
        folder.mkdir(parents=True, exist_ok=True)
    probe = write_bytes_atomic(folder / ".specref-write-probe", b"specref")
    probe.unlink()
    return folder


def write_bytes_atomic(path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically and return the path.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     write_bytes_atomic(os.path.join(d, "a.bin"), b"xy").stat().st_size
    2
    """
    with atomic_write(path, "wb") as handle:
        handle.write(data)
    return Path(path)


def write_text_atomic(path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically and return the path.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     write_text_atomic(os.path.join(d, "a.txt"), "é").read_text(encoding="utf-8")
    'é'
    """
    return write_bytes_atomic(path, text.encode("utf-8"))


def write_png(path, image) -> Path:
    """Write an 8-bit PNG atomically (imageio).

    Parameters
    ----------
    path : str or Path
        Destination.
    image : ndarray, shape (H, W) or (H, W, 3|4)
        uint8 values, or floats in [0, 1] that are quantized with round-half-up.

    Returns
    -------
    Path

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = write_png(os.path.join(d, "a.png"), np.zeros((2, 3, 3)))
    ...     read_png(p).shape
    (2, 3, 3)
    """
    import imageio.v3 as iio

    from reference.display import to_8bit

    image = np.asarray(image)
    if image.dtype != np.uint8:
        image = to_8bit(image)
    data = iio.imwrite("<bytes>", image, extension=".png")
    return write_bytes_atomic(path, data)


def read_png(path) -> np.ndarray:
    """Read a PNG (or another image imageio reads without plugins) as float64 in [0, 1], (H, W, C).

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
        image = iio.imread(path, plugin="pillow")
    except Exception as error:  # imageio raises many kinds; all mean "not a readable image"
        raise SpecrefError(f"{path}: cannot read image ({error.__class__.__name__})") from None
    image = np.asarray(image)
    scale = float(np.iinfo(image.dtype).max) if image.dtype.kind in "ui" else 1.0
    image = image.astype(np.float64) / scale
    return image[..., None] if image.ndim == 2 else image


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
        Extra string attributes of the header (``reference.render_metadata.exr_attributes``).

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
    reason = _WRITE_ERRORS[errno.ENOSPC] if "No space left" in text else f"OpenEXR: {text}"
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
        reason = _WRITE_ERRORS[errno.ENOSPC] if full else "the written file does not read back"
        raise SpecrefError(f"{path}: cannot write ({reason})") from None


def read_exr_parts(path, read, **options):
    """Open an OpenEXR file, return ``read(handle)``; a missing or unreadable file is one line.

    The one place that opens EXR files for reading: :func:`read_exr` reads the pixels,
    ``reference.render_metadata.read_exr_metadata`` the header (``header_only=True``).

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

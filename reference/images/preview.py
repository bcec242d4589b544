"""A display preview of a linear image of any layout (spectral bands, XYZ, RGB), read by blocks.

A 41-band panorama (``specref env spectralize``) or a spectral render (``specref render
--exr-output spectral``) opens in no image viewer. :func:`image_preview` writes the PNG a user
can open: the bands integrated to XYZ with the equal-energy weights of their grid
(:func:`reference.colour.colorimetry.spectral_channel_weights`, the normalisation of
docs/render-outputs.md), box-filtered by a whole factor to at most ``width`` pixels across, exposed
so that the median luminance is middle grey (or by a stated exposure), converted to sRGB and
encoded. The file is read a block of rows at a time (:func:`reference.images.spectral.
open_panorama_rows`), so a 4096 × 8192 × 41 panorama is never held whole.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from reference.errors import require

__all__ = ["MIDDLE_GREY", "channels_to_XYZ_function", "image_preview"]

#: The linear luminance the automatic exposure gives the image's median pixel (18 % grey).
MIDDLE_GREY = 0.18

#: Pixels per block of rows read at once (as spectralizing reads).
_BLOCK_PIXELS = 1 << 17


def channels_to_XYZ_function(names, where: str = "image"):
    """The function from an image's channels ``(..., C)`` to XYZ ``(..., 3)``, and its kind.

    Spectral channels (``S0.<nm>nm``, docs/render-outputs.md) are integrated with the grid's
    equal-energy weights; ``X, Y, Z`` are taken as they are; ``R, G, B`` are linear sRGB.

    Examples
    --------
    >>> to_XYZ, kind = channels_to_XYZ_function(["R", "G", "B"])
    >>> kind, to_XYZ(np.ones((1, 3))).round(4).tolist()
    ('rgb', [[0.9505, 1.0, 1.089]])
    >>> channels_to_XYZ_function(["A"], "a.exr")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: a.exr: no spectral channels (S0.<nm>nm), no X, Y, Z and no ...
    """
    from reference.colour.colorimetry import display_RGB_to_XYZ, spectral_channel_weights
    from reference.images.formats import channel_wavelengths_nm

    names = list(names)
    spectral = [i for i, n in enumerate(names) if channel_wavelengths_nm([n]) is not None]
    if spectral:
        wavelengths = channel_wavelengths_nm([names[i] for i in spectral])
        W = spectral_channel_weights(wavelengths, where)
        return (lambda data: data[..., spectral] @ W), "spectral"
    if all(c in names for c in "XYZ"):
        index = [names.index(c) for c in "XYZ"]
        return (lambda data: data[..., index].astype(np.float64)), "xyz"
    require(
        all(c in names for c in "RGB"),
        f"{where}: no spectral channels (S0.<nm>nm), no X, Y, Z and no R, G, B; has "
        f"{', '.join(names)}",
    )
    index = [names.index(c) for c in "RGB"]
    return (lambda data: display_RGB_to_XYZ(data[..., index])), "rgb"


def _box(XYZ: np.ndarray, factor: int, columns: int) -> np.ndarray:
    """Mean over ``factor × factor`` pixel boxes (rows a multiple of ``factor``)."""
    rows = XYZ.shape[0] // factor
    cut = XYZ[: rows * factor, : columns * factor]
    return cut.reshape(rows, factor, columns, factor, 3).mean(axis=(1, 3))


def _box_filtered_XYZ(rows, to_XYZ, width: int, progress) -> tuple[np.ndarray, int]:
    """The XYZ box-filtered by a whole factor to at most ``width`` across, and the factor."""
    from reference.progress import Progress

    factor = max(1, min(math.ceil(rows.width / width), rows.height))
    columns = max(1, rows.width // factor)
    step = factor * max(1, _BLOCK_PIXELS // (rows.width * factor))
    blocks = []
    with Progress(f"preview of {Path(rows.path).name}", rows.height, progress) as bar:
        for start in range(0, rows.height, step):
            stop = min(start + step, rows.height)
            XYZ = to_XYZ(np.asarray(rows.read(start, stop), dtype=np.float64))
            require(
                np.isfinite(XYZ).all(),
                f"{rows.path}: rows {start}-{stop - 1} hold NaN or infinite values",
            )
            if XYZ.shape[0] >= factor:  # the last rows that do not fill a box are left out
                blocks.append(_box(XYZ, factor, columns))
            bar.update(stop - start)
    return np.concatenate(blocks), factor


def image_preview(path, out, width: int = 2048, exposure_ev=None, progress=None) -> dict:
    """Write a display-encoded PNG preview of a linear image (module docstring).

    Parameters
    ----------
    path : str or Path
        ``.exr`` (spectral, XYZ or RGB channels), ``.hdr``, float ``.tif`` or ``.zarr``.
    out : str or Path
        The PNG (atomic write).
    width : int
        Widest preview in pixels: the image is box-filtered by the smallest whole factor that
        fits (the last rows and columns that do not fill a box are left out).
    exposure_ev : float, optional
        Exposure in stops applied to the XYZ (``× 2^EV``); default: the one that puts the median
        luminance of the preview's lit pixels (after the box filter) at :data:`MIDDLE_GREY`.
    progress : file-like, optional
        Where a progress line goes (the command line's stderr).

    Returns
    -------
    dict
        ``out``, ``kind`` (spectral, xyz, rgb), ``height``, ``width`` (of the image),
        ``factor``, ``preview`` (rows, columns), ``exposure_ev``, ``clipped`` (share of the
        preview's channel values above 1 after exposure).

    Raises
    ------
    SpecrefError
        An unreadable file or layout, a NaN or infinite value (naming the row block), a bad
        ``width`` or ``exposure_ev``.

    Examples
    --------
    >>> import tempfile, os
    >>> from reference.images.formats import spectral_channel_names, write_exr
    >>> wl = np.arange(380.0, 781.0, 10.0)
    >>> with tempfile.TemporaryDirectory() as d:
    ...     src = write_exr(os.path.join(d, "s.exr"), np.full((8, 16, 41), 0.5),
    ...                     spectral_channel_names(wl))
    ...     info = image_preview(src, os.path.join(d, "s.png"), width=4)
    >>> info["kind"], info["factor"], info["preview"], round(info["exposure_ev"], 3)
    ('spectral', 4, (2, 4), -1.474)
    """
    from reference.colour.colorimetry import XYZ_to_display_RGB
    from reference.display.encodings import linear_to_display
    from reference.images.formats import write_png
    from reference.images.spectral import open_panorama_rows

    require(
        isinstance(width, (int, np.integer)) and not isinstance(width, bool) and width >= 1,
        f"--width: must be a whole number >= 1, got {width!r}",
    )
    require(
        exposure_ev is None or (np.isfinite(exposure_ev) and abs(exposure_ev) <= 64),
        f"--exposure: must be a finite number of stops in [-64, 64], got {exposure_ev!r}",
    )
    require(
        str(out).lower().endswith(".png"),
        f"{out}: the preview is an sRGB PNG; give a name ending in .png",
    )
    with open_panorama_rows(path) as rows:
        to_XYZ, kind = channels_to_XYZ_function(rows.names, str(path))
        XYZ, factor = _box_filtered_XYZ(rows, to_XYZ, width, progress)
        height, image_width = rows.height, rows.width
    if exposure_ev is None:
        lit = XYZ[..., 1][XYZ[..., 1] > 0]
        exposure_ev = math.log2(MIDDLE_GREY / float(np.median(lit))) if lit.size else 0.0
    rgb = XYZ_to_display_RGB(XYZ * 2.0**exposure_ev)
    clipped = float(np.mean(rgb > 1.0))
    write_png(out, linear_to_display(np.clip(rgb, 0.0, 1.0), "srgb"))
    return {
        "out": str(out),
        "kind": kind,
        "height": height,
        "width": image_width,
        "factor": factor,
        "preview": XYZ.shape[:2],
        "exposure_ev": float(exposure_ev),
        "clipped": clipped,
    }

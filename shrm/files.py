"""File-level SH jobs behind ``specref sh project`` and ``specref sh prefilter``.

Maps are read with ``reference.images.spectral.read_environment_file`` (``.hdr`` RGBE, ``.exr`` RGB
or spectral with one channel per band, spectral float ``.tif`` from ``specref env spectralize``).
``bands="spectral"`` turns an RGB map into spectra on the 41-band grid
(``reference.colour.upsampling``, Mallett & Yuksel 2019); ``bands="rgb"`` turns a spectral map into
linear sRGB (equal-energy band weights); the default keeps the map as it is.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from reference.colour.colorimetry import band_weights, spectra_to_RGB_matrix
from reference.colour.spectra import DEFAULT_GRID
from reference.colour.upsampling import RGB_to_spectra
from reference.errors import require, require_choice
from reference.images.formats import spectral_channel_names, write_exr

__all__ = ["prefilter_file", "project_file", "read_environment"]


def read_environment(path, bands: str | None = None) -> tuple[np.ndarray, list[str]]:
    """Read a lat-long map and its channel names, converted to ``bands`` if given.

    Raises
    ------
    SpecrefError
        Unreadable file, not 2:1, NaN/inf or negative radiance, unknown ``bands``.

    Examples
    --------
    >>> read_environment("/nonexistent.hdr")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent.hdr: file not found
    """
    from reference.geometry.envmap import check_latlong_shape
    from reference.images.spectral import read_environment_file

    path = Path(path)
    image, names = read_environment_file(path)
    check_latlong_shape(image.shape, str(path))
    require(np.isfinite(image).all(), f"{path}: radiance must be finite, found NaN or inf")
    require((image >= 0).all(), f"{path}: radiance must be >= 0, found {image.min():g}")
    spectral = len(names) > 3 or not set(names) <= {"R", "G", "B", "A", "Y"}
    if bands is not None:
        require_choice(bands, ("spectral", "rgb"), "--bands")
    if bands == "spectral" and not spectral:
        image = RGB_to_spectra(image[..., :3], DEFAULT_GRID)
        names = spectral_channel_names(DEFAULT_GRID.wavelengths_nm)
    elif bands == "rgb" and spectral:
        require(
            image.shape[2] == DEFAULT_GRID.n_bands,
            f"{path}: --bands rgb needs a {DEFAULT_GRID.n_bands}-band map, got {image.shape[2]}",
        )
        image = image @ spectra_to_RGB_matrix(band_weights(DEFAULT_GRID, None))
        names = ["R", "G", "B"]
    return image, names


def project_file(
    path, order: int, out, window=None, bands=None, backend: str = "ducc0", progress=None
) -> dict:
    """Project a map file onto SH and save ``coeffs (C, (L+1)²)`` and metadata as ``.npz``.

    §5.3, Herbert et al.; Eq. (4), Ramamoorthi & Hanrahan 2001. ``progress``: a stream for a line
    per stage with its time (reading, projecting, writing), optional.

    Examples
    --------
    >>> project_file("/nonexistent.exr", 4, "/tmp/x.npz")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent.exr: file not found
    """
    import io

    from reference.files import write_bytes_atomic
    from reference.progress import ANNOUNCE_AFTER, StageTimer
    from shrm.transform import project_latlong

    timer = StageTimer(progress, f"sh project {Path(path).name}", ANNOUNCE_AFTER)
    if Path(path).suffix.lower() == ".zarr" and bands is None:
        # a chunked store is projected block by block, never read whole (shrm.streamed)
        from reference.images.zarr_store import open_zarr_image
        from shrm.streamed import project_zarr
        from shrm.windows import apply_window

        names = open_zarr_image(path).channels
        with timer.stage(f"projecting {len(names)} channels to order {order} ({backend})"):
            # a progress bar of rows on a terminal (none under CI or in a pipe)
            coeffs = project_zarr(path, order, backend, progress=None)
            if window is not None and window != "none":
                coeffs = apply_window(coeffs, window)
    else:
        with timer.stage("reading"):
            image, names = read_environment(path, bands)
        with timer.stage(f"projecting {len(names)} channels to order {order} ({backend})"):
            coeffs = project_latlong(image, order, window=window, backend=backend, where=str(path))
    with timer.stage("writing"):
        buffer = io.BytesIO()
        np.savez(
            buffer,
            coeffs=coeffs,
            order=order,
            channels=np.array(names),
            window=str(window or "none"),
            source=str(path),
            layout="real SH, Condon-Shortley phase, index l*l+l+m (docs/conventions.md)",
        )
        write_bytes_atomic(out, buffer.getvalue())
    return {"order": order, "channels": len(names), "out": str(out)}


def prefilter_file(
    path,
    kernel: str,
    out,
    tol: float = 1e-2,
    output: str = "cube",
    size: int = 64,
    bands=None,
    progress=None,
) -> dict:
    """Prefilter a map file and write the result as EXR (cube: faces stacked vertically).

    §5.4, Herbert et al. The cube layout is ``(6·S, S)``: faces +x, −x, +y, −y, +z, −z from top to
    bottom, each in the orientation of ``reference.geometry.cubemap``. ``progress``: a stream for
    a line per stage with its time (reading, prefiltering, writing), optional.

    Examples
    --------
    >>> prefilter_file("/nonexistent.hdr", "lambert", "/tmp/x.exr")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent.hdr: file not found
    """
    from reference.progress import ANNOUNCE_AFTER, StageTimer
    from shrm.prefilter import prefilter_environment

    require(
        Path(out).suffix.lower() == ".exr",
        f"--out: the prefiltered map is linear HDR, written as OpenEXR: the name must end in "
        f".exr, got {str(out)!r}",
    )
    timer = StageTimer(progress, f"sh prefilter {Path(path).name}", ANNOUNCE_AFTER)
    with timer.stage("reading"):
        image, names = read_environment(path, bands)
    shape = f"6 faces of {size}²" if output == "cube" else "a lat-long map"
    with timer.stage(f"prefiltering {len(names)} channels with {kernel} to {shape}"):
        result = prefilter_environment(
            image, kernel, tol=tol, output=output, size=size, where=str(path)
        )
    values = result.values
    if output == "cube":
        values = values.reshape(6 * size, size, -1)
    with timer.stage("writing"):
        write_exr(out, values, channels=names if len(names) != 3 else None)
    return {"order": result.order, "tail": result.tail, "kernel": result.kernel, "out": str(out)}

"""Painting files: a user's painting for ImpastoR (Ferwerda §3), and the demo painting as one.

Ferwerda's system renders a real painting: its colour (per-pixel spectral reflectance, rendered in
six channels, §3.2), its relief (a height map, §3.3) and its gloss (Ward–Dür ρ_s and α, §3.4).
A painting is a folder holding ``painting.toml`` and the images it names (``docs/impastor.md``,
"Painting files")::

    # specref painting 1
    name = "demo"
    width_m = 0.3                       # the canvas's width (square: its height too)
    [colour]
    file = "reflectance.tif"            # a spectral cube (specref's spectral TIFF or EXR), or an
                                        # RGB image: 8-bit sRGB .png/.jpg or linear .exr/.tif
    [height]
    file = "height.tif"                 # one channel; metres = value × scale_m
    scale_m = 1.0                       # (a 16-bit PNG is read as value / 65535)
    [gloss]
    rho_s = 0.04                        # a number, or { file = "rho_s.tif" }
    alpha = { file = "alpha.tif" }

An RGB photograph is turned into reflectance spectra by Mallett & Yuksel 2019's primaries (the
RGB taken as the linear sRGB albedo; erratum E111); a cube's bands are interpolated linearly onto
ImpastoR's 5 nm grid, its ends held. :func:`read_painting` returns the dictionary
:func:`impastor.painting.render_painting` takes (``reflectance`` per texel instead of the demo's
paint indices); :func:`write_painting` writes any such dictionary, the demo painting included.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from impastor.multispectral import MS_GRID
from reference.errors import SpecrefError, require

__all__ = [
    "MAX_PAINTING_SIDE",
    "PAINTING_FILE",
    "painting_file_paths",
    "painting_reflectance",
    "read_painting",
    "write_painting",
]

#: The file a painting folder holds.
PAINTING_FILE = "painting.toml"
_MAGIC = "# specref painting 1"
_KEYS = {"name", "width_m", "colour", "height", "gloss"}


def painting_reflectance(painting: dict, spectra: dict | None = None) -> np.ndarray:
    """Per-texel reflectance on ImpastoR's 5 nm grid, shape ``(H, W, 81)``.

    A painting read from files has it; the demo painting's paint indices are looked up in the
    measured paint spectra (the primed canvas is office paper).

    Examples
    --------
    >>> from impastor.painting import impasto_painting
    >>> painting_reflectance(impasto_painting(8)).shape
    (8, 8, 81)
    """
    if "reflectance" in painting:
        return np.asarray(painting["reflectance"])
    from impastor.painting import PAINT_SPECTRA, load_paint_spectra

    spectra = spectra or load_paint_spectra()
    table = np.stack([spectra[n] for n in (*PAINT_SPECTRA, "office-paper")])
    material = painting["material"]
    return table[np.where(material < 0, len(PAINT_SPECTRA), material)]


#: The largest painting side, pixels: its 81-band reflectance is then 10 GiB in float64, what the
#: renderer holds at once; a larger image is refused before it is converted.
MAX_PAINTING_SIDE = 4096


def _check_side(shape, path: Path, where: str) -> None:
    require(
        len(shape) >= 2 and max(shape[:2]) <= MAX_PAINTING_SIDE,
        f"{where}: {path}: {' × '.join(str(n) for n in shape[:2])} pixels; a painting is at most "
        f"{MAX_PAINTING_SIDE} pixels a side (scale the image down)",
    )


def _image(path: Path, where: str) -> np.ndarray:
    """An image file as float ``(H, W, C)``: 8/16-bit PNG and JPEG normalised, floats as stored."""
    from reference.images.formats import read_image

    require(path.is_file(), f"{where}: {path}: file not found")
    suffix = path.suffix.lower()
    try:
        if suffix in (".png", ".jpg", ".jpeg", ".tif", ".tiff"):
            if suffix in (".tif", ".tiff"):
                import tifffile

                raw = np.asarray(tifffile.imread(path))
            else:
                import imageio.v3 as iio

                raw = np.asarray(iio.imread(path))
            _check_side(raw.shape, path, where)
            scale = np.iinfo(raw.dtype).max if raw.dtype.kind in "ui" else 1.0
            image = raw.astype(np.float64) / scale
        else:
            image = read_image(path)
            _check_side(image.shape, path, where)
    except SpecrefError as error:
        raise SpecrefError(f"{where}: {error}") from None
    except (OSError, ValueError) as error:
        raise SpecrefError(f"{where}: {path}: cannot read ({type(error).__name__})") from None
    image = image[..., None] if image.ndim == 2 else image
    require(np.isfinite(image).all(), f"{where}: {path}: NaN or infinite values")
    return image


def _colour(doc: dict, folder: Path, where: str) -> np.ndarray:
    """The ``[colour]`` table: reflectance spectra on the 5 nm grid, ``(H, W, 81)``."""
    from reference.images.formats import channel_wavelengths_nm

    require(isinstance(doc, dict) and "file" in doc, f'{where}: needs file = "..."')
    path = folder / str(doc["file"])
    if path.suffix.lower() in (".png", ".jpg", ".jpeg"):
        from reference.display.encodings import display_to_linear

        rgb = display_to_linear(_image(path, where)[..., :3], "srgb")
        return _rgb_to_reflectance(rgb)
    image = _image(path, where)
    if image.shape[-1] == 3 or image.shape[-1] == 4:  # linear RGB(A)
        return _rgb_to_reflectance(image[..., :3])
    from reference.images.spectral import read_environment_file

    names = read_environment_file(path)[1]
    wavelengths = channel_wavelengths_nm(names)
    require(wavelengths is not None, f"{where}: {path}: neither RGB nor spectral channels")
    grid = MS_GRID.wavelengths_nm
    index = np.clip(np.searchsorted(wavelengths, grid) - 1, 0, len(wavelengths) - 2)
    t = np.clip((grid - wavelengths[index]) / np.diff(wavelengths)[index], 0.0, 1.0)
    # linear in λ between the cube's bands, its ends held beyond them
    return image[..., index] * (1 - t) + image[..., index + 1] * t


def _rgb_to_reflectance(rgb: np.ndarray) -> np.ndarray:
    from reference.colour.upsampling import RGB_to_spectra_Mallett2019

    # Eq. (4), Mallett & Yuksel 2019: the albedo as a mix of three basis spectra (erratum E111)
    return RGB_to_spectra_Mallett2019(np.clip(rgb, 0.0, 1.0), MS_GRID)


def _map(value, folder: Path, shape: tuple, where: str) -> np.ndarray:
    """A gloss or height entry: a number, or ``{ file = ... }`` of the painting's size."""
    if isinstance(value, int | float) and not isinstance(value, bool):
        return np.full(shape, float(value))
    require(isinstance(value, dict) and "file" in value, f"{where}: a number or {{ file = ... }}")
    image = _image(folder / str(value["file"]), where)[..., 0]
    require(
        image.shape == shape,
        f"{where}: {value['file']}: {image.shape[1]}×{image.shape[0]} pixels, the colour is "
        f"{shape[1]}×{shape[0]}",
    )
    return image


#: The keys of each table of ``painting.toml``.
_TABLE_KEYS = {"colour": {"file"}, "height": {"file", "scale_m"}, "gloss": {"rho_s", "alpha"}}


def _check_keys(doc: dict, where: str) -> None:
    """Unknown keys, at the top and in each table, are refused naming the table."""
    unknown = sorted(set(doc) - _KEYS)
    shown = unknown[0] if unknown else ""
    require(not unknown, f"{where}: unknown key {shown!r}; allowed: {', '.join(sorted(_KEYS))}")
    for table, allowed in _TABLE_KEYS.items():
        if isinstance(doc.get(table), dict):
            extra = sorted(set(doc[table]) - allowed)
            shown = extra[0] if extra else ""
            require(
                not extra,
                f"{where}: {table}: unknown key {shown!r}; allowed: {', '.join(sorted(allowed))}",
            )


def _read_doc(path) -> tuple[dict, Path, str]:
    path = Path(path)
    path = path if path.suffix.lower() == ".toml" else path / PAINTING_FILE
    require(path.is_file(), f"{path}: painting file not found")
    from reference.scene.loader import read_toml_file

    doc = read_toml_file(path)  # one line for unreadable text, bad TOML and deep nesting
    _check_keys(doc, str(path))
    return doc, path.parent, str(path)


def painting_file_paths(path) -> list[Path]:
    """The files a painting folder's ``painting.toml`` names, and the toml itself.

    What a command reads from the folder, for the write policy (``reference.files.
    check_outputs``): other files there may be replaced (a render written into the painting's own
    folder, again). A folder that cannot be read gives what could be found; the command that
    reads it says what is wrong.

    Examples
    --------
    >>> [p.name for p in painting_file_paths("/nonexistent")]
    ['painting.toml']
    """
    path = Path(path)
    toml = path if path.suffix.lower() == ".toml" else path / PAINTING_FILE
    found = [toml]
    try:
        doc, folder, _ = _read_doc(toml)
    except SpecrefError:
        return found
    tables = [doc.get("colour"), doc.get("height")]
    if isinstance(doc.get("gloss"), dict):
        tables += [doc["gloss"].get("rho_s"), doc["gloss"].get("alpha")]
    return found + [folder / str(t["file"]) for t in tables if isinstance(t, dict) and "file" in t]


def read_painting(path) -> dict:
    """Read a painting folder (or its ``painting.toml``): the dictionary the renderer takes.

    Returns
    -------
    dict
        ``name``, ``width_m``, ``pixel_size`` (m), ``reflectance`` (H, W, 81) on the 5 nm grid,
        ``height`` (m), ``rho_s`` and ``alpha`` maps (H, W).

    Raises
    ------
    SpecrefError
        One line naming the file and the key: a missing or unreadable file, an unknown key, a
        colour that is not square or more than :data:`MAX_PAINTING_SIDE` pixels a side, maps of
        another size, NaN, negative reflectance, a relief ``scale_m`` outside (0, 1] m, a gloss
        outside Ward–Dür's range (ρ_s in [0, 1], α in (0, 1]).

    Examples
    --------
    >>> read_painting("/nonexistent")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent/painting.toml: painting file not found
    """
    doc, folder, where = _read_doc(path)
    for key in ("width_m", "colour", "height"):
        require(key in doc, f"{where}: missing key {key!r}")
    width = doc["width_m"]
    require(
        isinstance(width, int | float) and not isinstance(width, bool) and 0 < width <= 10,
        f"{where}: width_m: must be a width in metres in (0, 10], got {width!r}",
    )
    reflectance = _colour(doc["colour"], folder, f"{where}: colour")
    shape = reflectance.shape[:2]
    require(shape[0] == shape[1], f"{where}: colour: {shape[1]}×{shape[0]} pixels; the canvas is "
            "square (crop or pad the image)")  # fmt: skip
    require(bool((reflectance >= 0).all()), f"{where}: colour: negative reflectance")
    height_doc = doc["height"]
    require(isinstance(height_doc, dict), f'{where}: height: needs file = "..." and scale_m')
    scale = height_doc.get("scale_m", 1.0)
    require(
        isinstance(scale, int | float) and not isinstance(scale, bool) and 0 < scale <= 1,
        f"{where}: height.scale_m: the relief of a height of 1, in metres, in (0, 1]; "
        f"got {scale!r}",
    )
    height = _map({"file": height_doc.get("file")}, folder, shape, f"{where}: height") * scale
    relief = float(height.max() - height.min())
    require(
        relief <= width,
        f"{where}: height: a relief of {relief:.3g} m on a canvas {width:g} m wide; heights are "
        "in metres (scale_m scales the file's values)",
    )
    gloss = doc.get("gloss", {})
    require(isinstance(gloss, dict), f"{where}: gloss: must be a table with rho_s and alpha")
    rho_s = _map(gloss.get("rho_s", 0.04), folder, shape, f"{where}: gloss.rho_s")
    alpha = _map(gloss.get("alpha", 0.2), folder, shape, f"{where}: gloss.alpha")
    require(bool(((rho_s >= 0) & (rho_s <= 1)).all()), f"{where}: gloss.rho_s: must be in [0, 1]")
    require(
        bool(((alpha > 0) & (alpha <= 1)).all()),
        f"{where}: gloss.alpha: Ward–Dür's roughness must be in (0, 1]",
    )
    return {
        "name": str(doc.get("name", folder.name)),
        "width_m": float(width),
        "pixel_size": float(width) / shape[1],
        "reflectance": reflectance,
        "height": height,
        "rho_s": rho_s,
        "alpha": alpha,
    }


def write_painting(folder, painting: dict, name: str = "painting", spectra=None) -> Path:
    """Write a painting (the demo one, or one read) as a painting folder; return its toml.

    The reflectance goes to a spectral TIFF on the 5 nm grid, the height (m) and the gloss maps to
    float TIFFs; every file is written atomically.

    Examples
    --------
    >>> import tempfile
    >>> from impastor.painting import impasto_painting
    >>> demo = impasto_painting(16, seed=3)
    >>> with tempfile.TemporaryDirectory() as d:
    ...     back = read_painting(write_painting(d, demo, "demo"))
    >>> bool(np.array_equal(back["height"], demo["height"])), back["reflectance"].shape
    (True, (16, 16, 81))
    """
    import tifffile

    from reference.files import atomic_path, check_output_folder, write_text_atomic
    from reference.images.spectral import write_spectral_blocks

    folder = check_output_folder(folder, marker="painting.toml")
    reflectance = painting_reflectance(painting, spectra).astype(np.float32)
    size = reflectance.shape[0]
    write_spectral_blocks(folder / "reflectance.tif", size, size, MS_GRID.wavelengths_nm,
                          [(0, reflectance)])  # fmt: skip
    for key in ("height", "rho_s", "alpha"):
        with atomic_path(folder / f"{key}.tif", suffix=".tif") as tmp:
            # float64: the maps read back bit for bit
            tifffile.imwrite(tmp, np.asarray(painting[key], dtype=np.float64))
    text = "\n".join([
        _MAGIC,
        f"name = {name!r}".replace("'", '"'),
        f"width_m = {float(painting['width_m'])!r}",
        "[colour]",
        'file = "reflectance.tif"',
        "[height]",
        'file = "height.tif"',
        "scale_m = 1.0",
        "[gloss]",
        'rho_s = { file = "rho_s.tif" }',
        'alpha = { file = "alpha.tif" }',
        "",
    ])  # fmt: skip
    return write_text_atomic(folder / PAINTING_FILE, text)

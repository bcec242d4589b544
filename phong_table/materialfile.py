"""Material files for ``specref phong --material FILE.toml``: a spectral Phong material, its light.

The format is documented in ``docs/phong-tables.md`` ("Material files"). A file holds a
``[material]`` table (``k_d``, ``k_s``, ``n`` and optionally ``k_a``, each a spectrum) and an
optional ``[light]`` table (``spectrum``, ``position``, ``intensity``, ``attenuation``); the
sphere, the camera and the views are those of the scenes (``phong_table.scenes``). A spectrum is:

- a number: constant over the grid (``n = 50``);
- a list of ``n_bands`` numbers on the grid (380-780 nm in 10 nm steps by default);
- ``{ wavelengths = [...], values = [...] }``: samples, interpolated linearly onto the grid;
- ``{ dataset = "illuminant", key = "D65" }``: a colour-science dataset (``illuminant``,
  ``light_source``, ``colorchecker``);
- ``{ csv = "file.csv", column = 1, row = 0, scale = 1.0 }``: a CSV file relative to the TOML file
  (long or wide layout, ``reference.spectra.spectrum_from_csv``);

and each table form takes ``extrapolation`` (``error`` by default, ``constant``, ``zero``,
``linear``) and ``scale``. Every error names the file and the key.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np

from phong_table.model import SpectralPhong
from phong_table.scenes import LIGHT_ATTENUATION, LIGHT_POSITION
from reference.errors import SpecrefError, require, require_finite
from reference.lights import PointLight
from reference.materials import PhongMaterial
from reference.spectra import (
    DEFAULT_GRID,
    GRIDS,
    SpectralGrid,
    Spectrum,
    make_spectrum,
    resample_spectrum,
    spectrum_from_csv,
    spectrum_from_dataset,
)

__all__ = ["load_material_file", "spectrum_from_value"]

_MATERIAL_KEYS = ("name", "k_d", "k_s", "n", "k_a")
_LIGHT_KEYS = ("spectrum", "position", "intensity", "attenuation")
_TABLE_KEYS = ("wavelengths", "values", "dataset", "key", "csv", "column", "row")
_TABLE_KEYS_ALL = (*_TABLE_KEYS, "extrapolation", "scale", "set")


def _check_keys(table: dict, allowed, where: str) -> None:
    for key in table:
        require(
            key in allowed,
            f"{where}: unknown key {key!r}; allowed: {', '.join(sorted(allowed))}",
        )


def spectrum_from_value(value, grid: SpectralGrid, where: str, base: Path) -> np.ndarray:
    """A spectrum given in a material file, on ``grid``.

    Parameters
    ----------
    value : number, list or dict
        One of the forms of the module docstring.
    grid : SpectralGrid
        Target grid.
    where : str
        ``"file.toml: material.k_d"``, for messages.
    base : Path
        Folder that CSV paths are relative to.

    Returns
    -------
    ndarray, shape (n_bands,)

    Examples
    --------
    >>> from pathlib import Path
    >>> from reference.spectra import GRID_31
    >>> spectrum_from_value(0.5, GRID_31, "m.toml: material.k_s", Path("."))[:2]
    array([0.5, 0.5])
    >>> ramp = {"wavelengths": [400, 700], "values": [0.0, 0.3]}
    >>> spectrum_from_value(ramp, GRID_31, "m.toml: material.k_s", Path("."))[:2]
    array([0.  , 0.01])
    """
    if isinstance(value, bool):
        raise SpecrefError(f"{where}: must be a number, a list or a table, got {value!r}")
    if isinstance(value, int | float):
        array = require_finite(value, where)
        return np.full(grid.n_bands, float(array))
    if isinstance(value, list):
        array = require_finite(value, where)
        require(
            array.ndim == 1 and array.size == grid.n_bands,
            f"{where}: a list must have {grid.n_bands} values (grid {grid.label}), got "
            f"{array.size}",
        )
        return array
    require(
        isinstance(value, dict),
        f"{where}: must be a number, a list or a table, got {type(value).__name__}",
    )
    _check_keys(value, _TABLE_KEYS_ALL, where)
    scale = value.get("scale", 1.0)
    require(
        isinstance(scale, int | float) and not isinstance(scale, bool) and np.isfinite(scale),
        f"{where}.scale: must be a number, got {scale!r}",
    )
    spectrum: Spectrum
    if "wavelengths" in value or "values" in value:
        require(
            "wavelengths" in value and "values" in value,
            f"{where}: give both wavelengths and values",
        )
        spectrum = make_spectrum(value["wavelengths"], value["values"], where, allow_negative=True)
    elif "dataset" in value:
        require("key" in value, f'{where}: a dataset needs a key, e.g. key = "D65"')
        spectrum = spectrum_from_dataset(value["dataset"], value["key"], value.get("set"))
    elif "csv" in value:
        path = base / str(value["csv"])
        spectrum = spectrum_from_csv(
            path, value.get("column"), value.get("row", 0), name=f"{where} ({path})"
        )
    else:
        raise SpecrefError(f"{where}: a table needs wavelengths/values, dataset/key or csv")
    extrapolation = value.get("extrapolation", "error")
    return scale * resample_spectrum(spectrum, grid, extrapolation)


def _vector3(value, where: str) -> tuple:
    array = require_finite(value, where)
    require(array.shape == (3,), f"{where}: must be 3 numbers, got {value!r}")
    return tuple(float(x) for x in array)


def load_material_file(path) -> SpectralPhong:
    """Read a material file: a spectral Phong material and its point light.

    Parameters
    ----------
    path : str or Path
        The TOML file.

    Returns
    -------
    SpectralPhong
        With the light of the file; when ``light.intensity`` is absent the intensity makes the
        brightest value, ``max_c (D_c + f_sp,c(1))``, display white (as in the scenes).

    Raises
    ------
    SpecrefError
        Unreadable file, bad TOML, unknown or missing keys, negative or NaN values, mismatched
        spectral lengths; the message names the file and the key.

    Examples
    --------
    >>> import tempfile, os
    >>> text = 'name = "gold"' + chr(10) + '[material]' + chr(10) + 'k_d = 0.2' + chr(10)
    >>> text += 'k_s = 0.5' + chr(10) + 'n = 40' + chr(10)
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = os.path.join(d, "m.toml")
    ...     _ = open(p, "w").write(text)
    ...     load_material_file(p).material.n[:2]
    array([40., 40.])
    """
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise SpecrefError(f"{path}: file not found") from None
    except (OSError, UnicodeDecodeError) as error:
        raise SpecrefError(f"{path}: cannot read ({error.__class__.__name__})") from None
    except tomllib.TOMLDecodeError as error:
        raise SpecrefError(f"{path}: not valid TOML ({error})") from None
    _check_keys(data, ("name", "grid", "material", "light"), str(path))
    grid_key = str(data.get("grid", "41"))
    require(
        grid_key in GRIDS,
        f"{path}: grid: must be one of {', '.join(sorted(GRIDS))}, got {grid_key!r}",
    )
    grid = GRIDS[grid_key] if "grid" in data else DEFAULT_GRID
    material = data.get("material")
    require(isinstance(material, dict), f"{path}: needs a [material] table")
    _check_keys(material, _MATERIAL_KEYS, f"{path}: material")
    name = str(material.get("name", data.get("name", path.stem)))
    params = {}
    for key in ("k_d", "k_s", "n", "k_a"):
        if key not in material:
            require(key == "k_a", f"{path}: material.{key}: missing (k_d, k_s and n are needed)")
            continue
        values = spectrum_from_value(material[key], grid, f"{path}: material.{key}", path.parent)
        bad = ~(values >= 0)
        require(
            not bad.any(),
            f"{path}: material.{key}: must be >= 0, got {values[bad][:1]} on the grid",
        )
        params[key] = values
    light = data.get("light", {})
    require(isinstance(light, dict), f"{path}: light: must be a table")
    _check_keys(light, _LIGHT_KEYS, f"{path}: light")
    spectrum_value = light.get("spectrum", {"dataset": "illuminant", "key": "D65"})
    position = _vector3(light.get("position", LIGHT_POSITION), f"{path}: light.position")
    attenuation = _vector3(
        light.get("attenuation", LIGHT_ATTENUATION), f"{path}: light.attenuation"
    )
    spectrum = _light_spectrum(spectrum_value, grid, f"{path}: light.spectrum", path.parent)
    intensity = light.get("intensity", 1.0)
    require(
        isinstance(intensity, int | float) and not isinstance(intensity, bool),
        f"{path}: light.intensity: must be a number, got {intensity!r}",
    )
    try:
        phong = PhongMaterial(name=name, **params)
        point = PointLight(position, spectrum, float(intensity), attenuation)
        model = SpectralPhong(phong, point, grid=grid)
    except SpecrefError as error:
        raise SpecrefError(f"{path}: {error}") from None
    if "intensity" not in light:
        peak = float((model.diffuse_RGB + model.specular(1.0)).max())
        point = PointLight(position, spectrum, 1.0 / peak if peak > 0 else 1.0, attenuation)
        model = SpectralPhong(phong, point, grid=grid)
    return model


def _light_spectrum(value, grid: SpectralGrid, where: str, base: Path) -> Spectrum:
    if isinstance(value, dict) and "dataset" in value and set(value) <= {"dataset", "key", "set"}:
        require("key" in value, f'{where}: a dataset needs a key, e.g. key = "D65"')
        return spectrum_from_dataset(value["dataset"], value["key"], value.get("set"))
    values = spectrum_from_value(value, grid, where, base)
    require((values >= 0).all(), f"{where}: must be >= 0")
    return make_spectrum(grid.wavelengths_nm, values, where)

"""Data shipped inside the package: real environment maps, measured spectra and fitted models.

The files below this folder are package data, found through :mod:`importlib.resources`, so an
installed wheel renders the documentation's scenes from any folder. ``PROVENANCE.md`` beside this
module gives each file's source and licence.

Scene files name a shipped file as ``data:<path>`` (``data:environments/venice_sunset_1k.hdr``,
``data:spectra/physicallybased/brick__nix_export.csv``); every other path in a scene file is
relative to the scene file's folder (``docs/scene-format.md``, "Files"). The environment variable
``SPECREF_SHARED_DATA`` may name a folder of the same layout that is searched first (an override,
for example a newer copy of the maps); nothing requires it.
"""

from __future__ import annotations

import importlib.resources
import os
from pathlib import Path, PurePosixPath

from reference.errors import SpecrefError, format_allowed

__all__ = [
    "DATA_SCHEME",
    "OVERRIDE_VARIABLE",
    "data_path",
    "data_root",
    "environment_maps",
    "measured_spectra_folder",
    "resolve_path",
]

#: The prefix that names a shipped file in scene files and command-line arguments.
DATA_SCHEME = "data:"
#: A folder of the same layout searched before the package data (optional).
OVERRIDE_VARIABLE = "SPECREF_SHARED_DATA"
#: Suffixes of the shipped environment maps.
_MAP_SUFFIXES = (".hdr", ".exr")


def data_root() -> Path:
    """The folder of the package data (``reference/data`` of the installed package).

    Examples
    --------
    >>> (data_root() / "PROVENANCE.md").is_file()
    True
    """
    return Path(str(importlib.resources.files(__name__)))


def _checked_name(name: str) -> PurePosixPath:
    relative = PurePosixPath(name)
    if not name or relative.is_absolute() or ".." in relative.parts or "\x00" in name:
        raise SpecrefError(
            f"{DATA_SCHEME}{name}: not a shipped file name (a path below the data folder, "
            "such as environments/venice_sunset_1k.hdr)"
        )
    return relative


def data_path(name: str) -> Path:
    """The shipped file or folder ``name`` (a path below the data folder, ``/``-separated).

    Parameters
    ----------
    name : str
        For example ``"environments/venice_sunset_1k.hdr"``; a leading ``data:`` is allowed.

    Returns
    -------
    Path
        The file in ``$SPECREF_SHARED_DATA`` if that variable is set and the file exists there,
        else the package's own copy.

    Raises
    ------
    SpecrefError
        One line naming the file and the shipped files of its folder, when it is not shipped.

    Examples
    --------
    >>> data_path("environments/venice_sunset_1k.hdr").name
    'venice_sunset_1k.hdr'
    >>> data_path("environments/venice.hdr")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: data:environments/venice.hdr: not shipped; allowed: ...
    """
    name = name.removeprefix(DATA_SCHEME)
    relative = _checked_name(name)
    override = os.environ.get(OVERRIDE_VARIABLE)
    if override and (Path(override) / relative).exists():
        return Path(override) / relative
    path = data_root() / relative
    if not path.exists():
        folder = path.parent
        shipped = sorted(p.name for p in folder.iterdir()) if folder.is_dir() else []
        shipped = [str(PurePosixPath(relative.parent) / s) for s in shipped if s != "__init__.py"]
        allowed = format_allowed(shipped) if shipped else "(no such folder)"
        raise SpecrefError(f"{DATA_SCHEME}{name}: not shipped; allowed: {allowed}")
    return path


def resolve_path(value, base_dir) -> Path:
    """A path as scene files and commands take it: ``data:<name>`` or relative to ``base_dir``.

    Examples
    --------
    >>> resolve_path("data:environments/studio_small_03_1k.hdr", "/tmp").name
    'studio_small_03_1k.hdr'
    >>> str(resolve_path("maps/a.hdr", "/scenes"))
    '/scenes/maps/a.hdr'
    """
    text = str(value)
    if text.startswith(DATA_SCHEME):
        return data_path(text)
    path = Path(text)
    return path if path.is_absolute() else Path(base_dir) / path


def environment_maps() -> list[Path]:
    """The shipped environment maps (lat-long, real captures), sorted by name.

    Examples
    --------
    >>> [p.name for p in environment_maps()]  # doctest: +NORMALIZE_WHITESPACE
    ['StageEnvLatLong.exr', 'st_fagans_interior_1k.hdr', 'studio_small_03_1k.hdr',
     'venice_sunset_1k.hdr']
    """
    folder = data_path("environments")
    return sorted(p for p in folder.iterdir() if p.suffix in _MAP_SUFFIXES)


def measured_spectra_folder() -> Path:
    """The folder of the 18 measured reflectances (Nix Spectro 2 exports, CC0).

    Examples
    --------
    >>> len(sorted(measured_spectra_folder().glob("*__nix_export.csv")))
    18
    """
    return data_path("spectra/physicallybased")

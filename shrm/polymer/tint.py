"""Spot-colour library for ``Tint_polymer``, Eq. (2), Herbert et al.: named spectra, ΔE00 search.

§5.1, Herbert et al.: ``Tint_polymer`` is "a tint color from a spot color database". specref's
library is a CSV of named reflectance spectra (``name,source,<wavelengths nm>`` after ``#`` comment
lines). The shipped one, ``shrm/polymer/data/spot_colours.csv``, holds 18 measured materials of
``data:spectra/physicallybased`` (``pb-*``) and the 24 ColorChecker N Ohta patches of
colour-science (``cc-*``); ``validation/precompute/spot_colours.py`` makes it. A user library has
the same layout.

References
----------
Herbert, M., et al. (2004). Multispectral Virtual Reality: Spectral Shading with Spherical
    Harmonics. (specref's Herbert et al.)
"""

from __future__ import annotations

import csv
import difflib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from reference.errors import SpecrefError, require

__all__ = ["DEFAULT_TINT_LIBRARY", "TintLibrary", "read_tint_library", "tint_search"]

#: The shipped library (sources in its header and in ``validation/precompute/spot_colours.py``).
DEFAULT_TINT_LIBRARY = Path(__file__).with_name("data") / "spot_colours.csv"


@dataclass(frozen=True)
class TintLibrary:
    """Named reflectance spectra on one wavelength grid.

    Parameters
    ----------
    wavelengths_nm : ndarray, shape (n_bands,)
    names : tuple of str
    spectra : ndarray, shape (n_names, n_bands)
        Reflectance factors in [0, 1].
    sources : tuple of str
    path : str
    """

    wavelengths_nm: np.ndarray
    names: tuple
    spectra: np.ndarray
    sources: tuple
    path: str = ""

    def tint(self, name: str) -> np.ndarray:
        """The spectrum of ``name``; an unknown name lists the closest names.

        Examples
        --------
        >>> library = read_tint_library()
        >>> library.tint("cc-dark-skin").shape
        (41,)
        >>> library.tint("cc-dark-skn")
        Traceback (most recent call last):
        ...
        reference.errors.SpecrefError: ...: unknown tint 'cc-dark-skn'; closest: cc-dark-skin, ...
        """
        if name not in self.names:
            close = difflib.get_close_matches(name, self.names, n=4, cutoff=0.0)
            raise SpecrefError(f"{self.path}: unknown tint {name!r}; closest: {', '.join(close)}")
        return self.spectra[self.names.index(name)]


def read_tint_library(path=None) -> TintLibrary:
    r"""Read a spot-colour library CSV (``name,source,<wavelengths>``).

    Parameters
    ----------
    path : str or Path, optional
        Default :data:`DEFAULT_TINT_LIBRARY`.

    Returns
    -------
    TintLibrary

    Raises
    ------
    SpecrefError
        Missing file or header, wavelengths not increasing, a row with the wrong number of values,
        a value outside [0, 1], a duplicate name.

    Examples
    --------
    >>> library = read_tint_library()
    >>> len(library.names), library.spectra.shape[1]
    (42, 41)
    """
    path = Path(DEFAULT_TINT_LIBRARY if path is None else path)
    require(path.is_file(), f"{path}: no such tint library")
    lines = [line for line in path.read_text().splitlines() if line.strip() and line[0] != "#"]
    require(lines, f"{path}: no header line (name,source,<wavelengths nm>)")
    rows = list(csv.reader(lines))
    header = rows[0]
    require(
        header[:2] == ["name", "source"] and len(header) > 2,
        f"{path}: header must be name,source,<wavelengths nm>, got {','.join(header[:3])}...",
    )
    try:
        wl = np.array([float(h) for h in header[2:]])
    except ValueError as error:
        raise SpecrefError(f"{path}: header: wavelengths must be numbers") from error
    require(bool(np.all(np.diff(wl) > 0)), f"{path}: header: wavelengths must increase")
    names, sources, spectra = [], [], []
    for number, row in enumerate(rows[1:], 2):
        require(
            len(row) == len(header),
            f"{path}: row {number}: {len(row) - 2} values for {len(header) - 2} wavelengths",
        )
        try:
            values = np.array([float(v) for v in row[2:]])
        except ValueError as error:
            raise SpecrefError(f"{path}: row {number}: values must be numbers") from error
        require(
            bool(np.all((values >= 0) & (values <= 1))),
            f"{path}: row {number} ({row[0]}): values must be in [0, 1]",
        )
        require(row[0] not in names, f"{path}: row {number}: duplicate name {row[0]!r}")
        names.append(row[0])
        sources.append(row[1])
        spectra.append(values)
    require(names, f"{path}: no spectra after the header")
    return TintLibrary(wl, tuple(names), np.array(spectra), tuple(sources), str(path))


def tint_search(Lab, library: TintLibrary | None = None, illuminant: str = "D65", count: int = 3):
    """The library's tints closest to a target CIELAB colour under an illuminant, by ΔE00.

    Parameters
    ----------
    Lab : array_like, shape (3,)
        Target L*, a*, b* (relative to the illuminant's white).
    library : TintLibrary, optional
        Default: the shipped one.
    illuminant : str
        A colour-science illuminant name (``D65``, ``A``, ``D50``, ``FL2`` ...).
    count : int
        How many to return.

    Returns
    -------
    list of (str, float)
        Names and ΔE00, closest first.

    Examples
    --------
    >>> [(name, round(dE, 2)) for name, dE in tint_search([40.0, 55.0, 30.0], count=2)]
    [('cc-red', ...), (...)]
    """
    from reference.colour.colorimetry import (
        XYZ_to_Lab,
        band_weights,
        delta_E_00,
        spectra_to_XYZ,
        white_XYZ,
    )
    from reference.colour.spectra import SpectralGrid, spectrum_from_dataset

    library = read_tint_library() if library is None else library
    wl = library.wavelengths_nm
    grid = SpectralGrid(float(wl[0]), float(wl[-1]), float(wl[1] - wl[0]))
    require(
        np.allclose(grid.wavelengths_nm, wl), f"{library.path}: tint search needs a uniform grid"
    )
    W = band_weights(grid, spectrum_from_dataset("illuminant", illuminant))
    Lab_library = XYZ_to_Lab(spectra_to_XYZ(library.spectra, W), white_XYZ(W))
    dE = delta_E_00(Lab_library, np.asarray(Lab, dtype=np.float64)[None, :])
    order = np.argsort(dE)[: int(count)]
    return [(library.names[i], float(dE[i])) for i in order]

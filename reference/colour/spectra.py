"""Wavelength grids, spectrum sources, and resampling onto a grid.

specref keeps every spectral quantity on a uniform wavelength grid, with the spectral axis last,
``(..., n_bands)``. The default grid is 380-780 nm in 10 nm steps (41 bands), as in Herbert et al.
§4; the 400-700 nm grid in 31 bands is also built in.

Spectra come from colour-science datasets (illuminants, light sources, ColorChecker patches),
constants, CSV files (two-column or one-row-per-sample "wide" exports such as the Nix files in
``data:spectra``, shipped with specref) and explicit ``(wavelengths, values)`` arrays.
:func:`resample_spectrum` puts any of them on a grid and is explicit about extrapolation: a spectrum
that does not cover the grid is refused unless the caller names how to extend it.

References
----------
- F. Herbert, J. Kirkenaer, O. Unter Ecker, "Achieving a Multi-spectral Virtual Reality", 2004.
- CIE 015:2018, Colorimetry, 4th ed., §7.2 (interpolation and extrapolation of spectral data).
- ASTM E308-15, Standard Practice for Computing the Colors of Objects by Using the CIE System.
"""

from __future__ import annotations

import csv
import itertools
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reference.errors import SpecrefError, format_allowed, require, require_choice

__all__ = [
    "DATASETS",
    "DEFAULT_GRID",
    "EXTRAPOLATIONS",
    "GRIDS",
    "GRID_31",
    "GRID_41",
    "INTERPOLATIONS",
    "SpectralGrid",
    "Spectrum",
    "make_spectrum",
    "resample_spectrum",
    "spectrum_constant",
    "spectrum_from_csv",
    "spectrum_from_dataset",
    "spectrum_to_colour_sd",
]

#: The ways :func:`resample_spectrum` may extend a spectrum beyond its measured range.
EXTRAPOLATIONS = ("error", "constant", "zero", "linear")
#: The ways :func:`resample_spectrum` may interpolate between measured samples.
INTERPOLATIONS = ("linear", "sprague")


@dataclass(frozen=True)
class SpectralGrid:
    """A uniform wavelength grid: ``start_nm, start_nm + step_nm, ..., end_nm``.

    Parameters
    ----------
    start_nm, end_nm : float
        First and last wavelength, nm; ``end_nm > start_nm``.
    step_nm : float
        Spacing, nm; must divide ``end_nm - start_nm``.

    Examples
    --------
    >>> GRID_41.n_bands, GRID_41.wavelengths_nm[:3]
    (41, array([380., 390., 400.]))
    >>> SpectralGrid(400, 700, 10).n_bands
    31
    """

    start_nm: float
    end_nm: float
    step_nm: float

    def __post_init__(self):
        for key in ("start_nm", "end_nm", "step_nm"):
            value = getattr(self, key)
            require(
                isinstance(value, int | float) and np.isfinite(value),
                f"grid: {key}: must be a finite number, got {value!r}",
            )
        require(self.step_nm > 0, f"grid: step_nm: must be > 0, got {self.step_nm}")
        require(
            self.end_nm > self.start_nm,
            f"grid: end_nm: must be > start_nm = {self.start_nm}, got {self.end_nm}",
        )
        count = (self.end_nm - self.start_nm) / self.step_nm
        require(
            round(count) >= 1 and abs(count - round(count)) < 1e-9,
            f"grid: step_nm: {self.step_nm} must divide end_nm - start_nm = "
            f"{self.end_nm - self.start_nm}",
        )
        require(round(count) + 1 <= 4096, f"grid: at most 4096 bands, got {round(count) + 1}")

    @property
    def n_bands(self) -> int:
        """Number of wavelengths on the grid."""
        return round((self.end_nm - self.start_nm) / self.step_nm) + 1

    @property
    def wavelengths_nm(self) -> np.ndarray:
        """The wavelengths, nm, shape ``(n_bands,)``."""
        return self.start_nm + self.step_nm * np.arange(self.n_bands, dtype=np.float64)

    @property
    def label(self) -> str:
        """A short name such as ``"380-780/10"`` for reports and cache keys."""
        return f"{self.start_nm:g}-{self.end_nm:g}/{self.step_nm:g}"


#: 380-780 nm in 10 nm steps, 41 bands: the default grid (Herbert et al. §4).
GRID_41 = SpectralGrid(380.0, 780.0, 10.0)
#: 400-700 nm in 10 nm steps, 31 bands.
GRID_31 = SpectralGrid(400.0, 700.0, 10.0)
#: The grid used when a scene or function does not name one.
DEFAULT_GRID = GRID_41
#: Built-in grids by the names scene files use.
GRIDS = {"41": GRID_41, "31": GRID_31}


@dataclass(frozen=True)
class Spectrum:
    """A sampled spectrum: strictly increasing wavelengths (nm) and finite values.

    Build one with :func:`make_spectrum`, :func:`spectrum_constant`, :func:`spectrum_from_dataset`
    or :func:`spectrum_from_csv`, which validate their input; this class itself only stores.

    Parameters
    ----------
    wavelengths_nm : ndarray, shape (n,)
        Sample wavelengths, nm, strictly increasing.
    values : ndarray, shape (n,)
        Spectral values (reflectance factor, relative power, ...).
    name : str
        Where it came from, used in messages.
    constant : bool
        True for a wavelength-independent spectrum, which covers every grid.
    """

    wavelengths_nm: np.ndarray
    values: np.ndarray
    name: str = "spectrum"
    constant: bool = False
    meta: dict = field(default_factory=dict, compare=False)

    def __repr__(self) -> str:
        if self.constant:
            return f"Spectrum({self.name!r}, constant {self.values[0]:g})"
        return (
            f"Spectrum({self.name!r}, {self.wavelengths_nm[0]:g}-{self.wavelengths_nm[-1]:g} nm, "
            f"{self.values.size} samples)"
        )


def make_spectrum(wavelengths_nm, values, name: str = "spectrum", allow_negative: bool = False):
    """Validate ``(wavelengths, values)`` and return a :class:`Spectrum`.

    Parameters
    ----------
    wavelengths_nm : array_like, shape (n,)
        Wavelengths, nm; finite, strictly increasing, in (0, 10000); ``n >= 2``.
    values : array_like, shape (n,)
        Finite values; non-negative unless ``allow_negative``.
    name : str
        Prefix for error messages, e.g. ``"scene.toml: materials.red.k_d"``.
    allow_negative : bool
        Accept negative values (basis functions, differences).

    Returns
    -------
    Spectrum

    Raises
    ------
    SpecrefError
        On mismatched lengths, non-monotonic wavelengths, NaN, inf or negative values.

    Examples
    --------
    >>> make_spectrum([400, 500, 600], [0.1, 0.5, 0.9], "red")
    Spectrum('red', 400-600 nm, 3 samples)
    >>> make_spectrum([400, 390], [0.1, 0.5], "red")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: red: wavelengths must increase strictly, got 400.0 then 390.0 at
    index 1
    """
    try:
        wl = np.asarray(wavelengths_nm, dtype=np.float64)
        v = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise SpecrefError(f"{name}: wavelengths and values must be numbers") from None
    require(wl.ndim == 1 and v.ndim == 1, f"{name}: wavelengths and values must be 1-D lists")
    require(
        wl.size == v.size,
        f"{name}: {wl.size} wavelengths but {v.size} values; the lengths must match",
    )
    require(wl.size >= 2, f"{name}: needs at least 2 samples, got {wl.size}")
    bad = ~np.isfinite(wl)
    require(not bad.any(), f"{name}: wavelengths must be finite, got {wl[bad][:1]}")
    steps = np.diff(wl)
    if (steps <= 0).any():
        i = int(np.argmax(steps <= 0)) + 1
        raise SpecrefError(
            f"{name}: wavelengths must increase strictly, got {wl[i - 1]} then {wl[i]} at index {i}"
        )
    require(
        wl[0] > 0 and wl[-1] < 1e4,
        f"{name}: wavelengths must be in nm within (0, 10000), got {wl[0]:g}-{wl[-1]:g}",
    )
    bad = ~np.isfinite(v)
    if bad.any():
        i = int(np.argmax(bad))
        raise SpecrefError(f"{name}: values must be finite, got {v[i]} at {wl[i]:g} nm")
    if not allow_negative and (v < 0).any():
        i = int(np.argmax(v < 0))
        raise SpecrefError(f"{name}: values must be >= 0, got {v[i]:g} at {wl[i]:g} nm")
    wl.setflags(write=False)
    v.setflags(write=False)
    return Spectrum(wl, v, name)


def spectrum_constant(value: float, name: str = "constant") -> Spectrum:
    """A wavelength-independent spectrum, which covers any grid without extrapolation.

    Parameters
    ----------
    value : float
        The constant, finite and >= 0.
    name : str
        Prefix for error messages.

    Returns
    -------
    Spectrum

    Examples
    --------
    >>> resample_spectrum(spectrum_constant(0.5), GRID_31)[:3]
    array([0.5, 0.5, 0.5])
    """
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise SpecrefError(f"{name}: constant must be a number, got {value!r}") from None
    require(
        np.isfinite(value) and value >= 0, f"{name}: constant must be finite and >= 0, got {value}"
    )
    spectrum = make_spectrum([1.0, 9999.0], [value, value], name)
    return Spectrum(spectrum.wavelengths_nm, spectrum.values, name, constant=True)


# --- colour-science datasets ---------------------------------------------------------


def _colorchecker(set_name: str = "ColorChecker N Ohta"):
    import colour

    require_choice(set_name, list(colour.SDS_COLOURCHECKERS), "colorchecker set")
    return colour.SDS_COLOURCHECKERS[set_name]


def _dataset_table(dataset: str, set_name: str | None = None):
    """The colour-science mapping behind a dataset kind."""
    import colour

    if dataset == "illuminant":
        return colour.SDS_ILLUMINANTS
    if dataset == "light_source":
        return colour.SDS_LIGHT_SOURCES
    if dataset == "colorchecker":
        return _colorchecker(set_name or "ColorChecker N Ohta")
    raise SpecrefError(f"unknown dataset {dataset!r}; allowed: {format_allowed(DATASETS)}")


#: Dataset kinds that :func:`spectrum_from_dataset` reads from colour-science.
DATASETS = ("illuminant", "light_source", "colorchecker")


def spectrum_from_dataset(dataset: str, key: str, set_name: str | None = None) -> Spectrum:
    """A spectrum from a colour-science dataset, at its native sampling.

    Parameters
    ----------
    dataset : {"illuminant", "light_source", "colorchecker"}
        ``colour.SDS_ILLUMINANTS`` (A, D50, D65, FL2, LED-B1, ...), ``colour.SDS_LIGHT_SOURCES``, or
        the patches of a ColorChecker (``colour.SDS_COLOURCHECKERS``).
    key : str
        The entry: ``"D65"``, ``"FL2"``, ``"dark skin"``, ...
    set_name : str, optional
        For ``"colorchecker"``: the measurement set, default ``"ColorChecker N Ohta"`` (5 nm,
        380-780 nm).

    Returns
    -------
    Spectrum
        Native wavelengths and values, e.g. 5 nm steps for the CIE illuminants.

    Raises
    ------
    SpecrefError
        For an unknown dataset or key, listing what is allowed.

    Examples
    --------
    >>> d65 = spectrum_from_dataset("illuminant", "D65")
    >>> d65.wavelengths_nm[:3]
    array([300., 305., 310.])
    >>> spectrum_from_dataset("colorchecker", "dark skin")
    Spectrum('colorchecker:dark skin', 380-780 nm, 81 samples)
    """
    table = _dataset_table(dataset, set_name)
    if key not in table:
        raise SpecrefError(f"unknown {dataset} {key!r}; allowed: {format_allowed(table)}")
    sd = table[key]
    spectrum = make_spectrum(sd.wavelengths, sd.values, f"{dataset}:{key}")
    # Keep colour-science's own object: its interpolator (linear for the CIE illuminants, whose FL
    # lines Sprague would ring around) is part of the data, and sd_to_XYZ uses it.
    spectrum.meta["colour_sd"] = sd
    return spectrum


def spectrum_to_colour_sd(spectrum: Spectrum):
    """The spectrum as a ``colour.SpectralDistribution`` (for colour-science functions).

    A dataset spectrum returns colour-science's own object, with its interpolator; any other
    spectrum gets linear interpolation, which never overshoots (spectral lines, sharp cut-offs) and
    keeps values >= 0.

    Examples
    --------
    >>> spectrum_to_colour_sd(spectrum_from_dataset("illuminant", "A")).shape
    SpectralShape(300.0, 780.0, 5.0)
    """
    import colour
    from colour.algebra import LinearInterpolator

    if "colour_sd" in spectrum.meta:
        return spectrum.meta["colour_sd"]
    return colour.SpectralDistribution(
        spectrum.values,
        spectrum.wavelengths_nm,
        name=spectrum.name,
        interpolator=LinearInterpolator,
    )


# --- CSV files -----------------------------------------------------------------------

_WAVELENGTH_HEADER = re.compile(r"^\s*[A-Za-z]{0,3}\s*(\d+(?:\.\d+)?)\s*(?:nm)?\s*$")


def _read_rows(path: Path) -> tuple[list[list[str]], list[int]]:
    """Rows of a delimited text file and their 1-based line numbers; the delimiter is sniffed."""
    try:
        text = path.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise SpecrefError(f"{path}: file not found") from None
    except (OSError, UnicodeDecodeError) as error:
        raise SpecrefError(
            f"{path}: cannot read spectrum file ({error.__class__.__name__})"
        ) from None
    numbered = [
        (n, line)
        for n, line in enumerate(text.splitlines(), start=1)
        if line.strip() and not line.lstrip().startswith("#")
    ]
    require(numbered, f"{path}: empty spectrum file")
    delimiter = None
    if numbered[0][1].lower().startswith("sep="):
        delimiter = numbered[0][1][4:5] or ","
        numbered = numbered[1:]
    numbers = [n for n, _ in numbered]
    lines = [line for _, line in numbered]
    if delimiter is None:
        sample = "\n".join(lines[:20])
        counts = {d: sample.count(d) for d in (";", ",", "\t")}
        best = max(counts, key=counts.get)
        delimiter = best if counts[best] else None
    if delimiter is None:
        return [line.split() for line in lines], numbers
    rows = [
        [cell.strip().strip('"') for cell in row] for row in csv.reader(lines, delimiter=delimiter)
    ]
    return rows, numbers


def _as_float(cell: str) -> float | None:
    try:
        return float(cell)
    except ValueError:
        return None


def spectrum_from_csv(
    path, column: str | int | None = None, row: int = 0, scale: float = 1.0, name: str | None = None
) -> Spectrum:
    """Read a spectrum from a delimited text file.

    Two layouts are recognised:

    - **long**: one sample per line, wavelength (nm) in the first column and values in the others;
      a header line is optional. ``column`` picks the value column by header name or 1-based index
      (default: the second column).
    - **wide**: a header row whose cells name wavelengths (``400``, ``400nm``, ``R400 nm``),
      followed by data rows; ``row`` picks the data row (0-based, default the first). Preamble
      lines before the header are skipped, as in the Nix Spectro exports in ``data:spectra``,
      shipped with specref.

    The delimiter (``;``, ``,``, tab or spaces) is sniffed; a first line ``sep=;`` is honoured.

    Parameters
    ----------
    path : str or Path
        The file.
    column : str or int, optional
        Long layout: value column, by header name or 1-based index (the wavelength column is 0).
    row : int
        Wide layout: 0-based data row.
    scale : float
        Multiply the values by this (e.g. 0.01 for percentages).
    name : str, optional
        Name for messages; default the file path.

    Returns
    -------
    Spectrum

    Raises
    ------
    SpecrefError
        Missing file, no recognisable layout, NaN/inf/negative values, non-monotonic wavelengths.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = os.path.join(d, "r.csv")
    ...     _ = open(p, "w").write("nm,R" + chr(10) + "400,0.1" + chr(10) + "410,0.2" + chr(10))
    ...     spectrum_from_csv(p).values
    array([0.1, 0.2])
    """
    path = Path(path)
    label = name or str(path)
    rows, line_numbers = _read_rows(path)
    wide = _wide_header(rows)
    if wide is not None:
        header_row, wl_cols = wide
        wavelengths, values = _wide_samples(rows[header_row + 1 :], wl_cols, row, label)
    else:
        wavelengths, values = _long_samples(rows, line_numbers, column, label)
    return make_spectrum(wavelengths, np.asarray(values) * scale, label)


def _wide_header(rows: list[list[str]]) -> tuple[int, list[tuple[float, int]]] | None:
    """The wide layout's header: the first row with >= 3 increasing wavelength cells (200-2500 nm).

    Returns its index and its ``(wavelength, column)`` cells, or None for the long layout.
    """
    for r, cells in enumerate(rows):
        wl_cols = [
            (float(m.group(1)), i)
            for i, m in enumerate(_WAVELENGTH_HEADER.match(c) for c in cells)
            if m and 200.0 <= float(m.group(1)) <= 2500.0
        ]
        increasing = all(a[0] < b[0] for a, b in itertools.pairwise(wl_cols))
        if len(wl_cols) >= 3 and increasing:
            return r, wl_cols
    return None


def _wide_samples(data_rows, wl_cols, row: int, label: str) -> tuple[list[float], list[float]]:
    """Wavelengths and values of data row ``row`` under the wide header's wavelength columns."""
    require(
        0 <= row < len(data_rows),
        f"{label}: row: must be in [0, {len(data_rows) - 1}], got {row}",
    )
    data = data_rows[row]
    values = []
    for wl, i in wl_cols:
        value = _as_float(data[i]) if i < len(data) else None
        require(value is not None, f"{label}: row {row}: no number under the {wl:g} nm column")
        values.append(value)
    return [wl for wl, _ in wl_cols], values


def _long_samples(rows, line_numbers, column, label: str) -> tuple[list[float], list[float]]:
    """Wavelengths (first column) and values (``column``) of the long layout, one per line."""
    header = None
    if rows and _as_float(rows[0][0]) is None:
        header, rows, line_numbers = rows[0], rows[1:], line_numbers[1:]
    if column is None:
        index = 1
    elif isinstance(column, int) and not isinstance(column, bool):
        index = column
    else:
        require(
            header is not None and column in header,
            f"{label}: column: {column!r} is not a header of this file; allowed: "
            f"{format_allowed(header[1:] if header else [])}",
        )
        index = header.index(column)
    wavelengths, values = [], []
    for n, cells in zip(line_numbers, rows, strict=True):
        require(len(cells) > index, f"{label}: line {n}: expected at least {index + 1} columns")
        wl, value = _as_float(cells[0]), _as_float(cells[index])
        require(
            wl is not None and value is not None,
            f"{label}: line {n}: expected numbers, got {cells[0]!r}, {cells[index]!r}",
        )
        wavelengths.append(wl)
        values.append(value)
    require(
        len(wavelengths) >= 2,
        f"{label}: needs at least 2 samples (a wavelength and a value per line, or a header row "
        f"of wavelengths), got {len(wavelengths)}",
    )
    return wavelengths, values


# --- resampling ----------------------------------------------------------------------


def resample_spectrum(
    spectrum: Spectrum,
    grid: SpectralGrid = DEFAULT_GRID,
    extrapolation: str = "error",
    interpolation: str = "linear",
) -> np.ndarray:
    """Values of ``spectrum`` at the wavelengths of ``grid``.

    Inside the measured range the samples are interpolated (``"linear"``, which never overshoots, or
    ``"sprague"``, the fifth-order interpolation that CIE 167 recommends for uniformly spaced data,
    through colour-science). Outside it, nothing happens silently: ``extrapolation`` must say what
    to do.

    Parameters
    ----------
    spectrum : Spectrum
        The spectrum.
    grid : SpectralGrid
        Target grid.
    extrapolation : {"error", "constant", "zero", "linear"}
        ``"error"`` (default) refuses a spectrum that does not cover the grid; ``"constant"`` holds
        the end values (CIE 015 §7.2.2); ``"zero"`` sets 0; ``"linear"`` extends the end segments
        (clipped at 0).
    interpolation : {"linear", "sprague"}
        Interpolation between samples.

    Returns
    -------
    ndarray, shape (n_bands,)

    Raises
    ------
    SpecrefError
        When the spectrum does not cover the grid and ``extrapolation="error"``, naming both ranges.

    Examples
    --------
    >>> s = make_spectrum([400, 700], [0.2, 0.8], "ramp")
    >>> resample_spectrum(s, SpectralGrid(400, 700, 100))
    array([0.2, 0.4, 0.6, 0.8])
    >>> resample_spectrum(s, SpectralGrid(380, 720, 170), extrapolation="constant")
    array([0.2, 0.5, 0.8])
    >>> resample_spectrum(s, GRID_41)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: ramp: covers 400-700 nm but the grid needs 380-780 nm; set
    extrapolation to one of: constant, linear, zero
    """
    require_choice(extrapolation, EXTRAPOLATIONS, "extrapolation")
    require_choice(interpolation, INTERPOLATIONS, "interpolation")
    target = grid.wavelengths_nm
    wl, v = spectrum.wavelengths_nm, spectrum.values
    if spectrum.constant:
        return np.full(target.shape, v[0])
    tol = 1e-9
    covers = wl[0] <= target[0] + tol and wl[-1] >= target[-1] - tol
    if not covers and extrapolation == "error":
        allowed = format_allowed(e for e in EXTRAPOLATIONS if e != "error")
        raise SpecrefError(
            f"{spectrum.name}: covers {wl[0]:g}-{wl[-1]:g} nm but the grid needs "
            f"{target[0]:g}-{target[-1]:g} nm; set extrapolation to one of: {allowed}"
        )
    inside = (target >= wl[0] - tol) & (target <= wl[-1] + tol)
    out = np.empty_like(target)
    # Inside the measured range: interpolate.
    out[inside] = _interpolate(spectrum, target[inside], interpolation)
    # Outside it: the extrapolation the caller chose.
    if extrapolation != "error":  # "error" has refused a spectrum that does not cover the grid
        below, above = target < wl[0] - tol, target > wl[-1] + tol
        out[below], out[above] = _extrapolate(spectrum, target[below], target[above], extrapolation)
    return out


def _interpolate(spectrum: Spectrum, x: np.ndarray, interpolation: str) -> np.ndarray:
    """Values at wavelengths ``x`` inside the measured range, ``"linear"`` or ``"sprague"``."""
    wl, v = spectrum.wavelengths_nm, spectrum.values
    if interpolation == "sprague":
        # Sprague's fifth-order scheme needs six uniformly spaced samples (CIE 167): refuse rather
        # than fall back to linear without saying so.
        uniform = wl.size >= 2 and np.allclose(np.diff(wl), wl[1] - wl[0])
        require(
            wl.size >= 6 and uniform,
            f"{spectrum.name}: sprague interpolation needs at least 6 uniformly spaced samples, "
            f'got {wl.size}{"" if uniform else " unevenly spaced"}; use interpolation = "linear"',
        )
        from colour.algebra import SpragueInterpolator

        return SpragueInterpolator(wl, v)(np.clip(x, wl[0], wl[-1]))
    return np.interp(x, wl, v)


def _extrapolate(spectrum: Spectrum, below, above, extrapolation: str):
    """Values at wavelengths ``below`` and ``above`` the measured range (CIE 015 §7.2.2)."""
    wl, v = spectrum.wavelengths_nm, spectrum.values
    if extrapolation == "constant":
        return v[0], v[-1]
    if extrapolation == "zero":
        return 0.0, 0.0
    # "linear": the end segments extended, clipped at 0
    slope_lo = (v[1] - v[0]) / (wl[1] - wl[0])
    slope_hi = (v[-1] - v[-2]) / (wl[-1] - wl[-2])
    return (
        np.maximum(v[0] + slope_lo * (below - wl[0]), 0.0),
        np.maximum(v[-1] + slope_hi * (above - wl[-1]), 0.0),
    )

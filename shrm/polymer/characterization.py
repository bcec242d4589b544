"""Polymer characterization files: Herbert et al.'s chip matrix, written, read and looked up.

§3.1, Herbert et al.: "From the spectral measurements we built a matrix of color values as a
function of thickness and TiO2 concentration." A characterization holds, for every chip of a
thickness × TiO2 grid, its spectral reflectance over a black and over a white backing and its
transmittance. :func:`characterize_model` makes one from the Kubelka–Munk slab
(``shrm.polymer.kubelka_munk``); :func:`read_characterization` reads one that a user measured;
:meth:`Characterization.lookup` interpolates between the chips, once per frame (§5.1: "per-frame
otherwise").

The file format (CSV, ``docs/herbert-polymer.md``) is one measured spectrum per line::

    # specref polymer characterization, version 1
    # material: HDPE-like
    # index: 1.54
    # backing_white: 0.9
    thickness_mm,tio2_pct,measurement,380,390,...,780
    0.762,0,over_black,0.0412,...
    0.762,0,over_white,0.0805,...
    0.762,0,transmittance,0.912,...

``#`` lines before the header carry ``key: value`` metadata (``index`` of the polymer, default
1.54; ``backing_white``, the white backing's reflectance, default 0.9; ``material``, a label).
The header names the wavelengths in nm, increasing. Rows come in grid order: thickness
non-decreasing, and within each thickness the TiO2 loads increasing, the same loads for every
thickness; each chip has exactly the three measurements ``over_black``, ``over_white`` and
``transmittance``, as reflectance factors in [0, 1].

Interpolation is monotone cubic (PCHIP) in log thickness and linear TiO2 load: against the model at
the midpoints of the default grid it stays within 0.07 ΔE00 mean (0.3 max) under D65 and A, where
bilinear interpolation is at 0.6 mean (2.3 max) in transmission
(``tests/shrm/polymer/test_characterization.py``).

References
----------
Herbert, M., et al. (2004). Multispectral Virtual Reality: Spectral Shading with Spherical
    Harmonics. (specref's Herbert et al.)
Fritsch, F. N., & Carlson, R. E. (1980). Monotone piecewise cubic interpolation. SIAM J. Numer.
    Anal. 17, 238–246 (PCHIP).
"""

from __future__ import annotations

import csv
import itertools
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reference.colour.spectra import DEFAULT_GRID, SpectralGrid
from reference.errors import SpecrefError, require
from reference.files import atomic_write
from reference.materials.fresnel import MAX_REFRACTIVE_INDEX
from shrm.polymer.kubelka_munk import PolymerConstituents, polymer_K_S, slab_measured

__all__ = [
    "DEFAULT_THICKNESS_MM",
    "DEFAULT_TIO2_PCT",
    "HARD_MAX_CHIPS",
    "HERBERT_THICKNESS_MM",
    "MAX_CHIPS",
    "MEASUREMENTS",
    "Characterization",
    "characterize_model",
    "check_chip_count",
    "read_characterization",
    "write_characterization",
]

#: The three chip thicknesses of Herbert et al. §3.1: 0.03", 0.06" and 0.120", in mm.
HERBERT_THICKNESS_MM = (0.762, 1.524, 3.048)
#: The thickness grid ``specref polymer characterize`` writes by default, mm: Herbert's three and
#: points between and beyond them.
DEFAULT_THICKNESS_MM = (0.381, 0.762, 1.143, 1.524, 2.286, 3.048, 4.572)
#: The TiO2 grid ``specref polymer characterize`` writes by default, % by weight.
DEFAULT_TIO2_PCT = (0.0, 0.02, 0.05, 0.1, 0.2, 0.35, 0.5, 0.75, 1.0, 1.5, 2.0)
#: The three measurements of each chip, in file order.
MEASUREMENTS = ("over_black", "over_white", "transmittance")
#: Chips (thicknesses × loads) a characterization makes without being asked twice (``--yes``);
#: the default grid has 77, a finely sampled one a few thousand.
MAX_CHIPS = 10_000
#: Chips it makes at all: about 1.7 GB of CSV on the 41-band grid.
HARD_MAX_CHIPS = 1_000_000
#: Bytes of CSV per written value (``%.10g`` and a comma), measured on the default model.
_CSV_BYTES_PER_VALUE = 14
_MAGIC = "# specref polymer characterization, version 1"


@dataclass(frozen=True)
class Characterization:
    """The chip matrix: spectra over black, over white, and in transmission, per thickness × TiO2.

    Parameters
    ----------
    wavelengths_nm : ndarray, shape (n_bands,)
        Increasing.
    thickness_mm : ndarray, shape (n_d,)
        Increasing, > 0.
    tio2_pct : ndarray, shape (n_c,)
        Increasing, >= 0.
    over_black, over_white, transmittance : ndarray, shape (n_d, n_c, n_bands)
        Reflectance factors and transmittance in [0, 1].
    meta : dict
        ``index``, ``backing_white``, ``material`` and where the data came from.
    """

    wavelengths_nm: np.ndarray
    thickness_mm: np.ndarray
    tio2_pct: np.ndarray
    over_black: np.ndarray
    over_white: np.ndarray
    transmittance: np.ndarray
    meta: dict = field(default_factory=dict, compare=False)

    def lookup(self, thickness_mm, tio2_pct) -> dict[str, np.ndarray]:
        """The three spectra of a chip between grid points (PCHIP in log thickness and TiO2).

        Parameters
        ----------
        thickness_mm, tio2_pct : float or array_like, broadcasting
            Inside the grid's range.

        Returns
        -------
        dict of str to ndarray, shape (..., n_bands)
            Keyed by :data:`MEASUREMENTS`.

        Raises
        ------
        SpecrefError
            For a point outside the grid or NaN.

        Examples
        --------
        >>> ch = characterize_model(thickness_mm=(0.5, 1.0, 2.0), tio2_pct=(0.0, 0.5, 1.0))
        >>> spectra = ch.lookup(0.8, 0.25)
        >>> spectra["over_black"].shape, bool(spectra["transmittance"][20] < 1)
        ((41,), True)
        """
        d = np.asarray(thickness_mm, dtype=np.float64)
        c = np.asarray(tio2_pct, dtype=np.float64)
        for name, value, axis in (
            ("thickness_mm", d, self.thickness_mm),
            ("tio2_pct", c, self.tio2_pct),
        ):
            outside = ~((value >= axis[0]) & (value <= axis[-1]))
            if np.any(outside):
                raise SpecrefError(
                    f"characterization: {name}: must be in [{axis[0]:g}, {axis[-1]:g}] (the grid), "
                    f"got {np.atleast_1d(value)[np.atleast_1d(outside)][0]!r}"
                )
        # imported here: SciPy's interpolate costs every command's start-up about 0.3 s
        from scipy.interpolate import RegularGridInterpolator

        d, c = np.broadcast_arrays(d, c)
        points = np.stack([np.log(d), c], axis=-1).reshape(-1, 2)
        out = {}
        for name in MEASUREMENTS:
            table = getattr(self, name)
            axes = (np.log(self.thickness_mm), self.tio2_pct)
            method = "pchip" if min(len(a) for a in axes) >= 4 else "linear"
            interpolate = RegularGridInterpolator(axes, table, method=method)
            values = interpolate(points).reshape(*d.shape, table.shape[-1])
            out[name] = np.clip(values, 0.0, 1.0)
        return out


def characterize_model(
    constituents: PolymerConstituents | None = None,
    thickness_mm=DEFAULT_THICKNESS_MM,
    tio2_pct=DEFAULT_TIO2_PCT,
    backing_white: float = 0.9,
    grid: SpectralGrid = DEFAULT_GRID,
) -> Characterization:
    """The chip matrix that the Kubelka–Munk slab predicts (specref's stand-in for Herbert's chips).

    Parameters
    ----------
    constituents : PolymerConstituents, optional
        Default: ``shrm.polymer.kubelka_munk.polymer_constituents(grid)`` (HDPE-like base, rutile
        TiO2).
    thickness_mm, tio2_pct : sequence of float
        The grid, increasing; thickness > 0, loads >= 0.
    backing_white : float
        Reflectance of the white backing, in (0, 1].
    grid : SpectralGrid
        Used when ``constituents`` is None.

    Returns
    -------
    Characterization

    Raises
    ------
    SpecrefError
        For a grid that is not increasing, a thickness <= 0 or a negative load.

    Examples
    --------
    >>> ch = characterize_model(thickness_mm=(0.762, 3.048), tio2_pct=(0.0, 1.0))
    >>> ch.over_black.shape, bool((ch.over_white >= ch.over_black).all())
    ((2, 2, 41), True)
    """
    from shrm.polymer.kubelka_munk import polymer_constituents

    constituents = polymer_constituents(grid) if constituents is None else constituents
    d = _axis(thickness_mm, "thickness_mm", "characterize_model")
    c = _axis(tio2_pct, "tio2_pct", "characterize_model")
    require(d[0] > 0, f"characterize_model: thickness_mm: must be > 0, got {d[0]:g}")
    require(
        0 < backing_white <= 1,
        f"characterize_model: backing_white: must be in (0, 1], got {backing_white!r}",
    )
    K, S = polymer_K_S(constituents, c)
    n = constituents.index
    over_black, transmittance = slab_measured(K, S, d[:, None, None], n=n)
    over_white, _ = slab_measured(K, S, d[:, None, None], R_g=backing_white, n=n)
    meta = {
        "material": constituents.name,
        "index": n,
        "backing_white": float(backing_white),
        "source": "shrm.polymer.kubelka_munk model (specref polymer characterize)",
    }
    wl = constituents.grid.wavelengths_nm
    return Characterization(wl, d, c, over_black, over_white, transmittance, meta)


def _axis(values, name: str, where: str) -> np.ndarray:
    try:
        axis = np.asarray(values, dtype=np.float64).ravel()
    except (TypeError, ValueError) as error:
        raise SpecrefError(f"{where}: {name}: must be numbers, got {values!r:.60}") from error
    require(
        axis.size >= 1 and np.all(np.isfinite(axis)), f"{where}: {name}: must be finite numbers"
    )
    require(bool(np.all(axis >= 0)), f"{where}: {name}: must be >= 0, got {axis.min():g}")
    require(
        bool(np.all(np.diff(axis) > 0)),
        f"{where}: {name}: the grid is not monotonic (must increase), got {axis.tolist()}",
    )
    return axis


def check_chip_count(n_thickness: int, n_tio2: int, n_bands: int, large: bool = False) -> int:
    """The number of chips of a grid, refused above :data:`MAX_CHIPS` (or :data:`HARD_MAX_CHIPS`).

    Checked before any work, with the estimated size of the file in the message.

    Examples
    --------
    >>> check_chip_count(7, 11, 41)
    77
    >>> check_chip_count(2000, 300, 41)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: grid: 600,000 chips (2,000 thicknesses × 300 TiO2 loads ×
    41 bands, about 1.0 GB of CSV); at most 10,000 without --yes, 1,000,000 with it
    """
    chips = n_thickness * n_tio2
    limit = HARD_MAX_CHIPS if large else MAX_CHIPS
    size = chips * len(MEASUREMENTS) * n_bands * _CSV_BYTES_PER_VALUE
    shown = f"{size / 1e9:.1f} GB" if size >= 1e9 else f"{size / 1e6:.0f} MB"
    require(
        chips <= limit,
        f"grid: {chips:,} chips ({n_thickness:,} thicknesses × {n_tio2:,} TiO2 loads × "
        f"{n_bands} bands, about {shown} of CSV); at most {limit:,}"
        + ("" if large else f" without --yes, {HARD_MAX_CHIPS:,} with it"),
    )
    return chips


def write_characterization(path, ch: Characterization, progress=None) -> Path:
    """Write a characterization file (atomically).

    Parameters
    ----------
    path : str or Path
        The ``.csv`` to write.
    ch : Characterization
    progress : file-like, optional
        Where a progress line goes (the command line's stderr).

    Returns
    -------
    Path

    Examples
    --------
    >>> import tempfile, pathlib
    >>> ch = characterize_model(thickness_mm=(0.762, 3.048), tio2_pct=(0.0, 1.0))
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "hdpe.csv"
    >>> read_characterization(write_characterization(path, ch)).over_black.shape
    (2, 2, 41)
    """
    from reference.progress import Progress

    # streamed into the temporary file (a large grid's CSV is never one string in memory)
    with atomic_write(path, "w") as out:
        out.write(_MAGIC + "\n")
        for key, value in ch.meta.items():
            out.write(f"# {key}: {value}\n")
        writer = csv.writer(out, lineterminator="\n")
        writer.writerow(
            ["thickness_mm", "tio2_pct", "measurement", *(f"{w:g}" for w in ch.wavelengths_nm)]
        )
        desc = f"writing {Path(path).name}"
        with Progress(desc, ch.thickness_mm.size, progress, unit="thicknesses") as bar:
            for i, d in enumerate(ch.thickness_mm):
                for j, c in enumerate(ch.tio2_pct):
                    for name in MEASUREMENTS:
                        values = getattr(ch, name)[i, j]
                        writer.writerow([f"{d:g}", f"{c:g}", name, *(f"{v:.10g}" for v in values)])
                bar.update(1)
    return Path(path)


def _float(cell: str, where: str) -> float:
    try:
        value = float(cell)
    except ValueError as error:
        raise SpecrefError(f"{where}: must be a number, got {cell!r:.40}") from error
    require(np.isfinite(value), f"{where}: must be finite, got {cell!r}")
    return value


#: The wavelengths a characterization file must cover, nm: outside them the CIE 1931 colour
#: matching functions carry 0.06 % of ∫ȳ (0.5 % of ∫z̄); inside them nothing is extrapolated.
COVERED_NM = (400.0, 700.0)


def read_characterization(path) -> Characterization:
    r"""Read a characterization file (format in the module docstring and docs/herbert-polymer.md).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    Characterization

    Raises
    ------
    SpecrefError
        One line naming the file, the line and the problem: no header, wavelengths not increasing,
        a row whose spectrum does not match the header, an unknown measurement, a grid that is not
        monotonic or not complete (spectra that do not match the grid), values outside [0, 1].

    Examples
    --------
    >>> import tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "bad.csv"
    >>> _ = path.write_text("thickness_mm,tio2_pct,measurement,400,500\n2,0,over_black,0.1,0.1\n")
    >>> read_characterization(path)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: ...bad.csv: spectra do not match the grid: ... has no over_white
    """
    path = Path(path)
    meta, (header_line, header), rows = _read_rows(path)
    require(
        [h.strip() for h in header[:3]] == ["thickness_mm", "tio2_pct", "measurement"]
        and len(header) > 3,
        f"{path}:{header_line}: header must be thickness_mm,tio2_pct,measurement,<wavelengths nm>",
    )
    wavelengths = np.array([_float(h, f"{path}:{header_line}: wavelength") for h in header[3:]])
    require(
        bool(np.all(np.diff(wavelengths) > 0)),
        f"{path}:{header_line}: wavelengths must increase, got {header[3:]}",
    )
    spectra, order = _read_spectra(path, header, rows)
    thickness, loads = _grid_axes(path, spectra, order)
    arrays = {
        name: np.array([[spectra[d, c, name] for c in loads] for d in thickness])
        for name in MEASUREMENTS
    }
    for key, default in (("index", 1.54), ("backing_white", 0.9)):
        meta[key] = _float(str(meta.get(key, default)), f"{path}: # {key}")
    require(
        1 < meta["index"] <= MAX_REFRACTIVE_INDEX,
        f"{path}: # index: a refractive index must be in (1, {MAX_REFRACTIVE_INDEX:g}], "
        f"got {meta['index']:g}",
    )
    require(
        0 < meta["backing_white"] <= 1,
        f"{path}: # backing_white: a reflectance, in (0, 1], got {meta['backing_white']:g}",
    )
    low, high = COVERED_NM
    require(
        wavelengths[0] <= low and wavelengths[-1] >= high,
        f"{path}:{header_line}: wavelengths must cover {low:g}-{high:g} nm (the visible range the "
        f"renders integrate), got {wavelengths[0]:g}-{wavelengths[-1]:g} nm",
    )
    meta.setdefault("material", path.stem)
    return Characterization(
        wavelengths,
        np.array(thickness),
        np.array(loads),
        arrays["over_black"],
        arrays["over_white"],
        arrays["transmittance"],
        meta,
    )


def _read_rows(path: Path) -> tuple[dict, tuple, list]:
    """The file's ``# key: value`` lines before the header, its header and its rows, numbered."""
    require(path.is_file(), f"{path}: no such characterization file")
    try:
        lines = path.read_text().splitlines()
    except UnicodeDecodeError as error:
        raise SpecrefError(f"{path}: not a text file") from error
    meta: dict = {}
    body = []
    for number, line in enumerate(lines, 1):
        if line.startswith("#"):
            key, sep, value = line[1:].partition(":")
            if sep and not body:
                meta[key.strip()] = value.strip()
        elif line.strip():
            body.append((number, line))
    require(body, f"{path}: no header line (thickness_mm,tio2_pct,measurement,<wavelengths>)")
    rows = [
        (number, row)
        for number, row in zip(
            (n for n, _ in body), csv.reader(line for _, line in body), strict=True
        )
    ]
    return meta, rows[0], rows[1:]


def _read_spectra(path: Path, header: list, rows: list) -> tuple[dict, list]:
    """Each row's spectrum by ``(thickness, TiO2, measurement)``, and the chips in file order."""
    spectra: dict[tuple[float, float, str], np.ndarray] = {}
    order: list[tuple[float, float]] = []
    for number, row in rows:
        where = f"{path}:{number}"
        require(
            len(row) == len(header),
            f"{where}: spectra do not match the grid: {len(row) - 3} values for "
            f"{len(header) - 3} wavelengths",
        )
        d = _float(row[0], f"{where}: thickness_mm")
        c = _float(row[1], f"{where}: tio2_pct")
        name = row[2].strip()
        require(
            name in MEASUREMENTS,
            f"{where}: measurement must be one of {', '.join(MEASUREMENTS)}, got {name!r}",
        )
        values = np.array([_float(v, f"{where}: value") for v in row[3:]])
        require(
            bool(np.all((values >= 0) & (values <= 1))),
            f"{where}: {name}: values must be in [0, 1] (reflectance factors), got "
            f"{values.min():g}..{values.max():g}",
        )
        require(
            (d, c, name) not in spectra, f"{where}: duplicate {name} at thickness {d:g}, TiO2 {c:g}"
        )
        spectra[d, c, name] = values
        if not order or order[-1] != (d, c):
            order.append((d, c))
    return spectra, order


def _grid_axes(path: Path, spectra: dict, order: list) -> tuple[list, list]:
    """The thickness and TiO2 axes of the chips, checked to form a complete, monotonic grid."""
    require(order, f"{path}: no spectra after the header")
    thickness = list(dict.fromkeys(d for d, _ in order))
    loads = [c for d, c in order if d == thickness[0]]
    require(
        all(b > a for a, b in itertools.pairwise(thickness))
        and all(b > a for a, b in itertools.pairwise(loads)),
        f"{path}: the grid is not monotonic: rows must run through increasing thickness_mm, and "
        "within each thickness through increasing tio2_pct",
    )
    expected = [(d, c) for d in thickness for c in loads]
    require(
        order == expected,
        f"{path}: the grid is not monotonic or not complete: every thickness needs the TiO2 loads "
        f"{[f'{c:g}' for c in loads]}, in that order",
    )
    for d, c in expected:
        for name in MEASUREMENTS:
            require(
                (d, c, name) in spectra,
                f"{path}: spectra do not match the grid: thickness {d:g}, TiO2 {c:g} has no {name}",
            )
    require(thickness[0] > 0, f"{path}: thickness_mm must be > 0, got {thickness[0]:g}")
    return thickness, loads

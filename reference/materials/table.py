"""Tabulated isotropic BRDFs f(θ_i, θ_o, Δφ) per band, and their text format (after ASTM E1392).

A measured 3-D BRDF (Herbert et al. §3.2, §5) is a table of values on a grid of angles. specref's
tables (:class:`BRDFTable`) hold ``values[i, o, p, c] = f(θ_i[i], θ_o[o], Δφ[p], λ[c])`` on:

- **the grid**: polar angles ``θ_i``, ``θ_o`` in [0°, 90°] and the azimuth difference ``Δφ`` in
  [0°, 180°], each strictly increasing (any spacing); one value per wavelength (nm). Isotropy and
  reciprocity make ``Δφ`` in [0°, 180°] enough: ``f(Δφ) = f(−Δφ)``. Synthesized tables
  (:func:`tabulate_brdf`) use the same nodes for θ_i and θ_o, so the interpolant stays reciprocal.
- **interpolation** (:func:`brdf_tabulated`): trilinear in ``(θ_i, θ_o, Δφ)`` measured in degrees,
  per band; outside the grid's θ range the nearest node is used (clamped); below the horizon the
  BRDF is 0.

The text format (``docs/brdf-format.md``) is modelled on ASTM E1392's angle-resolved scatter
records: one row per geometry with the incidence angle ``theta_i``, the scatter angle ``theta_s``,
the scatter azimuth ``phi_s`` (degrees; ``phi_s = 0`` is the specular side of the plane of
incidence, 180 the side of the source, so ``Δφ = 180° − phi_s``), then the BRDF (1/sr) per
wavelength. :func:`read_brdf_table` refuses missing or duplicated geometries, angles out of range,
and negative or NaN values with one line naming the file and line; :func:`write_brdf_table` writes
the same format atomically.

References
----------
- ASTM E1392-96, "Standard Practice for Angle Resolved Optical Scatter Measurements on Specular or
  Diffuse Surfaces" (the record layout this format follows).
- F. E. Nicodemus et al., "Geometrical considerations and nomenclature for reflectance", NBS
  Monograph 160, 1977 (the BRDF, 1/sr).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from reference.errors import SpecrefError, require
from reference.files import write_text_atomic
from reference.materials.brdf import BRDFMethod
from reference.materials.isotropic import (
    _cosine_pdf,
    _cosine_sample,
    isotropic_angles,
    isotropic_directions,
    register_brdf,
)

__all__ = [
    "MAX_TABLE_ANGLES",
    "BRDFTable",
    "brdf_tabulated",
    "read_brdf_table",
    "tabulable_brdf_names",
    "tabulate_brdf",
    "tabulate_registered_brdf",
    "write_brdf_table",
]

#: Largest tabulated BRDF, in (θ_i, θ_o, Δφ) triples: 91² × 91 at 1° θ and 2° Δφ steps.
MAX_TABLE_ANGLES = 91 * 91 * 91

#: The first line of a file written by :func:`write_brdf_table`.
FORMAT_LINE = "# specref-brdf 1: angle-resolved scatter after ASTM E1392"


def _axis(values, where: str, low: float, high: float) -> np.ndarray:
    axis = np.asarray(values, dtype=np.float64)
    require(axis.ndim == 1 and axis.size >= 1, f"{where}: must be a 1-D list of angles")
    require(bool(np.isfinite(axis).all()), f"{where}: must be finite")
    require(
        bool((axis >= low).all() and (axis <= high).all()),
        f"{where}: angles must be in [{low:g}, {high:g}] degrees, got "
        f"{axis.min():g}..{axis.max():g}",
    )
    require(bool((np.diff(axis) > 0).all()), f"{where}: angles must be strictly increasing")
    return axis


@dataclass(frozen=True, eq=False)
class BRDFTable:
    """An isotropic BRDF tabulated on a grid of angles, per band.

    Parameters
    ----------
    theta_i_deg, theta_o_deg : ndarray, shape (n_i,), (n_o,)
        Polar angles of incidence and scattering, degrees in [0, 90], strictly increasing.
    phi_d_deg : ndarray, shape (n_p,)
        Azimuth difference ``Δφ = φ_o − φ_i``, degrees in [0, 180] (180 = mirror side).
    wavelengths_nm : ndarray, shape (C,)
        The bands, nm.
    values : ndarray, shape (n_i, n_o, n_p, C)
        BRDF, 1/sr, finite and >= 0.
    name : str
        Shown in messages.

    Examples
    --------
    >>> t = BRDFTable([0.0, 45.0], [0.0, 45.0], [0.0, 180.0], [550.0], np.full((2, 2, 2, 1), 0.3))
    >>> t.values.shape, t.n_bands
    ((2, 2, 2, 1), 1)
    """

    theta_i_deg: np.ndarray
    theta_o_deg: np.ndarray
    phi_d_deg: np.ndarray
    wavelengths_nm: np.ndarray
    values: np.ndarray
    name: str = "brdf table"

    def __post_init__(self):
        where = self.name
        set_ = object.__setattr__
        set_(self, "theta_i_deg", _axis(self.theta_i_deg, f"{where}: theta_i", 0.0, 90.0))
        set_(self, "theta_o_deg", _axis(self.theta_o_deg, f"{where}: theta_o", 0.0, 90.0))
        set_(self, "phi_d_deg", _axis(self.phi_d_deg, f"{where}: phi_d", 0.0, 180.0))
        lam = np.asarray(self.wavelengths_nm, dtype=np.float64)
        require(
            lam.ndim == 1 and lam.size >= 1 and bool((lam > 0).all()),
            f"{where}: wavelengths_nm: must be a 1-D list of positive wavelengths",
        )
        set_(self, "wavelengths_nm", lam)
        values = np.asarray(self.values, dtype=np.float64)
        shape = (self.theta_i_deg.size, self.theta_o_deg.size, self.phi_d_deg.size, lam.size)
        require(
            values.shape == shape, f"{where}: values: must have shape {shape}, got {values.shape}"
        )
        require(bool(np.isfinite(values).all()), f"{where}: values: must be finite (no NaN)")
        require(bool((values >= 0).all()), f"{where}: values: must be >= 0, got {values.min():g}")
        values = values.copy()
        values.setflags(write=False)
        set_(self, "values", values)

    @property
    def n_bands(self) -> int:
        """Number of wavelengths."""
        return self.wavelengths_nm.size


def tabulate_brdf(
    function, params: dict, theta_deg, phi_d_deg, wavelengths_nm, name=None
) -> BRDFTable:
    """Tabulate a BRDF ``function(wi, wo, normal, **params)`` on a grid (θ_i and θ_o share nodes).

    Parameters
    ----------
    function : callable
        A BRDF with the :data:`reference.materials.brdf.BRDF_METHODS` calling convention, returning
        ``(..., C)``.
    params : dict
        Its parameters.
    theta_deg : array_like, shape (n,)
        Polar-angle nodes for both θ_i and θ_o, degrees in [0, 90].
    phi_d_deg : array_like, shape (n_p,)
        Azimuth-difference nodes, degrees in [0, 180].
    wavelengths_nm : array_like, shape (C,)
        The bands the function's parameters are given on.
    name : str, optional
        The table's name.

    Returns
    -------
    BRDFTable

    Examples
    --------
    >>> from reference.materials.brdf import brdf_lambert
    >>> t = tabulate_brdf(brdf_lambert, {"rho_d": [0.5]}, [0, 45, 89], [0, 180], [550.0])
    >>> t.values.shape, float(t.values.max()).__round__(6)
    ((3, 3, 2, 1), 0.159155)
    """
    theta = _axis(theta_deg, "tabulate_brdf: theta_deg", 0.0, 90.0)
    phi = _axis(phi_d_deg, "tabulate_brdf: phi_d_deg", 0.0, 180.0)
    pd = np.radians(phi)
    # Nodes at exactly 90° lie on the horizon, where the BRDF is 0; evaluate just above it.
    lift = np.radians(np.minimum(theta, 90.0 - 1e-6))
    ti, to = np.meshgrid(lift, lift, indexing="ij")
    wi, wo = isotropic_directions(ti[..., None], to[..., None], pd)
    values = np.asarray(function(wi, wo, np.array([0.0, 0.0, 1.0]), **params), dtype=np.float64)
    lam = np.atleast_1d(np.asarray(wavelengths_nm, dtype=np.float64))
    values = np.broadcast_to(values, (*ti.shape, phi.size, lam.size))
    label = name or getattr(function, "__name__", "brdf")
    return BRDFTable(theta, theta, phi, lam, values, name=label)


def tabulable_brdf_names() -> list[str]:
    """Keys of ``BRDF_METHODS`` that :func:`tabulate_registered_brdf` takes.

    The isotropic 3-D BRDFs (``BRDFMethod.isotropic``) and Lambert, in registry order.

    Examples
    --------
    >>> "ggx" in tabulable_brdf_names(), "ward_duer" in tabulable_brdf_names()
    (True, False)
    """
    from reference.materials.brdf import BRDF_METHODS

    return [n for n, m in BRDF_METHODS.items() if m.isotropic or n == "lambert"]


def tabulate_registered_brdf(
    name: str, theta_step_deg: float = 5.0, phi_step_deg: float = 15.0
) -> BRDFTable:
    """Tabulate a registered isotropic BRDF with its default parameters on a uniform grid.

    Parameters
    ----------
    name : str
        A key of :data:`reference.materials.brdf.BRDF_METHODS` whose entry is isotropic.
    theta_step_deg, phi_step_deg : float
        Grid steps, degrees; they must divide 90 and 180.

    Returns
    -------
    BRDFTable
        On ``θ = 0, step, ..., 90`` and ``Δφ = 0, step, ..., 180``, on the model's bands (its
        ``wavelengths_nm`` parameter, else one band per channel at 380-780 nm).

    Examples
    --------
    >>> tabulate_registered_brdf("ggx", 30.0, 90.0).values.shape
    (4, 4, 3, 3)
    """
    from reference.materials.brdf import BRDF_METHODS

    method = BRDF_METHODS.lookup(name)
    allowed = tabulable_brdf_names()
    require(
        name in allowed,
        f"brdf {name!r}: not an isotropic 3-D BRDF; allowed: {', '.join(allowed)}",
    )
    for label, step, span in (
        ("theta step", theta_step_deg, 90.0),
        ("phi step", phi_step_deg, 180.0),
    ):
        count = span / step if step > 0 else 0.5
        require(
            np.isfinite(step) and step > 0 and count >= 1 and abs(count - round(count)) < 1e-9,
            f"brdf tabulate: {label}: must divide {span:g} degrees, got {step:g}",
        )
    # Bound the table's size before allocating it: θ_i × θ_o × Δφ angles.
    angles = (round(90.0 / theta_step_deg) + 1) ** 2 * (round(180.0 / phi_step_deg) + 1)
    require(
        angles <= MAX_TABLE_ANGLES,
        f"brdf tabulate: the steps give {angles:,} angle triples; at most {MAX_TABLE_ANGLES:,} "
        "(a 1-degree theta step and a 2-degree phi step fit)",
    )
    params = dict(method.params)
    theta = np.linspace(0.0, 90.0, round(90.0 / theta_step_deg) + 1)
    phi = np.linspace(0.0, 180.0, round(180.0 / phi_step_deg) + 1)
    probe = method.reference(
        np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0]), **params
    )
    lam = params.get("wavelengths_nm", np.linspace(380.0, 780.0, np.shape(probe)[-1]))
    return tabulate_brdf(method.reference, params, theta, phi, lam, name=name)


def _linear_weights(axis: np.ndarray, x: np.ndarray):
    """Lower node index and weight of the upper node, clamped at the ends."""
    if axis.size == 1:
        return np.zeros(x.shape, dtype=np.int64), np.zeros(x.shape)
    x = np.clip(x, axis[0], axis[-1])
    k = np.clip(np.searchsorted(axis, x, side="right") - 1, 0, axis.size - 2)
    t = (x - axis[k]) / (axis[k + 1] - axis[k])
    return k, t


def brdf_tabulated(wi, wo, normal, table: BRDFTable) -> np.ndarray:
    """A tabulated BRDF, trilinear in ``(θ_i, θ_o, Δφ)`` (degrees), per band.

    Nicodemus et al. 1977, the BRDF as a function of (θ_i, θ_o, Δφ) for isotropic surfaces; the
    interpolation is documented in the module docstring.

    Parameters
    ----------
    wi, wo, normal : array_like, shape (..., 3)
        Unit directions away from the surface and the unit normal.
    table : BRDFTable
        The table.

    Returns
    -------
    ndarray, shape (..., C)
        BRDF, 1/sr; 0 below the horizon.

    Examples
    --------
    >>> t = BRDFTable([0.0, 90.0], [0.0, 90.0], [0.0, 180.0], [550.0],
    ...               np.arange(8.0).reshape(2, 2, 2, 1))
    >>> z = np.array([0.0, 0.0, 1.0]); w = np.array([np.sqrt(0.5), 0.0, np.sqrt(0.5)])
    >>> brdf_tabulated(w, z, z, t)  # θ_i = 45°, θ_o = 0°, Δφ = 0: halfway between 0 and 4
    array([2.])
    """
    require(isinstance(table, BRDFTable), "brdf_tabulated: table: must be a BRDFTable")
    theta_i, theta_o, phi_d = (np.degrees(a) for a in isotropic_angles(wi, wo, normal))
    above = (theta_i < 90.0) & (theta_o < 90.0)
    corners = [
        _linear_weights(axis, x)
        for axis, x in (
            (table.theta_i_deg, theta_i),
            (table.theta_o_deg, theta_o),
            (table.phi_d_deg, phi_d),
        )
    ]
    (ki, ti), (ko, to), (kp, tp) = corners
    step = [
        1 if axis.size > 1 else 0
        for axis in (table.theta_i_deg, table.theta_o_deg, table.phi_d_deg)
    ]
    f = np.zeros((*theta_i.shape, table.n_bands))
    # Trilinear interpolation: the 8 corners of the grid cell, weighted by their opposite volumes
    for a in (0, 1):
        wa = ti if a else 1.0 - ti
        for b in (0, 1):
            wb = to if b else 1.0 - to
            for c in (0, 1):
                wc = tp if c else 1.0 - tp
                value = table.values[ki + a * step[0], ko + b * step[1], kp + c * step[2]]
                f += (wa * wb * wc)[..., None] * value
    return np.where(above[..., None], f, 0.0)


# --- the text format --------------------------------------------------------------------------


def _fmt(x: float) -> str:
    # The shortest text that reads back as the same float64: write -> read is exact.
    return repr(float(x)).removesuffix(".0")


def write_brdf_table(path, table: BRDFTable, comments: dict | None = None) -> Path:
    """Write a table in specref's ASTM E1392-style text format, atomically.

    Parameters
    ----------
    path : str or Path
        Destination.
    table : BRDFTable
        The table.
    comments : dict, optional
        ``key: value`` lines for the header (sample, instrument, source, ...).

    Returns
    -------
    Path

    Examples
    --------
    >>> import tempfile, os
    >>> t = BRDFTable([0.0], [0.0, 30.0], [180.0], [450.0, 550.0], np.full((1, 2, 1, 2), 0.25))
    >>> with tempfile.TemporaryDirectory() as d:
    ...     text = write_brdf_table(os.path.join(d, "t.txt"), t).read_text()
    >>> print(text.splitlines()[-1])
    0 30 0 0.25 0.25
    """
    lines = [
        FORMAT_LINE,
        f"# name: {table.name}",
        "# units: theta_i, theta_s, phi_s in degrees; BRDF in 1/sr; wavelengths in nm",
        "# phi_s: 0 = specular side of the plane of incidence, 180 = towards the source",
    ]
    lines += [f"# {key}: {value}" for key, value in (comments or {}).items()]
    lines.append("theta_i theta_s phi_s " + " ".join(_fmt(w) for w in table.wavelengths_nm))
    for i, theta_i in enumerate(table.theta_i_deg):
        for o, theta_o in enumerate(table.theta_o_deg):
            # The file's φ_s runs from the specular side: φ_s = 180° − Δφ, in increasing order.
            for p in range(table.phi_d_deg.size - 1, -1, -1):
                phi_s = 180.0 - table.phi_d_deg[p]
                row = [theta_i, theta_o, phi_s, *table.values[i, o, p]]
                lines.append(" ".join(_fmt(x) for x in row))
    return write_text_atomic(path, "\n".join(lines) + "\n")


def read_brdf_table(path) -> BRDFTable:
    r"""Read a table in specref's ASTM E1392-style text format (``docs/brdf-format.md``).

    Parameters
    ----------
    path : str or Path
        The file.

    Returns
    -------
    BRDFTable
        Named after the file.

    Raises
    ------
    SpecrefError
        One line naming the file and line: unreadable file, no header, a row with the wrong number
        of columns or a non-number, an angle out of range, a negative or NaN value, a duplicated
        geometry, or a geometry missing from the grid.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = os.path.join(d, "b.txt")
    ...     _ = open(p, "w").write("theta_i theta_s phi_s 550\n0 0 0 0.3\n0 10 0 -1\n")
    ...     read_brdf_table(p)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: .../b.txt:3: BRDF at 550 nm: must be >= 0, got -1
    """
    path = Path(path)
    name, header, wavelengths, rows = _parse_brdf_table(_read_brdf_text(path), path)
    require(header is not None, f"{path}: no header line 'theta_i theta_s phi_s <wavelengths nm>'")
    require(rows, f"{path}: no data rows after the header (line {header})")
    axes = _brdf_table_axes(rows, path)
    values = np.empty((axes[0].size, axes[1].size, axes[2].size, wavelengths.size))
    for (theta_i, theta_s, phi_s), spectrum in rows.items():
        i = np.searchsorted(axes[0], theta_i)
        o = np.searchsorted(axes[1], theta_s)
        p = np.searchsorted(axes[2], phi_s)
        values[i, o, p] = spectrum
    # φ_s from the specular side becomes Δφ = 180° − φ_s, increasing.
    phi_d = 180.0 - axes[2][::-1]
    return BRDFTable(axes[0], axes[1], phi_d, wavelengths, values[:, :, ::-1], name=name)


def _read_brdf_text(path: Path) -> str:
    """The file's text, or a one-line error naming it."""
    try:
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise SpecrefError(f"{path}: file not found") from None
    except (OSError, UnicodeDecodeError) as error:
        raise SpecrefError(f"{path}: unreadable BRDF table ({error})") from None


def _parse_brdf_table(text: str, path: Path):
    """The table's name, header line number, wavelengths, and rows ``{(θ_i, θ_s, φ_s): values}``."""
    header, wavelengths, rows, where = None, None, {}, {}
    name = path.stem
    for number, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        if not line:
            continue
        if line.startswith("#"):
            key, _, value = line[1:].partition(":")
            if key.strip() == "name" and value.strip():
                name = value.strip()
            continue
        fields = line.replace(",", " ").split()
        if header is None:
            wavelengths, header = _brdf_table_header(fields, f"{path}:{number}"), number
            continue
        numbers = _brdf_table_row(fields, line, wavelengths, f"{path}:{number}")
        geometry = tuple(numbers[:3])
        if geometry in rows:
            theta_i, theta_s, phi_s = geometry
            raise SpecrefError(
                f"{path}:{number}: duplicated angles theta_i={theta_i:g} theta_s={theta_s:g} "
                f"phi_s={phi_s:g} (first at line {where[geometry]})"
            )
        rows[geometry], where[geometry] = numbers[3:], number
    return name, header, wavelengths, rows


def _brdf_table_header(fields: list[str], at: str) -> np.ndarray:
    """The wavelengths (nm) of a header ``theta_i theta_s phi_s <wavelengths>``, checked."""
    require(
        [f.lower() for f in fields[:3]] == ["theta_i", "theta_s", "phi_s"],
        f"{at}: header: must start with 'theta_i theta_s phi_s', got {' '.join(fields[:3])!r}",
    )
    try:
        wavelengths = np.array([float(f) for f in fields[3:]])
    except ValueError:
        raise SpecrefError(
            f"{at}: header: wavelength columns must be numbers (nm), got {' '.join(fields[3:])!r}"
        ) from None
    require(
        wavelengths.size >= 1 and bool((wavelengths > 0).all()),
        f"{at}: header: needs at least one positive wavelength column (nm)",
    )
    return wavelengths


def _brdf_table_row(fields: list[str], line: str, wavelengths, at: str) -> list[float]:
    """A data row's numbers ``theta_i, theta_s, phi_s, BRDF...``, checked: angles and values."""
    require(
        len(fields) == 3 + wavelengths.size,
        f"{at}: expected {3 + wavelengths.size} columns "
        f"(theta_i theta_s phi_s and {wavelengths.size} BRDF values), got {len(fields)}",
    )
    try:
        numbers = [float(f) for f in fields]
    except ValueError:
        raise SpecrefError(f"{at}: not a number in {line!r:.80}") from None
    theta_i, theta_s, phi_s = numbers[:3]
    for label, value, high in (
        ("theta_i", theta_i, 90.0),
        ("theta_s", theta_s, 90.0),
        ("phi_s", phi_s, 180.0),
    ):
        require(
            np.isfinite(value) and 0.0 <= value <= high,
            f"{at}: {label}: must be in [0, {high:g}] degrees, got {value:g}",
        )
    for lam, value in zip(wavelengths, numbers[3:], strict=True):
        require(np.isfinite(value), f"{at}: BRDF at {lam:g} nm: must be finite, got {value}")
        require(value >= 0, f"{at}: BRDF at {lam:g} nm: must be >= 0, got {value:g}")
    return numbers


def _brdf_table_axes(rows: dict, path: Path) -> list[np.ndarray]:
    """The grid's θ_i, θ_s and φ_s nodes; an error names a geometry the rows miss."""
    axes = [np.unique([g[k] for g in rows]) for k in range(3)]
    expected = axes[0].size * axes[1].size * axes[2].size
    if len(rows) != expected:
        for geometry in np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3):
            if tuple(geometry) not in rows:
                theta_i, theta_s, phi_s = geometry
                raise SpecrefError(
                    f"{path}: missing angles theta_i={theta_i:g} theta_s={theta_s:g} "
                    f"phi_s={phi_s:g}: the rows must cover every combination of the "
                    f"{axes[0].size} theta_i, {axes[1].size} theta_s and {axes[2].size} phi_s "
                    f"values"
                )
    return axes


def _table_example(rng):
    from reference.materials.isotropic import brdf_ggx

    return {
        "table": tabulate_brdf(
            brdf_ggx,
            {"rho_d": 0.3, "F_0": 0.04, "alpha": 0.3},
            np.linspace(0, 90, 10),
            np.linspace(0, 180, 7),
            [550.0],
        )
    }


register_brdf(
    BRDFMethod(
        "table",
        brdf_tabulated,
        None,
        "Nicodemus et al. 1977 (tabulated f(θ_i, θ_o, Δφ))",
        _table_example,
        sample=_cosine_sample,
        pdf=_cosine_pdf,
        params=_table_example(None),
        albedo_bound="that of the tabulated data",
        isotropic=True,
    )
)

"""Typed values of scene files: numbers, vectors, choices, files and spectra, with one-line errors.

A :class:`SceneReader` reads the values of one scene file. Every reader method takes the raw TOML
value and its dotted key path (``materials.gold.n``, ``objects[0].radius``), checks the type and
range, and raises :class:`~reference.errors.SpecrefError` with a message of the fixed form
``scene.toml: materials.gold.n: must be >= 0, got -3``: the file, the key, what is allowed and what
was given. Scene parsers (``reference.scene.loader``) and the parameter parsers of registered
material types use these readers, so every scene value is checked the same way.

Spectra in scenes take the forms registered in :data:`SPECTRUM_FORMS`:

- a number, or ``{ constant = 0.5 }``: a constant spectrum;
- ``{ illuminant = "D65" }``, ``{ light_source = "..." }``, ``{ colorchecker = "dark skin" }``
  (optional ``set``): colour-science datasets;
- ``{ csv = "path", column = ..., row = ..., scale = ... }``: a CSV file, the path relative to the
  scene file or ``data:<name>`` for a file shipped with specref (:mod:`reference.data`);
- ``{ wavelengths = [...], values = [...] }``: inline arrays.

Each table form takes the optional keys ``extrapolation`` and ``interpolation``, which are handed to
:func:`reference.colour.spectra.resample_spectrum`: a spectrum that does not cover the scene's grid
is refused unless the scene says how to extend it.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reference.colour.spectra import (
    DEFAULT_GRID,
    EXTRAPOLATIONS,
    INTERPOLATIONS,
    SpectralGrid,
    Spectrum,
    make_spectrum,
    resample_spectrum,
    spectrum_constant,
    spectrum_from_csv,
    spectrum_from_dataset,
)
from reference.data import resolve_path
from reference.errors import SpecrefError, format_allowed
from reference.registry import Registry

__all__ = ["MAX_SCENE_NUMBER", "SPECTRUM_FORMS", "SceneReader", "SpectrumForm", "SpectrumSpec"]

#: Keys every spectrum table may carry besides its form key.
RESAMPLING_KEYS = ("extrapolation", "interpolation")
#: The largest magnitude of any number in a scene file: far beyond any scene's (metres, relative
#: intensities, radiance), small enough that products and squares stay finite in float32 outputs.
MAX_SCENE_NUMBER = 1e12


def _shown(value) -> str:
    """A short repr of a user value for messages (long values are cut)."""
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


@dataclass(frozen=True)
class SpectrumSpec:
    """A spectrum read from a scene, with how to resample it onto the grid.

    Attributes
    ----------
    spectrum : Spectrum
        The spectrum at its native sampling.
    extrapolation, interpolation : str
        Handed to :func:`reference.colour.spectra.resample_spectrum`.
    key : str
        Where it was read (``scene.toml: lights[0].spectrum``), for messages.
    """

    spectrum: Spectrum
    extrapolation: str = "error"
    interpolation: str = "linear"
    key: str = "spectrum"


@dataclass
class SceneReader:
    """Reads and checks the values of one scene file.

    Parameters
    ----------
    file : str
        The file's label in messages (the path as the user gave it, or ``"<string>"``).
    base_dir : Path
        Folder that relative paths (CSV spectra, OBJ meshes, environment maps) are resolved in.
    grid : SpectralGrid
        The scene's wavelength grid (set once the ``[spectral]`` table is read).

    Examples
    --------
    >>> r = SceneReader("scene.toml")
    >>> r.number(-3, "materials.gold.n", minimum=0)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: scene.toml: materials.gold.n: must be >= 0, got -3
    >>> r.spectrum_on_grid(0.5, "materials.grey.k_d")[:3]
    array([0.5, 0.5, 0.5])
    """

    file: str = "<string>"
    base_dir: Path = field(default_factory=Path)
    grid: SpectralGrid = DEFAULT_GRID

    # --- messages -------------------------------------------------------------------------------

    def fail(self, key: str, message: str):
        """Raise ``SpecrefError("<file>: <key>: <message>")`` (no file part if ``file`` is "")."""
        prefix = f"{self.file}: " if self.file else ""
        raise SpecrefError(f"{prefix}{key}: {message}")

    @contextlib.contextmanager
    def context(self, key: str, alias: str | None = None):
        """Prefix errors raised inside with ``<file>: <key>: `` (unless they name the file already).

        A message that starts with ``alias`` (the name a library class uses for the same thing, e.g.
        a material's name) has that prefix replaced by ``key``.
        """
        try:
            yield
        except SpecrefError as error:
            message = str(error)
            if message.startswith(f"{self.file}: "):
                raise
            if alias and message.startswith(alias) and message[len(alias) : len(alias) + 1] in ".:":
                raise SpecrefError(f"{self.file}: {key}{message[len(alias) :]}") from None
            raise SpecrefError(f"{self.file}: {key}: {message}") from None

    # --- tables ---------------------------------------------------------------------------------

    def table(
        self, value, key: str, allowed: Iterable[str] | None = None, required: Iterable[str] = ()
    ) -> dict:
        """Check that ``value`` is a table whose keys are allowed and include ``required``.

        Examples
        --------
        >>> SceneReader("s.toml").table({"fov": 30}, "camera", ["eye", "fov_deg"])
        Traceback (most recent call last):
        ...
        reference.errors.SpecrefError: s.toml: camera: unknown key 'fov'; allowed: eye, fov_deg
        """
        if not isinstance(value, dict):
            self.fail(key, f"must be a table, got {_shown(value)}")
        if allowed is not None:
            allowed = list(allowed)
            for name in value:
                if name not in allowed:
                    self.fail(key, f"unknown key {name!r}; allowed: {format_allowed(allowed)}")
        for name in required:
            if name not in value:
                self.fail(key, f"missing key {name!r}")
        return value

    def array_of_tables(self, value, key: str) -> list:
        """Check that ``value`` is a list of tables (``[[objects]]``)."""
        if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
            self.fail(key, f"must be an array of tables ([[{key}]]), got {_shown(value)}")
        return value

    # --- scalars --------------------------------------------------------------------------------

    def number(
        self,
        value,
        key: str,
        minimum: float | None = None,
        maximum: float | None = None,
        exclusive_minimum: bool = False,
        exclusive_maximum: bool = False,
    ) -> float:
        """A finite number (TOML integer or float, not a boolean) within optional bounds.

        Every number is within :data:`MAX_SCENE_NUMBER` of zero: an intensity of 1e308 or a
        position of 1e300 wrote infinities and NaN into the image.

        Examples
        --------
        >>> SceneReader("s.toml").number(0, "render.exposure", minimum=0, exclusive_minimum=True)
        Traceback (most recent call last):
        ...
        reference.errors.SpecrefError: s.toml: render.exposure: must be > 0, got 0
        """
        if isinstance(value, bool) or not isinstance(value, int | float):
            self.fail(key, f"must be a number, got {_shown(value)}")
        try:
            number = float(value)
        except OverflowError:
            number = math.inf
        if not math.isfinite(number):
            self.fail(key, f"must be finite, got {_shown(value)}")
        if abs(number) > MAX_SCENE_NUMBER:
            self.fail(
                key,
                f"must be within ±{MAX_SCENE_NUMBER:g} (larger values overflow the render's "
                f"arithmetic), got {value!r}",
            )
        if minimum is not None:
            low = number <= minimum if exclusive_minimum else number < minimum
            if low:
                self.fail(
                    key, f"must be {'>' if exclusive_minimum else '>='} {minimum:g}, got {value!r}"
                )
        if maximum is not None:
            high = number >= maximum if exclusive_maximum else number > maximum
            if high:
                self.fail(
                    key, f"must be {'<' if exclusive_maximum else '<='} {maximum:g}, got {value!r}"
                )
        return number

    def integer(self, value, key: str, minimum: int, maximum: int) -> int:
        """An integer in ``[minimum, maximum]`` (a float with an integer value is accepted).

        Examples
        --------
        >>> SceneReader("s.toml").integer(0, "render.width", 1, 16384)
        Traceback (most recent call last):
        ...
        reference.errors.SpecrefError: s.toml: render.width: must be an integer in [1, 16384], got 0
        """
        ok = isinstance(value, int) and not isinstance(value, bool)
        if isinstance(value, float) and math.isfinite(value) and value.is_integer():
            value, ok = int(value), True
        if not ok or not minimum <= value <= maximum:
            self.fail(key, f"must be an integer in [{minimum}, {maximum}], got {_shown(value)}")
        return int(value)

    def vector(self, value, key: str, n: int = 3) -> tuple[float, ...]:
        """A list of ``n`` finite numbers.

        Examples
        --------
        >>> SceneReader("s.toml").vector([0, 1, 2.5], "camera.eye")
        (0.0, 1.0, 2.5)
        """
        if not isinstance(value, list) or len(value) != n:
            self.fail(key, f"must be a list of {n} numbers, got {_shown(value)}")
        return tuple(self.number(v, f"{key}[{i}]") for i, v in enumerate(value))

    def boolean(self, value, key: str) -> bool:
        """A TOML boolean (``true`` or ``false``)."""
        if not isinstance(value, bool):
            self.fail(key, f"must be true or false, got {_shown(value)}")
        return value

    def string(self, value, key: str) -> str:
        """A non-empty string."""
        if not isinstance(value, str) or not value:
            self.fail(key, f"must be a non-empty string, got {_shown(value)}")
        return value

    def choice(self, value, key: str, allowed: Iterable[str]) -> str:
        """One of ``allowed``.

        Examples
        --------
        >>> SceneReader("s.toml").choice("sRBG", "display.encoding", ["srgb", "linear"])
        Traceback (most recent call last):
        ...
        reference.errors.SpecrefError: s.toml: display.encoding: unknown value 'sRBG'; allowed:
        linear, srgb
        """
        allowed = list(allowed)
        if not isinstance(value, str) or value not in allowed:
            self.fail(key, f"unknown value {_shown(value)}; allowed: {format_allowed(allowed)}")
        return value

    def file_path(self, value, key: str) -> Path:
        """An existing file: ``data:<name>`` (shipped with specref), else relative to the scene.

        ``data:`` names a file of the package data (:mod:`reference.data`), so a scene renders from
        any folder and from an installed wheel; any other relative path is relative to the scene
        file's folder.

        Examples
        --------
        >>> SceneReader("s.toml", Path("/tmp")).file_path("nope.csv", "materials.red.k_d.csv")
        Traceback (most recent call last):
        ...
        reference.errors.SpecrefError: s.toml: materials.red.k_d.csv: file not found: /tmp/nope.csv
        >>> reader = SceneReader("s.toml", Path("/tmp"))
        >>> reader.file_path("data:environments/venice_sunset_1k.hdr", "lights[0].file").name
        'venice_sunset_1k.hdr'
        """
        name = self.string(value, key)
        if "\x00" in name:
            self.fail(key, f"not a valid path, got {_shown(name)}")
        try:
            path = resolve_path(name, self.base_dir)
        except SpecrefError as error:
            self.fail(key, str(error))
        try:
            found = path.is_file()
        except (OSError, ValueError) as error:
            self.fail(key, f"not a usable path ({error.__class__.__name__}): {_shown(name)}")
        if not found:
            self.fail(key, f"file not found: {path}")
        return path

    # --- spectra --------------------------------------------------------------------------------

    def spectrum_spec(self, value, key: str) -> SpectrumSpec:
        """Read a spectrum in any form of :data:`SPECTRUM_FORMS` (or a bare number).

        Examples
        --------
        >>> spec = SceneReader("s.toml").spectrum_spec({"illuminant": "A"}, "lights[0].spectrum")
        >>> spec.spectrum.name, spec.extrapolation
        ('illuminant:A', 'error')
        """
        if isinstance(value, int | float) and not isinstance(value, bool):
            constant = self.number(value, key, minimum=0)
            return SpectrumSpec(spectrum_constant(constant, f"{self.file}: {key}"), key=key)
        if not isinstance(value, dict):
            self.fail(
                key,
                f"must be a number or a spectrum table with one of "
                f"{format_allowed(SPECTRUM_FORMS)}, got {_shown(value)}",
            )
        forms = [name for name in value if name in SPECTRUM_FORMS]
        if len(forms) != 1:
            self.fail(
                key,
                f"a spectrum table needs exactly one of {format_allowed(SPECTRUM_FORMS)}, got "
                f"keys: {format_allowed(value) or 'none'}",
            )
        form: SpectrumForm = SPECTRUM_FORMS.lookup(forms[0])
        self.table(value, key, (form.name, *form.keys, *RESAMPLING_KEYS))
        extrapolation = self.choice(
            value.get("extrapolation", "error"), f"{key}.extrapolation", EXTRAPOLATIONS
        )
        interpolation = self.choice(
            value.get("interpolation", "linear"), f"{key}.interpolation", INTERPOLATIONS
        )
        with self.context(key):
            spectrum = form.parse(self, value, key)
        return SpectrumSpec(spectrum, extrapolation, interpolation, key)

    def spectrum_on_grid(self, value, key: str) -> np.ndarray:
        """Read a spectrum and resample it onto the grid: shape ``(n_bands,)``, finite, >= 0.

        Examples
        --------
        >>> r = SceneReader("s.toml")
        >>> r.spectrum_on_grid({"wavelengths": [400, 700], "values": [0.2, 0.8]}, "k_d")
        Traceback (most recent call last):
        ...
        reference.errors.SpecrefError: s.toml: k_d: covers 400-700 nm but the grid needs 380-780 nm;
        set extrapolation to one of: constant, linear, zero
        """
        spec = self.spectrum_spec(value, key)
        with self.context(key, alias=spec.spectrum.name):
            return resample_spectrum(
                spec.spectrum, self.grid, spec.extrapolation, spec.interpolation
            )

    def light_spectrum(self, value, key: str) -> Spectrum:
        """Read a light's spectrum, which band weights fold in at its own sampling.

        The spectrum must cover the grid unless ``extrapolation`` says how to extend it; then (and
        for ``interpolation = "sprague"``) it is resampled at 1 nm over the grid and its own range,
        so the band weights see the extension the scene asked for.

        Examples
        --------
        >>> SceneReader("s.toml").light_spectrum({"illuminant": "FL2"}, "lights[0].spectrum")
        Spectrum('illuminant:FL2', 380-780 nm, 81 samples)
        """
        spec = self.spectrum_spec(value, key)
        spectrum = spec.spectrum
        if spectrum.constant:
            return spectrum
        with self.context(key, alias=spectrum.name):
            resample_spectrum(spectrum, self.grid, spec.extrapolation, spec.interpolation)
            wl = spectrum.wavelengths_nm
            covers = wl[0] <= self.grid.start_nm and wl[-1] >= self.grid.end_nm
            if covers and spec.interpolation == "linear":
                return spectrum
            # The grid plus the spectrum's own range within the ASTM E308 practice range 360-780.
            start = math.floor(min(self.grid.start_nm, max(360.0, wl[0])))
            end = math.ceil(max(self.grid.end_nm, min(780.0, wl[-1])))
            fine = SpectralGrid(float(start), float(end), 1.0)
            values = resample_spectrum(spectrum, fine, spec.extrapolation, spec.interpolation)
            # Sprague can ring below 0 next to sharp features: make_spectrum refuses that.
            return make_spectrum(fine.wavelengths_nm, values, spectrum.name)


# --- spectrum forms
# ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class SpectrumForm:
    """One way to write a spectrum in a scene: the table key that selects it and its parser.

    Parameters
    ----------
    name : str
        The key that selects the form (``"illuminant"``).
    parse : callable
        ``parse(reader, table, key) -> Spectrum``.
    keys : tuple of str
        Further keys the form accepts (besides ``extrapolation`` and ``interpolation``).
    doc : str
        One line for ``docs/scene-format.md``.
    """

    name: str
    parse: Callable[[SceneReader, dict, str], Spectrum]
    keys: tuple = ()
    doc: str = ""


def _parse_constant(reader: SceneReader, table: dict, key: str) -> Spectrum:
    value = reader.number(table["constant"], f"{key}.constant", minimum=0)
    return spectrum_constant(value, f"{reader.file}: {key}")


def _dataset_parser(dataset: str):
    def parse(reader: SceneReader, table: dict, key: str) -> Spectrum:
        name = reader.string(table[dataset], f"{key}.{dataset}")
        set_name = None
        if "set" in table:
            set_name = reader.string(table["set"], f"{key}.set")
        with reader.context(f"{key}.{dataset}"):
            return spectrum_from_dataset(dataset, name, set_name)

    return parse


def _parse_csv(reader: SceneReader, table: dict, key: str) -> Spectrum:
    path = reader.file_path(table["csv"], f"{key}.csv")
    column = table.get("column")
    if column is not None and not (
        isinstance(column, str) or (isinstance(column, int) and not isinstance(column, bool))
    ):
        reader.fail(f"{key}.column", f"must be a header name or a 1-based index, got {column!r}")
    if isinstance(column, int):
        reader.integer(column, f"{key}.column", 1, 10**6)
    row = reader.integer(table.get("row", 0), f"{key}.row", 0, 10**9)
    scale = reader.number(table.get("scale", 1.0), f"{key}.scale", minimum=0)
    return spectrum_from_csv(path, column=column, row=row, scale=scale)


def _parse_arrays(reader: SceneReader, table: dict, key: str) -> Spectrum:
    if "values" not in table:
        reader.fail(key, "inline spectrum needs 'values' beside 'wavelengths'")
    arrays = {}
    for name in ("wavelengths", "values"):
        value = table[name]
        if not isinstance(value, list):
            reader.fail(f"{key}.{name}", f"must be a list of numbers, got {_shown(value)}")
        for i, v in enumerate(value):
            if isinstance(v, bool) or not isinstance(v, int | float):
                reader.fail(f"{key}.{name}[{i}]", f"must be a number, got {_shown(v)}")
        try:
            arrays[name] = np.array(value, dtype=np.float64)
        except OverflowError:
            reader.fail(f"{key}.{name}", "numbers out of range")
    return make_spectrum(arrays["wavelengths"], arrays["values"], f"{reader.file}: {key}")


#: Spectrum forms by the table key that selects them; a new form is registered here.
SPECTRUM_FORMS = Registry("spectrum form", SpectrumForm)
SPECTRUM_FORMS.register(
    SpectrumForm("constant", _parse_constant, (), "a constant (a bare number works too)")
)
SPECTRUM_FORMS.register(
    SpectrumForm(
        "illuminant",
        _dataset_parser("illuminant"),
        (),
        "a colour-science illuminant (`colour.SDS_ILLUMINANTS`): A, D50, D65, FL2, LED-B1, ...",
    )
)
SPECTRUM_FORMS.register(
    SpectrumForm(
        "light_source",
        _dataset_parser("light_source"),
        (),
        "a colour-science light source (`colour.SDS_LIGHT_SOURCES`)",
    )
)
SPECTRUM_FORMS.register(
    SpectrumForm(
        "colorchecker",
        _dataset_parser("colorchecker"),
        ("set",),
        "a ColorChecker patch by name; `set` picks the measurement (default ColorChecker N Ohta)",
    )
)
SPECTRUM_FORMS.register(
    SpectrumForm(
        "csv",
        _parse_csv,
        ("column", "row", "scale"),
        "a CSV file (path relative to the scene file), long or wide layout",
    )
)
SPECTRUM_FORMS.register(
    SpectrumForm(
        "wavelengths",
        _parse_arrays,
        ("values",),
        "inline arrays: strictly increasing wavelengths (nm) and values >= 0",
    )
)

"""Wang, Chern & Lee's WYSIWYG spectral material editor (§1, §5, Wang et al.): the Python side.

``specref phong edit`` (``phong_table.editor.app``) shows four curves, the light spectrum
``I_p(λ)``, ``k_d(λ)``, ``k_s(λ)`` and ``n(λ)`` of Eq. (2), Wang et al. Each curve is kept whole,
at its own sampling (the material's three on the 41-band grid, the light at the wavelengths of its
file or preset: FL2's mercury lines stay), and edited through control points at every fourth
wavelength of the grid (Erratum E28): moving a point adds to the curve a displacement that is
linear in ``λ`` between the point's neighbours (``n``: a factor, linear in ``log n``), so what lies
between the points is kept. This module holds everything the page does that is not layout:

- :class:`EditorState`: the curves, their control points, the material they make
  (:meth:`EditorState.model`), presets, open and save (the documented material-file format,
  ``docs/scene-format.md``, atomic write; open then save writes what was opened);
- :func:`render_table_frame` and :func:`render_exact_frame`: the sphere through the table path
  (every edit) and the exact path (after a drag ends), with the RMS of Table 1 and the timings;
- :class:`LatestWorker`: a thread that renders only the newest request and drops the stale ones.

Examples
--------
>>> state = EditorState.default()
>>> len(state.control_nm), state.model().grid.n_bands, state.curve_wavelengths("light").size
(11, 41, 81)
"""

from __future__ import annotations

import math
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from phong_table.materialfile import load_material_file
from phong_table.model import SpectralPhong
from phong_table.render import rms_8bit, shade_pixels, shading_buffer, sphere_gbuffer
from phong_table.scenes import LIGHT_ATTENUATION, LIGHT_POSITION
from phong_table.table import build_table, check_interpolation
from reference.colour.spectra import DEFAULT_GRID, Spectrum
from reference.display.encodings import linear_to_display
from reference.errors import SpecrefError, require
from reference.files import write_text_atomic
from reference.materials.types import PhongMaterial
from reference.scene.lights import PointLight

__all__ = [
    "CURVES",
    "EditorState",
    "LatestWorker",
    "difference_gain",
    "difference_rgba",
    "illuminant_presets",
    "measured_presets",
    "render_exact_frame",
    "render_table_frame",
]

#: The four edited curves: key -> (label, lower bound, upper bound, log axis).
CURVES = {
    "light": ("light spectrum I_p(λ)", 0.0, 3.0, False),
    "k_d": ("diffuse k_d(λ)", 0.0, 1.0, False),
    "k_s": ("specular k_s(λ)", 0.0, 1.0, False),
    "n": ("exponent n(λ)", 1.0, 10000.0, True),
}

#: Every fourth wavelength of the grid carries a control point (Erratum E28).
CONTROL_STRIDE = 4


def measured_presets(folder=None) -> dict[str, np.ndarray]:
    """Reflectances of ``<folder>/*__nix_export.csv`` on the grid, by material name.

    ``folder`` defaults to the 18 measurements shipped with specref
    (:func:`reference.data.measured_spectra_folder`); a folder without such files gives ``{}``.

    Examples
    --------
    >>> presets = measured_presets()
    >>> len(presets), presets["lemon"].shape
    (18, (41,))
    >>> measured_presets("/nonexistent")
    {}
    """
    from reference.colour.spectra import resample_spectrum, spectrum_from_csv
    from reference.data import measured_spectra_folder

    folder = Path(folder) if folder is not None else measured_spectra_folder()
    out = {}
    for path in sorted(folder.glob("*__nix_export.csv")):
        name = path.name.split("__")[0]
        spectrum = spectrum_from_csv(path, name=name)
        values = resample_spectrum(spectrum, DEFAULT_GRID, extrapolation="constant")
        out[name] = np.clip(values, 0.0, 1.0)
    return out


def illuminant_presets(names=("A", "D50", "D65", "FL2", "FL11", "E")) -> dict[str, tuple]:
    """colour-science's CIE illuminants at their own sampling over 380-780 nm, 1 at 560 nm.

    Returns
    -------
    dict of str to (ndarray, ndarray)
        ``name -> (wavelengths in nm, relative power)``: the tabulated samples (5 nm for every
        CIE illuminant here) within the grid's range, not resampled, so FL2's and FL11's mercury
        lines keep their height.

    Examples
    --------
    >>> wl, values = illuminant_presets(("FL2",))["FL2"]
    >>> wl.size, float(wl[1] - wl[0]), round(float(np.interp(560.0, wl, values)), 6)
    (81, 5.0, 1.0)
    """
    from reference.colour.spectra import spectrum_from_dataset

    out = {}
    for name in names:
        spectrum = spectrum_from_dataset("illuminant", name)
        wl, values = spectrum.wavelengths_nm, spectrum.values
        keep = (wl >= DEFAULT_GRID.start_nm) & (wl <= DEFAULT_GRID.end_nm)
        wl, values = wl[keep].astype(np.float64), values[keep].astype(np.float64)
        out[name] = (wl, values / np.interp(560.0, wl, values))
    return out


@dataclass
class EditorState:
    """The edited material: four curves, their control points, the light's intensity, a name.

    A curve is its ``base`` (the samples it was opened or preset with) plus the displacement
    its control points make (:meth:`curve`); with no point moved, :meth:`curve` is the base, bit
    for bit.

    Attributes
    ----------
    control_nm : ndarray, shape (K,)
        The control wavelengths (nm), every ``CONTROL_STRIDE``-th of the grid and its last.
    points : dict of str to ndarray, shape (K,)
        ``light``, ``k_d``, ``k_s``, ``n`` at the control wavelengths (what the page drags).
    intensity : float
        The light's intensity (kept fixed while editing, so the picture answers to the curves).
    name : str
        The material's name.
    base : dict of str to (ndarray, ndarray)
        Each curve's samples before the edit: ``(wavelengths in nm, values)``; ``k_d``, ``k_s``
        and ``n`` on the grid, the light at its own sampling. Missing keys are made from the
        points (the polyline through them).
    """

    control_nm: np.ndarray
    points: dict
    intensity: float = 1.0
    name: str = "edited"
    grid: object = field(default=DEFAULT_GRID, repr=False)
    base: dict = field(default_factory=dict, repr=False)

    def __post_init__(self):
        wl = self.grid.wavelengths_nm
        for key in CURVES:
            if key not in self.base:
                values = np.asarray(self.points[key], dtype=np.float64)
                polyline = (
                    np.exp(np.interp(wl, self.control_nm, np.log(values)))
                    if CURVES[key][3]
                    else np.interp(wl, self.control_nm, values)
                )
                self.base[key] = (wl.copy(), polyline)

    @classmethod
    def default(cls) -> EditorState:
        """A grey plastic with a bluish, sharper highlight in the blue, under D65."""
        wl = DEFAULT_GRID.wavelengths_nm
        base = {
            "light": illuminant_presets(("D65",))["D65"],
            "k_d": (wl.copy(), np.full(wl.size, 0.3)),
            "k_s": (wl.copy(), np.full(wl.size, 0.5)),
            "n": (wl.copy(), 20.0 * np.exp(2.0 * (700.0 - wl) / 300.0)),
        }
        state = cls.from_curves(base)
        state.intensity = state.unit_peak_intensity()
        return state

    @classmethod
    def from_curves(cls, base: dict, intensity=1.0, name="edited", grid=DEFAULT_GRID):
        """A state whose curves are ``base`` (``key -> (wavelengths, values)``), no point moved.

        Examples
        --------
        >>> wl = DEFAULT_GRID.wavelengths_nm
        >>> flat = {key: (wl, np.full(41, 2.0)) for key in CURVES}
        >>> EditorState.from_curves(flat).points["k_s"][:3].tolist()
        [2.0, 2.0, 2.0]
        """
        control_nm = grid.wavelengths_nm[::CONTROL_STRIDE].copy()
        base = {
            key: tuple(np.asarray(a, dtype=np.float64).copy() for a in base[key]) for key in CURVES
        }
        points = {key: _sample(key, *base[key], control_nm) for key in CURVES}
        return cls(control_nm, points, float(intensity), name, grid, base)

    @classmethod
    def from_model(cls, model: SpectralPhong, name: str | None = None) -> EditorState:
        """The curves of a material and its light, kept whole (the light at its own sampling)."""
        grid = model.grid
        require(
            grid.n_bands == DEFAULT_GRID.n_bands and grid.start_nm == DEFAULT_GRID.start_nm,
            f"editor: the material's grid {grid.label} is not the editor's {DEFAULT_GRID.label}",
        )
        wl = grid.wavelengths_nm
        spectrum = model.light.spectrum
        light = (
            (wl, np.full(wl.size, float(spectrum.values[0])))
            if spectrum.constant
            else (spectrum.wavelengths_nm, spectrum.values)
        )
        m = model.material
        base = {"light": light, "k_d": (wl, m.k_d), "k_s": (wl, m.k_s), "n": (wl, m.n)}
        return cls.from_curves(base, float(model.light.intensity), name or m.name, grid)

    def curve_wavelengths(self, key: str) -> np.ndarray:
        """The wavelengths (nm) :meth:`curve` is sampled at: the grid, or the light's own."""
        return self.base[key][0]

    def curve(self, key: str) -> np.ndarray:
        """A curve at :meth:`curve_wavelengths`: its base plus the control points' displacement.

        The displacement is ``Δ_j = p_j − base(λ_j)`` at the control wavelengths ``λ_j``, linear in
        ``λ`` between them; for ``n`` (log axis) a factor ``p_j / base(λ_j)``, linear in ``log``.
        Where it is not zero the result is clipped to the curve's bounds; elsewhere it is the
        base, unchanged (Erratum E28).

        Examples
        --------
        >>> state = EditorState.default()
        >>> wl, before = state.curve_wavelengths("light"), state.curve("light")
        >>> state.set_point("light", 10, 0.5)  # 780 nm: only 740-780 nm move
        >>> moved = wl[state.curve("light") != before]
        >>> float(moved.min()), float(moved.max())
        (745.0, 780.0)
        """
        wl, base = self.base[key]
        at_control = _sample(key, wl, base, self.control_nm)
        low, high, log = CURVES[key][1], CURVES[key][2], CURVES[key][3]
        points = np.asarray(self.points[key], dtype=np.float64)
        if log:
            shift = np.interp(wl, self.control_nm, np.log(points) - np.log(at_control))
            edited = base * np.exp(shift)
        else:
            shift = np.interp(wl, self.control_nm, points - at_control)
            edited = base + shift
        return np.where(shift != 0.0, np.clip(edited, low, high), base)

    def set_point(self, key: str, index: int, value: float) -> None:
        """Move one control point, clipped to the curve's bounds (what a drag does)."""
        require(key in CURVES, f"editor: unknown curve {key!r}; allowed: {', '.join(CURVES)}")
        low, high = CURVES[key][1], CURVES[key][2]
        value = float(value)
        require(math.isfinite(value), f"editor: {key}[{index}]: must be finite, got {value}")
        self.points[key][int(index)] = min(max(value, low), high)

    def set_curve(self, key: str, values, wavelengths=None) -> None:
        """Replace a curve by a preset: its samples become the base, no point moved.

        ``wavelengths`` (nm) defaults to the grid; ``k_d``, ``k_s`` and ``n`` are resampled
        onto the grid (where the material lives), the light keeps its own sampling.
        """
        grid_nm = self.grid.wavelengths_nm
        wl = grid_nm if wavelengths is None else np.asarray(wavelengths, dtype=np.float64)
        values = np.asarray(values, dtype=np.float64)
        if key != "light" and not np.array_equal(wl, grid_nm):
            wl, values = grid_nm, np.interp(grid_nm, wl, values)
        self.base[key] = (wl.copy(), values.copy())
        self.points[key] = _sample(key, wl, values, self.control_nm)

    def model(self) -> SpectralPhong:
        """The material and light of the curves (Eq. (2), Wang et al.)."""
        phong = PhongMaterial(self.curve("k_d"), self.curve("k_s"), self.curve("n"), name=self.name)
        wl = self.curve_wavelengths("light")
        spectrum = Spectrum(wl.copy(), self.curve("light"), name="edited light")
        light = PointLight(LIGHT_POSITION, spectrum, self.intensity, LIGHT_ATTENUATION)
        return SpectralPhong(phong, light, grid=self.grid)

    def unit_peak_intensity(self) -> float:
        """The intensity that makes ``max_c (D_c + f_sp,c(1))`` display white (as the scenes do)."""
        self.intensity = 1.0
        model = self.model()
        peak = float((model.diffuse_RGB + model.specular(1.0)).max())
        return 1.0 / peak if peak > 0 else 1.0

    def material_text(self) -> str:
        """The material file (``docs/scene-format.md``, Phong material files) of the curves.

        Values are written in Python's shortest round-trip form, so reading the file gives the
        same floats; the light at its own wavelengths.
        """

        def spectrum(key):
            wl = ", ".join(repr(float(w)) for w in self.curve_wavelengths(key))
            values = ", ".join(repr(float(v)) for v in self.curve(key))
            return f"{{ wavelengths = [{wl}], values = [{values}] }}"

        lines = [
            "# written by specref phong edit",
            f"name = {_toml_string(self.name)}",
            "",
            "[material]",
            *(f"{key} = {spectrum(key)}" for key in ("k_d", "k_s", "n")),
            "",
            "[light]",
            f"spectrum = {spectrum('light')}",
            f"position = [{', '.join(repr(float(c)) for c in LIGHT_POSITION)}]",
            f"intensity = {self.intensity!r}",
            f"attenuation = [{', '.join(repr(float(c)) for c in LIGHT_ATTENUATION)}]",
        ]
        return "\n".join(lines) + "\n"

    def save(self, path) -> Path:
        """Write the material file atomically (temporary file, then rename)."""
        require(str(path).strip() != "", "save: give a file name ending in .toml")
        return write_text_atomic(Path(path), self.material_text())

    @classmethod
    def open(cls, path) -> EditorState:
        """Read a material file through ``phong_table.materialfile.load_material_file``."""
        return cls.from_model(load_material_file(path))


def _sample(key: str, wavelengths, values, at_nm) -> np.ndarray:
    """A curve's samples read at other wavelengths: linear in λ (``n``: in ``log n``)."""
    if CURVES[key][3]:
        return np.exp(np.interp(at_nm, wavelengths, np.log(values)))
    return np.interp(at_nm, wavelengths, values)


def _toml_string(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


@dataclass
class Frame:
    """One rendered sphere: display RGBA (uint8, (H, W, 4), first row at the bottom) and facts."""

    rgba: np.ndarray
    linear: np.ndarray
    info: dict


def _rgba(geometry, pixels_linear) -> np.ndarray:
    image = geometry.to_image(linear_to_display(np.clip(pixels_linear, 0.0, 1.0), "srgb"))
    rgba = np.full((*image.shape[:2], 4), 255, dtype=np.uint8)
    rgba[..., :3] = np.round(np.clip(image, 0.0, 1.0) * 255.0).astype(np.uint8)
    return rgba[::-1].copy()


def render_table_frame(
    model: SpectralPhong,
    view: str = "far",
    resolution: int = 256,
    placement: str = "error",
    interpolation: str = "monotone",
    entries: int = 200,
    exact: np.ndarray | None = None,
) -> Frame:
    """The sphere through the table path (build, then deferred shading); never the exact path.

    ``info`` holds the table's ``nodes`` and ``values`` (``f_sp`` at the nodes, shape (m + 1, 3)),
    ``build_s``, ``shade_s`` and, when ``exact`` (linear pixels of the exact render) is given,
    ``rms`` = max(display, linear) RMS in 8-bit units, as in Table 1 (``validation.studies.phong``).

    Examples
    --------
    >>> frame = render_table_frame(EditorState.default().model(), resolution=16, entries=32)
    >>> frame.rgba.shape, frame.info["nodes"].shape
    ((16, 16, 4), (33,))
    """
    check_interpolation(interpolation, entries)
    geometry = sphere_gbuffer(view, resolution)
    buffer = shading_buffer(geometry, model)
    start = time.perf_counter()
    table = build_table(
        model, entries, placement, None, True, buffer.t_range, buffer.t_density, interpolation
    )
    built = time.perf_counter()
    pixels = shade_pixels(buffer, model, "table", table, interpolation)
    done = time.perf_counter()
    info = {
        "nodes": table.nodes,
        "values": table.values,
        "build_s": built - start,
        "shade_s": done - built,
    }
    if exact is not None:
        info["rms"] = max(rms_8bit(pixels, exact))
    return Frame(_rgba(geometry, pixels), pixels, info)


def render_exact_frame(model: SpectralPhong, view: str = "far", resolution: int = 256) -> Frame:
    """The exact spectral render of the same pixels (one power per band), with its time.

    Examples
    --------
    >>> render_exact_frame(EditorState.default().model(), resolution=16).linear.shape
    (148, 3)
    """
    geometry = sphere_gbuffer(view, resolution)
    start = time.perf_counter()
    pixels = shade_pixels(shading_buffer(geometry, model), model, "exact")
    return Frame(_rgba(geometry, pixels), pixels, {"shade_s": time.perf_counter() - start})


def difference_gain(table: Frame, exact: Frame, percentile: float = 99.5) -> float:
    """The gain that shows ``|table − exact|`` at full brightness: 255 / its ``percentile``.

    Taken over the channels of the pixels that differ at all, at least 1 and at most 255 (one
    8-bit step shown white). A fixed gain left the difference of a good table nearly black.

    Examples
    --------
    >>> a = Frame(np.full((2, 2, 4), 100, np.uint8), None, {})
    >>> b = Frame(a.rgba.copy(), None, {})
    >>> b.rgba[0, 0, 0] = 105
    >>> difference_gain(a, b), difference_gain(a, a)
    (51.0, 1.0)
    """
    diff = np.abs(table.rgba[..., :3].astype(np.int32) - exact.rgba[..., :3].astype(np.int32))
    differing = diff[diff > 0]
    if differing.size == 0:
        return 1.0
    return float(np.clip(255.0 / np.percentile(differing, percentile), 1.0, 255.0))


def difference_rgba(table: Frame, exact: Frame, gain: float = 8.0) -> np.ndarray:
    """``gain × |table − exact|`` of the display images, as RGBA (the difference view).

    Examples
    --------
    >>> a = Frame(np.full((1, 1, 4), 100, np.uint8), None, {})
    >>> difference_rgba(a, a)[0, 0].tolist()
    [0, 0, 0, 255]
    """
    diff = np.abs(table.rgba[..., :3].astype(np.int32) - exact.rgba[..., :3].astype(np.int32))
    out = np.full(table.rgba.shape, 255, dtype=np.uint8)
    out[..., :3] = np.clip(np.round(diff * gain), 0, 255).astype(np.uint8)
    return out


class LatestWorker:
    """A thread that runs only the newest submitted job; older pending jobs are dropped.

    ``submit(job)`` replaces the pending job (a drag sends many); the thread runs ``job()`` and
    hands its result to ``deliver(result, sequence)``. ``dropped`` counts the replaced jobs.

    Examples
    --------
    >>> got = []
    >>> worker = LatestWorker(lambda result, seq: got.append(result))
    >>> worker.submit(lambda: 7)
    >>> worker.wait_idle(5.0), got
    (True, [7])
    >>> worker.stop()
    """

    def __init__(self, deliver):
        self._deliver = deliver
        self._cond = threading.Condition()
        self._pending = None
        self._busy = False
        self._stopped = False
        self.sequence = 0
        self.dropped = 0
        self._thread = threading.Thread(target=self._run, daemon=True, name="editor-worker")
        self._thread.start()

    def submit(self, job) -> None:
        """Queue ``job`` (a callable with no arguments), replacing a pending one."""
        with self._cond:
            if self._pending is not None:
                self.dropped += 1
            self.sequence += 1
            self._pending = (job, self.sequence)
            self._cond.notify_all()

    def _run(self):
        while True:
            with self._cond:
                while self._pending is None and not self._stopped:
                    self._cond.wait()
                if self._stopped:
                    return
                (job, sequence), self._pending = self._pending, None
                self._busy = True
            try:
                result = job()
            except SpecrefError as error:
                result = error
            except Exception as error:  # a page must survive any request: one line, thread lives
                name = type(error).__name__
                result = SpecrefError(f"editor: the render failed ({name}: {error})")
            self._deliver(result, sequence)
            with self._cond:
                self._busy = False
                self._cond.notify_all()

    def wait_idle(self, timeout: float) -> bool:
        """Block until nothing is pending or running; False on timeout."""
        with self._cond:
            return self._cond.wait_for(lambda: self._pending is None and not self._busy, timeout)

    def stop(self) -> None:
        """End the thread after the running job."""
        with self._cond:
            self._stopped = True
            self._cond.notify_all()

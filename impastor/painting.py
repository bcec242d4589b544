"""The ImpastoR demo: a booth light over a procedural impasto painting, rendered end to end.

Ferwerda 2015 (§3.2, §3.5): the painting lies under the ceiling light of a viewing booth (Fig. 7);
its diffuse light comes from median-cut point lights with horizon-map shadows (Eqs. (2)-(3),
Ferwerda), its gloss from the Ward–Dür lobe (Eq. (4), Ferwerda) lit by the method the user picks
from :data:`PAINTING_LIGHTING_METHODS`.

- :func:`booth_plane_light`, :func:`impasto_painting`, :func:`load_paint_spectra`: the scene.
- :func:`render_painting`: the six-channel pipeline, with per-stage frame times;
  :func:`cached_horizon_map` computes a height field's horizon map once, not once per frame.

References
----------
J. A. Ferwerda, "ImpastoR: A Realistic Surface Display System", ACM TAP 12(4), 2015.
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from dataclasses import dataclass, replace
from pathlib import Path
from typing import NamedTuple

import numpy as np

from impastor.arealights import PlaneLight, booth_light_image
from impastor.horizon import (
    horizon_lookup,
    horizon_map,
    light_azimuth_elevation,
    normal_map_from_height,
    tangent_to_world,
)
from impastor.multispectral import (
    MS_GRID,
    MULTISPECTRAL_DESIGNS,
    channels_to_XYZ,
    light_to_channels,
    spectra_to_channels,
)
from impastor.point_lights import (
    illuminance_point_lights,
    point_lights_every_pixel,
    point_lights_from_plane,
)
from impastor.specular_hybrid import (
    check_group_methods,
    specular_by_alpha_group,
    specular_hybrid,
)
from impastor.specular_lighting import specular_fis, specular_point_lights
from reference.colour.colorimetry import XYZ_to_display_RGB
from reference.colour.spectra import resample_spectrum, spectrum_from_csv, spectrum_from_dataset
from reference.data import measured_spectra_folder
from reference.display.encodings import linear_to_display
from reference.errors import SpecrefError, require, require_positive_int
from reference.progress import StageTimer
from reference.registry import Method, Registry

__all__ = [
    "EYE",
    "HORIZON_SECTORS",
    "PAINTING_LIGHTING_METHODS",
    "PAINT_SPECTRA",
    "PaintingScene",
    "booth_in_canvas_frame",
    "booth_lamp_kind",
    "booth_light_spectrum",
    "booth_plane_light",
    "booth_plane_light_from_map",
    "cached_horizon_map",
    "canvas_frame",
    "canvas_materials",
    "canvas_pixels",
    "centre_illuminance",
    "check_eye",
    "check_pose",
    "impasto_painting",
    "lights_visibility",
    "load_paint_spectra",
    "painting_samples",
    "painting_scene",
    "painting_specular_fis",
    "painting_specular_hybrid",
    "painting_specular_point_lights",
    "posed_scene",
    "render_painting",
    "shade_canvas",
]

#: Measured reflectances used for the painting's strokes (shipped: ``reference.data``).
PAINT_SPECTRA = (
    "lemon",
    "orange",
    "brick",
    "terracotta",
    "chocolate",
    "blackboard",
    "egg-shell-brown",
    "cardboard",
    "toothpaste",
    "office-paper",
)
#: Horizon-map sectors of the renderer: 36 (twelve three-channel images, twice the paper's 18 in
#: six), the fewest that keep horizon-map shadows within 2 % of ray-marched ones at every light
#: elevation from 10° to 75° for relief up to four times the painting's (erratum E95).
HORIZON_SECTORS = 36
#: The booth: the viewer's eye and the ceiling light (§3.2, Fig. 7), metres, y up.
EYE = (0.0, 0.45, 0.6)


# --- the booth and the painting ------------------------------------------------------------------


def booth_plane_light(kind: str = "fluorescent", width: int = 128, height: int = 64) -> PlaneLight:
    """The booth ceiling: a 1.2 m × 0.8 m light at y = 0.6 m over the painting (Fig. 7, Ferwerda).

    Examples
    --------
    >>> booth_plane_light("fluorescent", 16, 8).n_light
    array([ 0., -1.,  0.])
    """
    image = booth_light_image(kind, width, height)
    return PlaneLight(image, (-0.6, 0.6, -1.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0), 1.2, 0.8)


def centre_illuminance(plane: PlaneLight) -> float:
    """Eq. (2), Ferwerda, at the canvas's centre facing +y, every pixel of ``plane`` a light (lux).

    Examples
    --------
    >>> plane = booth_plane_light("fluorescent", 16, 8)
    >>> 500 < centre_illuminance(plane) < 1000
    True
    """
    lights = point_lights_every_pixel(plane)
    return float(illuminance_point_lights([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], lights)[0])


def booth_plane_light_from_map(
    path, width: int = 128, height: int = 64, lux: float | None = None
) -> PlaneLight:
    """The booth's ceiling showing a captured room: an HDR panorama seen through it (E113).

    The map (Radiance ``.hdr`` or an RGB OpenEXR, linear sRGB primaries; y up) becomes luminance
    and is projected onto the booth's ceiling from the canvas's centre
    (:func:`impastor.arealights.plane_image_from_latlong`), then scaled so the canvas's centre gets
    ``lux`` (default: what the procedural fluorescent booth gives it, so frames compare). The
    lamp's spectrum stays ``light``'s.

    Examples
    --------
    >>> import tempfile, os
    >>> from reference.images.formats import write_exr
    >>> path = write_exr(os.path.join(tempfile.mkdtemp(), "room.exr"), np.ones((16, 32, 3)))
    >>> plane = booth_plane_light_from_map(path, 16, 8, lux=1500.0)
    >>> round(centre_illuminance(plane), 6), float(np.ptp(plane.image))
    (1500.0, 0.0)
    """
    from impastor.arealights import plane_image_from_latlong
    from reference.colour.colorimetry import display_RGB_to_XYZ
    from reference.images.spectral import read_environment_file

    image, names = read_environment_file(path)
    require(
        names[:3] == ["R", "G", "B"],
        f"{path}: the light map must be RGB (R, G, B channels, linear sRGB), got {names[:4]}",
    )
    require(
        image.shape[1] == 2 * image.shape[0],
        f"{path}: the light map must be a lat-long panorama (2:1), got "
        f"{image.shape[1]} × {image.shape[0]} pixels",
    )
    Y = display_RGB_to_XYZ(np.asarray(image[..., :3], dtype=np.float64))[..., 1]
    require(
        bool(np.isfinite(Y).all()) and float(Y.min()) >= 0.0,
        f"{path}: the light map must be finite and >= 0",
    )
    booth = booth_plane_light("fluorescent", width, height)
    plane = replace(booth, image=plane_image_from_latlong(Y, booth))
    E = centre_illuminance(plane)
    require(
        E > 0.0,
        f"{path}: no light in the directions the booth's ceiling covers (above the canvas, behind "
        "it); the map's y axis must point up",
    )
    target = centre_illuminance(booth) if lux is None else float(lux)
    require(np.isfinite(target) and target > 0, f"lux: must be > 0, got {lux!r}")
    return replace(plane, image=plane.image * (target / E))


def booth_light_spectrum(light: str):
    """The booth light's spectrum: an illuminant key, or a measured lamp's CSV file.

    A file (``*.csv`` or ``*.txt``: wavelength in nm and relative power per line, or a wide
    export; :func:`reference.colour.spectra.spectrum_from_csv`) is a spectroradiometer's reading
    of the lamp; it must cover 400-700 nm, be finite and >= 0, and is held constant beyond its
    ends (erratum E113). It lights the booth's fluorescent luminaire (:func:`booth_lamp_kind`).

    Examples
    --------
    >>> booth_light_spectrum("FL2").name
    'illuminant:FL2'
    >>> booth_light_spectrum("/nonexistent/lamp.csv")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent/lamp.csv: the lamp's spectrum: file not found
    """
    if Path(str(light)).suffix.lower() not in (".csv", ".txt"):
        return spectrum_from_dataset("illuminant", light)
    path = Path(light)
    require(path.is_file(), f"{path}: the lamp's spectrum: file not found")
    try:
        spectrum = spectrum_from_csv(path, name=path.stem)
    except SpecrefError as error:
        raise SpecrefError(f"{path}: the lamp's spectrum: {error}") from None
    wl, values = spectrum.wavelengths_nm, spectrum.values
    require(
        bool(np.isfinite(values).all() and (values >= 0).all()),
        f"{path}: the lamp's spectrum: values must be finite and >= 0",
    )
    require(
        wl[0] <= 400 and wl[-1] >= 700,
        f"{path}: the lamp's spectrum covers {wl[0]:g}-{wl[-1]:g} nm; it must cover 400-700 nm",
    )
    from reference.colour.spectra import Spectrum

    grid = MS_GRID.wavelengths_nm
    # ImpastoR's 5 nm grid, linear between the readings, their ends held (erratum E113)
    return Spectrum(grid.copy(), np.interp(grid, wl, values), name=f"lamp:{path.stem}")


def booth_lamp_kind(light: str) -> str:
    """The booth's lamp for an illuminant: ``"incandescent"`` under A, else ``"fluorescent"``.

    Examples
    --------
    >>> booth_lamp_kind("A"), booth_lamp_kind("D65")
    ('incandescent', 'fluorescent')
    """
    return "incandescent" if light == "A" else "fluorescent"


def load_paint_spectra(folder=None, names=PAINT_SPECTRA) -> dict:
    """Measured reflectances (Nix Spectro 2 exports) on the 5 nm grid, by name.

    Parameters
    ----------
    folder : str or Path, optional
        A folder of ``<name>__nix_export.csv`` files; default the shipped ones
        (:func:`reference.data.measured_spectra_folder`).
    names : sequence of str
        The materials to read.

    Raises
    ------
    SpecrefError
        When a file is missing, naming it.

    Examples
    --------
    >>> spectra = load_paint_spectra(names=("lemon",))
    >>> spectra["lemon"].shape
    (81,)
    """
    folder = Path(folder) if folder is not None else measured_spectra_folder()
    out = {}
    for name in names:
        path = folder / f"{name}__nix_export.csv"
        require(path.is_file(), f"{path}: measured spectrum not found")
        spectrum = spectrum_from_csv(path, name=name)
        out[name] = resample_spectrum(spectrum, MS_GRID, extrapolation="constant")
    return out


def impasto_painting(size: int = 256, seed: int = 1, width_m: float = 0.3, n_strokes=None) -> dict:
    """A procedural impasto painting: brush-stroke height field, stroke materials, gloss maps.

    Strokes are ridged bands (a raised body with a furrow along its middle) of random direction,
    length and width, laid in order so that later strokes cover earlier ones; a canvas weave lies
    under them. Everything is periodic, so the surface tiles.

    Parameters
    ----------
    size : int
        Pixels per side.
    seed : int
        Random seed.
    width_m : float
        Physical width, m (a 30 cm canvas by default).
    n_strokes : int, optional
        Default ``400 · (width_m / 0.3)²``.

    Returns
    -------
    dict
        ``height`` (m, (size, size)), ``material`` (int index into :data:`PAINT_SPECTRA`, −1 is
        the primed canvas), ``rho_s`` and ``alpha`` maps, ``pixel_size`` (m).

    Examples
    --------
    >>> p = impasto_painting(64, seed=3)
    >>> p["height"].shape, bool(p["height"].max() < 5e-3), int(p["material"].max()) < 10
    ((64, 64), True, True)
    """
    size = require_positive_int(size, "painting: size", 8192)
    rng = np.random.default_rng(seed)
    pixel = width_m / size
    n = n_strokes or int(400 * (width_m / 0.3) ** 2)
    coordinate = np.arange(size) * pixel
    y, x = np.meshgrid(coordinate, coordinate, indexing="ij")
    # Canvas weave: two crossed sinusoids, 1 mm period, 20 µm deep.
    height = 2e-5 * (np.sin(2 * np.pi * x / 1e-3) * np.sin(2 * np.pi * y / 1e-3))
    material = np.full((size, size), -1, dtype=np.int64)
    rho_s = np.full((size, size), 0.01)
    alpha = np.full((size, size), 0.4)
    for _ in range(n):
        cx, cy = rng.uniform(0, width_m, 2)
        theta = rng.uniform(0, np.pi)
        length = rng.uniform(0.02, 0.07)
        half_width = rng.uniform(0.002, 0.006)
        amplitude = rng.uniform(5e-4, 2e-3)
        # Minimum-image offsets: the canvas tiles.
        dx = (coordinate - cx + width_m / 2) % width_m - width_m / 2
        dy = (coordinate - cy + width_m / 2) % width_m - width_m / 2
        # The stroke is zero beyond |along| = length/2 or |across| = half_width, so only the rows
        # and columns within length/2 + half_width of its centre are computed (the same values).
        reach = length / 2 + half_width
        window = np.ix_(np.flatnonzero(np.abs(dy) < reach), np.flatnonzero(np.abs(dx) < reach))
        dx, dy = dx[window[1]], dy[window[0]]
        along = dx * np.cos(theta) + dy * np.sin(theta)
        across = -dx * np.sin(theta) + dy * np.cos(theta)
        r = np.abs(across) / half_width
        # A thick body with steep edges and a furrow along its middle (the brush's trace).
        body = np.sqrt(np.clip(1.0 - r**6, 0.0, None)) * (1.0 - 0.4 * np.exp(-((r / 0.25) ** 2)))
        ends = np.sqrt(np.clip(1.0 - (2.0 * along / length) ** 6, 0.0, None))
        bump = amplitude * body * ends
        covered = bump > 0.15 * amplitude
        # The new stroke lies on top: it replaces the surface where it is thick.
        under = height[window]
        height[window] = np.where(covered, np.maximum(under, bump + 0.5 * under), under)
        material[window] = np.where(covered, rng.integers(0, len(PAINT_SPECTRA)), material[window])
        rho_s[window] = np.where(covered, rng.uniform(0.02, 0.08), rho_s[window])
        alpha[window] = np.where(covered, rng.uniform(0.04, 0.3), alpha[window])
    return {
        "height": height,
        "material": material,
        "rho_s": rho_s,
        "alpha": alpha,
        "pixel_size": pixel,
        "width_m": width_m,
    }


def check_eye(eye, where: str = "--observer") -> np.ndarray:
    """A viewer's position (m) in the booth's frame, in front of the canvas (y > 0).

    Examples
    --------
    >>> check_eye((0.0, 0.45, 0.6)).tolist()
    [0.0, 0.45, 0.6]
    >>> check_eye((0.0, -0.1, 0.6))
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: --observer: (0, -0.1, 0.6) m is behind the canvas (its plane
    is y = 0, facing +y)
    """
    point = np.asarray(eye, dtype=np.float64)
    require(
        point.shape == (3,) and bool(np.isfinite(point).all()),
        f"{where}: must be x,y,z in metres, got {eye!r}",
    )
    require(
        point[1] > 1e-3,
        f"{where}: ({', '.join(f'{c:g}' for c in point)}) m is behind the canvas (its plane is "
        "y = 0, facing +y)",
    )
    return point


def _tilt_rotation(tilt: float) -> np.ndarray:
    """``R_x(tilt)``: the booth's frame into the frame of a canvas tilted by ``tilt`` radians."""
    tilt = float(tilt)
    require(
        np.isfinite(tilt) and abs(tilt) <= np.pi / 2,
        f"tilt: must be within ±90° of the booth's canvas, got {np.degrees(tilt):g}°",
    )
    c, s = np.cos(tilt), np.sin(tilt)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def booth_in_canvas_frame(
    plane: PlaneLight, eye, tilt: float = 0.0
) -> tuple[PlaneLight, np.ndarray]:
    """The booth's light and viewer seen from a canvas turned by ``tilt`` about the booth's x axis.

    ImpastoR's painting is the display (§3.4, Ferwerda): as the screen is tilted, the painting
    turns with it under the booth's fixed light, in front of a viewer who stays where they are.
    The canvas turns about its centre line from left to right by the rotation that tilts the
    screen in :mod:`reference.display.pipeline`, ``R_x(−tilt)``: a positive tilt takes its normal
    from +y towards −z, away from the viewer and towards the booth's light. The renderer keeps the
    canvas in y = 0 facing +y, so the light plane and the viewer turn by the inverse, ``R_x(tilt)``.

    Parameters
    ----------
    plane : PlaneLight
        The booth's light in the booth's frame.
    eye : (3,) array_like
        The viewer in the booth's frame, m.
    tilt : float
        The canvas's tilt, radians, in [−π/2, π/2].

    Returns
    -------
    (PlaneLight, ndarray of shape (3,))
        The light and the viewer in the canvas's frame.

    Examples
    --------
    >>> plane = booth_plane_light("fluorescent", 16, 8)
    >>> turned, eye = booth_in_canvas_frame(plane, EYE, np.radians(90.0))
    >>> np.round(eye, 12).tolist(), np.round(turned.n_light, 12).tolist()
    ([0.0, -0.6, 0.45], [0.0, 0.0, -1.0])
    >>> booth_in_canvas_frame(plane, EYE, 0.0)[0] is plane    # at rest: the booth as it is
    True
    """
    R = _tilt_rotation(tilt)
    if float(tilt) == 0.0:
        return plane, np.asarray(eye, dtype=np.float64)
    turned = replace(
        plane,
        origin=tuple(R @ np.asarray(plane.origin)),
        A=tuple(R @ np.asarray(plane.A)),
        B=tuple(R @ np.asarray(plane.B)),
    )
    return turned, R @ np.asarray(eye, dtype=np.float64)


def check_pose(eye=EYE, tilt: float = 0.0) -> np.ndarray:
    """The viewer (the booth's frame, m) in the frame of the canvas tilted by ``tilt`` radians.

    One-line errors for a viewer that is not x, y, z, a tilt beyond ±90° and a viewer the tilted
    canvas faces away from.

    Examples
    --------
    >>> check_pose(EYE, np.radians(20.0)).round(3).tolist()
    [0.0, 0.218, 0.718]
    >>> check_pose(EYE, np.radians(45.0))
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: tilt: at 45° the canvas faces away from the viewer at (0, 0.45,
    0.6) m
    """
    eye = np.asarray(check_eye(eye, "eye"), dtype=np.float64)
    eye_canvas = _tilt_rotation(tilt) @ eye
    require(
        eye_canvas[1] > 1e-3,
        f"tilt: at {np.degrees(tilt):g}° the canvas faces away from the viewer at "
        f"({', '.join(f'{c:g}' for c in eye)}) m",
    )
    return eye_canvas


def posed_scene(scene: PaintingScene, eye=EYE, tilt: float = 0.0) -> tuple:
    """The scene and the viewer in the frame of the canvas tilted by ``tilt`` radians (a pose).

    :func:`check_pose`, then :func:`booth_in_canvas_frame` applied to the scene's light.

    Examples
    --------
    >>> scene = painting_scene("D65", "median_cut", impasto_painting(16), light_resolution=(16, 8))
    >>> posed, eye = posed_scene(scene, EYE, np.radians(20.0))
    >>> bool(posed.plane.origin[1] > scene.plane.origin[1]), bool(eye[1] < EYE[1])
    (True, True)
    >>> posed_scene(scene, EYE, 0.0)[0] is scene
    True
    """
    eye_canvas = check_pose(eye, tilt)
    plane, _ = booth_in_canvas_frame(scene.plane, eye, tilt)
    return (scene if plane is scene.plane else scene._replace(plane=plane)), eye_canvas


def _painting_gbuffer(size: int, width_m: float, eye=EYE):
    from reference.geometry.camera import Camera
    from reference.geometry.gbuffer import render_gbuffer
    from reference.geometry.shapes import Plane

    plane = Plane((0.0, 0.0, 0.0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0), size=(width_m, width_m))
    # the camera at the viewer, aimed at the canvas's centre (§3.4: the painting follows the viewer)
    camera = Camera(eye=tuple(eye), target=(0.0, 0.0, 0.0), fov_deg=25.0)
    return render_gbuffer([plane], camera, size, size)


#: Horizon maps by height-field content (``cached_horizon_map``); the oldest is dropped first.
_HORIZON_CACHE: OrderedDict = OrderedDict()
_HORIZON_CACHE_SIZE = 4


def cached_horizon_map(
    height, pixel_size: float, n_sectors: int = 18, max_steps: int = 32, backend: str = "numba"
) -> np.ndarray:
    """:func:`impastor.horizon.horizon_map`, computed once per height field and settings.

    The horizon map depends only on the height field (§3.5.3, Ferwerda), not on the light or the
    view, so the renderer computes it once and every frame looks it up. The cache is keyed by the
    height field's content (SHA-1 of its bytes, shape and dtype) and the settings, so an edited
    height field is never served a stale map; it holds the last four maps, read-only.

    Parameters
    ----------
    height : array_like, shape (H, W)
        Height field, m.
    pixel_size : float
        Texel size, m.
    n_sectors, max_steps : int
        As in :func:`impastor.horizon.horizon_map`.
    backend : {"numba", "numpy"}

    Returns
    -------
    ndarray
        The horizon map (read-only; shared by every caller with the same inputs).

    Examples
    --------
    >>> h = impasto_painting(16, seed=1)["height"]
    >>> first = cached_horizon_map(h, 0.3 / 16, 6, 8, backend="numpy")
    >>> cached_horizon_map(h.copy(), 0.3 / 16, 6, 8, backend="numpy") is first
    True
    >>> cached_horizon_map(h + 1e-4, 0.3 / 16, 6, 8, backend="numpy") is first
    False
    """
    h = np.ascontiguousarray(height, dtype=np.float64)
    digest = hashlib.sha1(h.tobytes()).hexdigest()
    key = (digest, h.shape, float(pixel_size), int(n_sectors), int(max_steps), backend)
    if key in _HORIZON_CACHE:
        _HORIZON_CACHE.move_to_end(key)
        return _HORIZON_CACHE[key]
    hmap = horizon_map(h, pixel_size, n_sectors, max_steps, backend=backend)
    hmap.setflags(write=False)
    _HORIZON_CACHE[key] = hmap
    while len(_HORIZON_CACHE) > _HORIZON_CACHE_SIZE:
        _HORIZON_CACHE.popitem(last=False)
    return hmap


def render_painting(
    light: str = "D65",
    size: int = 256,
    method: str = "hybrid",
    painting=None,
    design: str = "optimized",
    n_lights: int = 32,
    n_samples: int = 32,
    light_resolution: tuple = (128, 64),
    shadows: bool = True,
    spectra=None,
    backend: str = "numba",
    progress=None,
    n_sectors: int = HORIZON_SECTORS,
    failsafe: bool = True,
    eye=EYE,
    n_channels: int = 6,
    tilt: float = 0.0,
    light_map=None,
    by_group=None,
) -> dict:
    """Render a painting (the demo one by default) under a booth light through ImpastoR.

    G-buffer of the canvas, normals from the height map, six-channel ρ_d from measured spectra,
    diffuse light from median-cut lights (Eqs. (2)-(3), Ferwerda) with horizon-map shadows,
    specular light by ``method`` (:func:`shade_canvas`), and XYZ through the 3×N matrix.

    Parameters
    ----------
    light, size
        Illuminant key (A: the incandescent booth image, else the fluorescent one); image side, px.
    method : str
        A key of :data:`PAINTING_LIGHTING_METHODS`: the specular lighting, and the light sampling
        of the point lights that the diffuse term always uses.
    painting : dict, optional
        From :func:`impasto_painting` (default: one at ``size``).
    design, light_resolution, shadows, spectra, n_channels, light_map
        Pipeline settings (``spectra``: :func:`load_paint_spectra`; ``n_channels``: 3-10;
        ``light_map``: a captured room as the ceiling, :func:`booth_plane_light_from_map`).
    n_lights, n_samples, n_sectors, failsafe, by_group
        Point lights N, FIS samples K, horizon sectors S, the hybrid's fail-safe and α groups on
        one method (:func:`painting_specular_hybrid`): fixed here (32, 32, 36, on, none);
        :func:`impastor.settings.render_painting_to_tolerance` chooses them.
    backend, progress
        ``"numba"`` kernels or their ``"numpy"`` twins (no JIT warm-up: for small images); a stream
        for a line per stage with its time (``specref impastor render``), optional.
    eye, tilt
        The pose: the viewer (m; :data:`EYE` by default) and the canvas's tilt (radians) under the
        booth's fixed light, as the display showing it is tilted (:func:`booth_in_canvas_frame`;
        the sRGB keeps the exposure at rest). The camera, shading and specular term follow both.

    Returns
    -------
    dict
        ``XYZ`` (H, W, 3) in cd/m², ``sRGB`` encoded (H, W, 3) in [0, 1] (white = 1.2× the
        white diffuser's luminance), ``seconds`` per stage (``shadows`` is the horizon lookup,
        plus the horizon map the first time a height field is rendered: :func:`cached_horizon_map`),
        ``settings`` (N, K, S, fail-safe, ``by_group`` if any), ``pose`` (``eye``, m; ``tilt_deg``).

    Examples
    --------
    >>> out = render_painting("D65", size=32, method="median_cut", light_resolution=(32, 16))
    >>> out["XYZ"].shape, sorted(out["seconds"]), out["settings"]["n_lights"]
    ((32, 32, 3), ['diffuse', 'shadows', 'specular'], 32)
    """
    painting = painting or impasto_painting(size)
    options = (design, light_resolution, spectra, n_channels, light_map)
    rest = painting_scene(light, method, painting, *options)
    scene, eye_canvas = posed_scene(rest, eye, tilt)
    px = canvas_pixels(painting, size, eye_canvas)
    timer = StageTimer(progress, f"painting {size}×{size} under {light}")
    settings = _frame_settings(n_lights, n_samples, n_sectors, failsafe, by_group)
    # once per height field, not per frame (§3.5.3, Ferwerda: a precomputed map)
    horizon = _horizon_at(painting, px, n_sectors, backend) if shadows else None
    L, E = shade_canvas(scene, px, settings, horizon, backend, timer)
    if scene.plane is not rest.plane:  # the exposure of the canvas at rest: the white it had
        E = _rest_illuminance(rest, px, n_lights, horizon)
    XYZ, sRGB = _frame_images(px, L, E, scene.design)
    pose = {"eye": np.asarray(eye, float).tolist(), "tilt_deg": float(np.degrees(tilt))}
    return {"XYZ": XYZ, "sRGB": sRGB, "seconds": timer.seconds, "settings": settings, "pose": pose}


def _frame_settings(n_lights, n_samples, n_sectors, failsafe, by_group) -> dict:
    """A frame's settings as :func:`shade_canvas` reads them and the render records them."""
    settings = {"n_lights": n_lights, "n_samples": n_samples, "n_sectors": n_sectors}
    settings["failsafe"] = bool(failsafe)
    if by_group:  # a method per group of similar α (the hybrid's; erratum E96)
        settings["by_group"] = check_group_methods(by_group)
    return settings


def _horizon_at(painting: dict, px, n_sectors: int, backend: str):
    """The horizon angles at the pixels' texels, as a call (the map cached per height field)."""

    def horizon():
        height, pixel_size = painting["height"], painting["pixel_size"]
        return cached_horizon_map(height, pixel_size, n_sectors, 32, backend)[px.row, px.col]

    return horizon


def _rest_illuminance(rest: PaintingScene, px, n_lights: int, horizon) -> np.ndarray:
    """Eq. (2), Ferwerda, at the pixels under the untilted booth: a tilted frame's exposure."""
    lights = point_lights_from_plane(rest.plane, rest.lighting.sampling, n_lights)
    visibility = None if horizon is None else lights_visibility(horizon(), px.P, lights)
    return illuminance_point_lights(px.P, px.N, lights, visibility)


def _frame_images(px, L, E, design) -> tuple[np.ndarray, np.ndarray]:
    """The frame's XYZ and its display encoding: sRGB, the white diffuser at 1/1.2 of white."""
    XYZ = np.zeros((*px.gbuffer.shape, 3))
    XYZ[px.gbuffer.mask] = channels_to_XYZ(L, design)
    white_Y = float(np.median(E)) / np.pi
    rgb = XYZ_to_display_RGB(XYZ / (1.2 * white_Y))
    return XYZ, linear_to_display(rgb, "srgb")


class PaintingScene(NamedTuple):
    """What a frame of the painting needs besides its pixels and settings (:func:`painting_scene`).

    ``painting`` (from :func:`impasto_painting`), ``spectra`` (paint reflectances), ``design``
    (the six-channel design), ``plane`` (the booth's ceiling), ``S6`` (the illuminant in the six
    channels) and ``lighting`` (the :class:`PaintingLighting` method).
    """

    painting: dict
    spectra: dict
    design: object
    plane: PlaneLight
    S6: np.ndarray
    lighting: object


def painting_scene(
    light: str = "D65",
    method: str = "hybrid",
    painting=None,
    design: str = "optimized",
    light_resolution: tuple = (128, 64),
    spectra=None,
    n_channels: int = 6,
    light_map=None,
) -> PaintingScene:
    """The painting, its paints, the channel design and the booth light, ready to shade.

    ``light`` gives the lamp's spectrum; the ceiling's image is the procedural booth's, or with
    ``light_map`` (an HDR panorama's file) the room it captures
    (:func:`booth_plane_light_from_map`).

    Examples
    --------
    >>> scene = painting_scene("A", "median_cut", impasto_painting(16), light_resolution=(16, 8))
    >>> scene.plane.shape, scene.S6.shape
    ((8, 16), (6,))
    """
    lighting = PAINTING_LIGHTING_METHODS.lookup(method)
    painting = painting or impasto_painting(256)
    spectra = spectra or load_paint_spectra()
    d = MULTISPECTRAL_DESIGNS.lookup(design).reference(n_channels)
    if light_map is None:
        plane = booth_plane_light(booth_lamp_kind(light), *light_resolution)
    else:  # a captured room as the booth's ceiling (E113)
        plane = booth_plane_light_from_map(light_map, *light_resolution)
    S6 = light_to_channels(booth_light_spectrum(light), d)
    return PaintingScene(painting, spectra, d, plane, S6, lighting)


def shade_canvas(scene: PaintingScene, px, settings: dict, horizon, backend: str, timer=None):
    """Six-channel radiance at canvas pixels: Eqs. (2)-(4), Ferwerda, at the given settings.

    Parameters
    ----------
    scene : PaintingScene
    px : _CanvasPixels
        The pixels (:func:`canvas_pixels`).
    settings : dict
        ``n_lights``, ``n_samples``, ``failsafe`` and optionally ``by_group`` (the hybrid's:
        :func:`painting_specular_hybrid`; other methods ignore both).
    horizon : callable or None
        Returns the horizon angles ``(n, S)`` at the pixels' texels; None for no shadows.
    backend : {"numba", "numpy"}
    timer : StageTimer, optional

    Returns
    -------
    L : ndarray, shape (n, 6)
        Radiance per channel (cd/m² in the design's channels).
    E : ndarray, shape (n, 1)
        Illuminance from the point lights, lux.

    Examples
    --------
    >>> scene = painting_scene("D65", "median_cut", impasto_painting(16), light_resolution=(16, 8))
    >>> px = canvas_pixels(scene.painting, 8)
    >>> settings = {"n_lights": 4, "n_samples": 4, "failsafe": False}
    >>> L, E = shade_canvas(scene, px, settings, None, "numpy")
    >>> L.shape == (px.P.shape[0], 6), bool((E > 0).all())
    (True, True)
    """
    timer = timer or StageTimer(None, "")
    lights = point_lights_from_plane(scene.plane, scene.lighting.sampling, settings["n_lights"])
    with timer.stage("shadows"):
        visibility = None if horizon is None else lights_visibility(horizon(), px.P, lights)
    rho_d, rho_s, alpha = canvas_materials(scene.painting, scene.spectra, scene.design, px)
    with timer.stage("diffuse"):
        # Eq. (2), Ferwerda: illuminance from the point lights (luminance image: one channel)
        E = illuminance_point_lights(px.P, px.N, lights, visibility)
        # Eq. (3), Ferwerda: L_out,j = ρ_d,j S_j E / π
        L_diffuse = rho_d * scene.S6 * E / np.pi
    with timer.stage("specular"):
        extra = {}
        if scene.lighting.failsafe:  # the hybrid: its fail-safe, and methods by α group
            extra = {"failsafe": settings["failsafe"], "by_group": settings.get("by_group")}
        I_s = scene.lighting.reference(
            px.P, px.N, px.V, alpha, scene.plane, lights, settings["n_samples"], visibility,
            backend, **extra,
        )  # fmt: skip
        L_specular = rho_s * scene.S6 * I_s
    return L_diffuse + L_specular, E


class _CanvasPixels(NamedTuple):
    """The canvas's visible pixels: G-buffer, points, views, texels and normal-mapped normals."""

    gbuffer: object
    P: np.ndarray
    V: np.ndarray
    row: np.ndarray
    col: np.ndarray
    N: np.ndarray

    def subset(self, index) -> _CanvasPixels:
        """The pixels at ``index`` (of the visible ones), without the G-buffer."""
        return _CanvasPixels(None, *(x[index] for x in self[1:]))


def canvas_pixels(painting: dict, size: int, eye=EYE) -> _CanvasPixels:
    """The canvas seen from ``eye`` (default :data:`EYE`) at ``size²`` pixels, normal-mapped.

    Returns the visible pixels' G-buffer, points P, views V, texel rows and columns and
    normal-mapped normals N.

    Examples
    --------
    >>> px = canvas_pixels(impasto_painting(16), 8)
    >>> px.P.shape == px.N.shape == px.V.shape, px.row.shape == px.P.shape[:1]
    (True, True)
    """
    g = _painting_gbuffer(size, painting["width_m"], eye)
    mask = g.mask
    P, V = g.position[mask], g.view[mask]
    # Texel of each visible pixel (uv: u along +x columns, v along +z rows).
    n_tex = painting["height"].shape[0]
    col = np.clip((g.uv[mask][:, 0] * n_tex).astype(int), 0, n_tex - 1)
    row = np.clip((g.uv[mask][:, 1] * n_tex).astype(int), 0, n_tex - 1)
    T, B, N_geo = canvas_frame()
    normals_tangent = normal_map_from_height(painting["height"], painting["pixel_size"])
    N = tangent_to_world(normals_tangent[row, col], T, B, N_geo)
    return _CanvasPixels(g, P, V, row, col, N)


def canvas_frame() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The canvas's tangent frame T, B, N in world axes: u along +x, v along +z, up +y.

    Examples
    --------
    >>> canvas_frame()[2]
    array([0., 1., 0.])
    """
    return np.array([1.0, 0, 0]), np.array([0, 0, 1.0]), np.array([0, 1.0, 0])


def lights_visibility(horizon: np.ndarray, P: np.ndarray, lights) -> np.ndarray:
    """Each point's visibility (0 or 1) of each point light, by its texel's horizon (§3.5.3).

    Parameters
    ----------
    horizon : ndarray, shape (n, S)
        Horizon angles at each point's texel (:func:`cached_horizon_map` or
        :func:`impastor.horizon.horizon_at_texels`).
    P : ndarray, shape (n, 3)
        Points on the canvas, m.
    lights : PointLights

    Returns
    -------
    ndarray, shape (n, N)

    Examples
    --------
    >>> lights = point_lights_from_plane(booth_plane_light("fluorescent", 8, 4), "median_cut", 2)
    >>> lights_visibility(np.zeros((1, 4)), np.zeros((1, 3)), lights)
    array([[1., 1.]])
    """
    to_light = lights.position[None] - P[:, None]
    phi, beta = light_azimuth_elevation(to_light, *canvas_frame())
    return horizon_lookup(horizon[:, None, :], phi, beta).astype(float)


def canvas_materials(painting: dict, spectra: dict, d, px: _CanvasPixels):
    """Six-channel materials per pixel: ρ_d from the measured spectra, ρ_s and α from the maps.

    A painting read from files (:func:`impastor.painting_files.read_painting`) has a reflectance
    spectrum per texel instead of the demo's paint indices.

    Returns ``rho_d`` (n, 6), ``rho_s`` (n, 1) and the Ward–Dür ``alpha`` (n,) at the pixels'
    texels.

    Examples
    --------
    >>> painting = impasto_painting(16)
    >>> px = canvas_pixels(painting, 8)
    >>> d = MULTISPECTRAL_DESIGNS.lookup("optimized").reference(6)
    >>> rho_d, rho_s, alpha = canvas_materials(painting, load_paint_spectra(), d, px)
    >>> rho_d.shape[1], bool((alpha > 0).all())
    (6, True)
    """
    if "reflectance" in painting:  # a painting read from files: a spectrum per texel
        rho_d = spectra_to_channels(painting["reflectance"][px.row, px.col], d)
    else:
        names = list(PAINT_SPECTRA)
        R6 = spectra_to_channels(np.stack([spectra[n] for n in names]), d)
        canvas = spectra_to_channels(spectra.get("office-paper", np.full(81, 0.85)), d)
        table = np.concatenate([R6, canvas[None]])
        material = painting["material"][px.row, px.col]
        rho_d = table[np.where(material < 0, len(names), material)]
    rho_s = painting["rho_s"][px.row, px.col][:, None]
    alpha = painting["alpha"][px.row, px.col]
    return rho_d, rho_s, alpha


def painting_samples(n_side: int, painting: dict):
    """Surface points on an ``n_side²`` grid over the painting, with normal-mapped normals.

    Parameters
    ----------
    n_side : int
        Points per side (pixel centres of an ``n_side × n_side`` grid over the canvas).
    painting : dict
        From :func:`impasto_painting`.

    Returns
    -------
    P, N, V : ndarray, shape (n_side², 3)
        World positions (m), unit normals (from the height field) and unit view vectors to
        :data:`EYE`.

    Examples
    --------
    >>> P, N, V = painting_samples(3, impasto_painting(16, seed=1))
    >>> P.shape, bool(np.allclose(np.linalg.norm(V, axis=-1), 1.0))
    ((9, 3), True)
    """
    w = painting["width_m"]
    g = (np.arange(n_side) + 0.5) / n_side
    u, v = np.meshgrid(g, g)
    P = np.stack([(u - 0.5) * w, np.zeros_like(u), (v - 0.5) * w], axis=-1).reshape(-1, 3)
    n_tex = painting["height"].shape[0]
    col = np.clip((u.ravel() * n_tex).astype(int), 0, n_tex - 1)
    row = np.clip((v.ravel() * n_tex).astype(int), 0, n_tex - 1)
    tangent = normal_map_from_height(painting["height"], painting["pixel_size"])[row, col]
    N = tangent_to_world(tangent, [1.0, 0, 0], [0, 0, 1.0], [0, 1.0, 0])
    V = np.asarray(EYE) - P
    V /= np.linalg.norm(V, axis=-1, keepdims=True)
    return P, N, V


# --- the lighting methods of the painting --------------------------------------------------------


def painting_specular_point_lights(P, N, V, alpha, plane, lights, n_samples, visibility, backend):
    """The painting's gloss lit by its point lights: the Ward–Dür lobe summed over them.

    Eq. (2), Ferwerda, with the lobe of Eq. (4), Ferwerda (:func:`specular_point_lights`); the
    plane light and ``n_samples`` are unused. Every method of :data:`PAINTING_LIGHTING_METHODS`
    takes these arguments.

    Parameters
    ----------
    P, N, V : ndarray, shape (n, 3)
        Surface points (m), unit normals and unit view vectors.
    alpha : ndarray, shape (n,)
        Ward–Dür roughness per point.
    plane : PlaneLight
        The booth's ceiling light.
    lights : PointLights
        Its point lights (median cut or variance minimization).
    n_samples : int
        FIS samples per point (for the methods that sample).
    visibility : ndarray, shape (n, N) or None
        Shadowing of each point light (horizon maps), or None for none.
    backend : {"numba", "numpy"}

    Returns
    -------
    ndarray, shape (n, 1)
        ``I_s``: the specular luminance factor per point (multiply by ρ_s and the light's channels).

    Examples
    --------
    >>> inputs = _painting_example(np.random.default_rng(1))
    >>> painting_specular_point_lights(*inputs).shape
    (4, 1)
    """
    return specular_point_lights(P, N, V, alpha, lights, visibility, backend=backend)


def painting_specular_fis(P, N, V, alpha, plane, lights, n_samples, visibility, backend):
    """The painting's gloss by filtered importance sampling of the plane light (no shadows).

    Eq. (4), Ferwerda, integrated with FIS over the light plane (Eqs. (5)-(8), Ferwerda:
    :func:`specular_fis`); ``lights`` and ``visibility`` are unused. Parameters and result as in
    :func:`painting_specular_point_lights`.

    Examples
    --------
    >>> inputs = _painting_example(np.random.default_rng(1))
    >>> painting_specular_fis(*inputs).shape
    (4, 1)
    """
    return specular_fis(P, N, V, alpha, plane, n_samples, backend=backend)


def painting_specular_hybrid(
    P, N, V, alpha, plane, lights, n_samples, visibility, backend, failsafe: bool = True,
    by_group=None,
):  # fmt: skip
    """The painting's gloss by the per-pixel hybrid of point lights and FIS.

    Eq. (4), Ferwerda, estimated both ways and mixed per pixel by the error estimates of
    :func:`specular_hybrid`. Parameters and result as in :func:`painting_specular_point_lights`;
    ``failsafe=False`` skips the hybrid's fail-safe (its unbiased check of the choice);
    ``by_group`` gives groups of similar α the point lights or FIS alone
    (:func:`~impastor.specular_hybrid.specular_by_alpha_group`, erratum E96).

    Examples
    --------
    >>> inputs = _painting_example(np.random.default_rng(1))
    >>> painting_specular_hybrid(*inputs).shape
    (4, 1)
    """
    if by_group:
        return specular_by_alpha_group(
            P, N, V, alpha, plane, lights, n_samples, visibility, backend, failsafe, by_group
        )
    return specular_hybrid(
        P, N, V, alpha, plane, lights, n_samples, visibility, backend, failsafe=failsafe
    )


def _painting_example(rng):
    P = np.stack([rng.uniform(-0.1, 0.1, 4), np.zeros(4), rng.uniform(-0.1, 0.1, 4)], axis=-1)
    N = np.tile([0.0, 1.0, 0.0], (4, 1))
    V = np.asarray(EYE) - P
    V /= np.linalg.norm(V, axis=-1, keepdims=True)
    plane = booth_plane_light("fluorescent", 16, 8)
    lights = point_lights_from_plane(plane, "median_cut", 4)
    return P, N, V, rng.uniform(0.05, 0.3, 4), plane, lights, 8, None, "numpy"


@dataclass(frozen=True, kw_only=True)
class PaintingLighting(Method):
    """How the painting's gloss is lit.

    ``reference(P, N, V, alpha, plane, lights, n_samples, visibility, backend)`` returns the
    specular illuminance ``I_s`` per point.

    Parameters
    ----------
    sampling : str
        The key of :data:`impastor.point_lights.LIGHT_SAMPLING_METHODS` that makes the point
        lights (which the diffuse term always uses).
    failsafe : bool
        ``reference`` takes ``failsafe=`` (the hybrid's fail-safe, which a tolerance may drop) and
        ``by_group=`` (a method per group of similar α, which a tolerance may choose).
    """

    sampling: str
    failsafe: bool = False


#: The painting's lighting methods by key.
PAINTING_LIGHTING_METHODS = Registry("lighting method", PaintingLighting)
for _name, _function, _sampling, _cites in (
    ("median_cut", painting_specular_point_lights, "median_cut", "Eq. (2), Ferwerda"),
    ("variance_min", painting_specular_point_lights, "variance_min", "Eq. (2), Ferwerda"),
    ("fis", painting_specular_fis, "median_cut", "Eq. (4), Ferwerda"),
    ("hybrid", painting_specular_hybrid, "median_cut", "Eq. (4), Ferwerda"),
):
    _method = PaintingLighting(
        _name, _function, None, _cites, _painting_example, sampling=_sampling, failsafe=False
    )
    PAINTING_LIGHTING_METHODS.register(replace(_method, failsafe=_name == "hybrid"))

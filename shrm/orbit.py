"""Camera orbits of a render session: the built-in demo scene, scene files, PNG frames and timings.

§5.2, Herbert et al.: a viewpoint change re-runs only extraction and shading, so an orbit pays for
SHRM creation on its first frame only. :func:`render_orbit` renders one with a
:class:`shrm.session.RenderSession` and writes ``frame_###.png`` and ``timings.csv`` (seconds per
stage per frame). Its state comes from :func:`demo_state` (a sphere under a shared environment) or
from a scene file (:func:`scene_state`, docs/scene-format.md) whose objects share one
``isotropic_brdf`` material lit by one environment light.

Importing this module registers the scene-file material type ``isotropic_brdf`` (a registered
isotropic 3-D BRDF of ``reference.materials.brdf.BRDF_METHODS`` and its parameters) and its shader
for environment lights, ``IsotropicBRDFMaterial/EnvironmentLight``, which renders through a SHRM
(§5.5-5.6, Herbert et al.) with the distant-viewer approximation of global SHRMs: one view
direction, the mean over the shaded points.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field

import numpy as np

from reference.errors import require
from reference.materials.types import MATERIAL_TYPES, MaterialType
from reference.registry import Method
from reference.scene.lights import EnvironmentLight, PointLight
from reference.scene.options import check_fraction, register_render_option
from reference.scene.shading import SHADERS, Surface
from reference.scene.sphere_light import sphere_light_shader

__all__ = [
    "IsotropicBRDFMaterial",
    "analytic_isotropic_brdf_names",
    "brdf_params_on_grid",
    "demo_state",
    "merl_to_spectral_brdf_table",
    "orbit_camera",
    "render_orbit",
    "scene_state",
    "shade_isotropic_brdf_environment",
    "shade_isotropic_brdf_point",
    "shade_isotropic_brdf_sphere",
]


@dataclass(frozen=True)
class IsotropicBRDFMaterial:
    """A scene material made of a registered isotropic 3-D BRDF (``type = "isotropic_brdf"``).

    Attributes
    ----------
    brdf : str
        A key of ``reference.materials.brdf.BRDF_METHODS`` that is ``isotropic``.
    params : dict
        Its parameters on the scene's grid (spectral ones per band, :func:`brdf_params_on_grid`).
    name : str
    """

    brdf: str
    params: dict = field(default_factory=dict)
    name: str = "isotropic_brdf"


def analytic_isotropic_brdf_names() -> list[str]:
    """Keys of ``reference.materials.brdf.BRDF_METHODS`` that ``isotropic_brdf`` materials take.

    The isotropic 3-D BRDFs given by formulas (``BRDFMethod.isotropic``), not the tabulated one,
    which needs a file.

    Examples
    --------
    >>> "ggx" in analytic_isotropic_brdf_names(), "table" in analytic_isotropic_brdf_names()
    (True, False)
    """
    from reference.materials.brdf import BRDF_METHODS

    return [n for n, m in BRDF_METHODS.items() if m.isotropic and "table" not in m.params]


def _isotropic_method(brdf: str):
    from reference.materials.brdf import BRDF_METHODS

    method = BRDF_METHODS.lookup(brdf)
    allowed = analytic_isotropic_brdf_names()
    require(
        brdf in allowed,
        f"must be an analytic isotropic 3-D BRDF; allowed: {', '.join(allowed)}; got {brdf!r}",
    )
    return method


def brdf_params_on_grid(brdf: str, grid, params: dict | None = None) -> dict:
    """A BRDF's parameters on a spectral grid: its defaults, overridden by ``params``.

    Spectral parameters (1-D arrays among the defaults) given as k values are spread evenly over
    380-780 nm and interpolated linearly onto the grid; ``wavelengths_nm`` becomes the grid's.

    Examples
    --------
    >>> from reference.colour.spectra import SpectralGrid
    >>> p = brdf_params_on_grid("ggx", SpectralGrid(380.0, 780.0, 200.0), {"alpha": 0.3})
    >>> p["rho_d"].tolist(), p["alpha"]
    ([0.5, 0.3, 0.1], 0.3)
    """
    method = _isotropic_method(brdf)
    out = {**dict(method.params), **(params or {})}
    for key, value in out.items():
        if key == "wavelengths_nm":
            out[key] = grid.wavelengths_nm
        elif np.ndim(value) == 1 and np.size(value) != grid.n_bands:
            out[key] = np.interp(
                grid.wavelengths_nm, np.linspace(380, 780, len(value)), np.asarray(value)
            )
    return out


def _parse_isotropic_brdf(reader, table: dict, key: str, name: str):
    """Scene-file parser: ``brdf`` (required) and the BRDF's parameters (spectra or numbers).

    ``brdf = "table"`` takes a ``file`` key instead: a BRDF table (docs/brdf-format.md), its
    bands interpolated linearly onto the scene's grid (constant beyond its ends).
    """
    brdf = reader.string(table.get("brdf"), f"{key}.brdf") if "brdf" in table else None
    if brdf is None:
        reader.fail(key, "missing key 'brdf'")
    if brdf == "table":
        return IsotropicBRDFMaterial("table", _table_on_grid(reader, table, key), name)
    with reader.context(f"{key}.brdf"):
        method = _isotropic_method(brdf)
    defaults = {k: v for k, v in method.params.items() if k != "wavelengths_nm"}
    reader.table(table, key, ("type", "brdf", *defaults))
    params = {}
    for p, default in defaults.items():
        if p in table:
            where = f"{key}.{p}"
            # a spectral default takes a spectrum (or a number); a scalar one a number, or a
            # spectrum table where the BRDF takes one per band (GGX's F_0 of a fitted paint:
            # under environment light each band then has its own SHRM)
            spectral = np.ndim(default) == 1 or (isinstance(table[p], dict) and p != "alpha")
            params[p] = (
                reader.spectrum_on_grid(table[p], where)
                if spectral
                else reader.number(table[p], where)
            )
    on_grid = brdf_params_on_grid(brdf, reader.grid, params)
    # The BRDF checks its own parameters: evaluated once here, so that a bad value is refused
    # when the scene loads, naming the file and the key, not when the first pixel is shaded.
    up = np.array([0.0, 0.0, 1.0])
    with reader.context(key, alias=brdf):
        method.reference(up, up, up, **on_grid)
    return IsotropicBRDFMaterial(brdf, on_grid, name)


def _table_on_grid(reader, table: dict, key: str) -> dict:
    """``{"table": BRDFTable}`` of a material's ``file``, resampled onto the scene's grid.

    A ``.binary`` file is a MERL BRDF (Matusik et al. 2003, :mod:`reference.materials.merl`),
    tabulated at 2° in θ and 4° in Δφ, its RGB turned into spectra on the grid by Mallett &
    Yuksel's primaries (the RGB taken as linear sRGB; docs/brdf-format.md).
    """
    from reference.materials.table import BRDFTable, read_brdf_table

    reader.table(table, key, ("type", "brdf", "file"))
    if "file" not in table:
        reader.fail(key, "brdf = 'table' needs a key 'file' (a BRDF table, docs/brdf-format.md)")
    path = reader.file_path(table["file"], f"{key}.file")
    if path.suffix.lower() == ".binary":
        return {"table": _merl_on_grid(reader, path, key)}
    with reader.context(f"{key}.file"):
        t = read_brdf_table(path)
    wl, target = np.asarray(t.wavelengths_nm), reader.grid.wavelengths_nm
    # Linear interpolation of the table's bands onto the grid
    M = np.stack([np.interp(target, wl, np.eye(wl.size)[i]) for i in range(wl.size)])
    values = t.values @ M
    return {"table": BRDFTable(t.theta_i_deg, t.theta_o_deg, t.phi_d_deg, target, values, t.name)}


def merl_to_spectral_brdf_table(merl, grid, theta_step_deg: float = 2.0, phi_step_deg: float = 4.0):
    """A MERL BRDF as a spectral BRDF table on ``grid``: RGB by Mallett & Yuksel's primaries.

    Matusik et al. 2003 (the measured RGB BRDF, :func:`reference.materials.merl.brdf_merl`,
    resampled by :func:`reference.materials.merl.merl_to_brdf_table`); each channel c becomes
    the basis spectrum ``b_c(λ)`` of Mallett & Yuksel 2019, the MERL RGB taken as linear
    sRGB (our heuristic: the database does not state its primaries; docs/brdf-format.md).

    Parameters
    ----------
    merl : reference.materials.merl.MERLBRDF
        The measured BRDF.
    grid : reference.colour.spectra.SpectralGrid
        The bands.
    theta_step_deg, phi_step_deg : float
        The table's steps in θ_i, θ_o and Δφ, degrees (dividing 90 and 180).

    Returns
    -------
    reference.materials.table.BRDFTable

    Examples
    --------
    >>> from reference.colour.spectra import SpectralGrid
    >>> from reference.materials.merl import MERLBRDF
    >>> grey = MERLBRDF(np.full((90, 90, 180, 3), 0.1))
    >>> t = merl_to_spectral_brdf_table(grey, SpectralGrid(400.0, 700.0, 100.0), 45.0, 90.0)
    >>> t.values.shape, t.values[0, 0, 0].round(4)  # white stays flat
    ((3, 3, 3, 4), array([0.1, 0.1, 0.1, 0.1]))
    """
    from reference.colour.upsampling import RGB_to_spectra_Mallett2019
    from reference.materials.merl import merl_to_brdf_table

    # Mallett & Yuksel 2019, the spectral primaries: f(λ) = f_R b_R(λ) + f_G b_G(λ) + f_B b_B(λ)
    basis = RGB_to_spectra_Mallett2019(np.eye(3), grid)
    return merl_to_brdf_table(merl, basis, grid.wavelengths_nm, theta_step_deg, phi_step_deg)


def _merl_on_grid(reader, path, key: str):
    """The BRDF table of a MERL file on the scene's grid, or a one-line error naming the key."""
    from reference.materials.merl import read_merl_brdf

    with reader.context(f"{key}.file"):
        return merl_to_spectral_brdf_table(read_merl_brdf(path), reader.grid)


MATERIAL_TYPES.register(
    MaterialType(
        "isotropic_brdf",
        IsotropicBRDFMaterial,
        ("brdf",),
        (),
        "§5.5, Herbert et al. (an isotropic 3-D BRDF rendered through a SHRM)",
        parse=_parse_isotropic_brdf,
    )
)

#: Per-pixel tolerance of the scene shader, relative to the image's peak (``shrm_tol``).
DEFAULT_SHRM_TOL = 0.002

_RENDERERS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _working_environment(light: EnvironmentLight, rows: int) -> EnvironmentLight:
    """The light with its map box-filtered to at most ``rows`` rows (2:1 lat-long)."""
    from dataclasses import replace

    from reference.geometry.camera import downsample_box

    image = light.image
    factor = max(1, image.shape[0] // rows)
    h = factor * (image.shape[0] // factor)
    return replace(light, image=downsample_box(image[:h, : 2 * h], factor))


def _renderer(surface: Surface, material: IsotropicBRDFMaterial, light, ctx, tol: float):
    """The split renderer of this light and material, made once per grid, upsampling and tol."""
    from shrm.environment import cached_spectral_radiance
    from shrm.split import split_renderer

    key = (id(material), ctx.grid, ctx.options.get("upsampling"), tol)
    per_light = _RENDERERS.setdefault(light, {})
    if key not in per_light or per_light[key][0] is not material:
        radiance = cached_spectral_radiance(light, ctx)
        y_weights = ctx.weights(None)[:, 1]
        renderer = split_renderer(
            radiance, material.brdf, material.params, y_weights, surface.normal, surface.view, tol
        )
        per_light[key] = (material, renderer)
    return per_light[key][1]


def shade_isotropic_brdf_environment(
    surface: Surface, material: IsotropicBRDFMaterial, light: EnvironmentLight, ctx
) -> np.ndarray:
    """XYZ of an isotropic 3-D BRDF under an environment: SHRM + angular split, or brute force.

    §9, Herbert et al. (:mod:`shrm.split`): the environment at full resolution is split into a
    band-limited part, rendered through a global SHRM (§5.5-5.6, Herbert et al.; one distant view,
    the mean of the points' views), and the residual texels, integrated per pixel in angular
    space. The settings (F, P, cube size, split threshold) are chosen for the per-pixel tolerance
    ``ctx.options["shrm_tol"]`` (default :data:`DEFAULT_SHRM_TOL`, relative to the peak), made
    once per light, material, grid and upsampling, and stated in ``ctx.records["shrm"]``.
    With ``ctx.options["environment"] == "bruteforce"`` (``specref render --oracle``) every pixel
    sums the BRDF over every texel with its own view (:func:`shrm.split.angular_sum`). The
    environment's spectra follow ``ctx.options["upsampling"]`` (:mod:`shrm.environment`).

    Examples
    --------
    >>> from reference.scene.shading import ShadingContext
    >>> from reference.colour.spectra import SpectralGrid
    >>> ctx = ShadingContext(SpectralGrid(400.0, 700.0, 20.0))
    >>> m = IsotropicBRDFMaterial("ggx", brdf_params_on_grid("ggx", ctx.grid))
    >>> env = EnvironmentLight(np.ones((16, 32, 3)))
    >>> n = np.array([[0.0, 0.0, 1.0]])
    >>> shade_isotropic_brdf_environment(Surface(n * 0, n, n, np.zeros((1, 2))), m, env,
    ...                                  ctx).shape
    (1, 3)
    """
    from shrm.environment import cached_spectral_radiance
    from shrm.shrm_oracles import env_quadrature
    from shrm.split import angular_sum, split_shade

    if surface.normal.shape[0] == 0:
        return np.zeros((0, 3))
    if ctx.options.get("environment") == "bruteforce":
        env = env_quadrature(cached_spectral_radiance(light, ctx))
        spectra = angular_sum(env, *_full_brdf(material), surface.normal, surface.view)
        ctx.records.setdefault("shrm", {})["method"] = "bruteforce"
        return spectra @ ctx.weights(None)
    tol = ctx.options.get("shrm_tol", DEFAULT_SHRM_TOL)
    require(
        isinstance(tol, int | float) and not isinstance(tol, bool) and 0.0 < tol < 1.0,
        f"render.options.shrm_tol: must be a number in (0, 1), got {tol!r}",
    )
    tol = float(tol)
    renderer = _renderer(surface, material, light, ctx, tol)
    spectra, clamped = split_shade(renderer, surface.normal, surface.view)
    meta = ctx.records.setdefault("shrm", {})
    meta.update(method="shrm+angular", **renderer.settings.metadata())
    meta["clamped_values"] = meta.get("clamped_values", 0) + clamped
    return spectra @ ctx.weights(None)


def _full_brdf(material: IsotropicBRDFMaterial):
    """The material's whole BRDF (Lambertian part included) and its parameters."""
    from reference.materials.brdf import BRDF_METHODS

    return BRDF_METHODS.lookup(material.brdf).reference, material.params


def shade_isotropic_brdf_point(
    surface: Surface, material: IsotropicBRDFMaterial, light: PointLight, ctx
) -> np.ndarray:
    """XYZ of an isotropic 3-D BRDF under a point light: ``π f(ω_i, ω_o) cos θ_i f_att I``.

    The rendering equation for a point light (Pharr et al., pbrt-v4 §12.1: ``L_o = f I cos θ_i /
    d²``) in the scene format's units: a white diffuser (``f = 1/π``) facing the light at
    ``f_att = 1`` has Y = ``intensity`` (docs/scene-format.md), so the reflected fraction per band
    is ``π f cos θ_i f_att``, with the attenuation of Eq. (1), Wang et al. (``[0, 0, 1]`` is
    ``1/d²``). The light's spectrum is folded into the band weights (errata E7).

    Examples
    --------
    >>> from reference.scene.shading import ShadingContext
    >>> from reference.colour.spectra import SpectralGrid
    >>> ctx = ShadingContext(SpectralGrid(400.0, 700.0, 20.0))
    >>> white = IsotropicBRDFMaterial("lambert", {"rho_d": np.ones(16)})
    >>> n = np.array([[0.0, 0.0, 1.0]])
    >>> XYZ = shade_isotropic_brdf_point(Surface(n * 0, n, n, np.zeros((1, 2))), white,
    ...                                  PointLight((0.0, 0.0, 2.0), intensity=0.5), ctx)
    >>> round(float(XYZ[0, 1]), 12)                       # a white diffuser: Y = intensity
    0.5
    """
    from reference.scene.lights import attenuation_Wang, point_light_vectors

    L, d = point_light_vectors(light.position, surface.position)
    f_att = attenuation_Wang(d, *light.attenuation)
    cos_i = np.maximum(np.einsum("ij,ij->i", surface.normal, L), 0.0)
    brdf, params = _full_brdf(material)
    f = brdf(L, surface.view, surface.normal, **params)
    # L_o / I = f cos θ_i f_att, times π for the scene format's unit (a white diffuser: Y = I)
    spectra = (np.pi * cos_i * f_att)[:, None] * f
    return light.intensity * (spectra @ ctx.weights(light.spectrum))


SHADERS.register(
    Method(
        "IsotropicBRDFMaterial/PointLight",
        shade_isotropic_brdf_point,
        None,
        "§12.1, Pharr et al. (pbrt-v4); Eq. (1), Wang et al. (attenuation)",
    )
)
_isotropic_brdf_sphere = sphere_light_shader(shade_isotropic_brdf_point)


def shade_isotropic_brdf_sphere(
    surface: Surface, material: IsotropicBRDFMaterial, light, ctx
) -> np.ndarray:
    """XYZ of an isotropic 3-D BRDF under a sphere light: ``L_e ∫ f cos θ_i dω`` over its cone.

    The cone above the horizon (Pharr et al., pbrt-v4 §12.2; ``reference.scene.sphere_light``).

    Examples
    --------
    >>> from reference.scene.lights import SphereLight
    >>> from reference.scene.shading import ShadingContext
    >>> from reference.colour.spectra import SpectralGrid
    >>> ctx = ShadingContext(SpectralGrid(400.0, 700.0, 20.0))
    >>> white = IsotropicBRDFMaterial("lambert", {"rho_d": np.ones(16)})
    >>> n = np.array([[0.0, 0.0, 1.0]])
    >>> XYZ = shade_isotropic_brdf_sphere(Surface(n * 0, n, n, np.zeros((1, 2))), white,
    ...                                   SphereLight((0.0, 0.0, 2.0), 1.0, intensity=0.5), ctx)
    >>> round(float(XYZ[0, 1]), 9)                   # a white diffuser: L r²/d²
    0.125
    """
    return _isotropic_brdf_sphere(surface, material, light, ctx)


SHADERS.register(
    Method(
        "IsotropicBRDFMaterial/SphereLight",
        shade_isotropic_brdf_sphere,
        None,
        "§12.2, Pharr et al. (pbrt-v4)",
    )
)
SHADERS.register(
    Method(
        "IsotropicBRDFMaterial/EnvironmentLight",
        shade_isotropic_brdf_environment,
        None,
        "§5.6, Herbert et al.",
    )
)


def orbit_camera(frame: int, frames: int, radius: float = 5.0, elevation_deg: float = 15.0):
    """An orthographic camera on a circle about the y axis, looking at the origin.

    Parameters
    ----------
    frame, frames : int
        This frame's index and the number of frames of a full turn.
    radius : float
        Distance from the origin.
    elevation_deg : float
        Height of the circle, degrees above the horizon.

    Returns
    -------
    reference.geometry.camera.Camera

    Examples
    --------
    >>> orbit_camera(0, 4, elevation_deg=0.0).eye
    (0.0, 0.0, 5.0)
    """
    from reference.geometry.camera import Camera

    a = 2.0 * np.pi * frame / frames
    e = np.radians(elevation_deg)
    eye = radius * np.array([np.cos(e) * np.sin(a), np.sin(e), np.cos(e) * np.cos(a)])
    return Camera(
        eye=tuple(float(x) + 0.0 for x in np.round(eye, 12)),
        target=(0.0, 0.0, 0.0),
        projection="orthographic",
        extent=2.4,
    )


def _demo_environment(environment_path, env_height: int, n_bands: int) -> np.ndarray:
    """The map box-filtered to ``env_height`` rows, its luminance on every band (equal energy)."""
    from pathlib import Path

    from reference.data import data_path
    from reference.geometry.camera import downsample_box
    from reference.images.formats import read_image

    default = data_path("environments/venice_sunset_1k.hdr")
    path = Path(environment_path) if environment_path else default
    require(path.is_file(), f"{path}: environment file not found (--env)")
    image = read_image(path)
    H, W = image.shape[:2]
    require(W == 2 * H, f"{path}: a lat-long map must be 2:1 (width = 2 × height), got {W}×{H}")
    factor = max(1, image.shape[0] // env_height)
    image = downsample_box(image[: factor * env_height, : factor * 2 * env_height], factor)
    luminance = image @ np.array([0.2126, 0.7152, 0.0722])
    return np.repeat(luminance[..., None], n_bands, axis=-1)


def demo_state(
    environment_path=None,
    env_height: int = 64,
    brdf: str = "effect_pigment",
    grid=None,
    size: int = 32,
    resolution: int = 96,
    **config,
) -> dict:
    """A built-in scene for the orbit and the report: a sphere under a shared environment.

    The environment (default ``data:environments/venice_sunset_1k.hdr``, shipped with specref)
    is box-filtered to ``env_height`` rows and turned into spectra by replicating
    its luminance over the grid (an equal-energy spectral environment); the illuminant is CIE D65.

    Parameters
    ----------
    environment_path : str or Path, optional
        A lat-long ``.hdr`` or ``.exr``.
    env_height : int
        Rows of the working environment (a power-of-two fraction of the file's height).
    brdf : str
        A key of :data:`reference.materials.brdf.BRDF_METHODS` (isotropic), with its default
        parameters.
    grid : reference.colour.spectra.SpectralGrid, optional
        Default a 16-band 400-700 nm grid (20 nm), which keeps the demo quick.
    size : int
        Cube face size of the maps.
    resolution : int
        Image width and height.
    **config
        Further configuration (``F_max``, ``P_max``, ``light_order``, ``tol``, ``frame``).

    Returns
    -------
    dict
        State for :class:`RenderSession`.

    Examples
    --------
    >>> state = demo_state(env_height=16, size=4, resolution=8)
    >>> state["environment"].shape, sorted(state["dynamic"])
    ((16, 32, 16), ['k_d', 'k_e', 'k_s'])
    """
    from reference.colour.spectra import SpectralGrid, resample_spectrum, spectrum_from_dataset
    from reference.geometry.shapes import Sphere

    grid = grid or SpectralGrid(400.0, 700.0, 20.0)
    environment = _demo_environment(environment_path, env_height, grid.n_bands)
    illuminant = spectrum_from_dataset("illuminant", "D65")
    D65 = np.asarray(resample_spectrum(illuminant, grid), dtype=np.float64)
    params = brdf_params_on_grid(brdf, grid)
    return {
        "illuminant": D65 / D65.max(),
        "environment": environment,
        "viewpoint": orbit_camera(0, 8),
        "gloss": 64.0,
        "brdf": {"name": brdf, "params": params},
        "dynamic": {"k_d": 0.0, "k_s": 0.0, "k_e": 1.0},
        "config": {
            "size": size,
            "width": resolution,
            "height": resolution,
            "objects": [Sphere((0.0, 0.0, 0.0), 1.0)],
            "grid": [grid.start_nm, grid.end_nm, grid.step_nm],
            **config,
        },
    }


def turn_camera(camera, angle: float):
    """The camera turned by ``angle`` radians about the vertical (y) axis through its target.

    Examples
    --------
    >>> from reference.geometry.camera import Camera
    >>> turn_camera(Camera(eye=(0.0, 1.0, 5.0)), np.pi / 2).eye
    (5.0, 1.0, 0.0)
    """
    from dataclasses import replace

    t = np.asarray(camera.target, dtype=np.float64)
    d = np.asarray(camera.eye, dtype=np.float64) - t
    c, s = np.cos(angle), np.sin(angle)
    turned = np.array([c * d[0] + s * d[2], d[1], -s * d[0] + c * d[2]]) + t
    return replace(camera, eye=tuple(float(x) + 0.0 for x in np.round(turned, 12)))


def scene_state(scene, env_height: int = 32, size: int = 16, **config) -> dict:
    """Session state of a scene file (docs/scene-format.md) for :func:`render_orbit`.

    The scene's objects must share one ``isotropic_brdf`` material and its lights be one
    ``environment`` light; its camera starts the orbit, its ``[render]`` size is the image size.
    The environment's spectral radiance on the scene's grid (``shrm.environment``) is box-filtered
    to ``env_height`` rows; the illuminant is flat (the radiance carries the light's colour).

    Parameters
    ----------
    scene : reference.scene.loader.Scene
    env_height : int
        Rows of the working environment.
    size : int
        Cube face size of the maps.
    **config
        Further configuration (``F_max``, ``P_max``, ``light_order``, ``tol``, ``F``, ``P``).

    Returns
    -------
    dict

    Raises
    ------
    SpecrefError
        Another material or light, or no object, naming the scene file.

    Examples
    --------
    >>> from reference.scene.loader import loads_scene
    >>> scene = loads_scene('''
    ... [materials.m]
    ... type = "isotropic_brdf"
    ... brdf = "ggx"
    ... [[objects]]
    ... type = "sphere"
    ... material = "m"
    ... [[lights]]
    ... type = "point"
    ... position = [0, 0, 5]
    ... ''', "s.toml")
    >>> scene_state(scene)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: s.toml: lights: SHRM orbits need one environment light; got point
    """
    from shrm.environment import environment_spectral_radiance

    where = scene.file
    kinds = [type(m).__name__ for m in scene.materials]
    require(
        len(scene.materials) == 1 and isinstance(scene.materials[0], IsotropicBRDFMaterial),
        f"{where}: materials: SHRM orbits need exactly one material of type isotropic_brdf; "
        f"got {', '.join(kinds) or 'none'}",
    )
    lights = [type(x).__name__.removesuffix("Light").lower() for x in scene.lights]
    require(
        len(scene.lights) == 1 and isinstance(scene.lights[0], EnvironmentLight),
        f"{where}: lights: SHRM orbits need one environment light; "
        f"got {', '.join(lights) or 'none'}",
    )
    require(len(scene.objects) > 0, f"{where}: objects: SHRM orbits need an object; got none")
    material, grid = scene.materials[0], scene.grid
    work = _working_environment(scene.lights[0], env_height)
    return {
        "illuminant": np.ones(grid.n_bands),
        "environment": environment_spectral_radiance(work, grid),
        "viewpoint": scene.camera,
        "gloss": 64.0,
        "brdf": {"name": material.brdf, "params": material.params},
        "dynamic": {"k_d": 0.0, "k_s": 0.0, "k_e": 1.0},
        "config": {
            "size": size,
            "width": scene.render.width,
            "height": scene.render.height,
            "objects": list(scene.objects),
            "grid": [grid.start_nm, grid.end_nm, grid.step_nm],
            **config,
        },
    }


def render_orbit(session, frames: int, out_dir=None, progress: bool = True):
    """Render a camera orbit; write PNG frames and a per-stage timing table (``timings.csv``).

    The orbit turns the session's camera about the vertical axis through its target. The first
    frame pays for creation; later frames run only ``gbuffer``, ``extract`` and ``shade`` (§5.2,
    Herbert et al.).

    Parameters
    ----------
    session : shrm.session.RenderSession
        With a ``config.grid`` of ``[start_nm, end_nm, step_nm]``.
    frames : int
        Frames of a full turn, >= 1.
    out_dir : str or Path, optional
        Where to write ``frame_###.png`` and ``timings.csv`` (atomically); None writes nothing.
    progress : bool
        tqdm progress on stderr.

    Returns
    -------
    list of dict
        ``{stage: seconds}`` per frame.

    Examples
    --------
    >>> from shrm.session import RenderSession
    >>> s = RenderSession(demo_state(env_height=16, size=4, resolution=8, F_max=8, P_max=4))
    >>> times = render_orbit(s, 2, progress=False)
    >>> sorted(times[1])
    ['extract', 'gbuffer', 'shade']
    """
    import sys
    from pathlib import Path

    from tqdm import tqdm

    from reference.colour.colorimetry import XYZ_to_display_RGB, band_weights, spectra_to_XYZ
    from reference.colour.spectra import SpectralGrid
    from reference.display.encodings import linear_to_display
    from reference.errors import require_positive_int
    from reference.files import check_output_folder, write_text_atomic
    from reference.images.formats import write_png

    frames = require_positive_int(frames, "orbit --frames", 100000)
    if out_dir is not None:
        check_output_folder(out_dir)  # before the first frame, not after it
    grid = SpectralGrid(*session.state["config"]["grid"])
    W = band_weights(grid, None)
    white = float(spectra_to_XYZ(np.asarray(session.state["illuminant"]), W)[1])
    rows, start = [], session.state["viewpoint"]
    for f in tqdm(range(frames), desc="orbit", unit="frame", file=sys.stderr, disable=not progress):
        # A full turn about the vertical axis through the first camera's target
        session.update(viewpoint=turn_camera(start, 2.0 * np.pi * f / frames))
        result = session.render()
        times = session.frame_times[-1]
        rows.append(times)
        if out_dir is not None:
            XYZ = spectra_to_XYZ(result["shade"]["radiance"], W) / white
            RGB = linear_to_display(np.clip(XYZ_to_display_RGB(XYZ), 0.0, None), "srgb")
            write_png(Path(out_dir) / f"frame_{f:03d}.png", np.clip(RGB, 0.0, 1.0))
    if out_dir is not None:
        names = [s.name for s in session.stages]
        lines = ["frame," + ",".join(names) + ",total"]
        for f, times in enumerate(rows):
            cells = [f"{times.get(n, 0.0):.6f}" for n in names]
            lines.append(f"{f}," + ",".join(cells) + f",{sum(times.values()):.6f}")
        write_text_atomic(Path(out_dir) / "timings.csv", "\n".join(lines) + "\n")
    return rows


register_render_option(
    "shrm_tol",
    check_fraction,
    f"SHRMs' per-pixel tolerance, of the peak (default {DEFAULT_SHRM_TOL})",
)

"""Rendering a scene: G-buffer, deferred shading, box resolve, XYZ to display RGB, encoding.

:func:`render_scene` runs the pipeline of a :class:`~reference.scene.loader.Scene`:

1. the G-buffer at ``supersample ×`` the resolution (``reference.geometry.gbuffer.render_gbuffer``);
2. deferred shading to XYZ, Y = 1 for a white diffuser facing a unit light
   (``reference.scene.shading.shade_gbuffer``), with the background where no surface is visible;
3. the box filter back to the image size (``reference.geometry.camera.downsample_box``);
4. XYZ to linear display RGB in the scene's colourspace, with optional chromatic adaptation from the
   scene light's white to the colourspace white (Eq. (5), Wang et al.);
5. exposure, clipping to [0, 1] and the display encoding
   (``reference.display.encodings.ENCODINGS``).

The G-buffer is kept in the :class:`RenderResult`, so a material or light edit re-shades without
re-rasterizing: ``render_scene(edited, gbuffer=result.gbuffer)``. Shading runs in tiles of whole
rows of at most :data:`SHADING_TILE_SAMPLES` samples, which bounds the memory of spectral
temporaries.

:func:`write_render` writes the display-encoded PNG and the linear display RGB as float EXR (before
exposure), each atomically, so an interrupted run never leaves a half-written file.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from json import dumps
from pathlib import Path

import numpy as np

from reference.colour.colorimetry import (
    XYZ_to_RGB_matrix,
    band_weights,
    display_RGB_to_XYZ,
    white_XYZ,
)
from reference.colour.spectra import make_spectrum, resample_spectrum
from reference.colour.upsampling import DEFAULT_UPSAMPLING, RGB_to_radiance_spectra
from reference.display.encodings import linear_to_display
from reference.errors import SpecrefError, format_allowed, require
from reference.files import check_output_file, write_text_atomic
from reference.geometry.camera import downsample_box
from reference.geometry.envmap import latlong_lookup_bilinear
from reference.geometry.gbuffer import GBuffer, render_gbuffer
from reference.images.formats import write_exr, write_png
from reference.progress import Progress
from reference.scene.lights import EnvironmentLight
from reference.scene.loader import Scene, load_scene
from reference.scene.shading import SHADERS, shade_gbuffer, shader_key

__all__ = [
    "SHADING_TILE_SAMPLES",
    "RenderResult",
    "XYZ_to_display",
    "background_XYZ",
    "check_shaders",
    "render_scene",
    "render_scene_file",
    "scene_gbuffer",
    "shade_scene",
    "write_render",
]

#: Most G-buffer samples shaded at once (whole rows); larger images are shaded in row tiles.
SHADING_TILE_SAMPLES = 1 << 18


@dataclass(frozen=True, eq=False)
class RenderResult:
    """The outputs of :func:`render_scene`.

    Attributes
    ----------
    XYZ : ndarray, shape (H, W, 3)
        Tristimulus values, Y = 1 for a white diffuser facing a unit light.
    RGB_linear : ndarray, shape (H, W, 3)
        Linear display RGB in the scene's colourspace (adapted if the scene says so), unclipped and
        before exposure: what the EXR output holds.
    encoded : ndarray, shape (H, W, 3)
        Display-encoded values in [0, 1] (exposure, clipping, encoding): what the PNG holds.
    gbuffer : GBuffer
        The supersampled G-buffer, ``(supersample·H, supersample·W)``; pass it back to
        :func:`render_scene` to re-shade without re-rasterizing.
    supersample : int
        Sub-samples per pixel per axis.
    timings : dict
        Seconds spent in ``"gbuffer"``, ``"shading"`` and ``"display"``, and the ``"total"``.
    scene : Scene
        The scene as rendered (with any size override).
    spectral : ndarray or None, shape (H, W, n_bands)
        Relative spectral radiance per band when rendered with ``spectral=True``
        (``reference.scene.shading.spectral_output_weights``); XYZ is then ``spectral @ W_E``.
    records : dict
        What the shaders chose (``ShadingContext.record``): SH orders and the bounds they promise;
        ``reference.scene.metadata`` puts it in the metadata.
    metadata : dict
        What :func:`render_scene_file` wrote into the EXR header and ``--json`` (empty from
        :func:`render_scene`).
    """

    XYZ: np.ndarray
    RGB_linear: np.ndarray
    encoded: np.ndarray
    gbuffer: GBuffer
    supersample: int
    timings: dict = field(default_factory=dict)
    scene: Scene | None = None
    spectral: np.ndarray | None = None
    records: dict = field(default_factory=dict)
    metadata: dict = field(default_factory=dict)


def check_shaders(scene: Scene) -> None:
    """Refuse a scene with a material/light pair that no registered shader handles.

    Runs before rasterizing, so a missing shader fails fast. Shaders from ``phong_table`` and
    ``shrm`` are registered when those packages are imported (``specref render`` imports them).

    Raises
    ------
    SpecrefError
        Naming the material, the light and the registered shaders.

    Examples
    --------
    >>> from reference.scene.loader import loads_scene
    >>> check_shaders(loads_scene('[[lights]]' + chr(10) + 'type = "ambient"'))
    """
    used = sorted({obj.material for obj in scene.objects})
    for index in used:
        require(
            0 <= index < len(scene.materials),
            f"{scene.file}: an object uses material index {index} but the scene has "
            f"{len(scene.materials)} materials",
        )
        material = scene.materials[index]
        for j, light in enumerate(scene.lights):
            key = shader_key(material, light)
            if key not in SHADERS:
                raise SpecrefError(
                    f"{scene.file}: no shader for materials.{scene.material_names[index]} "
                    f"({type(material).__name__}) under lights[{j}] ({type(light).__name__}); "
                    f"registered: {format_allowed(SHADERS)}"
                )


def scene_gbuffer(scene: Scene, progress=None) -> GBuffer:
    """The scene's G-buffer at ``supersample ×`` its resolution (progress to a stream, optional).

    Examples
    --------
    >>> from reference.scene.loader import loads_scene
    >>> scene = loads_scene("[render]" + chr(10) + "width = 4" + chr(10) + "height = 2"
    ...                     + chr(10) + "supersample = 3")
    >>> scene_gbuffer(scene).shape
    (6, 12)
    """
    r = scene.render
    return render_gbuffer(scene.objects, scene.camera, r.width, r.height, r.supersample, progress)


def _adaptation_white(scene: Scene):
    """XYZ of the white diffuser under the display's white light (None without adaptation)."""
    display = scene.display
    if display.chromatic_adaptation is None:
        return None
    W = band_weights(scene.grid, display.white, scene.weights_method, scene.observer)
    return white_XYZ(W)


def _XYZ_to_RGB(scene: Scene) -> np.ndarray:
    display = scene.display
    return XYZ_to_RGB_matrix(
        display.colourspace, _adaptation_white(scene), display.chromatic_adaptation
    )


def background_values(scene: Scene, directions, output: str = "XYZ") -> np.ndarray:
    """The environment background in XYZ, or as relative spectral radiance per band.

    Spectral output upsamples an RGB map as the environment shaders do
    (``reference.colour.upsampling.RGB_to_radiance_spectra``, the scene's ``upsampling`` option).

    Examples
    --------
    >>> from reference.scene.loader import loads_scene
    >>> background_values(loads_scene(""), np.zeros((1, 3))).round(4)
    array([[0., 0., 0.]])
    """
    if output != "spectral":
        return background_XYZ(scene, directions)
    env = next(light for light in scene.lights if isinstance(light, EnvironmentLight))
    directions = np.asarray(directions, dtype=np.float64)
    values = latlong_lookup_bilinear(env.image, directions) * env.intensity
    if env.is_spectral:
        return values @ _spectral_to_grid(scene, env).T
    upsampling = scene.render.options.get("upsampling", DEFAULT_UPSAMPLING)
    return RGB_to_radiance_spectra(values, scene.grid, upsampling, env.colourspace)


def _spectral_to_grid(scene: Scene, env) -> np.ndarray:
    """The (n_bands, n_channels) linear interpolation of a spectral map's channels onto the grid."""
    columns = []
    for k in range(env.wavelengths_nm.size):
        unit = np.zeros(env.wavelengths_nm.size)
        unit[k] = 1.0
        channel = make_spectrum(env.wavelengths_nm, unit, env.name)
        columns.append(resample_spectrum(channel, scene.grid))
    return np.stack(columns, axis=-1)


def background_XYZ(scene: Scene, directions) -> np.ndarray:
    """XYZ seen along camera rays that hit nothing.

    A constant background is given in linear display RGB and mapped back through the scene's
    XYZ-to-RGB matrix, so the displayed background is exactly that RGB. An ``"environment"``
    background looks up the first environment light: an RGB map through its colourspace, a spectral
    map resampled onto the grid and weighted as radiance (equal-energy band weights).

    Parameters
    ----------
    scene : Scene
        The scene.
    directions : ndarray, shape (N, 3)
        Unit ray directions.

    Returns
    -------
    ndarray, shape (N, 3)

    Examples
    --------
    >>> from reference.scene.loader import loads_scene
    >>> scene = loads_scene("[render]" + chr(10) + "background = [1, 1, 1]")
    >>> background_XYZ(scene, np.zeros((1, 3))).round(4)
    array([[0.9505, 1.    , 1.089 ]])
    """
    directions = np.asarray(directions, dtype=np.float64)
    background = scene.render.background
    if background != "environment":
        XYZ = np.linalg.solve(_XYZ_to_RGB(scene), np.asarray(background, dtype=np.float64))
        return np.broadcast_to(XYZ, directions.shape).copy()
    env = next(light for light in scene.lights if isinstance(light, EnvironmentLight))
    values = latlong_lookup_bilinear(env.centred_image(), directions) * env.intensity
    if not env.is_spectral:
        return display_RGB_to_XYZ(values, env.colourspace)
    # A spectral map: linear interpolation onto the grid is a matrix (resample each unit channel).
    wl, grid = env.wavelengths_nm, scene.grid
    require(
        wl.size >= 2 and wl[0] <= grid.start_nm and wl[-1] >= grid.end_nm,
        f"{scene.file}: render.background: the spectral environment {env.name} covers "
        f"{wl[0]:g}-{wl[-1]:g} nm but the grid needs {grid.start_nm:g}-{grid.end_nm:g} nm; use a "
        "constant background",
    )
    to_grid = _spectral_to_grid(scene, env)
    W_E = band_weights(scene.grid, None, scene.weights_method, scene.observer)
    return (values @ to_grid.T) @ W_E


def shade_scene(
    scene: Scene,
    gbuffer: GBuffer,
    options: Mapping | None = None,
    output: str = "XYZ",
    records: dict | None = None,
    progress=None,
) -> np.ndarray:
    """XYZ of every G-buffer sample: deferred shading plus the background, shape ``(H, W, 3)``.

    Parameters
    ----------
    scene : Scene
        Materials, lights, grid and render options.
    gbuffer : GBuffer
        Visible surfaces (any resolution; the background rays are the camera's at that size).
    options : mapping, optional
        Merged over the scene's ``render.options`` into ``ShadingContext.options``.
    output : {"XYZ", "spectral"}
        XYZ, or relative spectral radiance per band (``ShadingContext.output``); in spectral
        output a constant background is 0 (it is display RGB, with no spectrum).
    records : dict, optional
        Filled with what the shaders chose (``ShadingContext.records``).
    progress : file-like, optional
        Where to say how the shading advances and how long it will take
        (:class:`reference.progress.Progress`, by covered samples, in blocks of at most 1/32 of
        the rows; the results do not depend on the blocks, shading being per sample).

    Returns
    -------
    ndarray, shape gbuffer.shape + (3,) or + (n_bands,)

    Examples
    --------
    >>> from reference.scene.loader import loads_scene
    >>> scene = loads_scene("[render]" + chr(10) + "background = 0.5")
    >>> shade_scene(scene, scene_gbuffer(scene))[0, 0].round(4)
    array([0.4752, 0.5   , 0.5444])
    """
    check_shaders(scene)
    ctx = dataclasses.replace(scene.shading_context(options), output=output)
    H, W = gbuffer.shape
    XYZ = np.empty((H, W, ctx.n_outputs))
    rows = max(1, SHADING_TILE_SAMPLES // max(W, 1))
    if progress is not None:  # blocks of at most 1/32 of the rows, so the estimate comes early
        rows = min(rows, -(-H // 32))
    # The work is in the covered samples (the background costs nothing): progress counts them.
    covered = gbuffer.mask.sum(axis=1)
    with Progress("shading", int(covered.sum()), progress, unit="covered samples") as bar:
        for start in range(0, H, rows):
            tile = gbuffer.rows(start, min(start + rows, H))
            XYZ[start : start + rows] = shade_gbuffer(tile, scene.materials, scene.lights, ctx)
            bar.update(int(covered[start : start + rows].sum()))
    if records is not None:
        records.update(ctx.records)
    missed = ~gbuffer.mask
    if missed.any():
        if scene.render.background == "environment":
            _, directions = scene.camera.rays(W, H)
            XYZ[missed] = background_values(scene, directions[missed], output)
        elif output == "spectral":
            XYZ[missed] = 0.0
        else:
            XYZ[missed] = background_XYZ(scene, np.zeros((1, 3)))[0]
    return XYZ


def XYZ_to_display(scene: Scene, XYZ) -> tuple[np.ndarray, np.ndarray]:
    """Linear display RGB (Eq. (5), Wang et al.) and display-encoded values of an XYZ image.

    Parameters
    ----------
    scene : Scene
        Its ``display`` settings: colourspace, chromatic adaptation, exposure, encoding.
    XYZ : ndarray, shape (..., 3)

    Returns
    -------
    RGB_linear : ndarray, shape (..., 3)
        Unclipped, before exposure.
    encoded : ndarray, shape (..., 3)
        In [0, 1].

    Examples
    --------
    >>> from reference.scene.loader import loads_scene
    >>> RGB, encoded = XYZ_to_display(loads_scene(""), np.array([0.95047, 1.0, 1.08883]) * 0.18)
    >>> RGB.round(3), encoded.round(3)
    (array([0.18, 0.18, 0.18]), array([0.461, 0.461, 0.461]))
    """
    # Eq. (5), Wang et al.: [R G B] = [X Y Z] · XYZtoRGB (with the adaptation folded in)
    RGB_linear = np.asarray(XYZ, dtype=np.float64) @ _XYZ_to_RGB(scene).T
    display = scene.display
    if display.calibration is not None:
        from reference.display.calibration_files import XYZ_to_calibrated_values

        # device values for the calibrated display (docs/display.md), relative colorimetric
        encoded, _ = XYZ_to_calibrated_values(
            np.asarray(XYZ) * display.exposure, display.calibration
        )
        return RGB_linear, encoded
    encoded = linear_to_display(RGB_linear, display.encoding, display.exposure)
    return RGB_linear, encoded


def render_scene(
    scene: Scene,
    width: int | None = None,
    height: int | None = None,
    supersample: int | None = None,
    options: Mapping | None = None,
    gbuffer: GBuffer | None = None,
    spectral: bool = False,
    progress=None,
) -> RenderResult:
    """Render a scene: G-buffer, shading, box resolve, display conversion and encoding.

    Parameters
    ----------
    scene : Scene
        The scene (``reference.scene.loader.load_scene``).
    width, height, supersample : int, optional
        Override the scene's ``[render]`` values (a lone width or height keeps the aspect ratio);
        checked against the limits of ``reference.scene.loader.check_render_size``.
    options : mapping, optional
        Shader options merged over ``render.options`` (``{"environment": "bruteforce"}`` is what
        ``specref render --oracle`` passes).
    gbuffer : GBuffer, optional
        A G-buffer from an earlier render of the same camera and geometry, to re-shade without
        re-rasterizing; its shape must be ``(supersample·height, supersample·width)``.
    spectral : bool
        Also keep the relative spectral radiance per band (``RenderResult.spectral``); XYZ is then
        its integral with the equal-energy band weights (docs/render-outputs.md).
    progress : file-like, optional
        Where to say how the shading advances, with its expected time (``specref render``).

    Returns
    -------
    RenderResult

    Raises
    ------
    SpecrefError
        Bad sizes, a material/light pair without a shader, a G-buffer of the wrong shape.

    Examples
    --------
    >>> from reference.scene.loader import loads_scene
    >>> scene = loads_scene('''
    ... [materials.white]
    ... type = "lambert"
    ... k_d = 1.0
    ... [[objects]]
    ... type = "sphere"
    ... material = "white"
    ... [[lights]]
    ... type = "point"
    ... position = [0, 0, 5]
    ... ''')
    >>> result = render_scene(scene, width=9, height=9)
    >>> result.XYZ[4, 4].round(4), result.encoded[4, 4].round(3)
    (array([0.9505, 1.    , 1.0888]), array([1., 1., 1.]))
    >>> again = render_scene(scene, width=9, height=9, gbuffer=result.gbuffer)
    >>> bool((again.XYZ == result.XYZ).all())
    True
    """
    start = time.perf_counter()
    if width is not None or height is not None or supersample is not None:
        scene = scene.with_render(width, height, supersample)
    r = scene.render
    check_shaders(scene)
    gbuffer = _render_gbuffer(scene, gbuffer, progress)
    t_gbuffer = time.perf_counter()
    records: dict = {}
    XYZ, spectral_image = _shade_and_resolve(scene, gbuffer, options, spectral, records, progress)
    t_shading = time.perf_counter()
    RGB_linear, encoded = XYZ_to_display(scene, XYZ)
    t_display = time.perf_counter()
    timings = _stage_timings(start, t_gbuffer, t_shading, t_display)
    return RenderResult(
        XYZ, RGB_linear, encoded, gbuffer, r.supersample, timings, scene, spectral_image, records
    )


def _render_gbuffer(scene: Scene, gbuffer: GBuffer | None, progress=None) -> GBuffer:
    """Stage 1: the scene's supersampled G-buffer, or the one given once its shape is checked."""
    if gbuffer is None:
        return scene_gbuffer(scene, progress)
    r = scene.render
    expected = (r.height * r.supersample, r.width * r.supersample)
    require(
        gbuffer.shape == expected,
        f"render_scene: the G-buffer has shape {gbuffer.shape} but the render needs "
        f"{expected} (height × width × supersample)",
    )
    return gbuffer


def _shade_and_resolve(
    scene: Scene, gbuffer: GBuffer, options, spectral: bool, records: dict, progress=None
):
    """Stages 2 and 3: XYZ (and the spectral radiance when asked) box-filtered to the image size."""
    r = scene.render
    if not spectral:
        XYZ = shade_scene(scene, gbuffer, options, records=records, progress=progress)
        return downsample_box(XYZ, r.supersample), None
    samples = shade_scene(scene, gbuffer, options, "spectral", records, progress)
    W_E = band_weights(scene.grid, None, scene.weights_method, scene.observer)
    XYZ = samples @ W_E
    if r.background != "environment":
        XYZ[~gbuffer.mask] = background_XYZ(scene, np.zeros((1, 3)))[0]
    spectral_image = downsample_box(samples, r.supersample)
    return downsample_box(XYZ, r.supersample), spectral_image


def _stage_timings(start: float, t_gbuffer: float, t_shading: float, t_display: float) -> dict:
    """``RenderResult.timings``: seconds per stage from the clock readings between them."""
    return {
        "gbuffer": t_gbuffer - start,
        "shading": t_shading - t_gbuffer,
        "display": t_display - t_shading,
        "total": t_display - start,
    }


def _check_output(path, suffix: str, flag: str) -> Path:
    """An output's name, and proof that it can be written (before the render, not after it)."""
    path = Path(path)
    require(
        path.suffix.lower() == suffix,
        f"{flag}: the output must end in {suffix}, got {str(path)!r}",
    )
    require(not path.is_dir(), f"{flag}: {path} is a folder; give a file name")
    return check_output_file(path)


def write_render(
    result: RenderResult, png=None, exr=None, exr_output: str = "display", metadata=None
) -> list[Path]:
    """Write a render's PNG (display-encoded, 8 bit) and EXR, atomically.

    Parameters
    ----------
    result : RenderResult
        From :func:`render_scene`.
    png, exr : str or Path, optional
        Destinations (``.png`` and ``.exr``).
    exr_output : str
        What the EXR holds, a key of ``reference.scene.metadata.RENDER_OUTPUTS``: ``display``
        (linear display RGB, before exposure), ``xyz`` or ``spectral`` (needs a render with
        ``spectral=True``; spectral OpenEXR channel names of Fichet et al. 2021).
    metadata : dict, optional
        ``reference.scene.metadata.render_metadata``, stored in the EXR header.

    Returns
    -------
    list of Path
        The files written.

    Raises
    ------
    SpecrefError
        Wrong suffix, or the file cannot be written (the message names it).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from reference.scene.loader import loads_scene
    >>> result = render_scene(loads_scene("[render]" + chr(10) + "background = 0.5"), 4, 2)
    >>> out = pathlib.Path(tempfile.mkdtemp())
    >>> [p.name for p in write_render(result, png=out / "a.png", exr=out / "a.exr")]
    ['a.exr', 'a.png']
    >>> write_render(result, png=out / "a.jpg")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: -o: the output must end in .png, got '.../a.jpg'
    """
    from reference.scene.metadata import exr_attributes, output_image

    jobs = []
    if exr is not None:
        image, names = output_image(result, exr_output)
        attributes = exr_attributes(metadata) if metadata else None
        jobs.append(
            (
                _check_output(exr, ".exr", "--exr"),
                lambda p, im: write_exr(p, im, names, attributes=attributes),
                image,
            )
        )
    if png is not None:
        jobs.append((_check_output(png, ".png", "-o"), write_png, result.encoded))
    written = []
    for path, writer, image in jobs:
        try:
            written.append(writer(path, image))
        except OSError as error:
            raise SpecrefError(
                f"{path}: cannot write ({error.__class__.__name__}: {error.strerror or error})"
            ) from None
    return written


def render_scene_file(
    scene_path,
    png=None,
    exr=None,
    width: int | None = None,
    height: int | None = None,
    supersample: int | None = None,
    oracle: bool = False,
    texel_placement: str | None = None,
    exr_output: str = "display",
    accuracy: float | None = None,
    json=None,
    progress=None,
) -> RenderResult:
    """Load a scene file, render it and write the outputs: what ``specref render`` does.

    Parameters
    ----------
    scene_path : str or Path
        The ``.toml`` scene.
    png, exr : str or Path, optional
        Outputs (see :func:`write_render`); checked before rendering.
    width, height, supersample : int, optional
        Size overrides (a lone width or height keeps the aspect ratio).
    oracle : bool
        Set ``ShadingContext.options["environment"] = "bruteforce"``: environment lights are
        integrated by brute force (the SH engine's oracle path) instead of the fast method.
    texel_placement : str, optional
        Every environment light's ``texel_placement`` (``"mitsuba"``: read as Mitsuba 3 does).
    exr_output : {"display", "xyz", "spectral"}
        What the EXR holds (:func:`write_render`).
    accuracy : float, optional
        Mean relative error of Y over lit pixels that fast methods promise (the maximum is 4×);
        default ``reference.scene.metadata.DEFAULT_ACCURACY`` (0.5 %).
    json : str or Path, optional
        Write the render's metadata (``reference.scene.metadata.render_metadata``) there; ``-``
        writes nothing (the CLI prints ``RenderResult.metadata``).
    progress : file-like, optional
        Where to say how the shading advances and its expected time (the CLI's stderr).

    Returns
    -------
    RenderResult

    Raises
    ------
    SpecrefError
        Anything wrong with the scene, the sizes or the outputs.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "s.toml").write_text("[render]" + chr(10) + "width = 0")
    >>> render_scene_file(folder / "s.toml", folder / "s.png")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: .../s.toml: render.width: must be an integer in [1, 16384], got 0
    >>> _ = (folder / "s.toml").write_text(chr(10).join(["[render]", "width = 6", "height = 4"]))
    >>> render_scene_file(folder / "s.toml", folder / "s.png").encoded.shape
    (4, 6, 3)
    """
    from reference.scene.metadata import check_accuracy, render_metadata

    _check_outputs(png, exr, json, exr_output)
    options = {"environment": "bruteforce"} if oracle else {}
    if accuracy is not None:
        options["environment_accuracy"] = check_accuracy(accuracy)
    scene = load_scene(scene_path)
    if width is not None or height is not None or supersample is not None:
        scene = scene.with_render(width, height, supersample, where="command line: render")
    if texel_placement is not None:
        scene = scene.with_texel_placement(texel_placement)
    spectral = exr_output == "spectral"
    result = render_scene(scene, options=options, spectral=spectral, progress=progress)
    metadata = render_metadata(result, exr_output, result.records, oracle)
    write_render(result, png, exr, exr_output, metadata)
    if json is not None and str(json) != "-":
        write_text_atomic(json, dumps(metadata, indent=2) + "\n")
    return dataclasses.replace(result, metadata=metadata)


def _check_outputs(png, exr, json, exr_output: str) -> None:
    """Check the output names and the EXR's contents before anything is rendered."""
    from reference.scene.metadata import RENDER_OUTPUTS

    if png is not None:
        _check_output(png, ".png", "-o")
    if exr is not None:
        _check_output(exr, ".exr", "--exr")
    if json is not None and str(json) != "-":
        _check_output(json, ".json", "--json")
    RENDER_OUTPUTS.lookup(exr_output)

"""Scene files: TOML (``tomllib``) into a :class:`Scene` of camera, objects, materials and lights.

A scene file has the tables ``[spectral]`` (the wavelength grid and colorimetry), ``[camera]``,
``[render]`` (size, supersampling, background, shader options), ``[display]`` (colourspace,
encoding, exposure, chromatic adaptation), ``[materials.<name>]``, and the arrays of tables
``[[objects]]`` and ``[[lights]]``. ``docs/scene-format.md`` gives every key, its type, default and
allowed values.

The loader is driven by registries, so a new type is added without editing it:

- material ``type`` keys come from ``reference.materials.types.MATERIAL_TYPES``; a type reads its
  parameters as spectra on the grid unless its ``MaterialType.parse`` says otherwise;
- object types from ``OBJECT_TYPES`` and light types from ``LIGHT_TYPES``
  (``reference.scene.items``), each entry a parser from the TOML table to a primitive or a light;
- spectrum forms from ``reference.scene.values.SPECTRUM_FORMS``.

Every value is checked where it is read, with one-line messages naming the file, the dotted key,
what is allowed and what was given: ``scene.toml: materials.gold.n: must be >= 0, got -3``.
Relative paths (CSV spectra, OBJ meshes, environment maps) are relative to the scene file's
folder.

Resolution limits: each image side is at most ``MAX_RESOLUTION`` (16384) pixels, supersampling at
most :data:`MAX_SUPERSAMPLE` (16) per axis, and the G-buffer at most :data:`MAX_RENDER_SAMPLES`
(4096² = 16 777 216) samples, ``width · height · supersample²``; larger requests are refused as
absurd (the G-buffer alone takes about 100 bytes per sample).
"""

from __future__ import annotations

import dataclasses
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import reference.scene.colorchecker  # noqa: F401  (registers the colorchecker material and its shaders)
from reference.colour.colorimetry import (
    BAND_WEIGHT_METHODS,
    DEFAULT_OBSERVER,
    OBSERVERS,
    band_weights,
)
from reference.colour.spectra import DEFAULT_GRID, GRIDS, SpectralGrid, Spectrum
from reference.data import DATA_SCHEME, resolve_path
from reference.display.encodings import ENCODINGS
from reference.errors import SpecrefError, format_allowed, require
from reference.geometry.camera import MAX_RESOLUTION, PROJECTIONS, Camera
from reference.materials.types import MATERIAL_TYPES, MaterialType, make_material
from reference.registry import Registry
from reference.scene.items import LIGHT_TYPES, OBJECT_TYPES, SceneItemType
from reference.scene.lights import EnvironmentLight
from reference.scene.shading import ShadingContext
from reference.scene.values import SceneReader

__all__ = [
    "LIGHT_TYPES",
    "MAX_RENDER_SAMPLES",
    "MAX_SUPERSAMPLE",
    "OBJECT_TYPES",
    "DisplaySettings",
    "RenderSettings",
    "Scene",
    "SceneItemType",
    "check_render_size",
    "load_scene",
    "loads_scene",
    "parse_spectral",
    "scene_from_dict",
]

#: Most G-buffer samples (``width · height · supersample²``) a render may ask for.
MAX_RENDER_SAMPLES = 4096 * 4096
#: Most sub-samples per pixel per axis.
MAX_SUPERSAMPLE = 16

_TOP_LEVEL_KEYS = (
    "title",
    "description",
    "spectral",
    "camera",
    "render",
    "display",
    "materials",
    "objects",
    "lights",
)


def check_render_size(width, height, supersample, where: str = "render") -> tuple[int, int, int]:
    """Check an image size and supersampling against the documented limits.

    Parameters
    ----------
    width, height : int
        Image size in pixels, each in [1, MAX_RESOLUTION].
    supersample : int
        Sub-samples per pixel per axis, in [1, MAX_SUPERSAMPLE].
    where : str
        Message prefix, e.g. ``"scene.toml: render"``.

    Returns
    -------
    tuple of int
        ``(width, height, supersample)``.

    Raises
    ------
    SpecrefError
        Zero, negative or non-integer values, or more than :data:`MAX_RENDER_SAMPLES` samples.

    Examples
    --------
    >>> check_render_size(640, 480, 2)
    (640, 480, 2)
    >>> check_render_size(8192, 8192, 4, "scene.toml: render")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: scene.toml: render: width × height × supersample² = 1073741824
    samples is above the limit of 16777216 (MAX_RENDER_SAMPLES)
    """
    reader = SceneReader("")
    width = reader.integer(width, f"{where}.width", 1, MAX_RESOLUTION)
    height = reader.integer(height, f"{where}.height", 1, MAX_RESOLUTION)
    supersample = reader.integer(supersample, f"{where}.supersample", 1, MAX_SUPERSAMPLE)
    samples = width * height * supersample**2
    if samples > MAX_RENDER_SAMPLES:
        raise SpecrefError(
            f"{where}: width × height × supersample² = {samples} samples is above the limit of "
            f"{MAX_RENDER_SAMPLES} (MAX_RENDER_SAMPLES)"
        )
    return width, height, supersample


@dataclass(frozen=True)
class RenderSettings:
    """The ``[render]`` table.

    Attributes
    ----------
    width, height : int
        Image size in pixels.
    supersample : int
        Sub-samples per pixel per axis (box filter).
    background : tuple of 3 floats or "environment"
        Linear display RGB where no surface is visible, or the first environment light's radiance.
    options : mapping
        Handed to ``ShadingContext.options`` (e.g. ``{"environment": "bruteforce"}``).
    """

    width: int = 256
    height: int = 256
    supersample: int = 1
    background: tuple | str = (0.0, 0.0, 0.0)
    options: Mapping = field(default_factory=dict)


@dataclass(frozen=True)
class DisplaySettings:
    """The ``[display]`` table.

    Attributes
    ----------
    colourspace : str
        A key of ``colour.RGB_COLOURSPACES``.
    encoding : str
        A key of ``reference.display.encodings.ENCODINGS``.
    exposure : float
        Multiplier applied to linear display RGB before encoding (not to the EXR output).
    chromatic_adaptation : str or None
        None (colorimetric) or a colour-science transform (``"Bradford"``, ``"CAT02"``, ...).
    white : Spectrum or None
        The light whose white diffuser is adapted to display white.
    calibration : CalibratedDisplay or None
        ``display.calibration``: the PNG then holds device values for that calibrated display
        (``reference.display.calibration_files``, docs/display.md) instead of the encoding.
    """

    colourspace: str = "sRGB"
    encoding: str = "srgb"
    exposure: float = 1.0
    chromatic_adaptation: str | None = None
    white: Spectrum | None = None
    calibration: object | None = None


@dataclass(frozen=True, eq=False)
class Scene:
    """A loaded scene: everything :func:`reference.scene.render.render_scene` needs.

    Attributes
    ----------
    camera : Camera
    objects : tuple
        Primitives (``Sphere``, ``Plane``, ...); each carries its material index.
    materials : tuple
        Material instances, in the order of the ``[materials]`` tables.
    material_names : tuple of str
        The materials' names in the file.
    lights : tuple
        Light instances, in file order.
    grid : SpectralGrid
    observer : str
    weights_method : str
        A key of ``reference.colour.colorimetry.BAND_WEIGHT_METHODS``.
    render : RenderSettings
    display : DisplaySettings
    file : str
        The file's label in messages.
    path : Path or None
        The file, if loaded from one.
    title : str

    Examples
    --------
    >>> scene = loads_scene('''
    ... [materials.grey]
    ... type = "lambert"
    ... k_d = 0.5
    ... [[objects]]
    ... type = "sphere"
    ... material = "grey"
    ... [[lights]]
    ... type = "point"
    ... position = [0, 0, 5]
    ... ''')
    >>> scene.grid.n_bands, scene.material_names, type(scene.lights[0]).__name__
    (41, ('grey',), 'PointLight')
    """

    camera: Camera
    objects: tuple
    materials: tuple
    material_names: tuple
    lights: tuple
    grid: SpectralGrid = DEFAULT_GRID
    observer: str = DEFAULT_OBSERVER
    weights_method: str = "astm_e308"
    render: RenderSettings = field(default_factory=RenderSettings)
    display: DisplaySettings = field(default_factory=DisplaySettings)
    file: str = "<string>"
    path: Path | None = None
    title: str = ""

    def shading_context(self, options: Mapping | None = None) -> ShadingContext:
        """The :class:`~reference.scene.shading.ShadingContext` of this scene, options merged in.

        Examples
        --------
        >>> scene = loads_scene('[render.options]' + chr(10) + 'environment = "sh"')
        >>> dict(scene.shading_context({"environment": "bruteforce"}).options)
        {'environment': 'bruteforce'}
        """
        merged = {**self.render.options, **(options or {})}
        return ShadingContext(self.grid, self.observer, self.weights_method, merged)

    def with_render(self, width=None, height=None, supersample=None, where="render") -> Scene:
        """The scene with another size or supersampling; a lone width or height keeps the aspect.

        Examples
        --------
        >>> scene = loads_scene('[render]' + chr(10) + 'width = 200' + chr(10) + 'height = 100')
        >>> s = scene.with_render(width=50).render
        >>> s.width, s.height
        (50, 25)
        """
        r = self.render
        # the sizes as given first, so a bad --height is named as such (not as the width from it)
        check_render_size(
            r.width if width is None else width,
            r.height if height is None else height,
            r.supersample if supersample is None else supersample,
            where,
        )
        if width is not None and height is None:
            height = max(1, round(width * r.height / r.width)) if _is_count(width) else width
        if height is not None and width is None:
            width = max(1, round(height * r.width / r.height)) if _is_count(height) else height
        width, height, supersample = check_render_size(
            r.width if width is None else width,
            r.height if height is None else height,
            r.supersample if supersample is None else supersample,
            where,
        )
        render = dataclasses.replace(r, width=width, height=height, supersample=supersample)
        return dataclasses.replace(self, render=render)

    def with_texel_placement(self, placement: str) -> Scene:
        """The scene with every environment light read under ``placement`` (``TEXEL_PLACEMENTS``).

        Examples
        --------
        >>> loads_scene("").with_texel_placement("mitsuba").lights
        ()
        """
        lights = tuple(
            dataclasses.replace(light, texel_placement=placement)
            if isinstance(light, EnvironmentLight)
            else light
            for light in self.lights
        )
        return dataclasses.replace(self, lights=lights)

    def material_index(self, name: str) -> int:
        """Index of the material called ``name``."""
        if name not in self.material_names:
            raise SpecrefError(
                f"{self.file}: unknown material {name!r}; allowed: "
                f"{format_allowed(self.material_names)}"
            )
        return self.material_names.index(name)


def _is_count(value) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= 1


# --- the scene tables
# -------------------------------------------------------------------------------------


def parse_spectral(reader: SceneReader, data: dict) -> tuple[SpectralGrid, str, str]:
    """The ``[spectral]`` table of a file: wavelength grid, observer and band-weight method.

    Scenes and ``specref phong`` material files share it (``docs/scene-format.md``).

    Examples
    --------
    >>> grid, observer, method = parse_spectral(SceneReader("s.toml"), {"spectral": {"grid": "31"}})
    >>> grid.n_bands, method
    (31, 'astm_e308')
    """
    key = "spectral"
    table = reader.table(
        data.get(key, {}),
        key,
        ("grid", "start_nm", "end_nm", "step_nm", "observer", "weights"),
    )
    explicit = [k for k in ("start_nm", "end_nm", "step_nm") if k in table]
    if explicit and "grid" in table:
        reader.fail(key, "give either grid or start_nm, end_nm, step_nm, not both")
    if explicit:
        if len(explicit) != 3:
            reader.fail(key, "start_nm, end_nm and step_nm go together; give all three")
        start, end = (
            reader.number(table[k], f"{key}.{k}", 0, 10000, True, True)
            for k in ("start_nm", "end_nm")
        )
        step = reader.number(table["step_nm"], f"{key}.step_nm", 0, exclusive_minimum=True)
        if (end - start) / step > 4096:
            reader.fail(key, f"at most 4096 bands, got {(end - start) / step + 1:.0f}")
        with reader.context(key):
            grid = SpectralGrid(start, end, step)
    else:
        grid = GRIDS[reader.choice(str(table.get("grid", "41")), f"{key}.grid", GRIDS)]
    observer = reader.choice(table.get("observer", DEFAULT_OBSERVER), f"{key}.observer", OBSERVERS)
    method = reader.choice(table.get("weights", "astm_e308"), f"{key}.weights", BAND_WEIGHT_METHODS)
    # The band weights check that the grid suits the method (ASTM E308: within 360-780 nm, ...).
    with reader.context(key):
        band_weights(grid, None, method, observer)
    return grid, observer, method


def _parse_camera(reader: SceneReader, data: dict) -> Camera:
    key = "camera"
    table = reader.table(
        data.get(key, {}), key, ("eye", "target", "up", "projection", "fov_deg", "extent")
    )
    defaults = Camera()
    kwargs = {}
    for name in ("eye", "target", "up"):
        kwargs[name] = reader.vector(
            table.get(name, list(getattr(defaults, name))), f"{key}.{name}"
        )
    kwargs["projection"] = reader.choice(
        table.get("projection", defaults.projection), f"{key}.projection", PROJECTIONS
    )
    kwargs["fov_deg"] = reader.number(
        table.get("fov_deg", defaults.fov_deg),
        f"{key}.fov_deg",
        0,
        180,
        exclusive_minimum=True,
        exclusive_maximum=True,
    )
    kwargs["extent"] = reader.number(
        table.get("extent", defaults.extent), f"{key}.extent", 0, exclusive_minimum=True
    )
    with reader.context(key, alias="camera"):
        return Camera(**kwargs)


def _parse_render(reader: SceneReader, data: dict, lights: tuple) -> RenderSettings:
    key = "render"
    table = reader.table(
        data.get(key, {}), key, ("width", "height", "supersample", "background", "options")
    )
    defaults = RenderSettings()
    width, height, supersample = check_render_size(
        table.get("width", defaults.width),
        table.get("height", defaults.height),
        table.get("supersample", defaults.supersample),
        f"{reader.file}: {key}",
    )
    background = table.get("background", 0.0)
    if background == "environment":
        if not any(isinstance(light, EnvironmentLight) for light in lights):
            reader.fail(f"{key}.background", '"environment" needs an environment light')
    elif isinstance(background, list):
        background = reader.vector(background, f"{key}.background")
        for i, value in enumerate(background):
            reader.number(value, f"{key}.background[{i}]", minimum=0)
    elif isinstance(background, int | float) and not isinstance(background, bool):
        background = (reader.number(background, f"{key}.background", minimum=0),) * 3
    else:
        reader.fail(
            f"{key}.background",
            f'must be a number, a list of 3 linear RGB values or "environment", got '
            f"{background!r:.60}",
        )
    options = dict(reader.table(table.get("options", {}), f"{key}.options"))
    _check_options(reader, options, f"{key}.options")
    _parse_upsampling(reader, options, f"{key}.options")
    return RenderSettings(width, height, supersample, background, options)


def _check_options(reader: SceneReader, options: dict, key: str) -> None:
    """Each key registered (``reference.scene.options.RENDER_OPTIONS``) and its value checked."""
    from reference.scene.options import RENDER_OPTIONS

    for name in list(options):
        if name not in RENDER_OPTIONS:
            reader.fail(
                key,
                f"unknown key {name!r}; allowed: {format_allowed(RENDER_OPTIONS)} (keys of "
                f"packages not imported are unknown: specref render imports them all)",
            )
        with reader.context(f"{key}.{name}"):
            options[name] = RENDER_OPTIONS.lookup(name).check(options[name])


def _parse_upsampling(reader: SceneReader, options: dict, key: str) -> None:
    """Check ``upsampling`` (a key of UPSAMPLING_METHODS) and ``upsampling_model`` (a model file).

    The model file's path is stored resolved, so shaders find it wherever they run.
    """
    from reference.colour.upsampling import UPSAMPLING_METHODS, load_upsampling_model

    if "upsampling" in options:
        reader.choice(options["upsampling"], f"{key}.upsampling", UPSAMPLING_METHODS)
    if "upsampling_model" not in options:
        return
    if options.get("upsampling") != "regression":
        reader.fail(f"{key}.upsampling_model", 'needs upsampling = "regression"')
    path = reader.file_path(options["upsampling_model"], f"{key}.upsampling_model")
    with reader.context(f"{key}.upsampling_model"):
        load_upsampling_model(path, reader.grid)
    options["upsampling_model"] = str(path.resolve())


def _parse_display(reader: SceneReader, data: dict, lights: tuple) -> DisplaySettings:
    import colour

    key = "display"
    table = reader.table(
        data.get(key, {}),
        key,
        ("colourspace", "encoding", "exposure", "chromatic_adaptation", "white", "calibration"),
    )
    colourspace = reader.choice(
        table.get("colourspace", "sRGB"), f"{key}.colourspace", colour.RGB_COLOURSPACES
    )
    encoding = reader.choice(table.get("encoding", "srgb"), f"{key}.encoding", ENCODINGS)
    exposure = reader.number(
        table.get("exposure", 1.0), f"{key}.exposure", 0, exclusive_minimum=True
    )
    adaptation = reader.choice(
        table.get("chromatic_adaptation", "none"),
        f"{key}.chromatic_adaptation",
        ["none", *colour.CHROMATIC_ADAPTATION_TRANSFORMS],
    )
    adaptation = None if adaptation == "none" else adaptation
    if "white" in table:
        white = reader.light_spectrum(table["white"], f"{key}.white")
    else:
        white = next((light.spectrum for light in lights if hasattr(light, "spectrum")), None)
    if adaptation is not None and white is None:
        reader.fail(
            f"{key}.chromatic_adaptation",
            "needs display.white when the scene has no point or ambient light",
        )
    calibration = None
    if "calibration" in table:
        from reference.display.calibration_files import load_calibrated_display

        path = reader.file_path(table["calibration"], f"{key}.calibration")
        if path.suffix != ".cal":
            reader.fail(f"{key}.calibration", f"must name a .cal file, got {path.name}")
        calibration = load_calibrated_display(path)
    return DisplaySettings(colourspace, encoding, exposure, adaptation, white, calibration)


def _parse_material(reader: SceneReader, table, key: str, name: str):
    reader.table(table, key, required=("type",))
    kind: MaterialType = MATERIAL_TYPES.lookup(
        reader.choice(table["type"], f"{key}.type", MATERIAL_TYPES)
    )
    if kind.parse is not None:
        return kind.parse(reader, table, key, name)
    parameters = (*kind.required, *kind.optional)
    reader.table(table, key, ("type", *parameters), kind.required)
    params = {p: reader.spectrum_on_grid(table[p], f"{key}.{p}") for p in parameters if p in table}
    with reader.context(key, alias=name):
        return make_material(kind.name, params, name)


def _item_type(reader: SceneReader, table: dict, key: str, registry: Registry) -> SceneItemType:
    reader.table(table, key, required=("type",))
    return registry.lookup(reader.choice(table["type"], f"{key}.type", registry))


def scene_from_dict(data: dict, file: str = "<string>", base_dir=".", path=None) -> Scene:
    """Build a :class:`Scene` from parsed TOML.

    Parameters
    ----------
    data : dict
        The parsed TOML document.
    file : str
        The file's label in messages.
    base_dir : str or Path
        Folder for relative paths.
    path : Path, optional
        The scene file.

    Returns
    -------
    Scene

    Raises
    ------
    SpecrefError
        Any invalid key or value, naming the file and the dotted key.

    Examples
    --------
    >>> scene_from_dict({"camera": {"fov": 30}}, "scene.toml")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: scene.toml: camera: unknown key 'fov'; allowed: extent, eye,
    fov_deg, projection, target, up
    """
    reader = SceneReader(file, Path(base_dir))
    reader.table(data, "top level", _TOP_LEVEL_KEYS)
    title = reader.string(data.get("title", "untitled"), "title")
    if "description" in data:
        reader.string(data["description"], "description")
    grid, observer, method = parse_spectral(reader, data)
    reader.grid = grid

    materials_table = reader.table(data.get("materials", {}), "materials")
    materials, names = [], []
    for name, table in materials_table.items():
        materials.append(_parse_material(reader, table, f"materials.{name}", name))
        names.append(name)
    index = {name: i for i, name in enumerate(names)}

    objects = []
    for i, table in enumerate(reader.array_of_tables(data.get("objects", []), "objects")):
        key = f"objects[{i}]"
        kind = _item_type(reader, table, key, OBJECT_TYPES)
        objects.append(kind.parse(reader, table, key, index))

    lights = []
    for i, table in enumerate(reader.array_of_tables(data.get("lights", []), "lights")):
        key = f"lights[{i}]"
        kind = _item_type(reader, table, key, LIGHT_TYPES)
        lights.append(kind.parse(reader, table, key))
    lights = tuple(lights)
    # Each light's band weights on this grid: computed (and cached) now, so a light the grid cannot
    # weigh is refused at load time.
    for i, light in enumerate(lights):
        if isinstance(getattr(light, "spectrum", None), Spectrum):
            with reader.context(f"lights[{i}].spectrum", alias=light.spectrum.name):
                band_weights(grid, light.spectrum, method, observer)

    return Scene(
        camera=_parse_camera(reader, data),
        objects=tuple(objects),
        materials=tuple(materials),
        material_names=tuple(names),
        lights=lights,
        grid=grid,
        observer=observer,
        weights_method=method,
        render=_parse_render(reader, data, lights),
        display=_parse_display(reader, data, lights),
        file=file,
        path=None if path is None else Path(path),
        title=title,
    )


def loads_scene(text: str, file: str = "<string>", base_dir=".") -> Scene:
    """Load a scene from TOML text (inline scenes in docs and tests).

    Parameters
    ----------
    text : str
        The TOML document.
    file : str
        Label for messages.
    base_dir : str or Path
        Folder for relative paths.

    Returns
    -------
    Scene

    Raises
    ------
    SpecrefError
        Malformed TOML, or any invalid key or value.

    Examples
    --------
    >>> loads_scene("[camera" + chr(10) + "eye = [0, 0, 5]", "scene.toml")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: scene.toml: malformed TOML: Expected ']' at the end of a table
    declaration (at line 1, column 8)
    """
    return scene_from_dict(_parse_toml(text, file), file, base_dir)


#: Deepest nesting of arrays and tables that a scene file may have (a scene needs about five).
MAX_NESTING = 64


def _parse_toml(text: str, file: str) -> dict:
    """``tomllib.loads`` with its errors as one-line SpecrefErrors naming the file."""
    if not isinstance(text, str):
        raise SpecrefError(f"{file}: a scene must be TOML text, got {type(text).__name__}")
    too_deep = (
        f"{file}: arrays and tables nested deeper than {MAX_NESTING} levels; no input needs that"
    )
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise SpecrefError(f"{file}: malformed TOML: {error}") from None
    except RecursionError:  # tomllib recurses once per level: tens of thousands exhaust the stack
        raise SpecrefError(too_deep) from None
    # The parsed document's depth, without recursion (the readers below recurse per level).
    stack = [(doc, 1)]
    while stack:
        value, depth = stack.pop()
        if depth > MAX_NESTING:
            raise SpecrefError(too_deep)
        children = value.values() if isinstance(value, dict) else value
        stack.extend((v, depth + 1) for v in children if isinstance(v, dict | list))
    return doc


def load_scene(path) -> Scene:
    """Load a scene file.

    Parameters
    ----------
    path : str or Path
        The ``.toml`` file, or ``data:examples/<name>.toml`` for a scene shipped with specref
        (:mod:`reference.data`); relative paths inside it are relative to its folder.

    Returns
    -------
    Scene

    Raises
    ------
    SpecrefError
        Missing or unreadable file, malformed TOML, any invalid key or value.

    Examples
    --------
    >>> load_scene("no-such-scene.toml")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: no-such-scene.toml: file not found
    >>> load_scene("data:examples/colorchecker-d65.toml").path.name
    'colorchecker-d65.toml'
    """
    file = str(path)
    path = resolve_path(path, Path.cwd()) if file.startswith(DATA_SCHEME) else Path(path)
    doc = read_toml_file(path)
    # an empty file rendered a black 256² image: it is a mistake, not a scene
    require(doc, f"{file}: an empty scene file (docs/scene-format.md: objects, lights, camera)")
    return scene_from_dict(doc, file, path.parent, path)


def read_toml_file(path) -> dict:
    """Read and parse a TOML file (scene, material, sweep or constituents file).

    The one reader of specref's TOML inputs: a missing or unreadable file, text that is not
    UTF-8, malformed TOML and nesting deeper than :data:`MAX_NESTING` are each one line naming
    the file.

    Raises
    ------
    SpecrefError
        As above.

    Examples
    --------
    >>> read_toml_file("no-such-file.toml")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: no-such-file.toml: file not found
    """
    file = str(path)
    path = Path(path)
    if path.is_dir():  # it was reported as "file not found"
        raise SpecrefError(f"{file}: is a folder, not a TOML file")
    if not path.is_file():
        raise SpecrefError(f"{file}: file not found")
    try:
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError:
        raise SpecrefError(f"{file}: not UTF-8 text, so not a TOML file") from None
    except OSError as error:
        raise SpecrefError(f"{file}: cannot read ({error.__class__.__name__})") from None
    return _parse_toml(text, file)

"""Object and light types of scene files: the registries ``OBJECT_TYPES`` and ``LIGHT_TYPES``.

Each entry is a :class:`SceneItemType`: the ``type`` key of an ``[[objects]]`` or ``[[lights]]``
table and a parser from that table to a primitive (``Sphere``, ``Plane``, ``TriangleMesh``) or a
light (``PointLight``, ``AmbientLight``, ``EnvironmentLight``). ``reference.scene.loader`` reads the
registries, so a new object or light type is added by registering it here or in its own
module. Values are read with ``reference.scene.values.SceneReader``, so errors name the file and the
dotted key (``scene.toml: objects[0].radius: must be > 0, got -1``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

import reference.geometry.raster  # noqa: F401  (registers the TriangleMesh G-buffer writer)
from reference.colour.spectra import Spectrum, spectrum_from_dataset
from reference.errors import SpecrefError, format_allowed
from reference.geometry.envmap import DEFAULT_TEXEL_PLACEMENT, TEXEL_PLACEMENTS
from reference.geometry.mesh import TriangleMesh, mesh_from_obj
from reference.geometry.shapes import Plane, Sphere
from reference.images.formats import channel_wavelengths_nm, read_exr, read_hdr
from reference.registry import Registry
from reference.scene.lights import AmbientLight, EnvironmentLight, PointLight, SphereLight
from reference.scene.values import SceneReader

__all__ = ["LIGHT_TYPES", "OBJECT_TYPES", "SceneItemType"]


@dataclass(frozen=True)
class SceneItemType:
    """A registered object or light type of scene files.

    Parameters
    ----------
    name : str
        The ``type`` key (``"sphere"``, ``"point"``).
    parse : callable
        Objects: ``parse(reader, table, key, materials) -> primitive``, where ``materials`` maps
        material names to indices; lights: ``parse(reader, table, key) -> light``.
    keys : tuple of str
        The keys the table accepts besides ``type`` (for documentation and the docs test).
    doc : str
        One line for ``docs/scene-format.md``.
    """

    name: str
    parse: Callable
    keys: tuple = ()
    doc: str = ""


def _material_ref(reader: SceneReader, table: dict, key: str, materials: Mapping) -> int:
    name = table.get("material")
    if not isinstance(name, str) or name not in materials:
        reader.fail(
            f"{key}.material",
            f"unknown material {name!r}; allowed: {format_allowed(materials) or 'none defined'}",
        )
    return materials[name]


def _parse_sphere(reader: SceneReader, table: dict, key: str, materials: Mapping) -> Sphere:
    reader.table(table, key, ("type", "material", "center", "radius"), ("material",))
    center = reader.vector(table.get("center", [0.0, 0.0, 0.0]), f"{key}.center")
    radius = reader.number(table.get("radius", 1.0), f"{key}.radius", 0, exclusive_minimum=True)
    with reader.context(key, alias="sphere"):
        return Sphere(center, radius, _material_ref(reader, table, key, materials))


def _plane_parser(rectangle: bool):
    def parse(reader: SceneReader, table: dict, key: str, materials: Mapping) -> Plane:
        keys = ("type", "material", "point", "normal", "u_axis", "size")
        required = ("material", "size") if rectangle else ("material",)
        reader.table(table, key, keys, required)
        point = reader.vector(table.get("point", [0.0, 0.0, 0.0]), f"{key}.point")
        normal = reader.vector(table.get("normal", [0.0, 1.0, 0.0]), f"{key}.normal")
        u_axis = reader.vector(table.get("u_axis", [1.0, 0.0, 0.0]), f"{key}.u_axis")
        size = None
        if "size" in table:
            size = reader.vector(table["size"], f"{key}.size", n=2)
            for i, s in enumerate(size):
                reader.number(s, f"{key}.size[{i}]", 0, exclusive_minimum=True)
        if np.linalg.norm(normal) == 0:
            reader.fail(f"{key}.normal", f"must be non-zero, got {list(normal)}")
        with reader.context(key, alias="plane"):
            return Plane(point, normal, u_axis, size, _material_ref(reader, table, key, materials))

    return parse


def _mesh_groups(reader: SceneReader, table: dict, key: str, materials: Mapping):
    """``groups``: false (usemtl ignored), true (same names) or a table of group → material."""
    value = table.get("groups", False)
    if isinstance(value, bool):
        return dict(materials) if value else None
    reader.table(value, f"{key}.groups")
    groups = {}
    for group, name in value.items():
        if not isinstance(name, str) or name not in materials:
            reader.fail(
                f"{key}.groups.{group}",
                f"unknown material {name!r}; allowed: "
                f"{format_allowed(materials) or 'none defined'}",
            )
        groups[group] = materials[name]
    return groups


def _parse_mesh(reader: SceneReader, table: dict, key: str, materials: Mapping) -> TriangleMesh:
    keys = ("type", "material", "file", "scale", "translate", "cull_backfaces", "groups")
    groups = _mesh_groups(reader, table, key, materials)
    reader.table(table, key, keys, ("file",) if groups is not None else ("material", "file"))
    path = reader.file_path(table["file"], f"{key}.file")
    scale = reader.number(table.get("scale", 1.0), f"{key}.scale", 0, exclusive_minimum=True)
    translate = np.array(reader.vector(table.get("translate", [0.0, 0.0, 0.0]), f"{key}.translate"))
    cull = reader.boolean(table.get("cull_backfaces", False), f"{key}.cull_backfaces")
    material = None
    if groups is None or "material" in table:
        material = _material_ref(reader, table, key, materials)
    with reader.context(f"{key}.file"):
        mesh = mesh_from_obj(path, material, cull, groups)
        if scale == 1.0 and not translate.any():
            return mesh
        # A uniform scale and a translation keep the shading normals as they are.
        with np.errstate(over="ignore", invalid="ignore"):
            vertices = mesh.vertices * scale + translate
        return dataclasses.replace(mesh, vertices=vertices)


def _parse_point_light(reader: SceneReader, table: dict, key: str) -> PointLight:
    keys = ("type", "position", "spectrum", "intensity", "attenuation")
    reader.table(table, key, keys, ("position",))
    position = reader.vector(table["position"], f"{key}.position")
    spectrum = _light_spectrum(reader, table, key)
    intensity = reader.number(table.get("intensity", 1.0), f"{key}.intensity", minimum=0)
    c = reader.vector(table.get("attenuation", [1.0, 0.0, 0.0]), f"{key}.attenuation")
    for i, value in enumerate(c):
        reader.number(value, f"{key}.attenuation[{i}]", minimum=0)
    if sum(c) <= 0:
        reader.fail(f"{key}.attenuation", f"c1, c2, c3 must not all be 0, got {list(c)}")
    with reader.context(key, alias="light"):
        return PointLight(position, spectrum, intensity, c)


def _parse_sphere_light(reader: SceneReader, table: dict, key: str) -> SphereLight:
    reader.table(table, key, ("type", "position", "radius", "spectrum", "intensity"),
                 ("position", "radius"))  # fmt: skip
    position = reader.vector(table["position"], f"{key}.position")
    radius = reader.number(table["radius"], f"{key}.radius", minimum=0)
    if radius <= 0:
        reader.fail(f"{key}.radius", f"must be > 0, got {radius}")
    spectrum = _light_spectrum(reader, table, key)
    intensity = reader.number(table.get("intensity", 1.0), f"{key}.intensity", minimum=0)
    with reader.context(key, alias="light"):
        return SphereLight(position, radius, spectrum, intensity)


def _light_spectrum(reader: SceneReader, table: dict, key: str) -> Spectrum:
    if "spectrum" not in table:
        return spectrum_from_dataset("illuminant", "D65")
    return reader.light_spectrum(table["spectrum"], f"{key}.spectrum")


def _parse_ambient_light(reader: SceneReader, table: dict, key: str) -> AmbientLight:
    reader.table(table, key, ("type", "spectrum", "intensity"))
    spectrum = _light_spectrum(reader, table, key)
    intensity = reader.number(table.get("intensity", 1.0), f"{key}.intensity", minimum=0)
    with reader.context(key, alias="light"):
        return AmbientLight(spectrum, intensity)


def _parse_environment_light(reader: SceneReader, table: dict, key: str) -> EnvironmentLight:
    import colour

    reader.table(
        table, key, ("type", "file", "intensity", "colourspace", "texel_placement"), ("file",)
    )
    path = reader.file_path(table["file"], f"{key}.file")
    placement = reader.choice(
        table.get("texel_placement", DEFAULT_TEXEL_PLACEMENT),
        f"{key}.texel_placement",
        TEXEL_PLACEMENTS.names(),
    )
    intensity = reader.number(table.get("intensity", 1.0), f"{key}.intensity", minimum=0)
    colourspace = reader.choice(
        table.get("colourspace", "sRGB"), f"{key}.colourspace", colour.RGB_COLOURSPACES
    )
    suffix = path.suffix.lower()
    wavelengths = None
    with reader.context(f"{key}.file"):
        if suffix == ".exr":
            image, names = read_exr(path)
            if names[:3] == ["R", "G", "B"]:
                image = image[..., :3]
            else:
                wavelengths = channel_wavelengths_nm(names)
                if wavelengths is None:
                    raise SpecrefError(
                        f"{path}: channels {', '.join(names)}; an environment needs R, G, B or "
                        "channels named by wavelength (S0.550,000000nm)"
                    )
        elif suffix in (".hdr", ".rgbe", ".pic"):
            image = read_hdr(path)
        elif suffix in (".tif", ".tiff"):
            from reference.images.spectral import read_spectral_tiff

            image, names = read_spectral_tiff(path)
            wavelengths = channel_wavelengths_nm(names)
        else:
            raise SpecrefError(
                f"{path}: unsupported environment map type {suffix!r}; allowed: .exr, .hdr, .tif"
            )
        return EnvironmentLight(
            image, wavelengths, colourspace, intensity, name=str(path), texel_placement=placement
        )


#: Object types of scene files (``[[objects]] type = ...``).
OBJECT_TYPES = Registry("object type", SceneItemType)
OBJECT_TYPES.register(
    SceneItemType("sphere", _parse_sphere, ("material", "center", "radius"), "an analytic sphere")
)
for _name, _rectangle, _doc in (
    ("plane", False, "an analytic plane (a rectangle if `size` is given)"),
    ("rectangle", True, "a plane with a required `size`; uv spans [0, 1] over it"),
):
    OBJECT_TYPES.register(
        SceneItemType(
            _name,
            _plane_parser(_rectangle),
            ("material", "point", "normal", "u_axis", "size"),
            _doc,
        )
    )
OBJECT_TYPES.register(
    SceneItemType(
        "mesh",
        _parse_mesh,
        ("material", "file", "scale", "translate", "cull_backfaces", "groups"),
        "a triangle mesh from a Wavefront OBJ file, rasterized",
    )
)

#: Light types of scene files (``[[lights]] type = ...``).
LIGHT_TYPES = Registry("light type", SceneItemType)
LIGHT_TYPES.register(
    SceneItemType(
        "point",
        _parse_point_light,
        ("position", "spectrum", "intensity", "attenuation"),
        "a point light with Wang et al.'s attenuation",
    )
)
LIGHT_TYPES.register(
    SceneItemType(
        "sphere",
        _parse_sphere_light,
        ("position", "radius", "spectrum", "intensity"),
        "a sphere of uniform radiance (an area light), integrated over the cone it fills",
    )
)
LIGHT_TYPES.register(
    SceneItemType(
        "ambient", _parse_ambient_light, ("spectrum", "intensity"), "the ambient term I_a"
    )
)
LIGHT_TYPES.register(
    SceneItemType(
        "environment",
        _parse_environment_light,
        ("file", "intensity", "colourspace", "texel_placement"),
        "a lat-long environment map (.hdr, .exr with RGB or wavelength channels, spectral .tif)",
    )
)

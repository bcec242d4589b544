"""Tests of reference.scene.items: the object and light types of scene files (OBJECT_TYPES,
LIGHT_TYPES), read directly and through the scene loader."""

from __future__ import annotations

import re

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reference.errors import SpecrefError
from reference.geometry.mesh import TriangleMesh
from reference.geometry.shapes import Plane, Sphere
from reference.images.formats import spectral_channel_names, write_exr
from reference.scene.items import LIGHT_TYPES, OBJECT_TYPES
from reference.scene.lights import AmbientLight, EnvironmentLight, PointLight
from reference.scene.loader import loads_scene
from reference.scene.values import SceneReader

GREY = """
[materials.grey]
type = "lambert"
k_d = 0.5
[[objects]]
type = "sphere"
material = "grey"
"""


def scene_with(text: str, tmp_path=None):
    return loads_scene(text, "scene.toml", tmp_path or ".")


def raises(message: str):
    """``pytest.raises`` for a SpecrefError whose message starts with ``message`` (literal)."""
    return pytest.raises(SpecrefError, match="^" + re.escape(message))


# --- the registries, read directly ----------------------------------------------------------------


def _parse(registry, table: dict):
    entry = registry.lookup(table["type"])
    reader = SceneReader("scene.toml")
    if registry is OBJECT_TYPES:
        return entry.parse(reader, table, "objects[0]", {"grey": 0, "gold": 1})
    return entry.parse(reader, table, "lights[0]")


@pytest.mark.parametrize(
    ("registry", "entry"),
    [(OBJECT_TYPES, e) for e in OBJECT_TYPES.values()]
    + [(LIGHT_TYPES, e) for e in LIGHT_TYPES.values()],
    ids=lambda v: getattr(v, "name", ""),
)
def test_documented_keys_are_the_accepted_keys(registry, entry):
    # Property: each entry's `keys` (what docs/scene-format.md lists) is exactly what its parser
    # accepts, so an unknown key's message names them all.
    allowed = ", ".join(sorted(("type", *entry.keys)))
    with raises(f"scene.toml: {'objects' if registry is OBJECT_TYPES else 'lights'}[0]: unknown "):
        _parse(registry, {"type": entry.name, "bogus": 1})
    with pytest.raises(SpecrefError, match=re.escape(f"'bogus'; allowed: {allowed}") + "$"):
        _parse(registry, {"type": entry.name, "bogus": 1})


def test_object_types_give_their_primitives():
    sphere = _parse(OBJECT_TYPES, {"type": "sphere", "material": "gold", "radius": 2.0})
    assert isinstance(sphere, Sphere)
    # Source: docs/scene-format.md, the documented defaults (center at the origin).
    assert (sphere.center, sphere.radius, sphere.material) == ((0.0, 0.0, 0.0), 2.0, 1)
    plane = _parse(OBJECT_TYPES, {"type": "plane", "material": "grey"})
    assert isinstance(plane, Plane)
    assert (plane.normal, plane.size, plane.material) == ((0.0, 1.0, 0.0), None, 0)
    rectangle = _parse(OBJECT_TYPES, {"type": "rectangle", "material": "grey", "size": [2, 3]})
    assert rectangle.size == (2.0, 3.0)
    with raises("scene.toml: objects[0]: missing key 'size'"):
        _parse(OBJECT_TYPES, {"type": "rectangle", "material": "grey"})
    with raises("scene.toml: objects[0].material: unknown material 'red'; allowed: gold, grey"):
        _parse(OBJECT_TYPES, {"type": "sphere", "material": "red"})
    with raises("scene.toml: objects[0].normal: must be non-zero, got [0.0, 0.0, 0.0]"):
        _parse(OBJECT_TYPES, {"type": "plane", "material": "grey", "normal": [0, 0, 0]})


def test_light_types_give_their_lights():
    point = _parse(LIGHT_TYPES, {"type": "point", "position": [0, 2, 0]})
    assert isinstance(point, PointLight)
    # Source: docs/scene-format.md, the documented defaults (D65, intensity 1, no fall-off).
    assert point.spectrum.name == "illuminant:D65"
    assert (point.intensity, point.attenuation) == (1.0, (1.0, 0.0, 0.0))
    ambient = _parse(LIGHT_TYPES, {"type": "ambient", "intensity": 0.25})
    assert isinstance(ambient, AmbientLight)
    assert ambient.intensity == 0.25
    with raises("scene.toml: lights[0].attenuation[1]: must be >= 0, got -1"):
        _parse(LIGHT_TYPES, {"type": "point", "position": [0, 2, 0], "attenuation": [1, -1, 0]})


# --- environment lights --------------------------------------------------------------------------


def test_environment_light_rgb_and_spectral_exr(tmp_path):
    rgb = np.full((4, 8, 3), 0.5)
    write_exr(tmp_path / "rgb.exr", rgb)
    wl = np.array([380.0, 580.0, 780.0])
    write_exr(tmp_path / "spec.exr", np.ones((4, 8, 3)), spectral_channel_names(wl))
    scene = scene_with(
        '[[lights]]\ntype = "environment"\nfile = "rgb.exr"\nintensity = 2\n'
        '[[lights]]\ntype = "environment"\nfile = "spec.exr"\n',
        tmp_path,
    )
    first, second = scene.lights
    assert isinstance(first, EnvironmentLight)
    assert not first.is_spectral
    assert_allclose(first.image, rgb)
    assert first.intensity == 2.0
    assert second.is_spectral
    assert_allclose(second.wavelengths_nm, wl)


def test_environment_light_reads_shared_hdr(package_data):
    path = package_data / "environments" / "studio_small_03_1k.hdr"
    scene = scene_with(f'[[lights]]\ntype = "environment"\nfile = "{path}"')
    assert scene.lights[0].image.shape == (512, 1024, 3)


def test_missing_and_unreadable_images(tmp_path):
    (tmp_path / "junk.hdr").write_bytes(b"#?RADIANCE\nthis is not an image\n")
    (tmp_path / "junk.exr").write_bytes(b"v/1\x01 not an exr")
    (tmp_path / "map.png").write_bytes(b"")
    env = '[[lights]]\ntype = "environment"\nfile = '
    with raises("scene.toml: lights[0].file: file not found: "):
        scene_with(env + '"nope.hdr"', tmp_path)
    with raises(f"scene.toml: lights[0].file: {tmp_path / 'junk.hdr'}: cannot read Radiance HDR"):
        scene_with(env + '"junk.hdr"', tmp_path)
    with raises(f"scene.toml: lights[0].file: {tmp_path / 'junk.exr'}: cannot read OpenEXR image"):
        scene_with(env + '"junk.exr"', tmp_path)
    with raises(f"scene.toml: lights[0].file: {tmp_path / 'map.png'}: unsupported environment map"):
        scene_with(env + '"map.png"', tmp_path)


def test_environment_maps_with_bad_values(tmp_path):
    image = np.ones((4, 8, 3))
    image[1, 2, 0] = np.nan
    write_exr(tmp_path / "nan.exr", image)
    write_exr(tmp_path / "neg.exr", -np.ones((4, 8, 3)))
    write_exr(tmp_path / "square.exr", np.ones((4, 4, 3)))
    write_exr(tmp_path / "other.exr", np.ones((4, 8, 2)), ["U", "V"])
    env = '[[lights]]\ntype = "environment"\nfile = '
    with raises("scene.toml: lights[0].file: "):
        scene_with(env + '"nan.exr"', tmp_path)
    with pytest.raises(SpecrefError, match=r"lights\[0\]\.file: .*radiance must be finite"):
        scene_with(env + '"nan.exr"', tmp_path)
    with pytest.raises(SpecrefError, match=r"lights\[0\]\.file: .*radiance must be >= 0"):
        scene_with(env + '"neg.exr"', tmp_path)
    with pytest.raises(SpecrefError, match=r"lights\[0\]\.file: .*2:1"):
        scene_with(env + '"square.exr"', tmp_path)
    with pytest.raises(SpecrefError, match=r"lights\[0\]\.file: .*channels U, V; an environment"):
        scene_with(env + '"other.exr"', tmp_path)


# --- meshes ---------------------------------------------------------------------------------------

QUAD_OBJ = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n"


def test_mesh_objects_load_and_place(tmp_path):
    (tmp_path / "quad.obj").write_text(QUAD_OBJ)
    scene = scene_with(
        GREY.replace("sphere", "mesh")
        + 'file = "quad.obj"\nscale = 0.5\ntranslate = [0, 1, -2]\ncull_backfaces = true',
        tmp_path,
    )
    (mesh,) = scene.objects
    assert isinstance(mesh, TriangleMesh)
    assert mesh.material == 0
    assert mesh.cull_backfaces
    # Source: the OBJ's vertices, scaled by 0.5 and moved by (0, 1, -2).
    assert_allclose(mesh.vertices[:, :2], [[-0.5, 0.5], [0.5, 0.5], [0.5, 1.5], [-0.5, 1.5]])
    assert_allclose(mesh.vertices[:, 2], -2.0)
    assert_allclose(mesh.normals, np.tile([0.0, 0.0, 1.0], (4, 1)))


def test_mesh_with_nan_or_inf_vertices_is_refused(tmp_path):
    (tmp_path / "nan.obj").write_text("v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    (tmp_path / "inf.obj").write_text("v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n")
    for name in ("nan.obj", "inf.obj"):
        with pytest.raises(
            SpecrefError,
            match=rf"^scene\.toml: objects\[0\]\.file: .*{name}.*(finite|not a number)",
        ):
            scene_with(GREY.replace("sphere", "mesh") + f'file = "{name}"', tmp_path)
    with raises("scene.toml: objects[0].file: file not found: "):
        scene_with(GREY.replace("sphere", "mesh") + 'file = "none.obj"', tmp_path)
    with raises("scene.toml: objects[0]: missing key 'file'"):
        scene_with(GREY.replace("sphere", "mesh"), tmp_path)
    with raises("scene.toml: objects[0].scale: must be > 0, got 0"):
        scene_with(GREY.replace("sphere", "mesh") + 'file = "nan.obj"\nscale = 0', tmp_path)
    with raises("scene.toml: objects[0].cull_backfaces: must be true or false, got 1"):
        scene_with(
            GREY.replace("sphere", "mesh") + 'file = "nan.obj"\ncull_backfaces = 1', tmp_path
        )

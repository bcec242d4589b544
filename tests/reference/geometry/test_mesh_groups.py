"""Material groups: an OBJ file's ``usemtl`` groups map to scene materials (§8, Herbert et al.)."""

import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.geometry.camera import Camera
from reference.geometry.gbuffer import render_gbuffer
from reference.geometry.mesh import TriangleMesh, mesh_from_obj
from reference.scene.loader import loads_scene

# Three unit squares side by side along x (two triangles each), in three groups; the first face
# comes before any usemtl.
OBJ = """\
v -3 -1 0
v -1 -1 0
v -1 1 0
v -3 1 0
v 1 -1 0
v 1 1 0
v 3 -1 0
v 3 1 0
f 1 2 3 4
usemtl body
f 2 5 6 3
usemtl cap
f 5 7 8 6
"""


@pytest.fixture
def obj(tmp_path):
    path = tmp_path / "groups.obj"
    path.write_text(OBJ)
    return path


def test_usemtl_groups_give_each_face_its_material(obj):
    mesh = mesh_from_obj(obj, material=7, groups={"body": 2, "cap": 5})
    # Source: the file above by hand: a quad is two triangles; the first quad precedes usemtl
    np.testing.assert_array_equal(mesh.face_materials, [7, 7, 2, 2, 5, 5])
    assert mesh_from_obj(obj).face_materials is None  # without groups usemtl is skipped


def test_a_group_without_material_is_one_line_naming_file_and_group(obj):
    with pytest.raises(SpecrefError) as error:
        mesh_from_obj(obj, groups={"body": 0})
    assert str(error.value) == (
        f"{obj}: line 12: usemtl group 'cap' has no scene material; allowed: body"
    )
    with pytest.raises(SpecrefError, match=r"line 9: face before any usemtl, and no material"):
        mesh_from_obj(obj, material=None, groups={"body": 0, "cap": 1})


def test_face_materials_are_validated():
    with pytest.raises(SpecrefError, match=r"tri: face_materials: must be 1 integers >= 0"):
        TriangleMesh(
            [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], source="tri", face_materials=[-1]
        )


def test_the_gbuffer_carries_each_pixels_face_material(obj):
    mesh = mesh_from_obj(obj, material=0, groups={"body": 1, "cap": 2})
    camera = Camera(eye=(0, 0, 5), target=(0, 0, 0), projection="orthographic", extent=2.0)
    g = render_gbuffer([mesh], camera, 12, 4)
    # Source: the three squares fill the image's thirds (x in [-3, -1], [-1, 1], [1, 3])
    expected = np.repeat([0, 1, 2], 4)
    np.testing.assert_array_equal(g.material_id[1], expected)
    np.testing.assert_array_equal(np.unique(g.material_id), [0, 1, 2])


def scene(obj, groups: str, material: str = "") -> str:
    return f"""
[materials.a]
type = "lambert"
k_d = 0.2
[materials.body]
type = "lambert"
k_d = 0.5
[materials.cap]
type = "lambert"
k_d = 0.8
[[objects]]
type = "mesh"
file = "{obj}"
{material}
{groups}
"""


def test_scene_groups_by_name_and_by_table(obj):
    s = loads_scene(scene(obj, "groups = true", 'material = "a"'), "s.toml")
    np.testing.assert_array_equal(s.objects[0].face_materials, [0, 0, 1, 1, 2, 2])
    s = loads_scene(
        scene(obj, 'groups = { body = "cap", cap = "a" }', 'material = "body"'), "s.toml"
    )
    np.testing.assert_array_equal(s.objects[0].face_materials, [1, 1, 2, 2, 0, 0])
    s = loads_scene(scene(obj, "", 'material = "cap"'), "s.toml")
    assert s.objects[0].face_materials is None
    assert s.objects[0].material == 2


@pytest.mark.parametrize(
    ("groups", "material", "message"),
    [
        (
            'groups = { body = "a" }',
            'material = "a"',
            r"^s.toml: objects\[0\].file: .*groups.obj: line 12: usemtl group 'cap' has no "
            r"scene material; allowed: body$",
        ),
        (
            'groups = { body = "nope" }',
            "",
            r"^s.toml: objects\[0\].groups.body: unknown material 'nope'; allowed: a, body, cap$",
        ),
        (
            "groups = true",
            "",
            r"^s.toml: objects\[0\].file: .*line 9: face before any usemtl, and no material",
        ),
    ],
)
def test_scene_group_errors_are_one_line(obj, groups, material, message):
    with pytest.raises(SpecrefError, match=message) as error:
        loads_scene(scene(obj, groups, material), "s.toml")
    assert "\n" not in str(error.value)

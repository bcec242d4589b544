import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.geometry.envmap import direction_to_latlong_uv
from reference.geometry.mesh import (
    TriangleMesh,
    grid_mesh,
    mesh_from_obj,
    mesh_to_obj,
    uv_sphere_mesh,
)
from reference.geometry.shapes import Plane, intersect_plane

TRI = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]


# --- TriangleMesh -------------------------------------------------------------------------------


def test_face_normals_counter_clockwise_closed_form():
    # Source: right-hand rule, (b − a) × (c − a) for the unit triangle in z = 0 is +z.
    mesh = TriangleMesh(TRI, [[0, 1, 2], [0, 2, 1]])
    np.testing.assert_array_equal(mesh.face_normals(), [[0, 0, 1], [0, 0, -1]])
    assert mesh.n_faces == 2
    assert not mesh.vertices.flags.writeable
    assert not mesh.faces.flags.writeable


def test_empty_mesh_is_allowed():
    mesh = TriangleMesh(np.zeros((0, 3)), np.zeros((0, 3), dtype=int))
    assert mesh.n_faces == 0


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (
            {"vertices": [[0, 0, 0], [1, 0, 0], [0, np.nan, 0]]},
            r"bunny.obj: vertices: must be finite, got \[0.0, nan, 0.0\] at vertex 2",
        ),
        ({"vertices": [[0, 0, 0], [np.inf, 0, 0], [0, 1, 0]]}, r"vertices: .* at vertex 1"),
        (
            {"vertices": [[0, 0], [1, 0], [0, 1]]},
            r"vertices: must have shape \(V, 3\), got \(3, 2\)",
        ),
        ({"vertices": "abc"}, "vertices: must be numbers"),
        ({"faces": [[0, 1, 3]]}, r"faces: index 3 out of range \[0, 3\) in face 0"),
        ({"faces": [[0, 1, 2], [0, -1, 2]]}, r"faces: index -1 out of range \[0, 3\) in face 1"),
        ({"faces": [[0, 1, 2, 0]]}, r"faces: must have shape \(F, 3\), got \(1, 4\)"),
        ({"faces": [[0.0, 1.0, 2.0]]}, "faces: must be integer vertex indices, got dtype float64"),
        ({"normals": [[0, 0, 1]] * 2}, r"normals: must have one row per vertex \(3\), got 2"),
        ({"normals": [[0, 0, 1], [0, 0, 0], [0, 0, 1]]}, "normals: must be non-zero, .* vertex 1"),
        ({"normals": [[0, 0, 1], [0, 0, 1], [0, 0, np.nan]]}, "normals: must be finite"),
        ({"uvs": [[0, 0, 0]] * 3}, r"uvs: must have shape \(V, 2\), got \(3, 3\)"),
        ({"uvs": [[0, 0]] * 4}, r"uvs: must have one row per vertex \(3\), got 4"),
        ({"material": -1}, "material: must be an integer >= 0, got -1"),
    ],
)
def test_mesh_bad_input(kwargs, match):
    args = {"vertices": TRI, "faces": [[0, 1, 2]], "source": "bunny.obj"} | kwargs
    with pytest.raises(SpecrefError, match=match) as info:
        TriangleMesh(**args)
    assert str(info.value).startswith("bunny.obj: ")
    assert "\n" not in str(info.value)


# --- Generators -----------------------------------------------------------------------------------


def _unique_position_ids(mesh):
    """Vertex ids merged by bit-identical position (the sphere repeats seam and pole vertices)."""
    _, ids = np.unique(mesh.vertices, axis=0, return_inverse=True)
    return ids.reshape(-1)[mesh.faces]


@pytest.mark.parametrize(("n_theta", "n_phi"), [(2, 3), (5, 7), (16, 32)])
def test_uv_sphere_is_a_closed_outward_oriented_manifold(n_theta, n_phi):
    mesh = uv_sphere_mesh(n_theta, n_phi, radius=2.0, center=(1.0, -1.0, 0.5))
    c = np.array([1.0, -1.0, 0.5])
    assert mesh.n_faces == 2 * n_phi * (n_theta - 1)
    faces = _unique_position_ids(mesh)
    # Every directed edge appears once and its reverse once: closed and consistently oriented.
    directed = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    as_set = {tuple(e) for e in directed}
    assert len(as_set) == len(directed)
    assert all((b, a) in as_set for a, b in as_set)
    # Source: Euler's formula for a sphere, V − E + F = 2.
    n_vertices = len(np.unique(faces))
    assert n_vertices - len(directed) // 2 + len(faces) == 2
    # Outward: every face normal points away from the centre.
    centroids = mesh.vertices[mesh.faces].mean(axis=1)
    assert (np.einsum("ij,ij->i", mesh.face_normals(), centroids - c) > 0).all()


def test_uv_sphere_vertices_normals_and_uvs_match_the_analytic_sphere():
    mesh = uv_sphere_mesh(6, 12, radius=2.0, center=(1.0, -1.0, 0.5))
    c = np.array([1.0, -1.0, 0.5])
    offsets = mesh.vertices - c
    np.testing.assert_allclose(np.linalg.norm(offsets, axis=1), 2.0, rtol=1e-15)
    np.testing.assert_allclose(mesh.normals, offsets / 2.0, atol=1e-15)
    # Source: reference.geometry.envmap.direction_to_latlong_uv, the convention intersect_sphere
    # uses; compared away from the poles (u undefined) and the u = 1 seam copy (the envmap wraps to
    # 0).
    u, v = direction_to_latlong_uv(mesh.normals)
    interior = (mesh.uvs[:, 1] > 0) & (mesh.uvs[:, 1] < 1) & (mesh.uvs[:, 0] < 1)
    np.testing.assert_allclose(mesh.uvs[interior, 0], u[interior], atol=1e-15)
    np.testing.assert_allclose(mesh.uvs[:, 1], v, atol=1e-15)


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((1, 8), "n_theta: must be an integer >= 2, got 1"),
        ((4, 2), "n_phi: must be an integer >= 3, got 2"),
        ((4, 8, -1.0), "radius: must be > 0, got -1.0"),
    ],
)
def test_uv_sphere_bad_input(args, match):
    with pytest.raises(SpecrefError, match=match):
        uv_sphere_mesh(*args)


def test_grid_mesh_matches_intersect_plane():
    plane = Plane((0.5, 1.0, -2.0), (0.2, 1.0, 0.3), (1.0, 0.0, 0.0), size=(3.0, 2.0), material=4)
    mesh = grid_mesh(plane, 3, 5)
    assert mesh.vertices.shape == (24, 3)
    assert mesh.n_faces == 30
    assert mesh.material == 4
    # Source: reference.geometry.shapes.intersect_plane at rays that hit the face centroids head on;
    # uv is affine on the plane, so the centroid's uv is the mean of the corners'.
    n = np.asarray(plane.normal)
    centroids = mesh.vertices[mesh.faces].mean(axis=1)
    hit = intersect_plane(plane, centroids + n, np.broadcast_to(-n, centroids.shape))
    np.testing.assert_allclose(hit.t, 1.0, rtol=1e-12)
    np.testing.assert_allclose(mesh.uvs[mesh.faces].mean(axis=1), hit.uv, atol=1e-14)
    # Counter-clockwise seen from the normal's side.
    np.testing.assert_allclose(mesh.face_normals(), np.broadcast_to(n, (30, 3)), atol=1e-15)


def test_grid_mesh_bad_input():
    with pytest.raises(SpecrefError, match=r"grid_mesh: plane\.size: must be given"):
        grid_mesh(Plane())
    with pytest.raises(SpecrefError, match="grid_mesh: n_v: must be an integer >= 1, got 0"):
        grid_mesh(Plane(size=(1.0, 1.0)), 2, 0)


# --- OBJ ------------------------------------------------------------------------------------------

OBJ_TEXT = """\
# a unit square and a pentagon, every face form
mtllib scene.mtl
o square
v 0 0 0
v 1 0 0
v 1 1 0 1.0
v 0 1 0  0.5 0.5 0.5
vt 0 0
vt 1 0
vt 1 1
vt 0 1 0
vn 0 0 1
g faces
usemtl red
s 1
f 1/1/1 2/2/1 3/3/1
f -4/-4/-1 -2/-2/-1 \\
  -1/-1/-1
"""


def test_obj_reader_all_corner_forms(tmp_path):
    path = tmp_path / "square.obj"
    path.write_text(OBJ_TEXT)
    mesh = mesh_from_obj(path, material=3)
    # Source: the file above by hand: the corners (v, vt, vn) are (i, i, 0), so the vertex order
    # is kept; vt's v is flipped (v = 1 − v_obj).
    np.testing.assert_array_equal(mesh.vertices, [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    np.testing.assert_array_equal(mesh.faces, [[0, 1, 2], [0, 2, 3]])
    np.testing.assert_array_equal(mesh.uvs, [[0, 1], [1, 1], [1, 0], [0, 0]])
    np.testing.assert_array_equal(mesh.normals, np.tile([0.0, 0.0, 1.0], (4, 1)))
    assert mesh.material == 3
    assert mesh.source == str(path)


@pytest.mark.parametrize(
    ("faces", "expected_faces", "has_uv", "has_normal"),
    [
        ("f 1 2 3 4 5", [[0, 1, 2], [0, 2, 3], [0, 3, 4]], False, False),  # pentagon: a fan
        ("f 1//1 2//1 3//1", [[0, 1, 2]], False, True),
        ("f 1/2 2/2 3/1", [[0, 1, 2]], True, False),
        ("f -5 -4 -3\nf -3 -2 -1", [[0, 1, 2], [2, 3, 4]], False, False),
    ],
)
def test_obj_reader_face_forms(tmp_path, faces, expected_faces, has_uv, has_normal):
    header = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv -1 0.5 0\nvt 0 0\nvt 1 0\nvn 0 0 1\n"
    path = tmp_path / "m.obj"
    path.write_text(header + faces + "\n")
    mesh = mesh_from_obj(path)
    np.testing.assert_array_equal(mesh.faces, expected_faces)
    assert (mesh.uvs is not None) == has_uv
    if has_uv:  # Source: by hand, corners (1, vt 2), (2, vt 2), (3, vt 1); v flipped
        np.testing.assert_array_equal(mesh.uvs, [[1, 1], [1, 1], [0, 1]])
    assert (mesh.normals is not None) == has_normal


def test_obj_reader_distinct_corners_become_vertices(tmp_path):
    # One position with two texture coordinates (a seam) becomes two mesh vertices.
    path = tmp_path / "seam.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nf 1/1 2/1 3/1\nf 1/2 3/1 2/1\n")
    mesh = mesh_from_obj(path)
    assert mesh.vertices.shape == (4, 3)
    np.testing.assert_array_equal(mesh.vertices[mesh.faces[1, 0]], [0, 0, 0])
    np.testing.assert_array_equal(mesh.uvs[mesh.faces[1, 0]], [1, 1])


@pytest.mark.parametrize("parts", ["all", "no_uv", "no_normal", "bare"])
def test_obj_round_trip_of_a_generated_mesh(tmp_path, parts):
    sphere = uv_sphere_mesh(5, 9, radius=1.3, center=(0.1, 0.2, 0.3))
    normals = None if parts in ("no_normal", "bare") else sphere.normals
    uvs = None if parts in ("no_uv", "bare") else sphere.uvs
    mesh = TriangleMesh(sphere.vertices, sphere.faces, normals, uvs, material=2)
    back = mesh_from_obj(mesh_to_obj(mesh, tmp_path / "sphere.obj"), material=2)
    # Unused vertices (two pole copies) are dropped, so compare face corners, bit for bit.
    np.testing.assert_array_equal(back.vertices[back.faces], mesh.vertices[mesh.faces])
    if normals is None:
        assert back.normals is None
    else:
        np.testing.assert_array_equal(back.normals[back.faces], mesh.normals[mesh.faces])
    if uvs is None:
        assert back.uvs is None
    else:
        # The v flip (1 − v, twice) rounds once each way: within 2^-52 of the original.
        np.testing.assert_allclose(back.uvs[back.faces], mesh.uvs[mesh.faces], rtol=0, atol=2**-52)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nfoo 1\n",
            "line 5: unknown statement 'foo'; allowed: v,",
        ),
        ("v 0 0 x\n", r"line 1: 'v': not a number in '0 0 x'"),
        ("v 0 0\n", "line 1: 'v' takes 3 to 7 numbers, got 2"),
        ("vn 0 0 1 1\n", "line 1: 'vn' takes 3 numbers, got 4"),
        ("vt\n", "line 1: 'vt' takes 1 to 3 numbers, got 0"),
        ("v 0 0 0\nv nan 0 0\n", r"line 2: v 2: must be finite, got \[nan, 0.0, 0.0\]"),
        ("vn inf 0 0\n", "line 1: vn 1: must be finite"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "line 4: face vertex index 0 is invalid"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", r"line 4: face vertex index 4 out of range \(3"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n", "line 4: face vertex index -4 out of range"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 a\n", "line 4: face vertex index 'a' is not an integer"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2/1 3\n", "line 4: face texture index 1 out of range"),
        ("v 0 0 0\nv 1 0 0\nf 1 2\n", "line 3: face needs at least 3 corners, got 2"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n", "line 4: face corner '1/1/1/1': expected"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf /1 2 3\n", "line 4: face corner '/1': expected"),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\nf 1 2 3\n",
            "line 6: face corner '1' lacks a vt index but earlier corners do",
        ),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\n# no faces\n", "no faces"),
    ],
)
def test_obj_reader_bad_input(tmp_path, text, match):
    path = tmp_path / "bad.obj"
    path.write_text(text)
    with pytest.raises(SpecrefError, match=match) as info:
        mesh_from_obj(path)
    assert str(info.value).startswith(f"{path}: ")


def test_obj_reader_unreadable_files(tmp_path):
    with pytest.raises(SpecrefError, match=r"missing\.obj: file not found"):
        mesh_from_obj(tmp_path / "missing.obj")
    with pytest.raises(SpecrefError, match="is a directory"):
        mesh_from_obj(tmp_path)
    binary = tmp_path / "binary.obj"
    binary.write_bytes(b"\xff\xfe\x00v 0 0 0")
    with pytest.raises(SpecrefError, match=r"binary\.obj: not a text OBJ file"):
        mesh_from_obj(binary)

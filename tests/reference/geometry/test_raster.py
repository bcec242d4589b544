import itertools
import warnings

import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.geometry._raster_kernels import rasterize_triangles_kernel
from reference.geometry.camera import Camera
from reference.geometry.gbuffer import PRIMITIVES, render_gbuffer
from reference.geometry.mesh import TriangleMesh, grid_mesh, uv_sphere_mesh
from reference.geometry.raster import (
    BACKENDS,
    RASTER_METHODS,
    pixel_coverage,
    rasterize_mesh,
    rasterize_triangles,
    triangle_setup,
)
from reference.geometry.shapes import Plane, Sphere, intersect_plane
from validation.report.sections.raster import sphere_tessellation_errors

GBUFFER_FIELDS = ("position", "normal", "uv", "depth", "view", "material_id", "object_id", "mask")
PROJECTIONS = {
    "perspective": Camera(eye=(0.7, 1.1, 3.3), target=(0, 0, 0), fov_deg=40),
    "orthographic": Camera(
        eye=(0.7, 1.1, 3.3), target=(0, 0, 0), projection="orthographic", extent=2.6
    ),
}


def _angle(a, b):
    """Angle between unit vectors, accurate near 0 (atan2 of |a × b| and a · b)."""
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.einsum("...i,...i", a, b))


def _ray_triangle_oracle(camera, width, height, vertices, faces, near):
    """Brute-force ray casting (Möller–Trumbore) of every pixel ray against every triangle.

    Returns the nearest hit per pixel with camera depth >= near (face −1 where none), its
    barycentrics and position, and a mask of pixels where the answer is ambiguous to 1e-9: a
    barycentric coordinate or the depth gap to the runner-up within 1e-9, or depth within 1e-9 of
    the near plane.
    """
    o, d = camera.rays(width, height)
    o, d = o[..., None, :], d[..., None, :]
    v0, v1, v2 = (vertices[faces[:, k]] for k in range(3))
    e1, e2 = v1 - v0, v2 - v0
    p = np.cross(d, e2)
    det = np.einsum("...i,...i", e1, p)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        s = o - v0
        u = np.einsum("...i,...i", s, p) * inv
        q = np.cross(s, e1)
        v = np.einsum("...i,...i", d, q) * inv
        t = np.einsum("...i,...i", e2, q) * inv
    forward = -camera.basis()[2]
    depth = t * np.einsum("...i,i", d, forward)
    b = np.stack([1 - u - v, u, v], axis=-1)
    hit = (b.min(axis=-1) >= 0) & (depth >= near) & np.isfinite(depth)
    edge = (np.abs(b) < 1e-9).any(axis=-1) & (depth >= near * (1 - 1e-9))
    at_near = (np.abs(depth - near) <= 1e-9 * near) & (b.min(axis=-1) >= -1e-9)
    depth_hit = np.where(hit, depth, np.inf)
    order = np.sort(depth_hit, axis=-1)
    face = np.where(np.isfinite(order[..., 0]), np.argmin(depth_hit, axis=-1), -1)
    with np.errstate(invalid="ignore"):  # inf − inf where fewer than two hits
        gap = order[..., 1] - order[..., 0] if faces.shape[0] > 1 else np.inf
    ambiguous = edge.any(-1) | at_near.any(-1) | (np.abs(gap) <= 1e-9 * np.abs(order[..., 0]))
    best = np.take_along_axis(b, np.maximum(face, 0)[..., None, None], axis=-2)[..., 0, :]
    position = np.einsum("...k,...ki->...i", best, vertices[faces[np.maximum(face, 0)]])
    return face, position, ambiguous


def _raster_faces(mesh, camera, width, height, method, near=None):
    """Face index per pixel (−1 where none) from the pipeline's own pieces."""
    s = triangle_setup(mesh, camera, width, height, near)
    _, triangle, _ = method(s.x, s.y, s.z, width, height, s.perspective, mesh.cull_backfaces)
    return np.where(triangle >= 0, s.face[np.maximum(triangle, 0)], -1)


# --- Against analytic and brute-force references -----------------------------------------------


@pytest.mark.parametrize("projection", PROJECTIONS)
def test_tessellated_sphere_matches_analytic_normals_and_coverage(projection):
    camera, W, H = PROJECTIONS[projection], 96, 96
    c = (0.1, -0.2, 0.0)
    mean_errors = []
    for n_theta in (8, 16, 32, 64):
        # Source: the exact sphere (reference.geometry.shapes.intersect_sphere via render_gbuffer),
        # and the chord-error bound acos(rho_min / r) derived in sphere_tessellation_errors: the
        # mesh normal at p is (p − c)/|p − c|, the exact hit p* on the same ray lies nearer the eye,
        # so cos∠(p − c, p* − c) >= |p − c|/r >= rho_min/r wherever the mesh normal faces the eye.
        e = sphere_tessellation_errors(n_theta, camera, W, H, 1.0, c)
        assert e["compared_pixels"] > 0.2 * W * H
        assert e["max"] <= e["bound"] + 1e-9, (n_theta, e)
        # Pixels left out (mesh normal facing away) and coverage differences lie in the
        # silhouette band: rays closer to c than rho_min hit both, rays farther than r neither.
        assert e["excluded_outside_band"] == 0
        assert e["mismatch_outside_band"] == 0
        mean_errors.append(e["mean"])
    # The mean error falls with the chord error, O(1/n²) (observed ratio ~4 per doubling).
    assert all(b < a for a, b in itertools.pairwise(mean_errors)), mean_errors


@pytest.mark.parametrize("projection", PROJECTIONS)
def test_tessellated_sphere_points_lie_on_their_rays_between_the_spheres(projection):
    camera, W, H = PROJECTIONS[projection], 64, 64
    c = np.array([0.1, -0.2, 0.0])
    mesh = uv_sphere_mesh(16, 32, 1.0, c)
    g = rasterize_mesh(mesh, camera, W, H)
    o, d = camera.rays(W, H)
    rho_min = np.abs(
        np.einsum("ij,ij->i", mesh.face_normals(), mesh.vertices[mesh.faces[:, 0]] - c)
    )
    radius = np.linalg.norm(g.position[g.mask] - c, axis=-1)
    assert (radius >= rho_min.min() * (1 - 1e-12)).all()
    assert (radius <= 1 + 1e-12).all()
    off_ray = np.linalg.norm(np.cross(g.position[g.mask] - o[g.mask], d[g.mask]), axis=-1)
    assert off_ray.max() < 1e-12
    # With exact vertex normals, the interpolated normal is the radial direction of the point.
    radial = (g.position[g.mask] - c) / radius[:, None]
    assert _angle(g.normal[g.mask], radial).max() < 1e-12


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("projection", PROJECTIONS)
def test_random_triangles_match_brute_force_ray_casting(backend, projection, rng):
    """Z-buffer, near clipping (1 or 2 vertices behind), back faces, off-screen parts."""
    camera, W, H = PROJECTIONS[projection], 48, 40
    eye = np.asarray(camera.eye)
    # Vertices around the origin and some behind the eye: many triangles cross the near plane.
    vertices = rng.uniform(-1.5, 1.5, (45, 3))
    vertices[::4] = eye + rng.uniform(-1.0, 1.0, (12, 3)) + 0.6 * (eye / np.linalg.norm(eye))
    faces = rng.permutation(45).reshape(15, 3)
    mesh = TriangleMesh(vertices, faces)
    near = 0.05
    setup = triangle_setup(mesh, camera, W, H, near)
    assert setup.x.shape[0] > 15  # some faces were split in two
    face, position, ambiguous = _ray_triangle_oracle(camera, W, H, vertices, faces, near)
    method = RASTER_METHODS.lookup("edge_function")
    raster = _raster_faces(
        mesh, camera, W, H, method.reference if backend == "numpy" else method.kernel, near
    )
    ok = ~ambiguous
    assert ok.mean() > 0.95
    np.testing.assert_array_equal(raster[ok], face[ok])
    g = rasterize_mesh(mesh, camera, W, H, backend=backend, near=near)
    hit = ok & (face >= 0)
    np.testing.assert_allclose(g.position[hit], position[hit], rtol=0, atol=1e-9)


def _oblique_quad(n_u=1, n_v=1):
    plane = Plane((0.2, -0.3, -1.0), (0.1, 1.0, 0.45), (1.0, 0.0, 0.2), size=(3.0, 2.2))
    camera = Camera(eye=(0.4, 0.9, 2.4), target=(0.0, -0.4, -1.2), fov_deg=60)
    return plane, camera


@pytest.mark.parametrize("backend", BACKENDS)
def test_perspective_correct_interpolation_matches_the_analytic_plane(backend):
    plane, camera = _oblique_quad()
    W, H = 64, 48
    mesh = grid_mesh(plane, 1, 1)
    g = rasterize_mesh(mesh, camera, W, H, backend=backend)
    # Source: exact ray-plane intersection (reference.geometry.shapes.intersect_plane).
    exact = render_gbuffer([plane], camera, W, H)
    uv = exact.uv
    edge = (np.minimum(uv, 1 - uv).min(axis=-1) < 1e-9) & exact.mask
    np.testing.assert_array_equal(g.mask[~edge], exact.mask[~edge])
    both = g.mask & exact.mask
    assert both.sum() > 500
    np.testing.assert_allclose(g.uv[both], exact.uv[both], rtol=0, atol=1e-9)
    np.testing.assert_allclose(g.position[both], exact.position[both], rtol=0, atol=1e-9)
    np.testing.assert_allclose(g.depth[both], exact.depth[both], rtol=1e-9)
    np.testing.assert_allclose(g.view[both], exact.view[both], rtol=0, atol=1e-9)
    np.testing.assert_allclose(g.normal[both], exact.normal[both], rtol=0, atol=1e-12)
    # Affine (screen-space) interpolation of the same uvs is far off: computed here by hand from
    # the projected corners, with each pixel's screen-space barycentrics in its triangle.
    x, y, _ = camera.project(mesh.vertices, W, H)
    j, i = np.nonzero(both)
    px, py = i + 0.5, j + 0.5
    affine = np.full((px.size, 2), np.nan)
    for face in mesh.faces:
        (x0, x1, x2), (y0, y1, y2) = x[face], y[face]
        det = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
        l1 = ((px - x0) * (y2 - y0) - (x2 - x0) * (py - y0)) / det
        l2 = ((x1 - x0) * (py - y0) - (px - x0) * (y1 - y0)) / det
        lam = np.stack([1 - l1 - l2, l1, l2], axis=-1)
        inside = lam.min(axis=-1) >= -1e-12
        affine[inside] = lam[inside] @ mesh.uvs[face]
    assert np.abs(affine - exact.uv[both]).max() > 0.05


@pytest.mark.parametrize("backend", BACKENDS)
def test_ground_plane_crossing_the_near_plane_matches_the_analytic_plane(backend):
    # A large ground rectangle under the eye: the faces around the eye cross the near plane.
    plane = Plane((0.0, -1.0, 0.0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0), size=(400.0, 400.0))
    camera = Camera(eye=(0.0, 0.0, 0.0), target=(0.0, -0.3, -1.0), fov_deg=70)
    W, H = 48, 36
    mesh = grid_mesh(plane, 4, 4)
    setup = triangle_setup(mesh, camera, W, H)
    assert setup.x.shape[0] > mesh.n_faces - 8  # faces behind were dropped, crossing ones split
    assert (setup.bary.max(axis=2) < 1).any()  # some vertices are clip points
    g = rasterize_mesh(mesh, camera, W, H, backend=backend)
    exact = render_gbuffer([plane], camera, W, H)
    np.testing.assert_array_equal(g.mask, exact.mask)
    m = exact.mask
    np.testing.assert_allclose(g.uv[m], exact.uv[m], rtol=0, atol=1e-9)
    np.testing.assert_allclose(g.position[m], exact.position[m], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(g.depth[m], exact.depth[m], rtol=1e-9)


@pytest.mark.parametrize("projection", PROJECTIONS)
def test_triangles_behind_the_camera_or_nearer_than_near_are_dropped(projection):
    camera = PROJECTIONS[projection]
    eye, back = np.asarray(camera.eye), camera.basis()[2]
    right, up = camera.basis()[:2]
    corners = np.array([-right - up, right - up, up])
    behind = TriangleMesh(eye + 1.0 * back + corners, [[0, 1, 2]])
    too_near = TriangleMesh(
        eye - 0.5e-4 * back + corners, [[0, 1, 2]]
    )  # near = 1e-4·|target − eye|
    for mesh in (behind, too_near):
        assert triangle_setup(mesh, camera, 16, 16).x.shape[0] == 0
        assert not rasterize_mesh(mesh, camera, 16, 16).mask.any()


@pytest.mark.parametrize("backend", BACKENDS)
def test_off_screen_triangles(backend):
    camera = Camera(eye=(0, 0, 5), target=(0, 0, 0), projection="orthographic", extent=2.0)
    far_left = TriangleMesh([[-9, 0, 0], [-8, 0, 0], [-9, 1, 0]], [[0, 1, 2]])
    assert not rasterize_mesh(far_left, camera, 8, 8, backend=backend).mask.any()
    # A triangle much larger than the screen covers all of it.
    huge = TriangleMesh([[-1e3, -1e3, 0], [1e3, -1e3, 0], [0, 1e3, 0]], [[0, 1, 2]])
    g = rasterize_mesh(huge, camera, 8, 8, backend=backend)
    assert g.mask.all()
    np.testing.assert_allclose(g.depth, 5.0, rtol=1e-12)


# --- Fill rule: no cracks, no double coverage -----------------------------------------------------


def _lattice_tiling(rng, perturb=1):
    """A 4×4-quad grid over raster [2.5, 26.5]² of a 32×32 orthographic view, its interior vertices
    moved by random whole pixels: every vertex sits on a pixel centre, so many edges (including
    the rectangle's, horizontal and vertical ones) pass exactly through pixel centres."""
    camera = Camera(eye=(0, 0, 5), target=(0, 0, 0), projection="orthographic", extent=2.0)
    # Raster X = 16 (x + 1), Y = 16 (1 − y): the rectangle's centre is at raster (14.5, 14.5).
    plane = Plane((14.5 / 16 - 1, 1 - 14.5 / 16, 0.0), (0, 0, 1), (1, 0, 0), size=(1.5, 1.5))
    mesh = grid_mesh(plane, 4, 4)
    vertices = mesh.vertices.copy()
    grid = vertices.reshape(5, 5, 3)
    grid[1:-1, 1:-1, :2] += rng.integers(-perturb, perturb + 1, (3, 3, 2)) / 16
    mesh = TriangleMesh(vertices, mesh.faces, uvs=mesh.uvs)
    assert (mesh.face_normals()[:, 2] > 0).all()  # no fold-over: the mesh still tiles
    return mesh, camera


def test_tiling_through_pixel_centres_covers_each_centre_exactly_once(rng):
    mesh, camera = _lattice_tiling(rng)
    x, y, _ = camera.project(mesh.vertices, 32, 32)
    assert np.array_equal(x, np.round(x - 0.5) + 0.5)  # the vertices sit on pixel centres
    assert np.array_equal(y, np.round(y - 0.5) + 0.5)
    count = pixel_coverage(mesh, camera, 32, 32)
    # Source: the top-left rule's definition: the rectangle [2.5, 26.5]² covers the centres with
    # 2.5 <= X < 26.5 and 2.5 <= Y < 26.5 (its top and left edges are in, bottom and right out).
    centre = np.arange(32) + 0.5
    inside = (centre >= 2.5) & (centre < 26.5)
    expected = (inside[:, None] & inside[None, :]).astype(int)
    np.testing.assert_array_equal(count, expected)
    for backend in BACKENDS:
        g = rasterize_mesh(mesh, camera, 32, 32, backend=backend)
        np.testing.assert_array_equal(g.mask, expected.astype(bool))


def test_tiling_under_perspective_is_watertight(rng):
    mesh, _ = _lattice_tiling(rng)
    plane = Plane((14.5 / 16 - 1, 1 - 14.5 / 16, 0.0), (0, 0, 1), (1, 0, 0), size=(1.5, 1.5))
    camera = Camera(eye=(0.9, -1.2, 1.6), target=(-0.1, 0.1, 0.0), fov_deg=50)
    W, H = 64, 56
    count = pixel_coverage(mesh, camera, W, H)
    # Source: exact ray-rectangle intersection; centres within 1e-9 (in uv) of the boundary are
    # left to the fill rule.
    o, d = camera.rays(W, H)
    uv = intersect_plane(plane, o, d).uv
    margin = np.nan_to_num(np.minimum(uv, 1 - uv).min(axis=-1), nan=-1.0)
    assert count.max() == 1
    np.testing.assert_array_equal(count[margin > 1e-9], 1)
    np.testing.assert_array_equal(count[margin < -1e-9], 0)


@pytest.mark.parametrize("flip", [False, True])
def test_fan_around_a_vertex_on_a_pixel_centre(rng, flip):
    camera = Camera(eye=(0, 0, 5), target=(0, 0, 0), projection="orthographic", extent=2.0)
    W = 32
    # Ring vertices on pixel centres around the centre vertex at raster (16.5, 16.5).
    angles = 2 * np.pi * np.arange(9) / 9 + rng.uniform(-0.2, 0.2, 9)
    radii = rng.uniform(4.0, 12.0, 9)
    X = np.round(16.5 + radii * np.cos(angles) - 0.5) + 0.5
    Y = np.round(16.5 + radii * np.sin(angles) - 0.5) + 0.5
    order = np.argsort(np.arctan2(Y - 16.5, X - 16.5))
    X, Y = np.r_[16.5, X[order]], np.r_[16.5, Y[order]]
    vertices = np.stack([X / 16 - 1, 1 - Y / 16, np.zeros_like(X)], axis=-1)
    ring = np.arange(1, 10)
    faces = np.stack([np.zeros(9, dtype=int), ring, np.roll(ring, -1)], axis=-1)
    if flip:
        faces = faces[:, ::-1]
    count = pixel_coverage(TriangleMesh(vertices, faces), camera, W, W)
    # Source: the winding number of each pixel centre about the ring polygon (sum of subtended
    # angles); centres within 1e-9 of the ring are left to the fill rule.
    px, py = np.meshgrid(np.arange(W) + 0.5, np.arange(W) + 0.5)
    ax, ay = X[1:, None, None] - px, Y[1:, None, None] - py
    bx, by = np.roll(ax, -1, axis=0), np.roll(ay, -1, axis=0)
    winding = np.arctan2(ax * by - ay * bx, ax * bx + ay * by).sum(axis=0) / (2 * np.pi)
    seg = np.stack([np.roll(X[1:], -1) - X[1:], np.roll(Y[1:], -1) - Y[1:]], -1)[:, None, None]
    t = np.clip((-ax * seg[..., 0] - ay * seg[..., 1]) / (seg**2).sum(-1), 0, 1)
    distance = np.hypot(ax + t * seg[..., 0], ay + t * seg[..., 1]).min(axis=0)
    interior = (np.abs(winding) > 0.5) & (distance > 1e-9)
    exterior = (np.abs(winding) < 0.5) & (distance > 1e-9)
    assert count.max() == 1
    assert count[16, 16] == 1  # the shared vertex itself
    np.testing.assert_array_equal(count[interior], 1)
    np.testing.assert_array_equal(count[exterior], 0)


def test_closed_mesh_covers_each_centre_once_front_and_once_back(rng):
    direction = rng.normal(size=3)
    eye = 3.5 * direction / np.linalg.norm(direction)
    camera = Camera(eye=tuple(eye), target=(0.05, -0.1, 0.0), fov_deg=45)
    sphere = uv_sphere_mesh(10, 20)
    front = TriangleMesh(sphere.vertices, sphere.faces, cull_backfaces=True)
    back = TriangleMesh(sphere.vertices, sphere.faces[:, ::-1], cull_backfaces=True)
    count_front = pixel_coverage(front, camera, 40, 40)
    count_back = pixel_coverage(back, camera, 40, 40)
    # Source: a closed convex surface: each ray through it enters once and leaves once.
    assert count_front.max() == 1
    assert count_front.sum() > 200
    np.testing.assert_array_equal(count_front, count_back)
    np.testing.assert_array_equal(pixel_coverage(sphere, camera, 40, 40), 2 * count_front)


# --- Degenerate and back-facing triangles ---------------------------------------------------------


@pytest.mark.parametrize("backend", BACKENDS)
def test_degenerate_triangles_are_skipped_without_nans(backend):
    camera = Camera(eye=(0, 0, 5), target=(0, 0, 0), fov_deg=40)
    good = [[-1, -1, 0], [1, -1, 0], [0, 1, 0]]
    degenerate = [
        [[-1, 0, 0], [-1, 0, 0], [1, 0.5, 0]],  # two equal vertices
        [[-1, 0, 0], [0, 0.25, 0], [1, 0.5, 0]],  # collinear
        [[0, 0, 0], [0, 0, 0], [0, 0, 0]],  # a point
        [[-1, 0.1, 0], [1, 0.1, 0], [0, 0.1 + 1e-14, 0]],  # a sliver, height 1e-14 of its base
        [[0, -1, 1], [0, 1, -1], [0, 0.5, 0.5]],  # seen edge-on: its plane x = 0 holds the eye
    ]
    vertices = np.concatenate([good, *degenerate]).astype(float)
    faces = np.arange(len(vertices)).reshape(-1, 3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        g = rasterize_mesh(TriangleMesh(vertices, faces), camera, 24, 24, backend=backend)
    alone = rasterize_mesh(TriangleMesh(good, [[0, 1, 2]]), camera, 24, 24, backend=backend)
    for name in GBUFFER_FIELDS:
        np.testing.assert_array_equal(getattr(g, name), getattr(alone, name))
    assert np.isfinite(g.position[g.mask]).all()
    assert g.mask.sum() > 50


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("projection", PROJECTIONS)
def test_back_facing_triangles_keep_their_normals_unless_culled(backend, projection):
    camera = PROJECTIONS[projection]
    right, up, back = camera.basis()
    corners = np.array([-right - up, right - up, up]) * 0.8
    clockwise = [[0, 2, 1]]  # as the camera sees it: back-facing
    flat = TriangleMesh(corners, clockwise)
    g = rasterize_mesh(flat, camera, 16, 16, backend=backend)
    assert g.mask.sum() > 20
    # The geometric normal (b − a) × (c − a) points away from the eye, and is kept.
    np.testing.assert_allclose(
        g.normal[g.mask], np.broadcast_to(-back, (g.mask.sum(), 3)), atol=1e-12
    )
    assert (np.einsum("ij,ij->i", g.normal[g.mask], g.view[g.mask]) < 0).all()
    given = np.tile(np.array([0.3, 0.2, 0.9]) / np.linalg.norm([0.3, 0.2, 0.9]), (3, 1))
    shaded = TriangleMesh(corners, clockwise, normals=given)
    np.testing.assert_allclose(
        rasterize_mesh(shaded, camera, 16, 16, backend=backend).normal[g.mask],
        np.broadcast_to(given[0], (g.mask.sum(), 3)),
        atol=1e-15,
    )
    culled = TriangleMesh(corners, clockwise, cull_backfaces=True)
    assert not rasterize_mesh(culled, camera, 16, 16, backend=backend).mask.any()
    front = TriangleMesh(corners, [[0, 1, 2]], cull_backfaces=True)
    np.testing.assert_array_equal(
        rasterize_mesh(front, camera, 16, 16, backend=backend).mask, g.mask
    )


def test_vanishing_interpolated_normal_falls_back_to_the_face_normal():
    camera = Camera(eye=(0, 0, 5), target=(0, 0, 0), projection="orthographic", extent=2.0)
    # Opposite vertex normals cancel on the line through the triangle's middle.
    vertices = [[-1, -1, 0], [1, -1, 0], [-1, 1, 0]]
    normals = [[0, 0, 1], [0, 0, -1], [0, 0, 1]]
    g = rasterize_mesh(TriangleMesh(vertices, [[0, 1, 2]], normals=normals), camera, 4, 4)
    assert np.isfinite(g.normal[g.mask]).all()
    np.testing.assert_allclose(np.linalg.norm(g.normal[g.mask], axis=-1), 1.0, rtol=1e-15)


# --- Twin equality, registry, G-buffer integration, errors ---------------------------------------


def _twin_cases(rng):
    camera = PROJECTIONS["perspective"]
    cases = {"example": RASTER_METHODS.lookup("edge_function").example_inputs(rng)}
    for n in (1, 40, 400):
        vertices = rng.uniform(-1.5, 1.5, (3 * n, 3))
        mesh = TriangleMesh(vertices, rng.permutation(3 * n).reshape(n, 3))
        s = triangle_setup(mesh, camera, 64, 48)
        cases[f"soup-{n}"] = (s.x, s.y, s.z, 64, 48, True, False)
    mesh, ortho = _lattice_tiling(rng)
    s = triangle_setup(mesh, ortho, 32, 32)
    cases["lattice-orthographic"] = (s.x, s.y, s.z, 32, 32, False, False)
    sphere = uv_sphere_mesh(12, 24)
    s = triangle_setup(sphere, camera, 40, 40)
    cases["sphere-culled"] = (s.x, s.y, s.z, 40, 40, True, True)
    return cases


@pytest.mark.parametrize("method", RASTER_METHODS.values(), ids=RASTER_METHODS.names())
def test_numpy_reference_and_numba_kernel_agree(method):
    for name, args in _twin_cases(np.random.default_rng(7)).items():
        depth, triangle, bary = method.reference(*args)
        depth_k, triangle_k, bary_k = method.kernel(*args)
        np.testing.assert_array_equal(triangle_k, triangle, err_msg=name)
        np.testing.assert_allclose(depth_k, depth, rtol=1e-12, atol=1e-14, err_msg=name)
        np.testing.assert_allclose(bary_k, bary, rtol=1e-12, atol=1e-14, err_msg=name)
        assert (triangle >= 0).any(), name


@pytest.mark.parametrize("projection", PROJECTIONS)
def test_gbuffers_of_both_backends_agree(projection, rng):
    camera = PROJECTIONS[projection]
    mesh = uv_sphere_mesh(9, 17, 0.9, (0.1, 0.0, -0.2))
    a = rasterize_mesh(mesh, camera, 40, 32, backend="numpy", object_id=3)
    b = rasterize_mesh(mesh, camera, 40, 32, backend="numba", object_id=3)
    for name in GBUFFER_FIELDS:
        np.testing.assert_allclose(getattr(b, name), getattr(a, name), rtol=1e-12, atol=1e-14)


def test_registry_lists_the_kernel():
    method = RASTER_METHODS.lookup("edge_function")
    assert method.reference is rasterize_triangles
    assert method.kernel is rasterize_triangles_kernel
    assert method.cites == "Eq. (1), Pineda 1988"


def test_render_gbuffer_composites_meshes_with_analytic_objects():
    assert "TriangleMesh" in PRIMITIVES
    camera = PROJECTIONS["perspective"]
    sphere = Sphere((0.0, 0.0, 0.0), 1.0, material=1)
    mesh = uv_sphere_mesh(16, 32, 0.7, (0.8, 0.2, 0.3), material=3)
    W, H = 48, 40
    g = render_gbuffer([sphere, mesh], camera, W, H)
    a = render_gbuffer([sphere], camera, W, H)
    m = rasterize_mesh(mesh, camera, W, H, object_id=1)
    # Source: the z-test, per pixel: the nearer of the two fragments.
    nearer_mesh = m.depth < a.depth
    np.testing.assert_array_equal(g.object_id, np.where(nearer_mesh, 1, a.object_id))
    np.testing.assert_array_equal(g.material_id, np.where(nearer_mesh, 3, a.material_id))
    np.testing.assert_array_equal(g.depth, np.minimum(a.depth, m.depth))
    assert nearer_mesh.sum() > 50
    assert (g.object_id == 0).sum() > 50
    assert render_gbuffer([mesh], camera, W, H, supersample=2).shape == (2 * H, 2 * W)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"backend": "cuda"}, "unknown raster backend 'cuda'; allowed: numba, numpy"),
        ({"method": "scanline"}, "unknown raster method 'scanline'; allowed: edge_function"),
        ({"near": 0.0}, r"raster\.near: must be > 0, got 0\.0"),
        ({"width": 0}, r"render\.width: must be an integer in \[1, 16384\], got 0"),
        ({"mesh": Sphere()}, "rasterize_mesh: mesh: must be a TriangleMesh, got Sphere"),
    ],
)
def test_rasterize_mesh_bad_input(kwargs, match):
    args = {"mesh": uv_sphere_mesh(3, 6), "camera": Camera(), "width": 8, "height": 8} | kwargs
    with pytest.raises(SpecrefError, match=match):
        rasterize_mesh(**args)


@pytest.mark.parametrize("backend", BACKENDS)
def test_shared_edges_through_a_pixel_centre_up_to_rounding(backend):
    """Adversarial: a shared edge whose float end points put a pixel centre on it up to rounding.

    Evaluating the edge function from either end differs in the last bits here, and would crack
    or double-cover about one case in eight; specref evaluates it from the same end in both.
    """
    method = RASTER_METHODS.lookup("edge_function")
    rasterize = method.reference if backend == "numpy" else method.kernel
    local = np.random.default_rng(11)
    p = np.array([8.5, 8.5])
    for _ in range(300):
        a = p + local.uniform(-6, 6, 2)
        b = p + local.uniform(0.3, 1.0) * (p - a)  # p lies on segment ab in exact arithmetic
        normal = np.array([a[1] - b[1], b[0] - a[0]])
        c1 = (a + b) / 2 + normal * local.uniform(0.5, 1.5)
        c2 = (a + b) / 2 - normal * local.uniform(0.5, 1.5)
        count = np.zeros((16, 16), dtype=int)
        for corners in (np.array([a, b, c1]), np.array([b, a, c2])):
            _, triangle, _ = rasterize(
                corners[None, :, 0].copy(),
                corners[None, :, 1].copy(),
                np.ones((1, 3)),
                16,
                16,
                True,
                False,
            )
            count += triangle >= 0
        assert count[8, 8] == 1, (a, b)
        assert count.max() == 1


@pytest.mark.parametrize("backend", BACKENDS)
def test_empty_mesh_draws_nothing(backend):
    empty = TriangleMesh(np.zeros((0, 3)), np.zeros((0, 3), dtype=int))
    g = rasterize_mesh(empty, PROJECTIONS["perspective"], 6, 4, backend=backend)
    assert not g.mask.any()
    assert np.isinf(g.depth).all()

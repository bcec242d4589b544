"""The triangle rasterizer: near-plane clipping, edge functions, top-left rule, z-buffer, G-buffer.

:func:`rasterize_mesh` turns a :class:`~reference.geometry.mesh.TriangleMesh` into a
:class:`~reference.geometry.gbuffer.GBuffer` fragment in four steps:

1. **Setup** (:func:`triangle_setup`). Vertices go through ``Camera.project`` to raster ``(x, y)``
   (pixel centres at half-integers, row 0 at the top, y *down*) and camera depth ``z``. Triangles
   are clipped against the near plane ``z = near`` in camera space: a triangle wholly behind it is
   dropped; one that crosses it becomes one triangle (one vertex in front) or two (two in front),
   whose new vertices lie on the crossing edges, found from the vertex in front so that
   neighbouring triangles compute the same point bit for bit. Each vertex after clipping keeps its
   barycentric coordinates in the original face.
2. **Coverage** (:func:`rasterize_triangles`, the NumPy reference, and its numba twin
   ``reference.geometry._raster_kernels.rasterize_triangles_kernel``). For each triangle, Pineda's
   edge functions are evaluated at the pixel centres of its bounding box. A pixel centre is covered
   when it is strictly inside every edge, or exactly on an edge that is a *top* or *left* edge (the
   top-left fill rule, below). A z-buffer on camera depth keeps the nearest triangle; on a tie the
   earlier triangle stays.
3. **Interpolation.** Perspective-correct barycentrics: the screen-space barycentrics ``λ_i`` are
   divided by the vertex depths and renormalised, ``b_i = (λ_i / z_i) / Σ_j λ_j / z_j``, and the
   pixel's depth is ``1 / Σ_j λ_j / z_j`` (orthographic cameras: ``b_i = λ_i``, depth affine).
4. **Resolve** (:func:`gbuffer_from_raster`): barycentrics in the original face interpolate the
   position, the shading normal (renormalised) and the uvs; ``view`` is the unit vector to the eye.

**Edge functions and orientation.** For an edge from ``a`` to ``b`` and a point ``p``, ``E(p) = (p_x
− a_x)(b_y − a_y) − (p_y − a_y)(b_x − a_x)`` (Eq. (1), Pineda 1988). In y-down raster space a
triangle wound counter-clockwise *as the viewer sees it* (front-facing, see
``reference.geometry.mesh``) has positive ``E`` inside. Back-facing triangles (negative area) are
rendered with their orientation flipped, keeping their normals as given, unless ``cull_backfaces``.

**Watertightness.** Each edge function is evaluated from the lexicographically smaller endpoint
(``(x, y)`` order) and negated if needed, so two triangles sharing an edge compute bit-identical
values of opposite sign: no pixel centre is inside both, and none falls between them.

**Top-left rule** (as in Direct3D and Vulkan, in y-down raster space). Orient the triangle so that
``E > 0`` inside. An edge from ``a`` to ``b`` is a **left** edge if ``b_y > a_y`` (it runs down the
screen) and a **top** edge if ``b_y == a_y`` and ``b_x < a_x`` (horizontal, running left, with the
triangle below it). A pixel centre with ``E = 0`` is covered only if that edge is top or left.
Of two triangles that share an edge, exactly one has it as top or left, so a pixel centre on a
shared edge (or shared vertex) is covered exactly once; a rectangle ``[x0, x1] × [y0, y1]`` tiled
by triangles covers the pixel centres with ``x0 ≤ x < x1`` and ``y0 ≤ y < y1``.

**Degenerate triangles** — twice the signed area ``|E_ab(c)| ≤ 1e-12 · (longest edge)²``, i.e. a
height below 1e-12 of the longest edge, where the edge functions are rounding noise, or a
non-finite area — are skipped, so the output is NaN-free.

References
----------
- J. Pineda, "A parallel algorithm for polygon rasterization", SIGGRAPH 1988, pp. 17-20.
- P. Heckbert, H. Moreton, "Interpolation for polygon texture mapping and shading", in *State of the
  Art in Computer Graphics*, Springer 1991 (perspective-correct interpolation).
- Microsoft, "Rasterization rules: triangle rasterization rules (without multisampling)",
  Direct3D 11 documentation (the top-left rule).
- M. Pharr, W. Jakob, G. Humphreys, *Physically Based Rendering*, 4th ed., §6.5 (triangle uvs).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from reference.errors import require, require_choice
from reference.geometry import _raster_kernels
from reference.geometry.camera import Camera, _check_resolution
from reference.geometry.gbuffer import PRIMITIVES, GBuffer, empty_gbuffer
from reference.geometry.mesh import TriangleMesh
from reference.registry import Method, Registry

__all__ = [
    "BACKENDS",
    "DEGENERATE_RELATIVE_AREA",
    "NEAR_RELATIVE",
    "RASTER_METHODS",
    "TriangleSetup",
    "edge_function",
    "gbuffer_from_raster",
    "pixel_coverage",
    "rasterize_mesh",
    "rasterize_triangles",
    "triangle_setup",
]

#: Backends of :func:`rasterize_mesh`: the readable NumPy reference or its numba twin.
BACKENDS = ("numpy", "numba")
#: Default near plane, as a fraction of the camera's eye-to-target distance.
NEAR_RELATIVE = 1e-4
#: Triangles with ``|2·area| <= DEGENERATE_RELATIVE_AREA · (longest edge)²`` are skipped.
DEGENERATE_RELATIVE_AREA = _raster_kernels.DEGENERATE_RELATIVE_AREA


def edge_function(a_x, a_y, b_x, b_y, p_x, p_y):
    """Pineda's edge function of the edge from ``a`` to ``b`` at points ``p``.

    Eq. (1), Pineda 1988.

    Parameters
    ----------
    a_x, a_y, b_x, b_y : float
        Edge end points, raster coordinates (pixels, y down).
    p_x, p_y : array_like
        Points, raster coordinates.

    Returns
    -------
    ndarray
        ``(p_x − a_x)(b_y − a_y) − (p_y − a_y)(b_x − a_x)``: twice the signed area of ``(a, b, p)``,
        positive when ``p`` lies on the inside of a counter-clockwise (as seen) triangle's edge.

    Examples
    --------
    >>> float(edge_function(0.0, 0.0, 0.0, 1.0, 1.0, 0.0))  # a left edge; p to its right
    1.0
    """
    return (p_x - a_x) * (b_y - a_y) - (p_y - a_y) * (b_x - a_x)


def _edge_canonical(a_x, a_y, b_x, b_y, p_x, p_y):
    """``edge_function(a, b, p)`` evaluated from the lexicographically smaller endpoint.

    Both triangles that share an edge then get bit-identical values of opposite sign.
    """
    if a_x < b_x or (a_x == b_x and a_y < b_y):
        return edge_function(a_x, a_y, b_x, b_y, p_x, p_y)
    return -edge_function(b_x, b_y, a_x, a_y, p_x, p_y)


def _is_top_left(d_x: float, d_y: float) -> bool:
    """Top-left rule for an edge with direction ``d`` in a triangle oriented so that ``E > 0``."""
    return d_y > 0.0 or (d_y == 0.0 and d_x < 0.0)


def _triangle_coverage(x, y, width: int, height: int, cull_backfaces: bool):
    """Pixel centres a triangle covers, and its edge functions there (``None`` if none).

    Returns ``(j_lo, i_lo, inside, E)`` with ``inside`` a boolean block of the bounding box whose
    top-left pixel is ``(j_lo, i_lo)`` and ``E`` the three edge functions (opposite vertex 0, 1, 2).
    """
    x_0, x_1, x_2 = x
    y_0, y_1, y_2 = y
    # Eq. (1), Pineda 1988: twice the signed area, E_01 at vertex 2
    area = edge_function(x_0, y_0, x_1, y_1, x_2, y_2)
    e_01 = (x_1 - x_0) * (x_1 - x_0) + (y_1 - y_0) * (y_1 - y_0)
    e_12 = (x_2 - x_1) * (x_2 - x_1) + (y_2 - y_1) * (y_2 - y_1)
    e_20 = (x_0 - x_2) * (x_0 - x_2) + (y_0 - y_2) * (y_0 - y_2)
    longest = max(e_01, e_12, e_20)
    if not (math.isfinite(area) and abs(area) > DEGENERATE_RELATIVE_AREA * longest):
        return None
    if cull_backfaces and area < 0.0:
        return None
    s = 1.0 if area > 0.0 else -1.0
    # Bounding box of the pixel centres (i + ½, j + ½), widened by a hair so that rounding in the
    # edge functions, not the box, decides pixels on the triangle's extreme vertices (clamped to
    # the image before rounding to integers).
    x_min, x_max = min(x_0, x_1, x_2), max(x_0, x_1, x_2)
    y_min, y_max = min(y_0, y_1, y_2), max(y_0, y_1, y_2)
    i_lo = max(math.ceil(max(x_min - 0.5 - 1e-9 * (1.0 + abs(x_min)), -1.0)), 0)
    i_hi = min(math.floor(min(x_max - 0.5 + 1e-9 * (1.0 + abs(x_max)), width)), width - 1)
    j_lo = max(math.ceil(max(y_min - 0.5 - 1e-9 * (1.0 + abs(y_min)), -1.0)), 0)
    j_hi = min(math.floor(min(y_max - 0.5 + 1e-9 * (1.0 + abs(y_max)), height)), height - 1)
    if i_lo > i_hi or j_lo > j_hi:
        return None
    p_x = (np.arange(i_lo, i_hi + 1) + 0.5)[None, :]
    p_y = (np.arange(j_lo, j_hi + 1) + 0.5)[:, None]
    inside = np.ones((j_hi - j_lo + 1, i_hi - i_lo + 1), dtype=bool)
    E = []
    for k in range(3):
        # Edge opposite vertex k, from a = vertex k+1 to b = vertex k+2: Eq. (1), Pineda 1988
        a, b = (k + 1) % 3, (k + 2) % 3
        E_k = _edge_canonical(x[a], y[a], x[b], y[b], p_x, p_y)
        # Top-left rule: a pixel centre on the edge is inside only for top and left edges.
        w = s * E_k
        if _is_top_left(s * (x[b] - x[a]), s * (y[b] - y[a])):
            inside &= w >= 0.0
        else:
            inside &= w > 0.0
        E.append(E_k)
    return j_lo, i_lo, inside, E


def rasterize_triangles(x, y, z, width: int, height: int, perspective=True, cull_backfaces=False):
    """Rasterize screen-space triangles with a z-buffer: the readable NumPy reference.

    Eq. (1), Pineda 1988 (edge functions); the top-left rule and perspective-correct barycentrics
    are described in the module docstring.

    Parameters
    ----------
    x, y : ndarray, shape (T, 3)
        Raster coordinates of each triangle's vertices (pixels; pixel centres at half-integers,
        y down).
    z : ndarray, shape (T, 3)
        Camera depth of each vertex, > 0 (clip first: :func:`triangle_setup`).
    width, height : int
        Image size in pixels.
    perspective : bool
        Perspective-correct interpolation (``1/z``); False for orthographic cameras, where
        screen-space interpolation is exact.
    cull_backfaces : bool
        Skip triangles with negative area (clockwise as seen).

    Returns
    -------
    depth : ndarray, shape (height, width)
        Camera depth of the nearest triangle, ``inf`` where none.
    triangle : ndarray of int64, shape (height, width)
        Index of the nearest triangle, −1 where none.
    bary : ndarray, shape (height, width, 3)
        Perspective-correct barycentric coordinates in that triangle (0 where none).

    Examples
    --------
    >>> x = np.array([[0.5, 0.5, 2.5]]); y = np.array([[0.5, 2.5, 0.5]])
    >>> depth, triangle, bary = rasterize_triangles(x, y, np.ones((1, 3)), 3, 3)
    >>> triangle  # the top and left edges are in, the diagonal (a right edge) is out
    array([[ 0,  0, -1],
           [ 0, -1, -1],
           [-1, -1, -1]])
    >>> bary[0, 1] + 0.0
    array([0.5, 0. , 0.5])
    """
    depth = np.full((height, width), np.inf)
    triangle = np.full((height, width), -1, dtype=np.int64)
    bary = np.zeros((height, width, 3))
    for t in range(x.shape[0]):
        covered = _triangle_coverage(x[t], y[t], width, height, cull_backfaces)
        if covered is None:
            continue
        j_lo, i_lo, inside, (E_0, E_1, E_2) = covered
        z_0, z_1, z_2 = z[t]
        with np.errstate(divide="ignore", invalid="ignore"):  # only pixels inside are kept
            # Screen-space barycentrics λ_k = E_k / Σ E
            S = E_0 + E_1 + E_2
            lambda_0, lambda_1, lambda_2 = E_0 / S, E_1 / S, E_2 / S
            if perspective:
                # Perspective-correct: λ/z and 1/z are affine in screen space
                q_0, q_1, q_2 = lambda_0 / z_0, lambda_1 / z_1, lambda_2 / z_2
                Q = q_0 + q_1 + q_2
                d = 1.0 / Q
                b_0, b_1, b_2 = q_0 / Q, q_1 / Q, q_2 / Q
            else:
                # Orthographic: depth and attributes are affine in screen space
                d = lambda_0 * z_0 + lambda_1 * z_1 + lambda_2 * z_2
                b_0, b_1, b_2 = lambda_0, lambda_1, lambda_2
        # Z-buffer: keep the nearer surface; ties keep the earlier triangle.
        rows = slice(j_lo, j_lo + inside.shape[0])
        cols = slice(i_lo, i_lo + inside.shape[1])
        nearer = inside & (d < depth[rows, cols])
        depth[rows, cols][nearer] = d[nearer]
        triangle[rows, cols][nearer] = t
        bary[rows, cols][nearer] = np.stack([b_0, b_1, b_2], axis=-1)[nearer]
    return depth, triangle, bary


@dataclass(frozen=True)
class TriangleSetup:
    """Screen-space triangles after near-plane clipping, ready for :func:`rasterize_triangles`.

    Attributes
    ----------
    x, y : ndarray, shape (T, 3)
        Raster coordinates of each (clipped) triangle's vertices.
    z : ndarray, shape (T, 3)
        Camera depths, >= ``near`` up to rounding.
    face : ndarray of int64, shape (T,)
        Index of the mesh face each triangle comes from (sorted; a clipped face gives 1 or 2).
    bary : ndarray, shape (T, 3, 3)
        ``bary[t, k]``: barycentric coordinates of vertex ``k`` of triangle ``t`` in its face.
    perspective : bool
        Whether the camera is perspective.
    """

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    face: np.ndarray
    bary: np.ndarray
    perspective: bool


def _default_near(camera: Camera) -> float:
    return NEAR_RELATIVE * float(np.linalg.norm(np.subtract(camera.target, camera.eye)))


def triangle_setup(
    mesh: TriangleMesh, camera: Camera, width: int, height: int, near: float | None = None
) -> TriangleSetup:
    """Project a mesh's vertices and clip its triangles against the near plane.

    Parameters
    ----------
    mesh : TriangleMesh
        The mesh.
    camera : Camera
        The camera; ``Camera.project`` gives raster coordinates and depth.
    width, height : int
        Image size in pixels.
    near : float, optional
        Near-plane depth (world units, > 0); default ``NEAR_RELATIVE`` times the eye-to-target
        distance. Geometry nearer than this is not drawn; there is no far plane.

    Returns
    -------
    TriangleSetup

    Examples
    --------
    >>> cam = Camera(eye=(0, 0, 1), target=(0, 0, 0))
    >>> tri = TriangleMesh([[0, 0, 0], [1, 0, 0], [0, 0, 2]], [[0, 1, 2]])  # vertex 2 is behind
    >>> s = triangle_setup(tri, cam, 4, 4, near=0.5)
    >>> s.face, s.z.round(6)
    (array([0, 0]), array([[1. , 1. , 0.5],
           [1. , 0.5, 0.5]]))
    >>> s.bary[1, 2]  # the point where the edge from vertex 0 to vertex 2 meets z = near
    array([0.75, 0.  , 0.25])
    """
    near = _default_near(camera) if near is None else float(near)
    require(np.isfinite(near) and near > 0, f"raster.near: must be > 0, got {near}")
    V, F = mesh.vertices, mesh.faces
    x_v, y_v, z_v = camera.project(V, width, height)
    # Near-plane clipping: the triangles left, as corner pairs of their faces (front: z >= near)
    face, p, q = _clipped_corners(z_v[F] >= near)
    a = np.take_along_axis(F[face], p, axis=1)  # vertex ids
    b = np.take_along_axis(F[face], q, axis=1)

    # Each clip point once, from its vertex in front, so neighbours share it bit for bit.
    clip = p != q
    edges, edge_id = np.unique(np.stack([a[clip], b[clip]], axis=1), axis=0, return_inverse=True)
    edge_id = edge_id.reshape(-1)
    i, j = edges[:, 0], edges[:, 1]
    t_edge = (z_v[i] - near) / (z_v[i] - z_v[j])  # z = near on the segment vertex i → vertex j
    x_c, y_c, z_c = camera.project(V[i] + t_edge[:, None] * (V[j] - V[i]), width, height)

    ids = a.copy()
    ids[clip] = len(V) + edge_id
    t = np.zeros(a.shape)
    t[clip] = t_edge[edge_id]
    # A clip point's barycentrics in its face: 1 − t at corner p, t at corner q.
    eye3 = np.eye(3)
    bary = (1.0 - t)[..., None] * eye3[p] + t[..., None] * eye3[q]
    table_x, table_y, table_z = (np.concatenate(v) for v in ((x_v, x_c), (y_v, y_c), (z_v, z_c)))
    return TriangleSetup(
        x=np.ascontiguousarray(table_x[ids]),
        y=np.ascontiguousarray(table_y[ids]),
        z=np.ascontiguousarray(table_z[ids]),
        face=face,
        bary=bary,
        perspective=camera.projection == "perspective",
    )


def _clipped_corners(front: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The triangles left by near-plane clipping, as faces and corner pairs, sorted by face.

    Each triangle after clipping is three corner pairs ``(p, q)`` of its face: ``p == q`` is the
    vertex itself, ``p != q`` the point where the edge from corner p (in front) to q (behind)
    meets ``z = near``. Rotating the corners keeps the winding. ``front`` is ``(F, 3)``: which
    corners are in front; the result is ``face`` ``(T,)`` and ``p``, ``q`` ``(T, 3)``.
    """
    n_front = front.sum(axis=1)
    k = np.arange(3)
    f = np.flatnonzero(n_front == 3)
    pieces = [(f, np.broadcast_to(k, (f.size, 3)), np.broadcast_to(k, (f.size, 3)))]
    f = np.flatnonzero(n_front == 1)  # c0 in front: the triangle (c0, c0→c1, c0→c2)
    c = (np.argmax(front[f], axis=1)[:, None] + k) % 3
    pieces.append((f, c[:, [0, 0, 0]], c[:, [0, 1, 2]]))
    f = np.flatnonzero(n_front == 2)  # c2 behind: the quad (c0, c1, c1→c2, c0→c2), two triangles
    c = (np.argmin(front[f], axis=1)[:, None] + k + 1) % 3
    pieces.append((f, c[:, [0, 1, 1]], c[:, [0, 1, 2]]))
    pieces.append((f, c[:, [0, 1, 0]], c[:, [0, 2, 2]]))
    face, p, q = (np.concatenate([piece[i] for piece in pieces]) for i in range(3))
    order = np.argsort(face, kind="stable")
    return face[order], p[order], q[order]


def gbuffer_from_raster(
    mesh: TriangleMesh,
    camera: Camera,
    setup: TriangleSetup,
    depth,
    triangle,
    bary,
    object_id: int = 0,
) -> GBuffer:
    """Interpolate a mesh's attributes at the rasterized pixels into a G-buffer fragment.

    Parameters
    ----------
    mesh : TriangleMesh
        The mesh.
    camera : Camera
        The camera (for the view vectors).
    setup : TriangleSetup
        The clipped triangles that were rasterized.
    depth, triangle, bary : ndarray
        The output of :func:`rasterize_triangles` (or its numba twin).
    object_id : int
        Id written where the mesh is visible.

    Returns
    -------
    GBuffer
        ``position = Σ b_k v_k`` with ``b`` the pixel's barycentrics in the original face;
        ``normal`` the interpolated shading normal, renormalised (the face's geometric normal
        where the mesh has none, or where the interpolated one vanishes); ``uv`` interpolated
        (pbrt's default ``(0, 0), (1, 0), (1, 1)`` per face without uvs); ``depth`` the camera
        depth; ``view`` the unit vector to the eye (``back`` for orthographic cameras).

    Examples
    --------
    >>> cam = Camera(eye=(0, 0, 3), target=(0, 0, 0), projection="orthographic", extent=2.0)
    >>> tri = TriangleMesh([[-1, -1, 0], [1, -1, 0], [-1, 1, 0]], [[0, 1, 2]])
    >>> s = triangle_setup(tri, cam, 4, 4)
    >>> g = gbuffer_from_raster(tri, cam, s, *rasterize_triangles(s.x, s.y, s.z, 4, 4, False))
    >>> g.mask.astype(int)  # pixel centres on the diagonal (a right edge) are not covered
    array([[0, 0, 0, 0],
           [1, 0, 0, 0],
           [1, 1, 0, 0],
           [1, 1, 1, 0]])
    >>> g.position[3, 0], g.normal[3, 0], g.uv[3, 0], float(g.depth[3, 0])
    (array([-0.75, -0.75,  0.  ]), array([0., 0., 1.]), array([0.25 , 0.125]), 3.0)
    """
    H, W = depth.shape
    g = empty_gbuffer(H, W)
    pixel = np.flatnonzero(triangle.ravel() >= 0)  # covered pixels, flat indices
    tri = triangle.ravel()[pixel]
    # Barycentrics in the original face: the clipped triangle's, mapped through its vertices'.
    w = np.einsum("nk,nkc->nc", bary.reshape(-1, 3)[pixel], setup.bary[tri])
    corners = mesh.faces[setup.face[tri]]  # (N, 3) vertex ids
    position = _interpolate(w, corners, mesh.vertices)
    normal = _shading_normals(mesh, corners, w)
    if mesh.uvs is None:
        uv = np.stack([w[:, 1] + w[:, 2], w[:, 2]], axis=1)  # pbrt: (0, 0), (1, 0), (1, 1)
    else:
        uv = _interpolate(w, corners, mesh.uvs)
    view = _view_vectors(camera, position)
    g.position.reshape(-1, 3)[pixel] = position
    g.normal.reshape(-1, 3)[pixel] = normal
    g.uv.reshape(-1, 2)[pixel] = uv
    g.depth.reshape(-1)[pixel] = depth.ravel()[pixel]
    g.view.reshape(-1, 3)[pixel] = view
    if mesh.face_materials is None:
        g.material_id.reshape(-1)[pixel] = mesh.material
    else:  # material groups: the material of each pixel's face
        g.material_id.reshape(-1)[pixel] = mesh.face_materials[setup.face[tri]]
    g.object_id.reshape(-1)[pixel] = object_id
    g.mask.reshape(-1)[pixel] = True
    return g


def _interpolate(w: np.ndarray, corners: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Per-vertex ``values`` at the pixels: face barycentrics ``w`` times ``values[corners]``."""
    return np.einsum("nk,nkc->nc", w, values[corners])


def _face_normals(vertices: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """Unit geometric normals of the faces whose vertex ids are ``corners`` (N, 3)."""
    a, b, c = (vertices[corners[:, k]] for k in range(3))
    n = np.cross(b - a, c - a)
    return n / np.linalg.norm(n, axis=1, keepdims=True)  # non-zero: the face has area


def _shading_normals(mesh: TriangleMesh, corners: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The interpolated vertex normals, renormalised; the face normal where they are missing."""
    if mesh.normals is None:
        return _face_normals(mesh.vertices, corners)
    normal = _interpolate(w, corners, mesh.normals)
    # Renormalise; where opposite vertex normals cancel, fall back to the face normal.
    length = np.linalg.norm(normal, axis=1, keepdims=True)
    vanish = length[:, 0] <= 1e-12 * np.linalg.norm(mesh.normals[corners], axis=2).max(axis=1)
    length[vanish] = 1.0
    normal /= length
    normal[vanish] = _face_normals(mesh.vertices, corners[vanish])
    return normal


def _view_vectors(camera: Camera, position: np.ndarray) -> np.ndarray:
    """Unit vectors to the eye at ``position`` (N, 3); the camera's back axis if orthographic."""
    if camera.projection == "perspective":
        view = np.asarray(camera.eye) - position
        view /= np.linalg.norm(view, axis=1, keepdims=True)
        return view
    return camera.basis()[2]


def _example_triangles(rng) -> tuple:
    """Small random inputs for :func:`rasterize_triangles`: 20 triangles on a 24×16 raster."""
    x = rng.uniform(-4.0, 28.0, (20, 3))
    y = rng.uniform(-4.0, 20.0, (20, 3))
    z = rng.uniform(1.0, 3.0, (20, 3))
    return x, y, z, 24, 16, True, False


#: Rasterization methods: the NumPy reference and its numba twin, by key.
RASTER_METHODS = Registry("raster method")
RASTER_METHODS.register(
    Method(
        "edge_function",
        rasterize_triangles,
        _raster_kernels.rasterize_triangles_kernel,
        "Eq. (1), Pineda 1988",
        _example_triangles,
        {"fill_rule": "top-left", "interpolation": "perspective-correct"},
    )
)


def rasterize_mesh(
    mesh: TriangleMesh,
    camera: Camera,
    width: int,
    height: int,
    object_id: int = 0,
    backend: str = "numba",
    method: str = "edge_function",
    near: float | None = None,
) -> GBuffer:
    """Rasterize a triangle mesh into a G-buffer fragment (z-buffered, top-left rule).

    Eq. (1), Pineda 1988 (edge functions); perspective-correct barycentrics (Heckbert & Moreton
    1991).

    Parameters
    ----------
    mesh : TriangleMesh
        The mesh.
    camera : Camera
        Perspective or orthographic camera.
    width, height : int
        Image size in pixels, each in [1, MAX_RESOLUTION].
    object_id : int
        Id written where the mesh is visible.
    backend : {"numba", "numpy"}
        The numba kernel (default) or the readable NumPy reference; the two agree to 1e-12.
    method : str
        Key in :data:`RASTER_METHODS`.
    near : float, optional
        Near-plane depth; default ``NEAR_RELATIVE`` times the eye-to-target distance.

    Returns
    -------
    GBuffer
        Fields as in :class:`~reference.geometry.gbuffer.GBuffer`.

    Raises
    ------
    SpecrefError
        Unknown backend or method, bad resolution or near plane, or a mesh that is not a
        :class:`TriangleMesh`.

    Examples
    --------
    >>> from reference.geometry.mesh import uv_sphere_mesh
    >>> cam = Camera(eye=(0, 0, 5), target=(0, 0, 0), fov_deg=30)
    >>> g = rasterize_mesh(uv_sphere_mesh(16, 32), cam, 8, 8, backend="numpy")
    >>> int(g.mask.sum()), g.normal[4, 4].round(3)
    (32, array([ 0.136, -0.136,  0.981]))
    """
    # By class name, like reference.geometry.gbuffer.PRIMITIVES: robust to a module imported twice.
    require(
        type(mesh).__name__ == "TriangleMesh",
        f"rasterize_mesh: mesh: must be a TriangleMesh, got {type(mesh).__name__}",
    )
    require_choice(backend, BACKENDS, "raster backend")
    entry = RASTER_METHODS.lookup(method)
    _check_resolution(width, height)
    setup = triangle_setup(mesh, camera, width, height, near)
    rasterize = entry.reference if backend == "numpy" else entry.kernel
    depth, triangle, bary = rasterize(
        setup.x, setup.y, setup.z, int(width), int(height), setup.perspective, mesh.cull_backfaces
    )
    return gbuffer_from_raster(mesh, camera, setup, depth, triangle, bary, object_id)


def pixel_coverage(
    mesh: TriangleMesh, camera: Camera, width: int, height: int, near: float | None = None
) -> np.ndarray:
    """How many (clipped) triangles cover each pixel centre, ignoring depth: a watertightness check.

    Uses the same edge functions and top-left rule as :func:`rasterize_triangles`. A closed mesh
    seen from outside covers every pixel centre inside its silhouette exactly twice (once front-,
    once back-facing); a flat tiling covers each pixel centre of its interior exactly once.

    Parameters
    ----------
    mesh : TriangleMesh
        The mesh (``cull_backfaces`` is respected).
    camera : Camera
        The camera.
    width, height : int
        Image size in pixels.
    near : float, optional
        Near-plane depth, as in :func:`rasterize_mesh`.

    Returns
    -------
    ndarray of int64, shape (height, width)

    Examples
    --------
    >>> from reference.geometry.shapes import Plane
    >>> from reference.geometry.mesh import grid_mesh
    >>> cam = Camera(eye=(0, 0, 3), target=(0, 0, 0), projection="orthographic", extent=2.0)
    >>> quad = grid_mesh(Plane((0, 0, 0), (0, 0, 1), (1, 0, 0), size=(1.0, 1.0)), 2, 2)
    >>> pixel_coverage(quad, cam, 4, 4)
    array([[0, 0, 0, 0],
           [0, 1, 1, 0],
           [0, 1, 1, 0],
           [0, 0, 0, 0]])
    """
    _check_resolution(width, height)
    setup = triangle_setup(mesh, camera, width, height, near)
    count = np.zeros((height, width), dtype=np.int64)
    for t in range(setup.x.shape[0]):
        covered = _triangle_coverage(setup.x[t], setup.y[t], width, height, mesh.cull_backfaces)
        if covered is not None:
            j_lo, i_lo, inside, _ = covered
            count[j_lo : j_lo + inside.shape[0], i_lo : i_lo + inside.shape[1]] += inside
    return count


def _gbuffer_mesh(
    obj: TriangleMesh, camera: Camera, width: int, height: int, object_id: int
) -> GBuffer:
    return rasterize_mesh(obj, camera, width, height, object_id)


# pytest's importlib mode may execute this module a second time (after importing the package,
# which imports it): register once.
if "TriangleMesh" not in PRIMITIVES:
    PRIMITIVES.register(_gbuffer_mesh, "TriangleMesh")

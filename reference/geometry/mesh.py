"""Triangle meshes: the validated :class:`TriangleMesh`, an OBJ reader and writer, and generators.

A mesh is an indexed triangle list. Faces wind **counter-clockwise** when seen from their front
side, so the geometric normal of face ``(a, b, c)`` is ``(b − a) × (c − a)`` (right-handed, as in
OBJ, pbrt and Mitsuba 3). Optional per-vertex normals are shading normals; optional per-vertex uvs
follow specref's image convention, ``v = 0`` at the top row of a texture.

OBJ (Wavefront) files are read by :func:`mesh_from_obj`, a small parser written by hand: the subset
a triangle rasterizer needs (``v``, ``vt``, ``vn``, ``f``) is a few dozen lines, and a dependency
would add more than it saves. OBJ's ``vt`` has ``v = 0`` at the *bottom* of the image, so the reader
and writer flip it (``v_specref = 1 − v_obj``), as Mitsuba 3's OBJ loader does.

The generators :func:`uv_sphere_mesh` and :func:`grid_mesh` tessellate the analytic primitives of
``reference.geometry.shapes`` with matching normals and uvs, so a rasterized mesh can be checked
against the exact ray-cast surface.

References
----------
- Wavefront Technologies, *Object Files (.obj)*, Advanced Visualizer manual, Appendix B1 (1991).
- W. Jakob et al., Mitsuba 3 renderer, ``src/shapes/obj.cpp`` (2022).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reference.errors import SpecrefError, require
from reference.files import write_text_atomic
from reference.geometry.shapes import Plane

__all__ = ["TriangleMesh", "grid_mesh", "mesh_from_obj", "mesh_to_obj", "uv_sphere_mesh"]


def _as_float_array(values, where: str, columns: int, label: str) -> np.ndarray:
    """``values`` as a read-only contiguous float64 ``(n, columns)`` array of finite numbers."""
    try:
        array = np.array(values, dtype=np.float64, order="C")
    except (TypeError, ValueError) as error:
        raise SpecrefError(f"{where}: must be numbers, got {type(values).__name__}") from error
    require(
        array.ndim == 2 and array.shape[1] == columns,
        f"{where}: must have shape ({label}, {columns}), got {array.shape}",
    )
    bad = ~np.isfinite(array).all(axis=1)
    if bad.any():
        first = int(np.argmax(bad))
        raise SpecrefError(
            f"{where}: must be finite, got {array[first].tolist()} at vertex {first}"
        )
    array.setflags(write=False)
    return array


@dataclass(frozen=True, eq=False)
class TriangleMesh:
    """An indexed triangle mesh with optional per-vertex shading normals and uvs.

    Parameters
    ----------
    vertices : array_like, shape (V, 3)
        Vertex positions, world units; finite.
    faces : array_like of int, shape (F, 3)
        Vertex indices per triangle, each in ``[0, V)``, counter-clockwise seen from the front.
    normals : array_like, shape (V, 3), optional
        Per-vertex shading normals (non-zero; normalised after interpolation). Without them the
        rasterizer uses each face's geometric normal (flat shading).
    uvs : array_like, shape (V, 2), optional
        Per-vertex texture coordinates (``v = 0`` at the top row of a texture). Without them each
        triangle gets pbrt's default ``(0, 0), (1, 0), (1, 1)``.
    material : int
        Index of the mesh's material in the scene's material list.
    cull_backfaces : bool
        Skip triangles that face away from the camera; by default they are rendered with their
        normals as given.
    source : str
        Where the mesh came from (a file name), used in error messages.
    face_materials : array_like of int, shape (F,), optional
        A material index per face (material groups, e.g. an OBJ file's ``usemtl``); overrides
        ``material`` where given.

    Raises
    ------
    SpecrefError
        On wrong shapes, NaN or inf coordinates (naming the first bad vertex), out-of-range face
        indices, or zero-length normals.

    Examples
    --------
    >>> mesh = TriangleMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    >>> mesh.n_faces, mesh.face_normals()
    (1, array([[0., 0., 1.]]))
    >>> TriangleMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 3]], source="tri.obj")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: tri.obj: faces: index 3 out of range [0, 3) in face 0
    """

    vertices: np.ndarray
    faces: np.ndarray
    normals: np.ndarray | None = None
    uvs: np.ndarray | None = None
    material: int = 0
    cull_backfaces: bool = False
    source: str = "mesh"
    face_materials: np.ndarray | None = None

    def __post_init__(self):
        src = self.source
        vertices = _as_float_array(self.vertices, f"{src}: vertices", 3, "V")
        V = vertices.shape[0]
        faces = np.array(self.faces, order="C")
        if faces.size == 0:
            faces = faces.reshape(0, 3).astype(np.int64)
        require(
            np.issubdtype(faces.dtype, np.integer),
            f"{src}: faces: must be integer vertex indices, got dtype {faces.dtype}",
        )
        require(
            faces.ndim == 2 and faces.shape[1] == 3,
            f"{src}: faces: must have shape (F, 3), got {faces.shape}",
        )
        faces = faces.astype(np.int64)
        bad = ((faces < 0) | (faces >= V)).any(axis=1)
        if bad.any():
            first = int(np.argmax(bad))
            index = int(faces[first][(faces[first] < 0) | (faces[first] >= V)][0])
            raise SpecrefError(f"{src}: faces: index {index} out of range [0, {V}) in face {first}")
        faces.setflags(write=False)
        # Optional per-vertex attributes: one finite row per vertex.
        for key, columns in (("normals", 3), ("uvs", 2)):
            values = getattr(self, key)
            if values is not None:
                values = _as_float_array(values, f"{src}: {key}", columns, "V")
                require(
                    values.shape[0] == V,
                    f"{src}: {key}: must have one row per vertex ({V}), got {values.shape[0]}",
                )
                object.__setattr__(self, key, values)
        if self.normals is not None:
            zero = np.linalg.norm(self.normals, axis=1) == 0.0
            require(
                not zero.any(),
                f"{src}: normals: must be non-zero, got zero length at vertex "
                f"{int(np.argmax(zero))}",
            )
        require(
            isinstance(self.material, int | np.integer) and self.material >= 0,
            f"{src}: material: must be an integer >= 0, got {self.material!r}",
        )
        if self.face_materials is not None:
            groups = np.asarray(self.face_materials)
            require(
                np.issubdtype(groups.dtype, np.integer)
                and groups.shape == (faces.shape[0],)
                and bool(np.all(groups >= 0)),
                f"{src}: face_materials: must be {faces.shape[0]} integers >= 0 (one per face), "
                f"got shape {groups.shape}",
            )
            groups = groups.astype(np.int32)
            groups.setflags(write=False)
            object.__setattr__(self, "face_materials", groups)
        object.__setattr__(self, "vertices", vertices)
        object.__setattr__(self, "faces", faces)
        object.__setattr__(self, "material", int(self.material))
        object.__setattr__(self, "cull_backfaces", bool(self.cull_backfaces))

    @property
    def n_faces(self) -> int:
        """Number of triangles ``F``."""
        return int(self.faces.shape[0])

    def face_normals(self) -> np.ndarray:
        """Unit geometric normals ``(b − a) × (c − a)`` per face, shape (F, 3); zero if degenerate.

        Examples
        --------
        >>> TriangleMesh([[0, 0, 0], [0, 1, 0], [1, 0, 0]], [[0, 1, 2]]).face_normals()
        array([[ 0.,  0., -1.]])
        """
        a, b, c = (self.vertices[self.faces[:, k]] for k in range(3))
        n = np.cross(b - a, c - a)
        length = np.linalg.norm(n, axis=1, keepdims=True)
        return np.divide(n, length, out=np.zeros_like(n), where=length > 0)


# --- OBJ ------------------------------------------------------------------------------------------

#: OBJ statements the reader skips: object and group names, smoothing groups, materials, and
#: point and line elements (a triangle rasterizer has no use for them).
OBJ_IGNORED = ("o", "g", "s", "usemtl", "mtllib", "l", "p")
_OBJ_READ = ("v", "vt", "vn", "f")


def _obj_numbers(parts: list[str], where: str, low: int, high: int) -> list[float]:
    """Parse ``low..high`` numbers after an OBJ keyword, or raise naming the line."""
    keyword, values = parts[0], parts[1:]
    require(
        low <= len(values) <= high,
        f"{where}: '{keyword}' takes {low}"
        + (f" to {high}" if high > low else "")
        + f" numbers, got {len(values)}",
    )
    try:
        return [float(v) for v in values]
    except ValueError:
        raise SpecrefError(f"{where}: '{keyword}': not a number in {' '.join(values)!r}") from None


def _obj_index(token: str, count: int, kind: str, where: str) -> int:
    """A 1-based (or negative, relative) OBJ index resolved to 0-based, or raise naming the line."""
    try:
        index = int(token)
    except ValueError:
        raise SpecrefError(f"{where}: face {kind} index {token!r} is not an integer") from None
    require(index != 0, f"{where}: face {kind} index 0 is invalid (OBJ indices start at 1)")
    resolved = index - 1 if index > 0 else count + index
    require(
        0 <= resolved < count,
        f"{where}: face {kind} index {index} out of range ({count} {kind}s defined so far)",
    )
    return resolved


def mesh_from_obj(
    path, material: int = 0, cull_backfaces: bool = False, groups=None
) -> TriangleMesh:
    r"""Read a Wavefront OBJ file into a :class:`TriangleMesh`.

    Supported: ``v x y z [w]`` (extra numbers such as vertex colours are ignored), ``vt u [v [w]]``,
    ``vn x y z``, and ``f`` with corners ``v``, ``v/vt``, ``v//vn`` or ``v/vt/vn``; indices are
    1-based, negative ones count back from the last element defined. Polygons with more than three
    corners are fan-triangulated from their first corner (exact for the convex polygons OBJ
    exporters write). ``#`` starts a comment, ``\`` continues a line, and the statements in
    :data:`OBJ_IGNORED` (``o``, ``g``, ``s``, ``usemtl``, ``mtllib``, ``l``, ``p``) are skipped.

    Every distinct ``(v, vt, vn)`` corner becomes one mesh vertex (ordered by ``v``, then ``vt``,
    ``vn``), so a file that indexes all three alike keeps its vertex order; unused vertices are
    dropped. ``vt``'s v is flipped to specref's convention (``v = 1 − v_obj``).

    Parameters
    ----------
    path : str or Path
        The OBJ file (UTF-8 or ASCII text).
    material : int or None
        Material index of the mesh (with ``groups``: of faces before the first ``usemtl``; None
        refuses such faces).
    cull_backfaces : bool
        Passed to :class:`TriangleMesh`.
    groups : mapping of str to int, optional
        Material groups: each ``usemtl`` name to a material index. Given, every face takes the
        index of the ``usemtl`` above it (``material`` before the first one) and the mesh carries
        ``face_materials``; a ``usemtl`` name that ``groups`` lacks is an error naming the file,
        the line and the group. None (the default) skips ``usemtl``: one material for the mesh.

    Returns
    -------
    TriangleMesh
        With ``normals`` if every corner names a ``vn``, ``uvs`` if every corner names a ``vt``,
        ``face_materials`` if ``groups`` is given.

    Raises
    ------
    SpecrefError
        One line naming the file and line: missing or unreadable file, unknown statement (listing
        the allowed ones), malformed or non-finite numbers, bad or out-of-range indices, faces with
        fewer than three corners, corners that name ``vt``/``vn`` in some faces but not others, a
        file with no faces.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "quad.obj"
    >>> _ = path.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
    >>> mesh = mesh_from_obj(path)
    >>> mesh.faces
    array([[0, 1, 2],
           [0, 2, 3]])
    """
    name, text = _read_obj_text(path)
    obj = _ObjContents(current=material)
    for where, parts in _obj_statements(text, name):
        keyword = parts[0]
        if keyword == "usemtl" and groups is not None:
            obj.current = _obj_group(" ".join(parts[1:]), groups, where)
        elif keyword in OBJ_IGNORED:
            continue
        elif keyword not in _OBJ_READ:
            raise SpecrefError(
                f"{where}: unknown statement {keyword!r}; allowed: "
                f"{', '.join(_OBJ_READ + OBJ_IGNORED)}"
            )
        elif keyword == "f":
            obj.add_face(parts, where)
        else:
            obj.add_element(parts, where)
    require(len(obj.corners) > 0, f"{name}: no faces ('f' statements) found")
    return obj.mesh(name, material, cull_backfaces, grouped=groups is not None)


def _read_obj_text(path) -> tuple[str, str]:
    """The file's name and text, or a one-line error naming the file."""
    path = Path(path)
    name = str(path)
    try:
        return name, path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise SpecrefError(f"{name}: file not found") from None
    except IsADirectoryError:
        raise SpecrefError(f"{name}: is a directory, expected an OBJ file") from None
    except UnicodeDecodeError:
        raise SpecrefError(f"{name}: not a text OBJ file (not UTF-8)") from None
    except OSError as error:
        raise SpecrefError(f"{name}: cannot read ({error.strerror})") from None


def _obj_statements(text: str, name: str):
    """Each statement of an OBJ text as ``(where, words)``, comments and blank lines skipped."""
    lines = text.replace("\\\n", " ").splitlines()
    for number, raw in enumerate(lines, start=1):
        line = raw.split("#", 1)[0].strip()
        if line:
            yield f"{name}: line {number}", line.split()


def _obj_group(group: str, groups, where: str) -> int:
    """The material index of a ``usemtl`` group, or an error naming it and the groups allowed."""
    if group not in groups:
        raise SpecrefError(
            f"{where}: usemtl group {group!r} has no scene material; allowed: "
            f"{', '.join(sorted(groups)) or 'none defined'}"
        )
    return int(groups[group])


@dataclass(eq=False)
class _ObjContents:
    """What an OBJ file's statements have defined so far: elements, triangle corners, groups."""

    positions: list[list[float]] = field(default_factory=list)
    texcoords: list[list[float]] = field(default_factory=list)
    normals: list[list[float]] = field(default_factory=list)
    corners: list[tuple[int, int, int]] = field(default_factory=list)  # (v, vt, vn), -1: absent
    face_materials: list[int] = field(default_factory=list)  # per triangle, when groups are read
    current: int | None = 0  # the material of the faces that follow
    has_vt: bool | None = None
    has_vn: bool | None = None

    def add_element(self, parts: list[str], where: str) -> None:
        """A ``v``, ``vn`` or ``vt`` statement (``vt``'s v flipped to ``1 − v_obj``)."""
        keyword = parts[0]
        if keyword in ("v", "vn"):
            values = _obj_numbers(parts, where, 3, 7 if keyword == "v" else 3)[:3]
            elements = self.positions if keyword == "v" else self.normals
            require(
                all(np.isfinite(values)),
                f"{where}: {keyword} {len(elements) + 1}: must be finite, got {values}",
            )
            elements.append(values)
        else:
            values = _obj_numbers(parts, where, 1, 3)
            require(all(np.isfinite(values)), f"{where}: vt: must be finite, got {values}")
            u, v_obj = values[0], values[1] if len(values) > 1 else 0.0
            self.texcoords.append([u, 1.0 - v_obj])

    def add_face(self, parts: list[str], where: str) -> None:
        """An ``f`` statement, fan-triangulated, its triangles given the current material."""
        require(len(parts) >= 4, f"{where}: face needs at least 3 corners, got {len(parts) - 1}")
        face = [self._corner(token, where) for token in parts[1:]]
        # Fan triangulation from the first corner: (0, k, k + 1).
        require(
            self.current is not None,
            f"{where}: face before any usemtl, and no material for ungrouped faces",
        )
        for k in range(1, len(face) - 1):
            self.corners.extend((face[0], face[k], face[k + 1]))
            self.face_materials.append(self.current)

    def _corner(self, token: str, where: str) -> tuple[int, int, int]:
        """A face corner ``v[/vt][/vn]`` as 0-based ``(v, vt, vn)``, -1 where absent."""
        fields = token.split("/")
        require(
            len(fields) <= 3 and fields[0] != "",
            f"{where}: face corner {token!r}: expected v, v/vt, v//vn or v/vt/vn",
        )
        fields += [""] * (3 - len(fields))
        v = _obj_index(fields[0], len(self.positions), "vertex", where)
        vt = _obj_index(fields[1], len(self.texcoords), "texture", where) if fields[1] else -1
        vn = _obj_index(fields[2], len(self.normals), "normal", where) if fields[2] else -1
        for kind, present, seen in (("vt", vt >= 0, self.has_vt), ("vn", vn >= 0, self.has_vn)):
            require(
                seen is None or seen == present,
                f"{where}: face corner {token!r} "
                + ("names" if present else "lacks")
                + f" a {kind} index but earlier corners "
                + ("do not" if present else "do")
                + "; mixed faces are not supported",
            )
        self.has_vt, self.has_vn = vt >= 0, vn >= 0
        return v, vt, vn

    def mesh(self, name: str, material, cull_backfaces: bool, grouped: bool) -> TriangleMesh:
        """The mesh: one vertex per distinct ``(v, vt, vn)`` corner."""
        table = np.asarray(self.corners, dtype=np.int64)
        unique, inverse = np.unique(table, axis=0, return_inverse=True)
        faces = inverse.reshape(-1, 3)
        vertices = np.asarray(self.positions, dtype=np.float64)[unique[:, 0]]
        uvs = np.asarray(self.texcoords, dtype=np.float64)[unique[:, 1]] if self.has_vt else None
        vn = np.asarray(self.normals, dtype=np.float64)[unique[:, 2]] if self.has_vn else None
        per_face = np.asarray(self.face_materials, dtype=np.int32) if grouped else None
        return TriangleMesh(
            vertices,
            faces,
            vn,
            uvs,
            material or 0,
            cull_backfaces,
            source=name,
            face_materials=per_face,
        )


def mesh_to_obj(mesh: TriangleMesh, path) -> Path:
    """Write a mesh as a Wavefront OBJ file (atomically), readable by :func:`mesh_from_obj`.

    Coordinates are written with 17 significant digits, so reading the file back reproduces them
    exactly; uvs are flipped to OBJ's convention (``v_obj = 1 − v``).

    Parameters
    ----------
    mesh : TriangleMesh
        The mesh.
    path : str or Path
        Output file.

    Returns
    -------
    Path
        The file written.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> mesh = TriangleMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    >>> out = mesh_to_obj(mesh, pathlib.Path(tempfile.mkdtemp()) / "tri.obj")
    >>> mesh_from_obj(out).vertices
    array([[0., 0., 0.],
           [1., 0., 0.],
           [0., 1., 0.]])
    """
    path = Path(path)
    lines = [f"# specref TriangleMesh: {mesh.vertices.shape[0]} vertices, {mesh.n_faces} faces"]
    lines += ["v {!r} {!r} {!r}".format(*map(float, p)) for p in mesh.vertices]
    if mesh.uvs is not None:
        lines += [f"vt {float(u)!r} {1.0 - float(v)!r}" for u, v in mesh.uvs]
    if mesh.normals is not None:
        lines += ["vn {!r} {!r} {!r}".format(*map(float, n)) for n in mesh.normals]
    if mesh.uvs is not None and mesh.normals is not None:
        corner = "{0}/{0}/{0}"
    elif mesh.uvs is not None:
        corner = "{0}/{0}"
    elif mesh.normals is not None:
        corner = "{0}//{0}"
    else:
        corner = "{0}"
    lines += ["f " + " ".join(corner.format(int(i) + 1) for i in face) for face in mesh.faces]
    write_text_atomic(path, "\n".join(lines) + "\n")
    return path


# --- Generators -----------------------------------------------------------------------------------


def uv_sphere_mesh(
    n_theta: int, n_phi: int, radius: float = 1.0, center=(0.0, 0.0, 0.0), material: int = 0
) -> TriangleMesh:
    """A latitude-longitude tessellation of a sphere, with analytic normals and lat-long uvs.

    Vertices lie on the sphere at ``θ_j = jπ/n_theta`` (from +y) and ``φ_i = 2πi/n_phi`` in the
    lat-long convention of ``reference.geometry.envmap``: direction ``d = (sin θ sin φ, cos θ, −sin
    θ cos φ)``, ``uv = (φ/2π, θ/π)``, the seam at −z. This is the uv that
    ``geometry.intersect_sphere`` gives the analytic sphere, and the normals are the exact ``d``.
    The seam column is duplicated (``u = 0`` and ``u = 1``) with bit-identical positions, and each
    pole has one vertex per column (``u`` at the column's centre), so the mesh is watertight:
    ``2·n_phi·(n_theta − 1)`` triangles, all outward-facing (counter-clockwise seen from outside).

    Parameters
    ----------
    n_theta : int
        Latitude bands, >= 2.
    n_phi : int
        Longitude segments, >= 3.
    radius : float
        Radius, > 0.
    center : array_like, shape (3,)
        Centre.
    material : int
        Material index.

    Returns
    -------
    TriangleMesh

    Examples
    --------
    >>> mesh = uv_sphere_mesh(4, 8)
    >>> mesh.n_faces, mesh.vertices.shape
    (48, (45, 3))
    >>> bool(np.allclose(np.linalg.norm(mesh.vertices, axis=1), 1.0))
    True
    """
    require(
        isinstance(n_theta, int | np.integer) and n_theta >= 2,
        f"uv_sphere_mesh: n_theta: must be an integer >= 2, got {n_theta!r}",
    )
    require(
        isinstance(n_phi, int | np.integer) and n_phi >= 3,
        f"uv_sphere_mesh: n_phi: must be an integer >= 3, got {n_phi!r}",
    )
    require(
        np.isfinite(radius) and radius > 0,
        f"uv_sphere_mesh: radius: must be > 0, got {radius}",
    )
    c = np.asarray(center, dtype=np.float64)
    d, uv = _sphere_directions_uvs(n_theta, n_phi)
    faces = _sphere_faces(n_theta, n_phi)
    return TriangleMesh(
        c + radius * d.reshape(-1, 3),
        faces,
        normals=d.reshape(-1, 3),
        uvs=uv.reshape(-1, 2),
        material=material,
        source="uv_sphere_mesh",
    )


def _sphere_directions_uvs(n_theta: int, n_phi: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit directions ``(n_theta + 1, n_phi + 1, 3)`` and uvs of the sphere's vertex grid."""
    j = np.arange(n_theta + 1)[:, None]
    i = np.arange(n_phi + 1)[None, :]
    theta = np.pi * j / n_theta
    phi = 2.0 * np.pi * i / n_phi
    sin_theta = np.sin(theta)
    sin_theta[[0, -1]] = 0.0  # exact poles: sin(π) is 1.2e-16 in floating point
    d = np.stack(
        np.broadcast_arrays(sin_theta * np.sin(phi), np.cos(theta), -sin_theta * np.cos(phi)),
        axis=-1,
    )
    d[:, -1] = d[:, 0]  # the seam column repeats the first bit for bit
    u = np.broadcast_to(i / n_phi, (n_theta + 1, n_phi + 1)).copy()
    # Pole vertices: u at the centre of the one column each serves (the +y pole's vertex i serves
    # column i, the −y pole's vertex i column i − 1).
    u[0] = (i[0] + 0.5) / n_phi
    u[-1] = (i[0] - 0.5) / n_phi
    uv = np.stack([u, np.broadcast_to(j / n_theta, u.shape)], axis=-1)
    return d, uv


def _sphere_faces(n_theta: int, n_phi: int) -> np.ndarray:
    """The sphere's triangles over its vertex grid, outward-facing; none degenerate at the poles."""
    index = np.arange((n_theta + 1) * (n_phi + 1)).reshape(n_theta + 1, n_phi + 1)
    a, b = index[:-1, :-1], index[:-1, 1:]  # row j: columns i, i + 1
    c_, d_ = index[1:, :-1], index[1:, 1:]  # row j + 1
    upper = np.stack([a, b, d_], axis=-1)[1:]  # (j, i), (j, i+1), (j+1, i+1); none at the +y pole
    lower = np.stack([a, d_, c_], axis=-1)[:-1]  # (j, i), (j+1, i+1), (j+1, i); none at the −y pole
    return np.concatenate([upper.reshape(-1, 3), lower.reshape(-1, 3)])


def grid_mesh(plane: Plane, n_u: int = 1, n_v: int = 1) -> TriangleMesh:
    """A planar ``n_u × n_v`` grid of quads (two triangles each) covering a rectangular ``Plane``.

    Vertex positions, normals and uvs equal what ``geometry.intersect_plane`` reports for the same
    rectangle: ``p = point + s·a + r·(n × a)`` with ``uv = (s/w + ½, ½ − r/h)``. Triangles wind
    counter-clockwise seen from the side the normal points to.

    Parameters
    ----------
    plane : Plane
        A bounded plane (``size`` given).
    n_u, n_v : int
        Quads along ``u_axis`` and along ``normal × u_axis``, each >= 1.

    Returns
    -------
    TriangleMesh
        ``(n_u + 1)(n_v + 1)`` vertices, ``2·n_u·n_v`` faces.

    Examples
    --------
    >>> mesh = grid_mesh(Plane((0, 0, 0), (0, 0, 1), (1, 0, 0), size=(2.0, 2.0)))
    >>> mesh.vertices
    array([[-1., -1.,  0.],
           [ 1., -1.,  0.],
           [-1.,  1.,  0.],
           [ 1.,  1.,  0.]])
    >>> mesh.uvs[0], mesh.face_normals()[0]
    (array([0., 1.]), array([0., 0., 1.]))
    """
    require(plane.size is not None, "grid_mesh: plane.size: must be given (a bounded rectangle)")
    for key, value in (("n_u", n_u), ("n_v", n_v)):
        require(
            isinstance(value, int | np.integer) and value >= 1,
            f"grid_mesh: {key}: must be an integer >= 1, got {value!r}",
        )
    p0, n, a = (np.asarray(v) for v in (plane.point, plane.normal, plane.u_axis))
    b = np.cross(n, a)
    w, h = plane.size
    s = (np.arange(n_u + 1) / n_u - 0.5) * w
    r = (np.arange(n_v + 1) / n_v - 0.5) * h
    S, R = np.meshgrid(s, r)  # rows along r, columns along s
    vertices = p0 + S[..., None] * a + R[..., None] * b
    uvs = np.stack([S / w + 0.5, 0.5 - R / h], axis=-1)
    index = np.arange((n_u + 1) * (n_v + 1)).reshape(n_v + 1, n_u + 1)
    p00, p10 = index[:-1, :-1], index[:-1, 1:]
    p01, p11 = index[1:, :-1], index[1:, 1:]
    faces = np.concatenate(
        [np.stack([p00, p10, p11], -1).reshape(-1, 3), np.stack([p00, p11, p01], -1).reshape(-1, 3)]
    )
    return TriangleMesh(
        vertices.reshape(-1, 3),
        faces,
        normals=np.broadcast_to(n, ((n_u + 1) * (n_v + 1), 3)),
        uvs=uvs.reshape(-1, 2),
        material=plane.material,
        source="grid_mesh",
    )

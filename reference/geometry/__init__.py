"""Geometry: cameras, primitives, the G-buffer, meshes and the rasterizer, lat-long and cube maps.

- :mod:`~reference.geometry.envmap` — lat-long directions (Mitsuba 3's convention), solid angles.
- :mod:`~reference.geometry.camera`, :mod:`~reference.geometry.shapes`,
  :mod:`~reference.geometry.gbuffer` — cameras, analytic primitives, the G-buffer.
- :mod:`~reference.geometry.mesh`, :mod:`~reference.geometry.raster` — triangle meshes (OBJ) and
  the rasterizer (numba twin in ``_raster_kernels``).
- :mod:`~reference.geometry.cubemap` — cube maps from lat-long maps and their lookups (numba twins
  in ``_cubemap_kernels``).
"""

from __future__ import annotations

from reference.geometry.camera import (
    MAX_COORDINATE,
    MAX_RESOLUTION,
    PROJECTIONS,
    Camera,
    downsample_box,
)
from reference.geometry.cubemap import (
    CUBEMAP_FACES,
    CUBEMAP_METHODS,
    cubemap_lookup_bilinear,
    cubemap_texel_directions,
    cubemap_texel_solid_angles,
    cubemap_to_latlong,
    gather_bilinear,
    latlong_blocks_to_cubemap,
    latlong_to_cubemap,
)
from reference.geometry.envmap import (
    DEFAULT_TEXEL_PLACEMENT,
    TEXEL_PLACEMENTS,
    check_latlong_shape,
    direction_to_latlong_uv,
    latlong_lookup_bilinear,
    latlong_pixel_directions,
    latlong_pixel_solid_angles,
    latlong_rows_centred,
    latlong_rows_mitsuba_to_centred,
    latlong_uv_to_direction,
)
from reference.geometry.gbuffer import (
    PRIMITIVES,
    GBuffer,
    empty_gbuffer,
    gbuffer_from_hit,
    render_gbuffer,
)
from reference.geometry.mesh import (
    TriangleMesh,
    grid_mesh,
    mesh_from_obj,
    mesh_to_obj,
    uv_sphere_mesh,
)
from reference.geometry.raster import (
    BACKENDS,
    DEGENERATE_RELATIVE_AREA,
    NEAR_RELATIVE,
    RASTER_METHODS,
    TriangleSetup,
    edge_function,
    gbuffer_from_raster,
    pixel_coverage,
    rasterize_mesh,
    rasterize_triangles,
    triangle_setup,
)
from reference.geometry.shapes import (
    Hit,
    Plane,
    Sphere,
    intersect_plane,
    intersect_sphere,
    plane_uv_to_point,
)

__all__ = [
    "BACKENDS",
    "CUBEMAP_FACES",
    "CUBEMAP_METHODS",
    "DEFAULT_TEXEL_PLACEMENT",
    "DEGENERATE_RELATIVE_AREA",
    "MAX_COORDINATE",
    "MAX_RESOLUTION",
    "NEAR_RELATIVE",
    "PRIMITIVES",
    "PROJECTIONS",
    "RASTER_METHODS",
    "TEXEL_PLACEMENTS",
    "Camera",
    "GBuffer",
    "Hit",
    "Plane",
    "Sphere",
    "TriangleMesh",
    "TriangleSetup",
    "check_latlong_shape",
    "cubemap_lookup_bilinear",
    "cubemap_texel_directions",
    "cubemap_texel_solid_angles",
    "cubemap_to_latlong",
    "direction_to_latlong_uv",
    "downsample_box",
    "edge_function",
    "empty_gbuffer",
    "gather_bilinear",
    "gbuffer_from_hit",
    "gbuffer_from_raster",
    "grid_mesh",
    "intersect_plane",
    "intersect_sphere",
    "latlong_blocks_to_cubemap",
    "latlong_lookup_bilinear",
    "latlong_pixel_directions",
    "latlong_pixel_solid_angles",
    "latlong_rows_centred",
    "latlong_rows_mitsuba_to_centred",
    "latlong_to_cubemap",
    "latlong_uv_to_direction",
    "mesh_from_obj",
    "mesh_to_obj",
    "pixel_coverage",
    "plane_uv_to_point",
    "rasterize_mesh",
    "rasterize_triangles",
    "render_gbuffer",
    "triangle_setup",
    "uv_sphere_mesh",
]

"""Geometry: cameras, primitives, the G-buffer, meshes and the rasterizer, lat-long and cube maps.

- :mod:`~reference.geometry.envmap` — lat-long directions (Mitsuba 3's convention), solid angles.
- :mod:`~reference.geometry.camera`, :mod:`~reference.geometry.shapes`,
  :mod:`~reference.geometry.gbuffer` — cameras, analytic primitives, the G-buffer.
- :mod:`~reference.geometry.mesh`, :mod:`~reference.geometry.raster` — triangle meshes (OBJ) and
  the rasterizer (numba twin in ``_raster_kernels``).
- :mod:`~reference.geometry.cubemap` — cube maps from lat-long maps and their lookups (numba twins
  in ``_cubemap_kernels``).
- :mod:`~reference.geometry.sampling` — low-discrepancy (Hammersley) sample points.
"""

from __future__ import annotations

from reference.geometry import camera, cubemap, envmap, gbuffer, mesh, raster, sampling, shapes
from reference.geometry.camera import *  # noqa: F403
from reference.geometry.cubemap import *  # noqa: F403
from reference.geometry.envmap import *  # noqa: F403
from reference.geometry.gbuffer import *  # noqa: F403
from reference.geometry.mesh import *  # noqa: F403
from reference.geometry.raster import *  # noqa: F403
from reference.geometry.sampling import *  # noqa: F403
from reference.geometry.shapes import *  # noqa: F403

__all__ = sorted(
    {
        *envmap.__all__,
        *camera.__all__,
        *shapes.__all__,
        *gbuffer.__all__,
        *mesh.__all__,
        *raster.__all__,
        *sampling.__all__,
        *cubemap.__all__,
    }
)

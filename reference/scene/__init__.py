"""Scenes: lights, deferred shading, scene files, rendering, render metadata and comparison.

- :mod:`~reference.scene.lights` — point (Wang's attenuation), ambient, sphere and environment
  lights.
- :mod:`~reference.scene.shading` — deferred shading (``SHADERS``), the exact spectral Phong model.
- :mod:`~reference.scene.sphere_light` — sphere lights, integrated over the cone they fill.
- :mod:`~reference.scene.values`, :mod:`~reference.scene.items`, :mod:`~reference.scene.loader` —
  the TOML scene format: typed values, object and light types, the loader.
- :mod:`~reference.scene.colorchecker` — the ColorChecker chart material.
- :mod:`~reference.scene.render`, :mod:`~reference.scene.metadata` — ``render_scene`` and what every
  render states; :mod:`~reference.scene.compare` — ``specref compare``.
"""

from __future__ import annotations

from reference.scene import (
    colorchecker,
    compare,
    items,
    lights,
    loader,
    metadata,
    render,
    shading,
    sphere_light,
    values,
)
from reference.scene.colorchecker import *  # noqa: F403
from reference.scene.compare import *  # noqa: F403
from reference.scene.items import *  # noqa: F403
from reference.scene.lights import *  # noqa: F403
from reference.scene.loader import *  # noqa: F403
from reference.scene.metadata import *  # noqa: F403
from reference.scene.render import *  # noqa: F403
from reference.scene.shading import *  # noqa: F403
from reference.scene.sphere_light import *  # noqa: F403
from reference.scene.values import *  # noqa: F403

__all__ = sorted(
    {
        *lights.__all__,
        *shading.__all__,
        *sphere_light.__all__,
        *values.__all__,
        *colorchecker.__all__,
        *items.__all__,
        *loader.__all__,
        *metadata.__all__,
        *render.__all__,
        *compare.__all__,
    }
)

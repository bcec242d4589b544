"""Materials: BRDFs (Lambert, Phong, Ward–Dür, GGX, tables), Fresnel, thin film, material types.

- :mod:`~reference.materials.brdf` — Lambert, Phong and Ward–Dür (``BRDF_METHODS``).
- :mod:`~reference.materials.isotropic`, :mod:`~reference.materials.table`,
  :mod:`~reference.materials.thinfilm` — isotropic 3-D BRDFs, tabulated BRDFs and the thin-film
  effect pigment, registered in ``BRDF_METHODS`` too.
- :mod:`~reference.materials.merl` — measured BRDFs in the MERL binary layout (Matusik et al.
  2003): read, written, evaluated and resampled onto BRDF tables.
- :mod:`~reference.materials.fresnel` — dielectric Fresnel reflectance and its tables.
- :mod:`~reference.materials.types` — the material classes of scene files (``MATERIAL_TYPES``).
"""

from __future__ import annotations

from reference.materials import brdf, fresnel, isotropic, merl, table, thinfilm, types
from reference.materials.brdf import *  # noqa: F403
from reference.materials.fresnel import *  # noqa: F403
from reference.materials.isotropic import *  # noqa: F403
from reference.materials.merl import *  # noqa: F403
from reference.materials.table import *  # noqa: F403
from reference.materials.thinfilm import *  # noqa: F403
from reference.materials.types import *  # noqa: F403

__all__ = sorted(
    {
        *brdf.__all__,
        *isotropic.__all__,
        *merl.__all__,
        *table.__all__,
        *thinfilm.__all__,
        *fresnel.__all__,
        *types.__all__,
    }
)

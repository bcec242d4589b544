"""specref's shared core: colour, geometry and the rasterizer, materials, displays, images, scenes.

Users write ``reference.band_weights``, ``reference.Camera``; the sub-packages hold the equations
and their citations, each re-exporting its public names:

- :mod:`reference.colour` — spectra, colorimetry, upsampling, the spectral regression (Herbert §4);
- :mod:`reference.geometry` — lat-long maps, cameras, shapes, the G-buffer, meshes, the rasterizer,
  cube maps;
- :mod:`reference.display` — encodings, Ferwerda's display model, calibration (Herbert §6), ICC;
- :mod:`reference.materials` — BRDFs, Fresnel, thin film, the material types of scene files;
- :mod:`reference.images` — PNG, EXR, HDR, spectral images, Zarr panoramas;
- :mod:`reference.scene` — lights, shading, scene files, rendering, render metadata, comparison;

and the core modules :mod:`reference.errors`, :mod:`reference.registry`, :mod:`reference.files`
(atomic writes), :mod:`reference.data` (the data shipped with the package), :mod:`reference.tasks`
(Dask) and :mod:`reference.browser` (headless Chromium). ``reference`` imports none of
``phong_table``, ``shrm``, ``impastor`` or ``validation``.
"""

from reference import colour, display, errors, files, geometry, images, materials, registry, scene
from reference.colour import *  # noqa: F403
from reference.display import *  # noqa: F403
from reference.errors import *  # noqa: F403
from reference.files import *  # noqa: F403
from reference.geometry import *  # noqa: F403
from reference.images import *  # noqa: F403
from reference.materials import *  # noqa: F403
from reference.registry import *  # noqa: F403
from reference.scene import *  # noqa: F403

__all__ = sorted(
    {
        *colour.__all__,
        *display.__all__,
        *errors.__all__,
        *files.__all__,
        *geometry.__all__,
        *images.__all__,
        *materials.__all__,
        *registry.__all__,
        *scene.__all__,
    }
)

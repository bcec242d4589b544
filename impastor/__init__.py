"""ImpastoR after Ferwerda 2015: six-channel colour, booth lights, gloss, shadows, the painting.

Users write ``impastor.render_painting``, ``impastor.median_cut``, ``impastor.specular_fis``; the
modules hold the equations (``docs/impastor.md`` walks through the pipeline). The display model of
§3.4 (Eq. (1), Ferwerda) is shared with Herbert et al.'s calibration and lives in
``reference.display.model``.

- :mod:`impastor.multispectral`: six-channel sampling designs (``MULTISPECTRAL_DESIGNS``), spectra
  to channels and channels to XYZ (Table 1, §3.1).
- :mod:`impastor.arealights`: the booth's plane light and its lookups.
- :mod:`impastor.point_lights`: median cut and variance minimization (``LIGHT_SAMPLING_METHODS``),
  the point lights of Eq. (2), Ferwerda.
- :mod:`impastor.specular_lighting`: the Ward–Dür lobe (Eq. (4), Ferwerda) lit by point lights,
  filtered importance sampling (Eqs. (5)-(8), Ferwerda) and the brute-force integral.
- :mod:`impastor.specular_hybrid`: the per-pixel hybrid of point lights and FIS
  (``SPECULAR_METHODS``).
- :mod:`impastor.horizon`: normal maps, horizon maps and ray-marched shadows (``HORIZON_METHODS``).
- :mod:`impastor.painting`: the demo painting under the booth light (``PAINTING_LIGHTING_METHODS``).

``impastor`` imports ``reference`` only, never ``phong_table``, ``shrm`` or ``validation``.
"""

from impastor.arealights import PlaneLight, booth_light_image
from impastor.horizon import (
    HORIZON_METHODS,
    horizon_lookup,
    horizon_map,
    normal_map_from_height,
    ray_march_shadows,
)
from impastor.multispectral import (
    MULTISPECTRAL_DESIGNS,
    SamplingDesign,
    channels_to_XYZ,
    light_to_channels,
    load_design,
    render_channels,
    spectra_to_channels,
)
from impastor.painting import (
    PAINTING_LIGHTING_METHODS,
    booth_plane_light,
    impasto_painting,
    render_painting,
)
from impastor.point_lights import (
    LIGHT_SAMPLING_METHODS,
    PointLights,
    illuminance_point_lights,
    median_cut,
    point_lights_from_plane,
    variance_minimization,
)
from impastor.specular_hybrid import SPECULAR_METHODS, specular_hybrid
from impastor.specular_lighting import specular_brute_force, specular_fis, specular_point_lights

__all__ = [
    "HORIZON_METHODS",
    "LIGHT_SAMPLING_METHODS",
    "MULTISPECTRAL_DESIGNS",
    "PAINTING_LIGHTING_METHODS",
    "SPECULAR_METHODS",
    "PlaneLight",
    "PointLights",
    "SamplingDesign",
    "booth_light_image",
    "booth_plane_light",
    "channels_to_XYZ",
    "horizon_lookup",
    "horizon_map",
    "illuminance_point_lights",
    "impasto_painting",
    "light_to_channels",
    "load_design",
    "median_cut",
    "normal_map_from_height",
    "point_lights_from_plane",
    "ray_march_shadows",
    "render_channels",
    "render_painting",
    "spectra_to_channels",
    "specular_brute_force",
    "specular_fis",
    "specular_hybrid",
    "specular_point_lights",
    "variance_minimization",
]

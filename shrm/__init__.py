"""Herbert et al.: spherical harmonics, prefiltering, SH reflection maps and the polymer model.

The SH modules (``sh``, ``transform``, ``streamed``, ``windows``, ``rotation``, ``lobes``,
``prefilter``, ``accuracy``), the SHRMs (``brdf_sh``, ``shrm``, ``shrm_oracles``, ``split``,
``montecarlo``), the map cache (``cache``) and the render session (``session``, ``orbit``) sit here;
the polymer family (Kubelka–Munk, characterization, tint, Eqs. (1)–(5), Herbert et al., its scene
material and its physical oracle) is the sub-package :mod:`shrm.polymer`. Spectral environments (§4)
and display calibration (§6) are in the shared core (``reference.colour``, ``reference.display``),
which the renderer of every paper uses.

Importing ``shrm`` registers the environment-light shaders in ``reference.scene.shading.SHADERS``
(``shrm.environment``).
"""

from shrm import environment  # noqa: F401  (registers the environment-light shaders)
from shrm.accuracy import accuracy_order, bright_texels
from shrm.brdf_sh import brdf_sh_coefficients, shrm_brdf_parts, shrm_orders
from shrm.cache import Cache, cache_key, default_cache_dir
from shrm.lobes import PREFILTER_KERNELS, adaptive_order, parse_kernel
from shrm.orbit import render_orbit
from shrm.polymer.characterization import (
    characterize_model,
    read_characterization,
    write_characterization,
)
from shrm.polymer.hybrid import MIRROR_FACTORS, polymer_look, polymer_maps, polymer_terms
from shrm.polymer.kubelka_munk import (
    PolymerConstituents,
    km_invert,
    km_slab,
    polymer_constituents,
    polymer_K_S,
    slab_measured,
)
from shrm.polymer.material import PolymerMaterial
from shrm.prefilter import prefilter_bruteforce, prefilter_coefficients, prefilter_environment
from shrm.rotation import rotate_coefficients, rotation_matrix, sh_rotation_blocks
from shrm.session import HERBERT_STAGES, RenderSession
from shrm.sh import SH_MAX_ORDER, sh_basis, sh_evaluate, sh_index
from shrm.shrm import SHRM, render_shrm, shade_shrm, shrm_create, shrm_extract
from shrm.shrm_oracles import render_bruteforce, shrm_create_angular
from shrm.transform import SH_BACKENDS, project_function, project_latlong, synthesize_latlong
from shrm.windows import WINDOWS, apply_window, ringing_statistics

__all__ = [
    "HERBERT_STAGES",
    "MIRROR_FACTORS",
    "PREFILTER_KERNELS",
    "SHRM",
    "SH_BACKENDS",
    "SH_MAX_ORDER",
    "WINDOWS",
    "Cache",
    "PolymerConstituents",
    "PolymerMaterial",
    "RenderSession",
    "accuracy_order",
    "adaptive_order",
    "apply_window",
    "brdf_sh_coefficients",
    "bright_texels",
    "cache_key",
    "characterize_model",
    "default_cache_dir",
    "km_invert",
    "km_slab",
    "parse_kernel",
    "polymer_K_S",
    "polymer_constituents",
    "polymer_look",
    "polymer_maps",
    "polymer_terms",
    "prefilter_bruteforce",
    "prefilter_coefficients",
    "prefilter_environment",
    "project_function",
    "project_latlong",
    "read_characterization",
    "render_bruteforce",
    "render_orbit",
    "render_shrm",
    "ringing_statistics",
    "rotate_coefficients",
    "rotation_matrix",
    "sh_basis",
    "sh_evaluate",
    "sh_index",
    "sh_rotation_blocks",
    "shade_shrm",
    "shrm_brdf_parts",
    "shrm_create",
    "shrm_create_angular",
    "shrm_extract",
    "shrm_orders",
    "slab_measured",
    "synthesize_latlong",
    "write_characterization",
]

"""Spherical harmonics, prefiltering and SH reflection maps after Herbert et al.

Importing ``shrm`` registers the environment-light shaders in ``reference.shading.SHADERS``
(``shrm.environment``).
"""

from shrm import environment  # noqa: F401  (registers the environment-light shaders)
from shrm.prefilter import (
    PREFILTER_KERNELS,
    adaptive_order,
    parse_kernel,
    prefilter_bruteforce,
    prefilter_coefficients,
    prefilter_environment,
)
from shrm.rotation import rotate_coefficients, rotation_matrix, sh_rotation_blocks
from shrm.sh import (
    SH_BACKENDS,
    SH_MAX_ORDER,
    project_function,
    project_latlong,
    sh_basis,
    sh_evaluate,
    sh_index,
    synthesize_latlong,
)
from shrm.windows import WINDOWS, apply_window, ringing_statistics

__all__ = [
    "PREFILTER_KERNELS",
    "SH_BACKENDS",
    "SH_MAX_ORDER",
    "WINDOWS",
    "adaptive_order",
    "apply_window",
    "parse_kernel",
    "prefilter_bruteforce",
    "prefilter_coefficients",
    "prefilter_environment",
    "project_function",
    "project_latlong",
    "ringing_statistics",
    "rotate_coefficients",
    "rotation_matrix",
    "sh_basis",
    "sh_evaluate",
    "sh_index",
    "sh_rotation_blocks",
    "synthesize_latlong",
]

"""Scenes: lights, deferred shading, scene files, rendering, render metadata and comparison.

- :mod:`~reference.scene.lights` — point (Wang's attenuation), ambient and environment lights.
- :mod:`~reference.scene.shading` — deferred shading (``SHADERS``), the exact spectral Phong model.
- :mod:`~reference.scene.values`, :mod:`~reference.scene.items`, :mod:`~reference.scene.loader` —
  the TOML scene format: typed values, object and light types, the loader.
- :mod:`~reference.scene.colorchecker` — the ColorChecker chart material.
- :mod:`~reference.scene.render`, :mod:`~reference.scene.metadata` — ``render_scene`` and what every
  render states; :mod:`~reference.scene.compare` — ``specref compare``.
"""

from __future__ import annotations

from reference.scene.colorchecker import (
    COLORCHECKER_LAYOUT,
    ColorCheckerMaterial,
    colorchecker_material,
    colorchecker_patch_centres_uv,
    colorchecker_patch_index,
    colorchecker_patch_pixels,
    shade_colorchecker_ambient,
    shade_colorchecker_point,
)
from reference.scene.compare import (
    STDERR_CHANNELS,
    XYZ_to_uv_prime,
    compare_files,
    compare_images,
    exr_to_XYZ,
    pixel_differences,
    summary_line,
)
from reference.scene.items import (
    LIGHT_TYPES,
    OBJECT_TYPES,
    SceneItemType,
)
from reference.scene.lights import (
    AmbientLight,
    EnvironmentLight,
    PointLight,
    attenuation_Wang,
    point_light_vectors,
)
from reference.scene.loader import (
    MAX_RENDER_SAMPLES,
    MAX_SUPERSAMPLE,
    DisplaySettings,
    RenderSettings,
    Scene,
    check_render_size,
    load_scene,
    loads_scene,
    parse_spectral,
    scene_from_dict,
)
from reference.scene.metadata import (
    DEFAULT_ACCURACY,
    LIT_FRACTION,
    MAX_FACTOR,
    METADATA_SCHEMA,
    NORMALISATION,
    RENDER_OUTPUTS,
    check_accuracy,
    exr_attributes,
    output_channels,
    output_image,
    read_exr_metadata,
    render_metadata,
)
from reference.scene.render import (
    SHADING_TILE_SAMPLES,
    RenderResult,
    XYZ_to_display,
    background_XYZ,
    check_shaders,
    render_scene,
    render_scene_file,
    scene_gbuffer,
    shade_scene,
    write_render,
)
from reference.scene.shading import (
    PHONG_POINT_METHODS,
    SHADERS,
    ShadingContext,
    Surface,
    phong_cosines,
    phong_spectral_exact,
    shade_gbuffer,
    shader_key,
    spectral_output_weights,
    surface_of,
)
from reference.scene.values import (
    SPECTRUM_FORMS,
    SceneReader,
    SpectrumForm,
    SpectrumSpec,
)

__all__ = [
    "COLORCHECKER_LAYOUT",
    "DEFAULT_ACCURACY",
    "LIGHT_TYPES",
    "LIT_FRACTION",
    "MAX_FACTOR",
    "MAX_RENDER_SAMPLES",
    "MAX_SUPERSAMPLE",
    "METADATA_SCHEMA",
    "NORMALISATION",
    "OBJECT_TYPES",
    "PHONG_POINT_METHODS",
    "RENDER_OUTPUTS",
    "SHADERS",
    "SHADING_TILE_SAMPLES",
    "SPECTRUM_FORMS",
    "STDERR_CHANNELS",
    "AmbientLight",
    "ColorCheckerMaterial",
    "DisplaySettings",
    "EnvironmentLight",
    "PointLight",
    "RenderResult",
    "RenderSettings",
    "Scene",
    "SceneItemType",
    "SceneReader",
    "ShadingContext",
    "SpectrumForm",
    "SpectrumSpec",
    "Surface",
    "XYZ_to_display",
    "XYZ_to_uv_prime",
    "attenuation_Wang",
    "background_XYZ",
    "check_accuracy",
    "check_render_size",
    "check_shaders",
    "colorchecker_material",
    "colorchecker_patch_centres_uv",
    "colorchecker_patch_index",
    "colorchecker_patch_pixels",
    "compare_files",
    "compare_images",
    "exr_attributes",
    "exr_to_XYZ",
    "load_scene",
    "loads_scene",
    "output_channels",
    "output_image",
    "parse_spectral",
    "phong_cosines",
    "phong_spectral_exact",
    "pixel_differences",
    "point_light_vectors",
    "read_exr_metadata",
    "render_metadata",
    "render_scene",
    "render_scene_file",
    "scene_from_dict",
    "scene_gbuffer",
    "shade_colorchecker_ambient",
    "shade_colorchecker_point",
    "shade_gbuffer",
    "shade_scene",
    "shader_key",
    "spectral_output_weights",
    "summary_line",
    "surface_of",
    "write_render",
]

"""specref's reference layer: spectral core, geometry and rasterizer, BRDFs, lights and display.

Users write ``reference.band_weights``, ``reference.Camera``; the modules hold the equations and
their citations. ``reference`` imports none of ``phong_table``, ``shrm`` or ``validation``.
"""

import reference.materials.isotropic
import reference.materials.table
import reference.materials.thinfilm  # noqa: F401  (registers the effect pigment)
from reference.colour.colorimetry import (
    BAND_WEIGHT_METHODS,
    DEFAULT_OBSERVER,
    OBSERVERS,
    XYZ_to_display_RGB,
    XYZ_to_Lab,
    XYZ_to_RGB_matrix,
    band_weights,
    band_weights_ASTM_E308,
    band_weights_point_sampled,
    delta_E_00,
    display_RGB_to_XYZ,
    spectra_to_RGB_matrix,
    spectra_to_XYZ,
    white_XYZ,
)
from reference.colour.spectra import (
    DEFAULT_GRID,
    GRID_31,
    GRID_41,
    GRIDS,
    SpectralGrid,
    Spectrum,
    make_spectrum,
    resample_spectrum,
    spectrum_constant,
    spectrum_from_csv,
    spectrum_from_dataset,
)
from reference.display.encodings import ENCODINGS, display_to_linear, linear_to_display, to_8bit
from reference.errors import SpecrefError, SpecrefWarning, require
from reference.files import atomic_write
from reference.geometry.camera import MAX_RESOLUTION, PROJECTIONS, Camera, downsample_box
from reference.geometry.envmap import (
    check_latlong_shape,
    direction_to_latlong_uv,
    latlong_lookup_bilinear,
    latlong_pixel_directions,
    latlong_pixel_solid_angles,
    latlong_uv_to_direction,
)
from reference.geometry.gbuffer import PRIMITIVES, GBuffer, empty_gbuffer, render_gbuffer
from reference.geometry.mesh import (
    TriangleMesh,
    grid_mesh,
    mesh_from_obj,
    mesh_to_obj,
    uv_sphere_mesh,
)
from reference.geometry.raster import RASTER_METHODS, pixel_coverage, rasterize_mesh
from reference.geometry.shapes import Plane, Sphere, intersect_plane, intersect_sphere
from reference.images.formats import read_exr, read_hdr, read_image, read_png, write_exr, write_png
from reference.materials.types import MATERIAL_TYPES, LambertMaterial, PhongMaterial, make_material
from reference.registry import Method, Registry
from reference.scene.colorchecker import ColorCheckerMaterial, colorchecker_material
from reference.scene.compare import compare_images
from reference.scene.lights import (
    AmbientLight,
    EnvironmentLight,
    PointLight,
    attenuation_Wang,
    point_light_vectors,
)
from reference.scene.loader import (
    LIGHT_TYPES,
    MAX_RENDER_SAMPLES,
    OBJECT_TYPES,
    Scene,
    load_scene,
    loads_scene,
)
from reference.scene.metadata import RENDER_OUTPUTS, render_metadata
from reference.scene.render import RenderResult, render_scene, render_scene_file, write_render
from reference.scene.shading import (
    SHADERS,
    ShadingContext,
    Surface,
    phong_cosines,
    phong_spectral_exact,
    shade_gbuffer,
)
from reference.scene.values import SPECTRUM_FORMS

__all__ = [
    "BAND_WEIGHT_METHODS",
    "DEFAULT_GRID",
    "DEFAULT_OBSERVER",
    "ENCODINGS",
    "GRIDS",
    "GRID_31",
    "GRID_41",
    "LIGHT_TYPES",
    "MATERIAL_TYPES",
    "MAX_RENDER_SAMPLES",
    "MAX_RESOLUTION",
    "OBJECT_TYPES",
    "OBSERVERS",
    "PRIMITIVES",
    "PROJECTIONS",
    "RASTER_METHODS",
    "RENDER_OUTPUTS",
    "SHADERS",
    "SPECTRUM_FORMS",
    "AmbientLight",
    "Camera",
    "ColorCheckerMaterial",
    "EnvironmentLight",
    "GBuffer",
    "LambertMaterial",
    "Method",
    "PhongMaterial",
    "Plane",
    "PointLight",
    "Registry",
    "RenderResult",
    "Scene",
    "ShadingContext",
    "SpecrefError",
    "SpecrefWarning",
    "SpectralGrid",
    "Spectrum",
    "Sphere",
    "Surface",
    "TriangleMesh",
    "XYZ_to_Lab",
    "XYZ_to_RGB_matrix",
    "XYZ_to_display_RGB",
    "atomic_write",
    "attenuation_Wang",
    "band_weights",
    "band_weights_ASTM_E308",
    "band_weights_point_sampled",
    "check_latlong_shape",
    "colorchecker_material",
    "compare_images",
    "delta_E_00",
    "direction_to_latlong_uv",
    "display_RGB_to_XYZ",
    "display_to_linear",
    "downsample_box",
    "empty_gbuffer",
    "grid_mesh",
    "intersect_plane",
    "intersect_sphere",
    "latlong_lookup_bilinear",
    "latlong_pixel_directions",
    "latlong_pixel_solid_angles",
    "latlong_uv_to_direction",
    "linear_to_display",
    "load_scene",
    "loads_scene",
    "make_material",
    "make_spectrum",
    "mesh_from_obj",
    "mesh_to_obj",
    "phong_cosines",
    "phong_spectral_exact",
    "pixel_coverage",
    "point_light_vectors",
    "rasterize_mesh",
    "read_exr",
    "read_hdr",
    "read_image",
    "read_png",
    "render_gbuffer",
    "render_metadata",
    "render_scene",
    "render_scene_file",
    "require",
    "resample_spectrum",
    "shade_gbuffer",
    "spectra_to_RGB_matrix",
    "spectra_to_XYZ",
    "spectrum_constant",
    "spectrum_from_csv",
    "spectrum_from_dataset",
    "to_8bit",
    "uv_sphere_mesh",
    "white_XYZ",
    "write_exr",
    "write_png",
    "write_render",
]

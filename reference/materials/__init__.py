"""Materials: BRDFs (Lambert, Phong, Ward–Dür, GGX, tables), Fresnel, thin film, material types.

- :mod:`~reference.materials.brdf` — Lambert, Phong and Ward–Dür (``BRDF_METHODS``).
- :mod:`~reference.materials.isotropic`, :mod:`~reference.materials.table`,
  :mod:`~reference.materials.thinfilm` — isotropic 3-D BRDFs, tabulated BRDFs and the thin-film
  effect pigment, registered in ``BRDF_METHODS`` too.
- :mod:`~reference.materials.fresnel` — dielectric Fresnel reflectance and its tables.
- :mod:`~reference.materials.types` — the material classes of scene files (``MATERIAL_TYPES``).
"""

from __future__ import annotations

from reference.materials.brdf import (
    BRDF_METHODS,
    albedo_quadrature,
    brdf_lambert,
    brdf_ward_duer,
    brdf_ward_duer_specular,
    check_ward_duer_params,
    frame_from_normal,
    pdf_cosine,
    pdf_ward_duer,
    pdf_ward_duer_lobe,
    sample_cosine,
    sample_ward_duer,
    sample_ward_duer_lobe,
)
from reference.materials.fresnel import (
    FRESNEL_LUT_SIZE,
    FresnelLUT,
    fresnel_dielectric,
    fresnel_diffuse,
    fresnel_lut,
)
from reference.materials.isotropic import (
    brdf_ggx,
    brdf_lafortune,
    brdf_ward_isotropic,
    ggx_distribution,
    ggx_smith_G1,
    isotropic_angles,
    isotropic_directions,
    register_brdf,
)
from reference.materials.table import (
    MAX_TABLE_ANGLES,
    BRDFTable,
    brdf_tabulated,
    read_brdf_table,
    tabulable_brdf_names,
    tabulate_brdf,
    tabulate_registered_brdf,
    write_brdf_table,
)
from reference.materials.thinfilm import (
    airy_reflectance,
    brdf_effect_pigment,
)
from reference.materials.types import (
    MATERIAL_TYPES,
    LambertMaterial,
    MaterialType,
    PhongMaterial,
    make_material,
)

__all__ = [
    "BRDF_METHODS",
    "FRESNEL_LUT_SIZE",
    "MATERIAL_TYPES",
    "MAX_TABLE_ANGLES",
    "BRDFTable",
    "FresnelLUT",
    "LambertMaterial",
    "MaterialType",
    "PhongMaterial",
    "airy_reflectance",
    "albedo_quadrature",
    "brdf_effect_pigment",
    "brdf_ggx",
    "brdf_lafortune",
    "brdf_lambert",
    "brdf_tabulated",
    "brdf_ward_duer",
    "brdf_ward_duer_specular",
    "brdf_ward_isotropic",
    "check_ward_duer_params",
    "frame_from_normal",
    "fresnel_dielectric",
    "fresnel_diffuse",
    "fresnel_lut",
    "ggx_distribution",
    "ggx_smith_G1",
    "isotropic_angles",
    "isotropic_directions",
    "make_material",
    "pdf_cosine",
    "pdf_ward_duer",
    "pdf_ward_duer_lobe",
    "read_brdf_table",
    "register_brdf",
    "sample_cosine",
    "sample_ward_duer",
    "sample_ward_duer_lobe",
    "tabulable_brdf_names",
    "tabulate_brdf",
    "tabulate_registered_brdf",
    "write_brdf_table",
]

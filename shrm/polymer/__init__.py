"""Herbert et al.'s polymers: Kubelka–Munk chips, characterization, tint, the hybrid, its oracle.

- :mod:`~shrm.polymer.kubelka_munk` — the two-flux Kubelka–Munk slab that generates the chip matrix
  (§3.1, Herbert et al.).
- :mod:`~shrm.polymer.characterization` — chip-matrix files and their look-up.
- :mod:`~shrm.polymer.tint` — the spot-colour library of ``Tint_polymer`` (Eq. (2), Herbert et al.).
- :mod:`~shrm.polymer.hybrid` — Eqs. (1)–(5), Herbert et al., as spectral terms.
- :mod:`~shrm.polymer.material` — the ``polymer`` scene material and its environment shader.
- :mod:`~shrm.polymer.oracle` — the layered physical model behind Eq. (1), Herbert et al., by brute
  force.
"""

from __future__ import annotations

from shrm.polymer.characterization import (
    DEFAULT_THICKNESS_MM,
    DEFAULT_TIO2_PCT,
    HERBERT_THICKNESS_MM,
    MEASUREMENTS,
    Characterization,
    characterize_model,
    read_characterization,
    write_characterization,
)
from shrm.polymer.hybrid import (
    MIRROR_FACTORS,
    PolymerLook,
    PolymerMaps,
    effect_radiance,
    effect_shrm,
    mirror_factor_cosine,
    mirror_factor_fresnel,
    mirror_factor_none,
    polymer_look,
    polymer_maps,
    polymer_terms,
)
from shrm.polymer.kubelka_munk import (
    DEFAULT_CONSTITUENTS,
    PolymerConstituents,
    SaundersonConstants,
    km_invert,
    km_over_backing,
    km_R_infinity,
    km_slab,
    polymer_constituents,
    polymer_K_S,
    saunderson_constants,
    slab_measured,
)
from shrm.polymer.material import (
    POLYMER_DEFAULTS,
    POLYMER_KERNELS,
    PolymerMaterial,
    chip_lookup,
    modulation_at,
    polymer_characterization,
    polymer_environment_maps,
    polymer_material_look,
    polymer_pixel_parts,
    polymer_shade_parts,
    shade_polymer_environment,
)
from shrm.polymer.oracle import (
    GLOSS_ALPHA_MAX,
    ORACLE_KERNELS,
    PHONG_EXPONENT_MAX,
    OracleResult,
    gloss_alpha,
    gloss_phong_exponent,
    interface_coupling,
    oracle_bsdf,
    oracle_diffuse,
    polymer_oracle,
    rough_reflection_albedo,
    rough_specular_samples,
    smooth_plastic_albedo,
)
from shrm.polymer.tint import (
    DEFAULT_TINT_LIBRARY,
    TintLibrary,
    read_tint_library,
    tint_search,
)

__all__ = [
    "DEFAULT_CONSTITUENTS",
    "DEFAULT_THICKNESS_MM",
    "DEFAULT_TINT_LIBRARY",
    "DEFAULT_TIO2_PCT",
    "GLOSS_ALPHA_MAX",
    "HERBERT_THICKNESS_MM",
    "MEASUREMENTS",
    "MIRROR_FACTORS",
    "ORACLE_KERNELS",
    "PHONG_EXPONENT_MAX",
    "POLYMER_DEFAULTS",
    "POLYMER_KERNELS",
    "Characterization",
    "OracleResult",
    "PolymerConstituents",
    "PolymerLook",
    "PolymerMaps",
    "PolymerMaterial",
    "SaundersonConstants",
    "TintLibrary",
    "characterize_model",
    "chip_lookup",
    "effect_radiance",
    "effect_shrm",
    "gloss_alpha",
    "gloss_phong_exponent",
    "interface_coupling",
    "km_R_infinity",
    "km_invert",
    "km_over_backing",
    "km_slab",
    "mirror_factor_cosine",
    "mirror_factor_fresnel",
    "mirror_factor_none",
    "modulation_at",
    "oracle_bsdf",
    "oracle_diffuse",
    "polymer_K_S",
    "polymer_characterization",
    "polymer_constituents",
    "polymer_environment_maps",
    "polymer_look",
    "polymer_maps",
    "polymer_material_look",
    "polymer_oracle",
    "polymer_pixel_parts",
    "polymer_shade_parts",
    "polymer_terms",
    "read_characterization",
    "read_tint_library",
    "rough_reflection_albedo",
    "rough_specular_samples",
    "saunderson_constants",
    "shade_polymer_environment",
    "slab_measured",
    "smooth_plastic_albedo",
    "tint_search",
    "write_characterization",
]

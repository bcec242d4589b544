"""The conformance scenes: small canonical scenes, each testing one thing, shipped as scene files.

Each scene is a specref scene file in ``data:conformance/<name>.toml`` (docs/scene-format.md),
at most 64 × 64 pixels, with what it tests and the mistakes it catches (keys of
:data:`validation.conformance.diagnose.DIAGNOSES`). The files are written from this registry by
``python -m validation.precompute.conformance`` (with the 32 × 64 maps of
``data:conformance/maps/``, box averages of the shipped environment maps), and a test checks that
the shipped files are what the registry writes.

Conventions every scene spells out (docs/conformance.md): Y = 1 for a white diffuser facing a
unit light (``intensity`` of a point light at ``f_att = 1``; an illuminant normalized to Y = 1);
point lights fall off as ``1/d²`` (``attenuation = [0, 0, 1]``, the physical law) except in the
Phong scenes, which keep the attenuation of Eq. (1), Wang et al.; environment maps are lat-long in
Mitsuba 3's orientation, constant over each texel (``texel_placement = "centred"``: texel ``j``
spans rows ``j/H`` to ``(j + 1)/H``), each texel's RGB upsampled by Jakob and Hanika 2019 as
Mitsuba 3 and pbrt-v4 do (``upsampling = "jakob2019"``, erratum E80); the scenes lit by point
and ambient lights are on a 1 nm grid (:data:`FINE_GRID`), so that lamps with lines (FL2, FL11)
meet the materials as in a renderer that samples wavelengths (the sphere-lit scenes, whose
materials are flat, are on the 41-band grid); pixels are box-filtered over their area.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field

from reference.registry import Registry

__all__ = [
    "CALIBRATED_DISPLAY",
    "CONFORMANCE_SCENES",
    "ENVIRONMENT_MAPS",
    "RING_MAP",
    "ConformanceScene",
    "ring_map",
    "scene_path",
    "scene_text",
]

#: Shipped maps (``data:environments``) averaged to 32 × 64 for the environment scenes:
#: short name -> file name.
ENVIRONMENT_MAPS = {
    "venice": "venice_sunset_1k.hdr",
    "fagans": "st_fagans_interior_1k.hdr",
    "studio": "studio_small_03_1k.hdr",
    "stage": "StageEnvLatLong.exr",
}
#: Rows of those maps.
MAP_ROWS = 32
#: The synthetic map of ``lambert-env-ring`` (``data:conformance/maps/ring.exr``, :func:`ring_map`):
#: a grey sky of radiance ``sky`` with the texel row ``row`` (5.6°-11.25° from the zenith) at
#: ``ring``, relative to a white RGB texel of 1.
RING_MAP = {"row": 1, "ring": 20.0, "sky": 0.2}


def ring_map(rows: int = MAP_ROWS):
    """The ring map (:data:`RING_MAP`), ``rows × 2 rows × 3`` linear RGB, float32.

    Where a normal sees the ring at its horizon, the cosine across the ring's texel row changes
    by a large fraction of itself, so the row's place on the sphere decides the pixel: a
    renderer that reads the rows half a texel off changes the sphere's image by several times
    the tolerance (the photographed maps' spheres change by 0.5-1.7 times it; errata E102).

    Examples
    --------
    >>> m = ring_map()
    >>> m.shape, float(m[1, 0, 0]), float(m[0, 0, 0])
    ((32, 64, 3), 20.0, 0.2)
    """
    import numpy as np

    image = np.full((rows, 2 * rows, 3), RING_MAP["sky"], dtype=np.float32)
    image[RING_MAP["row"]] = RING_MAP["ring"]
    return image


#: The calibrated display of the display scene (``data:conformance/displays/<stem>.cal`` with its
#: ``.ti3``, ``.json`` and ``.cube``), as ``specref display calibrate`` writes them: the built-in
#: simulated display with wide LED-like primaries, calibrated to D65 and Herbert's L* curve
#: (Eq. (7), Herbert et al.), so that sRGB's primaries and transfer function are both wrong.
CALIBRATED_DISPLAY = {
    "stem": "led-wide-d65-lstar",
    "primaries": "led_wide",
    "white": "D65",
    "curve": "lstar",
    "points": 15,
    "seed": 0,
}


@dataclass(frozen=True)
class ConformanceScene:
    """One conformance scene.

    Attributes
    ----------
    name : str
        Key and file stem (``data:conformance/<name>.toml``).
    tests : str
        What a renderer must get right to pass.
    catches : tuple of str
        Keys of ``DIAGNOSES`` that this scene can tell apart (the mistakes it catches).
    body : callable
        ``body() -> str``: the scene file after its title and description.
    cannot_export : dict
        Export format -> why that renderer cannot express the scene.
    tolerance_Y, tolerance_dE : float
        Floors of the pass thresholds: mean relative ΔY of 4 × 4-pixel blocks and their mean
        ΔE00 (what two correct renderers may differ by: spectral sampling, pixel filters). The
        reference's own uncertainty is added (:mod:`validation.conformance.check`).
    """

    name: str
    tests: str
    catches: tuple
    body: Callable[[], str]
    cannot_export: dict = field(default_factory=dict)
    tolerance_Y: float = 0.01
    tolerance_dE: float = 1.0


#: The conformance scenes by name.
CONFORMANCE_SCENES = Registry("conformance scene", ConformanceScene)

_NO_PHONG = "Mitsuba 3 has no Phong BSDF (Wang et al.'s un-normalized cos^n(λ) lobe)"
_NO_WARD = "Mitsuba 3 has no Ward BSDF"
_NO_SCHLICK = (
    "Mitsuba 3's rough BSDFs use a dielectric or conductor Fresnel term, not Schlick's F_0 "
    "with a Lambertian base"
)


def _spectrum(wavelengths, values) -> str:
    wl = ", ".join(f"{w:g}" for w in wavelengths)
    v = ", ".join(f"{float(x):.6g}" for x in values)
    return f"{{ wavelengths = [{wl}], values = [{v}] }}"


#: The grid of the scenes lit by point and ambient lights: 1 nm, so that a lamp's lines meet the
#: materials' spectra as in a renderer that samples wavelengths (the band weights fold a light in
#: at its own sampling, but a material only at the grid's nodes, errata E7).
FINE_GRID = "\n".join(["[spectral]", "start_nm = 380", "end_nm = 780", "step_nm = 1"])


def _sphere_camera(width: int, supersample: int = 4) -> str:
    return "\n".join([
        "[camera]", "eye = [0, 0, 4]", "target = [0, 0, 0]", "fov_deg = 32",
        "[render]", f"width = {width}", f"height = {width}", f"supersample = {supersample}",
    ])  # fmt: skip


def _point_lit(material: list[str], illuminant: str) -> Callable[[], str]:
    """A sphere of ``material`` (its TOML lines) under a point light of ``illuminant``, 1/d²."""

    def body() -> str:
        return "\n".join([
            FINE_GRID, _sphere_camera(64),
            "[materials.m]", *material,
            "[[objects]]", 'type = "sphere"', 'material = "m"',
            "[[lights]]", 'type = "point"', "position = [3, 2, 4]",
            f'spectrum = {{ illuminant = "{illuminant}" }}', "intensity = 25",
            "attenuation = [0, 0, 1]",
        ])  # fmt: skip

    return body


def _phong(key: str) -> Callable[[], str]:
    def body() -> str:
        from phong_table.scenes import EYE, SCENES, VIEWS
        from reference.colour.spectra import DEFAULT_GRID

        model = SCENES.lookup(key).build()
        m, light = model.material, model.light
        wl = DEFAULT_GRID.wavelengths_nm
        return "\n".join([
            FINE_GRID,
            "[camera]", f"eye = {list(EYE)}", "target = [0, 0, 0]", f"fov_deg = {VIEWS['far']:g}",
            "[render]", "width = 64", "height = 64", "supersample = 4",
            "[materials.m]", 'type = "phong"', f"k_d = {_spectrum(wl, m.k_d)}",
            f"k_s = {_spectrum(wl, m.k_s)}", f"n = {_spectrum(wl, m.n)}",
            "[[objects]]", 'type = "sphere"', 'material = "m"',
            "[[lights]]", 'type = "point"', f"position = {list(light.position)}",
            f'spectrum = {{ illuminant = "{_illuminant_of(key)}" }}',
            f"intensity = {light.intensity:.9g}", f"attenuation = {list(light.attenuation)}",
        ])  # fmt: skip

    return body


def _illuminant_of(key: str) -> str:
    return {"R1": "D65", "R2": "A", "R3": "FL11", "bimodal": "D65"}[key]


def _sphere_lit(material: list[str], illuminant: str) -> Callable[[], str]:
    """A sphere of ``material`` under a sphere light of ``illuminant`` (radius 1.5, off camera).

    The light's radiance is ``25 / 1.5²``, so that far from it it is the point light of the
    point-lit scenes (intensity 25 at the same place). Flat spectra: on the 41-band grid a
    material meets the light as on a finer one (the light is folded in at its own sampling, E7).
    48 × 48 pixels of 2 × 2 samples: each sample integrates over the light (the GGX lobe needs
    about a thousand directions where it meets the light's edge).
    """

    def body() -> str:
        return "\n".join([
            _sphere_camera(48, 2),
            "[materials.m]", *material,
            "[[objects]]", 'type = "sphere"', 'material = "m"',
            "[[lights]]", 'type = "sphere"', "position = [3, 2, 4]", "radius = 1.5",
            f'spectrum = {{ illuminant = "{illuminant}" }}', f"intensity = {25 / 1.5**2:.9g}",
        ])  # fmt: skip

    return body


def _chart(illuminant: str, display: tuple = ()) -> Callable[[], str]:
    def body() -> str:
        return "\n".join([
            FINE_GRID,
            "[camera]", 'projection = "orthographic"', "eye = [0, 0, 5]", "target = [0, 0, 0]",
            "extent = 0.4",
            "[render]", "width = 60", "height = 40", "supersample = 4",
            "[materials.chart]", 'type = "colorchecker"', "gap_width = 0.12", "gap = 0",
            "[[objects]]", 'type = "rectangle"', "point = [0, 0, 0]", "normal = [0, 0, 1]",
            "u_axis = [1, 0, 0]", "size = [0.6, 0.4]", 'material = "chart"',
            "[[lights]]", 'type = "ambient"', f'spectrum = {{ illuminant = "{illuminant}" }}',
            *display,
        ])  # fmt: skip

    return body


def _environment(material: list[str], map_key: str, options: tuple = ()) -> Callable[[], str]:
    # the brute force of a glossy BRDF or a polymer costs 16 times a Lambertian's per pixel:
    # 2 × 2 samples
    supersample = 2 if any(k in material[0] for k in ("isotropic_brdf", "polymer")) else 4

    def body() -> str:
        return "\n".join([
            _sphere_camera(48, supersample), "[render.options]", 'upsampling = "jakob2019"',
            *options, "[materials.m]", *material,
            "[[objects]]", 'type = "sphere"', 'material = "m"',
            "[[lights]]", 'type = "environment"', f'file = "maps/{map_key}.exr"',
            'texel_placement = "centred"',
        ])  # fmt: skip

    return body


_LAMBERT_HALF = ['type = "lambert"', "k_d = 0.5"]
_ORANGE_K_D = (
    '{ csv = "data:spectra/physicallybased/orange__nix_export.csv", extrapolation = "constant" }'
)
_ORANGE = ['type = "lambert"', f"k_d = {_ORANGE_K_D}"]
_SCALE_MISTAKES = ("Y_scaled", "srgb_encoded")

CONFORMANCE_SCENES.register(ConformanceScene(
    "lambert-point-d65",
    "the cosine law, the 1/d² fall-off and the normalization of a D65 point light "
    "(a grey Lambertian sphere, ρ = 0.5)",
    ("missing_cosine", "illuminant_not_normalized", *_SCALE_MISTAKES),
    _point_lit(_LAMBERT_HALF, "D65"),
))  # fmt: skip
CONFORMANCE_SCENES.register(ConformanceScene(
    "lambert-point-orange-a",
    "a measured reflectance (an orange, Nix Spectro 2, held constant beyond 400-700 nm) times "
    "illuminant A, integrated per wavelength",
    ("missing_cosine", "illuminant_not_normalized", "rgb_rendering", *_SCALE_MISTAKES),
    _point_lit(_ORANGE, "A"),
))  # fmt: skip


CONFORMANCE_SCENES.register(ConformanceScene(
    "ggx-point-d65",
    "a GGX conductor (α = 0.3, F = 1, Smith G1·G1, Walter et al. 2007) under a D65 point light: "
    "the microfacet lobe's shape, height and place, and π f cos θ in the scene's units",
    ("missing_cosine", "illuminant_not_normalized", *_SCALE_MISTAKES),
    _point_lit(['type = "isotropic_brdf"', 'brdf = "ggx"', "rho_d = 0", "F_0 = 1",
                 "alpha = 0.3"], "D65"),
))  # fmt: skip
CONFORMANCE_SCENES.register(ConformanceScene(
    "ggx-plastic-point-fl2",
    "GGX with Schlick's Fresnel (F_0 = 0.04) over a measured reflectance (an orange) under an "
    "FL2 point light: a white highlight on a coloured base, per wavelength",
    ("missing_cosine", "illuminant_not_normalized", "rgb_rendering", *_SCALE_MISTAKES),
    _point_lit(['type = "isotropic_brdf"', 'brdf = "ggx"', f"rho_d = {_ORANGE_K_D}",
                 "F_0 = 0.04", "alpha = 0.2"], "FL2"),
    {"mitsuba": _NO_SCHLICK},
))  # fmt: skip
CONFORMANCE_SCENES.register(ConformanceScene(
    "ward-point-a",
    "Ward's isotropic BRDF (ρ_d = 0.2, ρ_s = 0.2, α = 0.15) under an illuminant A point light "
    "(flat spectra: an RGB renderer gets it right, so it does not list rgb_rendering)",
    ("missing_cosine", "illuminant_not_normalized", *_SCALE_MISTAKES),
    _point_lit(['type = "isotropic_brdf"', 'brdf = "ward_isotropic"', "rho_d = 0.2",
                 "rho_s = 0.2", "alpha = 0.15"], "A"),
    {"mitsuba": _NO_WARD},
))  # fmt: skip
CONFORMANCE_SCENES.register(ConformanceScene(
    "lambert-sphere-light-d65",
    "an area light: a grey Lambertian sphere (ρ = 0.5) under a D65 sphere light of radius 1.5, "
    "integrated over the part of the light above each point's horizon: the soft terminator that "
    "a point light at its centre does not give",
    ("area_light_as_point", "illuminant_not_normalized", *_SCALE_MISTAKES),
    _sphere_lit(_LAMBERT_HALF, "D65"),
))  # fmt: skip
CONFORMANCE_SCENES.register(ConformanceScene(
    "ggx-sphere-light-a",
    "an area light in a highlight: a GGX conductor (α = 0.2, F = 1) under an illuminant A "
    "sphere light of radius 1.5: the highlight is the light's disc blurred by the lobe, wider and "
    "lower than a point light's",
    ("area_light_as_point", "illuminant_not_normalized", *_SCALE_MISTAKES),
    _sphere_lit(['type = "isotropic_brdf"', 'brdf = "ggx"', "rho_d = 0", "F_0 = 1",
                 "alpha = 0.2"], "A"),
))  # fmt: skip
for _key, _what in (
    ("R1", "smooth spectra, n(λ) = 20-80, D65"),
    ("R2", "an exponent from 10 to 1000 across wavelengths, illuminant A"),
    ("R3", "a narrow-band k_s at 530 nm with n(λ) = 2000-3000 under FL11's lines"),
    ("bimodal", "n = 5 below 580 nm and 500 above: two highlights of different colour"),
):
    CONFORMANCE_SCENES.register(ConformanceScene(
        f"phong-point-{_key.lower()}",
        f"the spectral Phong model (Eq. (2), Wang et al.) with a per-wavelength exponent ({_what}; "
        "phong_table.scenes); the reference is the exact per-band evaluation",
        # under D65 the RGB product of a white light changes nothing
        (*(("rgb_rendering",) if _illuminant_of(_key) != "D65" else ()), *_SCALE_MISTAKES),
        _phong(_key),
        {"mitsuba": _NO_PHONG},
    ))  # fmt: skip
for _illuminant, _what in (
    ("D65", "daylight: the chart's colours as measured"),
    ("A", "incandescent light: every patch shifts towards orange"),
    (
        "FL2",
        "a cool-white fluorescent lamp with mercury lines that point sampling of the grid misses",
    ),
    ("FL11", "a narrow tri-band lamp: the largest metameric shifts of RGB rendering"),
):
    CONFORMANCE_SCENES.register(ConformanceScene(
        f"colorchecker-{_illuminant.lower()}",
        f"the 24 ColorChecker N Ohta patches under a uniform sky of {_illuminant} ({_what}); "
        "each patch is a Lambertian square, black gaps between them",
        (*(("rgb_rendering",) if _illuminant != "D65" else ()), "illuminant_not_normalized",
         *_SCALE_MISTAKES),
        _chart(_illuminant),
    ))  # fmt: skip
CONFORMANCE_SCENES.register(ConformanceScene(
    "colorchecker-d65-calibrated-display",
    "a display-calibrated frame: the D65 chart as device values for a calibrated display (wide "
    "LED-like primaries, D65 white, Herbert's L* curve; data:conformance/displays/), the frame "
    "an application sends once the calibration is in the video card; the check reads the PNG of "
    "device values and compares what the display shows",
    ("display_srgb", "display_primaries_ignored", "display_curve_ignored", "display_linear",
     "Y_scaled"),
    _chart("D65", (
        "[display]", f'calibration = "displays/{CALIBRATED_DISPLAY["stem"]}.cal"',
        # the white patch at 72 % of the display's white: a render 20 % too bright is not clipped
        "exposure = 0.8",
    )),
    {"mitsuba": "Mitsuba 3 writes scene-referred XYZ; the device values of a calibrated display "
                "are a colour-management step after the render (its chart is colorchecker-d65)"},
))  # fmt: skip
# The tests hold each scene to the mistakes it lists (each, made on purpose, fails and is named).
_ENV_MISTAKES = (
    "environment_mirrored", "environment_rotated_90", "environment_rotated_180",
    *_SCALE_MISTAKES,
)  # fmt: skip
for _map in ENVIRONMENT_MAPS:
    CONFORMANCE_SCENES.register(ConformanceScene(
        f"lambert-env-{_map}",
        f"a grey Lambertian sphere under the {_map} map: the map's orientation, its texel rows "
        "and its RGB-to-spectrum upsampling",
        _ENV_MISTAKES,
        _environment(_LAMBERT_HALF, _map),
    ))  # fmt: skip
CONFORMANCE_SCENES.register(ConformanceScene(
    "lambert-env-ring",
    "a grey Lambertian sphere under a dim grey sky with a bright ring 5.6°-11.25° from the zenith "
    "(one texel row of a 32-row map): where each texel row of the map sits, which a renderer "
    "that reads the rows half a texel off moves by several times the tolerance where the ring "
    "meets a normal's horizon",
    ("environment_rows_offset", *_SCALE_MISTAKES),
    _environment(_LAMBERT_HALF, "ring"),
))  # fmt: skip
CONFORMANCE_SCENES.register(ConformanceScene(
    "orange-env-venice",
    "a measured reflectance under an upsampled RGB environment (the product per wavelength)",
    _ENV_MISTAKES,
    _environment(_ORANGE, "venice"),
))  # fmt: skip
CONFORMANCE_SCENES.register(ConformanceScene(
    "ggx-env-venice",
    "a GGX conductor (α = 0.4, F = 1, Smith G1·G1, Walter et al. 2007) under venice: the "
    "reflection's orientation and the lobe's width",
    _ENV_MISTAKES,
    _environment(['type = "isotropic_brdf"', 'brdf = "ggx"', "rho_d = 0", "F_0 = 1",
                  "alpha = 0.4"], "venice"),
))  # fmt: skip
CONFORMANCE_SCENES.register(ConformanceScene(
    "polymer-smooth-env-studio",
    "Herbert's polymer in its opaque smooth limit (a 4.572 mm chip, 2 % TiO2, gloss 1, index "
    "1.54: a smooth dielectric coat over an opaque Kubelka-Munk body) under the studio map, the "
    "case a physical renderer expresses as a smooth plastic; the reference is the layered oracle",
    _ENV_MISTAKES,
    _environment(['type = "polymer"', 'model = "layered"', "thickness = 4.572", "tio2 = 2.0",
                  "gloss = 1.0"], "studio"),
))  # fmt: skip
CONFORMANCE_SCENES.register(ConformanceScene(
    "polymer-rough-env-venice",
    "Herbert's polymer in general (a translucent 0.762 mm chip, 0.2 % TiO2, tinted with the "
    "measured orange as a dye, gloss 0.7: a rough coat over a scattering, absorbing, transmitting "
    "body) under venice; the reference is specref's layered oracle",
    # each mistake listed is a render of the oracle (seconds here): the map's turns are told
    # apart by the seven other environment scenes
    ("environment_mirrored", *_SCALE_MISTAKES),
    _environment(['type = "polymer"', 'model = "layered"', "thickness = 0.762", "tio2 = 0.2",
                  'tint = "pb-orange"', "gloss = 0.7"], "venice",
                 # the oracle's Monte Carlo to 1 % of each sub-sample: a block of 4 × 4 pixels of
                 # 2 × 2 sub-samples averages it to about 0.13 %, far under the 1 % floor
                 ("polymer_oracle_tol = 0.01",)),
    {"mitsuba": "Mitsuba 3 has no rough coat over a translucent, transmitting Kubelka-Munk body"},
))  # fmt: skip
CONFORMANCE_SCENES.register(ConformanceScene(
    "ggx-plastic-env-fagans",
    "GGX with Schlick's Fresnel (F_0 = 0.04) over a Lambertian base (ρ_d = 0.4) under fagans",
    _ENV_MISTAKES,
    _environment(['type = "isotropic_brdf"', 'brdf = "ggx"', "rho_d = 0.4", "F_0 = 0.04",
                  "alpha = 0.3"], "fagans"),
    {"mitsuba": _NO_SCHLICK},
))  # fmt: skip
CONFORMANCE_SCENES.register(ConformanceScene(
    "ward-env-stage",
    "Ward's isotropic BRDF (ρ_d = 0.1, ρ_s = 0.3, α = 0.3) under the stage map",
    _ENV_MISTAKES,
    _environment(['type = "isotropic_brdf"', 'brdf = "ward_isotropic"', "rho_d = 0.1",
                  "rho_s = 0.3", "alpha = 0.3"], "stage"),
    {"mitsuba": _NO_WARD},
))  # fmt: skip


def scene_text(scene: ConformanceScene | str) -> str:
    """The scene file of a conformance scene: a comment header, title, description, the body.

    Examples
    --------
    >>> text = scene_text("lambert-point-d65")
    >>> text.splitlines()[0]
    '# specref conformance scene: lambert-point-d65 (docs/conformance.md)'
    >>> import tomllib; tomllib.loads(text)["lights"][0]["attenuation"]
    [0, 0, 1]
    """
    s = CONFORMANCE_SCENES.lookup(scene) if isinstance(scene, str) else scene
    head = [
        f"# specref conformance scene: {s.name} (docs/conformance.md)",
        "# Written by python -m validation.precompute.conformance; do not edit.",
        f"title = {json.dumps(s.name)}",
        f"description = {json.dumps('Tests ' + s.tests + '.')}",
    ]
    return "\n".join([*head, s.body()]) + "\n"


def scene_path(name: str):
    """The shipped file of a conformance scene (``data:conformance/<name>.toml``).

    Examples
    --------
    >>> scene_path("colorchecker-fl2").name
    'colorchecker-fl2.toml'
    """
    from reference.data import data_path

    CONFORMANCE_SCENES.lookup(name)
    return data_path(f"conformance/{name}.toml")

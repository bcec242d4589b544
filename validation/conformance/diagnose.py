"""The usual mistakes of a renderer, as transformed references that a failing render is tried on.

Each :class:`Diagnosis` makes the image a renderer would have produced had it made one mistake,
from the scene's reference (an image transform) or by rendering a variant of the scene with
specref's oracle path. :func:`validation.conformance.check.check_render` tries every diagnosis a
scene lists (``ConformanceScene.catches``) on a failing render and names the one under which the
render passes (or comes closest):

- ``Y_scaled``: the whole image off by one factor (least-squares fit of Y); the factor is named,
  and recognised when it is π or 1/π (a BRDF without its 1/π, radiance for irradiance) or 100 (an
  illuminant normalized to Y = 100);
- ``illuminant_not_normalized``: the light's spectrum used as tabulated (colour-science's
  illuminants peak near 100) instead of scaled to Y = 1;
- ``srgb_encoded``: the sRGB transfer function applied to values stored as linear;
- ``missing_cosine``: a point light's ``cos θ`` left out;
- ``rgb_rendering``: colours multiplied in RGB instead of spectra: the scene's light replaced by
  D65 gives the linear sRGB "albedo" a renderer would store, which is multiplied by the light's
  own linear sRGB colour (Y = 1);
- ``area_light_as_point``: a sphere light of radiance ``L`` and radius ``r`` lit as a point light
  of intensity ``L r²`` at its centre (right far from it, wrong at the terminator and in a
  highlight, which then has the point's shape, not the light's);
- ``environment_mirrored``, ``environment_rotated_90`` (either way), ``environment_rotated_180``:
  the lat-long map read flipped left-right or turned about the vertical axis;
- ``display_srgb``, ``display_primaries_ignored``, ``display_curve_ignored``, ``display_linear``:
  the colour-management mistakes of a frame for a calibrated display
  (:mod:`validation.conformance.display`).

In a scene for a calibrated display every variant is what the display shows for it (its device
values through the display's model), as the render is.

- ``environment_rows_offset``: the map's rows read half a texel off: at ``v = j/(H − 1)``
  (align-corners interpolation, as Mitsuba 3 reads them) or shifted half a texel towards either
  pole, instead of texel ``j`` spanning ``j/H`` to ``(j + 1)/H``. On the photographed maps it moves
  the spheres' images by 0.5-1.7 times the tolerance, too little to be told apart; the ring scene
  is made for it (errata E102).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from reference.registry import Registry

__all__ = [
    "DIAGNOSES",
    "Diagnosis",
    "DiagnosisContext",
    "diagnosis_variants",
    "illuminant_raw_Y",
]


@dataclass
class DiagnosisContext:
    """What the variants are made from: the scene's name, its reference and the render's Y."""

    name: str
    reference: object
    render_XYZ: np.ndarray

    def scene(self):
        """The shipped scene, loaded."""
        import phong_table  # noqa: F401  (registers the Phong table methods)
        import shrm  # noqa: F401  (registers isotropic_brdf and the environment shaders)
        from reference.scene.loader import load_scene
        from validation.conformance.scenes import scene_path

        return load_scene(scene_path(self.name))

    def rendered(self, scene) -> np.ndarray:
        """XYZ of a variant scene by the oracle path."""
        from validation.conformance.references import render_reference

        return render_reference(self.name, scene).XYZ


@dataclass(frozen=True)
class Diagnosis:
    """One mistake: ``variants(ctx) -> list of (label, XYZ image)`` (empty: not applicable).

    ``rendered``: the variants are renders of the scene alone (not of the user's image), cached
    beside the references (:func:`diagnosis_variants`).
    """

    name: str
    explanation: str
    variants: Callable[[DiagnosisContext], list]
    rendered: bool = False


def diagnosis_variants(diagnosis: Diagnosis, ctx: DiagnosisContext, folder=None) -> list:
    """A diagnosis's variants; rendered ones are read from ``folder/variants/`` when there.

    Rendered variants are written there (``<scene>.<diagnosis>.npz``, atomically) the first time,
    so a second check of a failing render does not render them again.

    Examples
    --------
    >>> import tempfile
    >>> from validation.conformance.references import Reference
    >>> XYZ = np.ones((2, 2, 3))
    >>> ctx = DiagnosisContext("x", Reference("x", XYZ, XYZ * 0, XYZ, np.ones(3), XYZ[..., 0]), XYZ)
    >>> diagnosis_variants(DIAGNOSES.lookup("Y_scaled"), ctx, tempfile.mkdtemp())[0][0]
    'by 1'
    """
    if not diagnosis.rendered or folder is None:
        return diagnosis.variants(ctx)
    from reference.files import atomic_path

    path = Path(folder) / "variants" / f"{ctx.name}.{diagnosis.name}.npz"
    if path.is_file():
        with np.load(path) as data:
            return [(str(label), data[f"v{i}"]) for i, label in enumerate(data["labels"])]
    variants = diagnosis.variants(ctx)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path, ".npz") as tmp:
        np.savez(tmp, labels=np.array([label for label, _ in variants]),
                 **{f"v{i}": image for i, (_, image) in enumerate(variants)})  # fmt: skip
    return variants


DIAGNOSES = Registry("diagnosis", Diagnosis)


def _fit_scale(ctx: DiagnosisContext) -> list:
    # least squares of Y over the fully covered pixels: k = Σ y r / Σ r²
    ref = ctx.reference
    full = ref.coverage >= 1.0
    r, y = ref.XYZ[..., 1][full], ctx.render_XYZ[..., 1][full]
    k = float((y * r).sum() / max((r * r).sum(), 1e-300))
    named = {np.pi: "π", 1 / np.pi: "1/π", 100.0: "100"}
    label = next((f"{v} ({k:.4g})" for c, v in named.items() if abs(k / c - 1) < 0.02), f"{k:.4g}")
    return [(f"by {label}", ref.XYZ * k)]


def illuminant_raw_Y(name: str) -> float:
    """Y of a colour-science illuminant as tabulated, relative to the same spectrum at Y = 1.

    ``Σ S ȳ / Σ ȳ`` at 1 nm over 360-780 nm (CIE 1931 2°).

    Examples
    --------
    >>> round(illuminant_raw_Y("D65"), 1)       # colour-science's D65 is 100 at 560 nm
    98.9
    """
    import colour

    shape = colour.SpectralShape(360, 780, 1)
    S = colour.SDS_ILLUMINANTS[name].copy().align(shape).values
    ybar = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape).values[:, 1]
    return float((S * ybar).sum() / ybar.sum())


def _light_spectrum_names(ctx: DiagnosisContext) -> list[str]:
    import tomllib

    from validation.conformance.scenes import scene_text

    lights = tomllib.loads(scene_text(ctx.name)).get("lights", [])
    return [light["spectrum"]["illuminant"] for light in lights if "spectrum" in light]


def _not_normalized(ctx: DiagnosisContext) -> list:
    names = _light_spectrum_names(ctx)
    if len(set(names)) != 1:
        return []
    k = illuminant_raw_Y(names[0])
    return [(f"{names[0]} at Y = {k:.4g}", ctx.reference.XYZ * k)]


def _srgb_encoded(ctx: DiagnosisContext) -> list:
    from reference.colour.colorimetry import XYZ_to_display_RGB, display_RGB_to_XYZ

    RGB = np.maximum(XYZ_to_display_RGB(ctx.reference.XYZ), 0.0)
    # IEC 61966-2-1 encoding, applied where the values should have stayed linear
    encoded = np.where(RGB <= 0.0031308, 12.92 * RGB, 1.055 * RGB ** (1 / 2.4) - 0.055)
    return [("sRGB transfer function on linear values", display_RGB_to_XYZ(encoded))]


def _missing_cosine(ctx: DiagnosisContext) -> list:
    from reference.scene.lights import PointLight
    from reference.scene.render import scene_gbuffer, shade_scene

    scene = ctx.scene()
    lights = [light for light in scene.lights if isinstance(light, PointLight)]
    if len(lights) != 1 or len(scene.lights) != 1:
        return []
    g = scene_gbuffer(scene)
    to_light = np.asarray(lights[0].position) - g.position
    cos = np.einsum("...i,...i->...", g.normal, to_light) / np.linalg.norm(to_light, axis=-1)
    samples = shade_scene(scene, g, {"phong": {"method": "exact"}})
    flat = np.where(g.mask & (cos > 0), samples[..., 1] / np.where(cos > 0, cos, 1.0), 0.0)
    S = scene.render.supersample
    ratio = _box(flat, S) / np.maximum(_box(samples[..., 1], S), 1e-300)
    return [("no cos θ", ctx.reference.XYZ * ratio[..., None])]


def _box(image, S):
    from reference.geometry.camera import downsample_box

    return downsample_box(image, S)


def _rgb_rendering(ctx: DiagnosisContext) -> list:
    from reference.colour.colorimetry import XYZ_to_display_RGB, display_RGB_to_XYZ
    from reference.colour.spectra import spectrum_from_dataset
    from reference.scene.lights import AmbientLight, PointLight

    scene = ctx.scene()
    if not scene.lights or not all(isinstance(x, (PointLight, AmbientLight)) for x in scene.lights):
        return []
    d65 = spectrum_from_dataset("illuminant", "D65")
    white = dataclasses.replace(
        scene, lights=tuple(dataclasses.replace(x, spectrum=d65) for x in scene.lights)
    )
    albedo = XYZ_to_display_RGB(ctx.rendered(white))
    light = _light_RGB(scene.lights[0].spectrum, scene)
    return [("sRGB albedo × sRGB light", display_RGB_to_XYZ(albedo * light))]


def _light_RGB(spectrum, scene) -> np.ndarray:
    """Linear sRGB of a light with Y = 1 (what an RGB renderer stores as the light's colour)."""
    from reference.colour.colorimetry import XYZ_to_display_RGB, band_weights

    XYZ = np.ones(scene.grid.n_bands) @ band_weights(scene.grid, spectrum)
    return XYZ_to_display_RGB(XYZ / XYZ[1])


def _area_light_as_point(ctx: DiagnosisContext) -> list:
    from reference.scene.lights import PointLight, SphereLight

    scene = ctx.scene()
    if not any(isinstance(x, SphereLight) for x in scene.lights):
        return []
    lights = tuple(
        PointLight(x.position, x.spectrum, x.intensity * x.radius**2, (0.0, 0.0, 1.0))
        if isinstance(x, SphereLight)
        else x
        for x in scene.lights
    )
    variant = ctx.rendered(dataclasses.replace(scene, lights=lights))
    return [("a point of L r² at the centre", variant)]


def _environment_variants(transforms: dict) -> Callable[[DiagnosisContext], list]:
    def variants(ctx: DiagnosisContext) -> list:
        from reference.scene.lights import EnvironmentLight

        scene = ctx.scene()
        if not any(isinstance(x, EnvironmentLight) for x in scene.lights):
            return []
        out = []
        for label, transform in transforms.items():
            lights = tuple(
                transform(x) if isinstance(x, EnvironmentLight) else x for x in scene.lights
            )
            out.append((label, ctx.rendered(dataclasses.replace(scene, lights=lights))))
        return out

    return variants


_DISPLAY_LABELS = {
    "display_srgb": "sRGB's primaries and transfer function",
    "display_primaries_ignored": "the {curve} curve on sRGB's primaries",
    "display_curve_ignored": "sRGB's transfer function on the display's primaries",
    "display_linear": "the display's primaries without the {curve} curve",
}


def _display_mistake(mistake: str) -> Callable[[DiagnosisContext], list]:
    def variants(ctx: DiagnosisContext) -> list:
        from validation.conformance.display import display_mistake_values, scene_display

        display = scene_display(ctx.name)
        if display is None:
            return []
        values = display_mistake_values(mistake, ctx.reference.XYZ, display)
        label = _DISPLAY_LABELS[mistake].format(curve=display.calibration.curve)
        return [(label, display.shown(values))]

    return variants


def _with_image(light, image):
    return dataclasses.replace(light, image=np.ascontiguousarray(image))


def _rows_shifted(light, towards: str):
    """The map with its texel rows moved half a texel towards the zenith or the nadir."""
    image = light.image
    if towards == "zenith":  # texel j then holds the lower half of j and the upper half of j + 1
        below = np.concatenate([image[1:], image[-1:]])
        return _with_image(light, 0.5 * (image + below))
    above = np.concatenate([image[:1], image[:-1]])
    return _with_image(light, 0.5 * (image + above))


DIAGNOSES.register(
    Diagnosis("Y_scaled", "the image is off by one factor (intensity or normalization)", _fit_scale)
)
DIAGNOSES.register(
    Diagnosis(
        "illuminant_not_normalized",
        "the light's spectrum was used as tabulated instead of scaled to Y = 1",
        _not_normalized,
    )
)
DIAGNOSES.register(
    Diagnosis("srgb_encoded", "the values are sRGB-encoded, not linear", _srgb_encoded)
)
DIAGNOSES.register(
    Diagnosis(
        "missing_cosine", "the point light's cos θ is missing", _missing_cosine, rendered=True
    )
)
DIAGNOSES.register(
    Diagnosis(
        "rgb_rendering",
        "colours were multiplied in RGB, not per wavelength",
        _rgb_rendering,
        rendered=True,
    )
)
DIAGNOSES.register(
    Diagnosis(
        "area_light_as_point",
        "the sphere light was lit as a point light at its centre",
        _area_light_as_point,
        rendered=True,
    )
)
DIAGNOSES.register(
    Diagnosis(
        "environment_mirrored",
        "the environment map is mirrored left-right",
        _environment_variants({"u → 1 − u": lambda x: _with_image(x, x.image[:, ::-1])}),
        rendered=True,
    )
)
DIAGNOSES.register(
    Diagnosis(
        "environment_rotated_90",
        "the environment map is turned 90° about the vertical axis",
        _environment_variants(
            {
                "+90°": lambda x: _with_image(x, np.roll(x.image, x.image.shape[1] // 4, axis=1)),
                "−90°": lambda x: _with_image(
                    x, np.roll(x.image, -(x.image.shape[1] // 4), axis=1)
                ),
            }
        ),
        rendered=True,
    )
)
DIAGNOSES.register(
    Diagnosis(
        "environment_rotated_180",
        "the environment map is turned 180° about the vertical axis",
        _environment_variants(
            {"180°": lambda x: _with_image(x, np.roll(x.image, x.image.shape[1] // 2, axis=1))}
        ),
        rendered=True,
    )
)
DIAGNOSES.register(
    Diagnosis(
        "environment_rows_offset",
        "the environment map's rows are read half a texel off",
        _environment_variants(
            {
                "rows at v = j/(H − 1) (align-corners)": lambda x: dataclasses.replace(
                    x, texel_placement="mitsuba"
                ),
                "rows half a texel towards the zenith": lambda x: _rows_shifted(x, "zenith"),
                "rows half a texel towards the nadir": lambda x: _rows_shifted(x, "nadir"),
            }
        ),
        rendered=True,
    )
)
for _key, _explanation in (
    ("display_srgb", "the frame was encoded for an sRGB monitor, not for the calibrated display"),
    (
        "display_primaries_ignored",
        "the calibration's curve was applied to sRGB's primaries, not the display's",
    ),
    (
        "display_curve_ignored",
        "the display's primaries with the sRGB transfer function, not the calibration's curve",
    ),
    ("display_linear", "the display's linear channel values were sent without its curve"),
):
    DIAGNOSES.register(Diagnosis(_key, _explanation, _display_mistake(_key)))

"""What a render states about itself: its outputs, their units and the settings it chose.

One scheme for every render (docs/render-outputs.md). :func:`render_metadata` builds a plain,
JSON-able dict; ``specref render --json`` writes it, and the EXR output carries it as the string
attribute ``specref`` (JSON) with the wavelength grid and units also as flat attributes
(:func:`exr_attributes`), which :func:`read_exr_metadata` reads back.

Keys (schema ``specref-render/1``)::

    schema, specref_version, scene, width, height, supersample
    output          "display" | "xyz" | "spectral"  (RENDER_OUTPUTS)
    channels        the EXR channel names
    units           what one unit of a channel means
    normalisation   "Y = 1 for a perfect white diffuser under the light" (docs/conventions.md)
    colourspace     display colourspace and chromatic adaptation (display output)
    spectral        wavelengths_nm, band_weights {method, observer}, interpolation
    environment     per environment light: file, upsampling, rows (texel placement), intensity
    oracle          True when environment light was integrated by brute force
    methods         what the shaders chose, by group: methods["environment"]["<light>:<kernel>"]
                    = {kernel, order, tol_mean, tol_max, estimate_mean, estimate_max, ...}

Shaders add to ``methods`` through ``ShadingContext.record(group, key, value)``; a new family of
shaders (the SHRM shaders, say) records under its own group name and needs no change here.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from reference.errors import SpecrefError, require
from reference.images.formats import read_exr_parts, spectral_channel_names
from reference.registry import Method, Registry

__all__ = [
    "DEFAULT_ACCURACY",
    "LIT_FRACTION",
    "MAX_FACTOR",
    "METADATA_SCHEMA",
    "NORMALISATION",
    "RENDER_OUTPUTS",
    "check_accuracy",
    "exr_attributes",
    "output_channels",
    "output_image",
    "read_exr_metadata",
    "render_metadata",
]

#: Schema name written into every render's metadata.
METADATA_SCHEMA = "specref-render/1"
#: The photometric normalisation shared by XYZ, spectral and display outputs.
NORMALISATION = "Y = 1 for a perfect white diffuser under the light"

# The accuracy a render promises (``specref render --accuracy TOL``): the mean relative error of Y
# over lit pixels is at most TOL and the maximum at most MAX_FACTOR × TOL, against the brute-force
# oracle of the same method. Every method that chooses its settings from a tolerance (SH orders,
# SHRM orders) reads these and records what it chose with ``ShadingContext.record``.

#: Default tolerance: mean relative error of Y over lit pixels (0.5 %); the max is 4× (2 %).
DEFAULT_ACCURACY = 5e-3
#: The promised maximum relative error is this multiple of the mean tolerance.
MAX_FACTOR = 4.0
#: Pixels count as lit when their Y is at least this fraction of the peak.
LIT_FRACTION = 0.01


def _placement_rows(name: str) -> str:
    # the row convention the light's texel placement reads its map with (reference.geometry.envmap)
    from reference.geometry.envmap import TEXEL_PLACEMENTS

    return TEXEL_PLACEMENTS.lookup(name).rows


def check_accuracy(tol, where: str = "--accuracy") -> float:
    """A mean-relative-error tolerance in (0, 0.25], or a one-line SpecrefError.

    Examples
    --------
    >>> check_accuracy(0.01)
    0.01
    >>> check_accuracy(0)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: --accuracy: must be a relative error in (0, 0.25], got 0
    """
    try:
        value = float(tol)
    except (TypeError, ValueError):
        value = float("nan")
    require(
        bool(np.isfinite(value)) and 0 < value <= 0.25,
        f"{where}: must be a relative error in (0, 0.25], got {tol}",
    )
    return value


def _display(result):
    """Linear display RGB (Eq. (5), Wang et al.) of a render and its channel names.

    Examples
    --------
    >>> from reference.scene.render import render_scene
    >>> from reference.scene.loader import loads_scene
    >>> image, names = _display(render_scene(loads_scene(""), 4, 2))
    >>> image.shape, names
    ((2, 4, 3), ['R', 'G', 'B'])
    """
    return result.RGB_linear, ["R", "G", "B"]


def _xyz(result):
    """CIE XYZ (Eq. (4), Wang et al.; Y = 1 for a white diffuser) of a render and its channels.

    Examples
    --------
    >>> from reference.scene.render import render_scene
    >>> from reference.scene.loader import loads_scene
    >>> _xyz(render_scene(loads_scene(""), 4, 2))[1]
    ['X', 'Y', 'Z']
    """
    return result.XYZ, ["X", "Y", "Z"]


def _spectral(result):
    """Relative spectral radiance per band (the terms of Eq. (4), Wang et al.) and its channels.

    Channel names of the spectral OpenEXR layout (Fichet et al. 2021).

    Examples
    --------
    >>> from reference.scene.render import render_scene
    >>> from reference.scene.loader import loads_scene
    >>> image, names = _spectral(render_scene(loads_scene(""), 4, 2, spectral=True))
    >>> image.shape, names[0]
    ((2, 4, 41), 'S0.380,000000nm')
    """
    require(result.spectral is not None, "spectral output: the render has no spectral image")
    return result.spectral, spectral_channel_names(result.scene.grid.wavelengths_nm)


@dataclass(frozen=True, kw_only=True)
class RenderOutput(Method):
    """An output kind of ``specref render --exr-output``; ``units`` says what its values are."""

    units: str


#: What the EXR holds (``specref render --exr-output``); ``reference(result) -> (image, names)``.
RENDER_OUTPUTS = Registry("render output", RenderOutput)
RENDER_OUTPUTS.register(
    RenderOutput(
        "display",
        _display,
        None,
        "Eq. (5), Wang et al.",
        units="linear display RGB of the scene's colourspace, before exposure",
    )
)
RENDER_OUTPUTS.register(
    RenderOutput(
        "xyz",
        _xyz,
        None,
        "Eq. (4), Wang et al.",
        units=f"CIE XYZ of the scene's observer, {NORMALISATION}",
    )
)
RENDER_OUTPUTS.register(
    RenderOutput(
        "spectral",
        _spectral,
        None,
        "Eq. (4), Wang et al.",
        units="relative spectral radiance per band; times spectral.band_weights "
        f"(equal-energy) it gives XYZ with {NORMALISATION}",
    )
)


def output_image(result, output: str) -> tuple[np.ndarray, list[str]]:
    """The image and EXR channel names of one output kind of a render.

    Examples
    --------
    >>> output_image(None, "rgb")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: unknown render output 'rgb'; allowed: display, spectral, xyz
    """
    return RENDER_OUTPUTS.lookup(output).reference(result)


def _environments(scene) -> list[dict]:
    from reference.colour.upsampling import DEFAULT_UPSAMPLING
    from reference.scene.lights import EnvironmentLight

    upsampling = scene.render.options.get("upsampling", DEFAULT_UPSAMPLING)
    out = []
    for light in scene.lights:
        if isinstance(light, EnvironmentLight):
            out.append(
                {
                    "name": light.name,
                    "spectral": bool(light.is_spectral),
                    "upsampling": None if light.is_spectral else upsampling,
                    "texel_placement": light.texel_placement,
                    "rows": _placement_rows(light.texel_placement),
                    "intensity": float(light.intensity),
                }
            )
    return out


def render_metadata(result, output: str = "display", records=None, oracle: bool = False) -> dict:
    """The metadata of a render (module docstring), as a JSON-able dict.

    Parameters
    ----------
    result : RenderResult
        The render (its scene, size and supersampling).
    output : str
        Key of :data:`RENDER_OUTPUTS`: what the EXR holds.
    records : dict, optional
        ``ShadingContext.records``: what the shaders chose.
    oracle : bool
        Whether environment light was integrated by brute force.

    Examples
    --------
    >>> from reference.scene.render import render_scene
    >>> from reference.scene.loader import loads_scene
    >>> meta = render_metadata(render_scene(loads_scene(""), 4, 2), "xyz")
    >>> meta["schema"], meta["channels"], len(meta["spectral"]["wavelengths_nm"])
    ('specref-render/1', ['X', 'Y', 'Z'], 41)
    """
    from importlib.metadata import PackageNotFoundError, version

    entry = RENDER_OUTPUTS.lookup(output)
    scene = result.scene
    try:
        specref_version = version("specref")
    except PackageNotFoundError:  # a source tree without installation
        specref_version = "unknown"
    wavelengths = scene.grid.wavelengths_nm
    channels = (
        spectral_channel_names(wavelengths) if output == "spectral" else output_channels(output)
    )
    return {
        "schema": METADATA_SCHEMA,
        "specref_version": specref_version,
        "scene": str(scene.file) if scene.file else None,
        "width": scene.render.width,
        "height": scene.render.height,
        "supersample": scene.render.supersample,
        "output": output,
        "channels": channels,
        "units": entry.units,
        "normalisation": NORMALISATION,
        "colourspace": {
            "name": scene.display.colourspace,
            "chromatic_adaptation": scene.display.chromatic_adaptation,
        },
        "spectral": {
            "wavelengths_nm": [float(w) for w in wavelengths],
            "band_weights": {"method": scene.weights_method, "observer": scene.observer},
            "interpolation": "per band (a band is the grid step wide, centred on its wavelength)",
        },
        "environment": _environments(scene),
        "oracle": bool(oracle),
        "methods": json.loads(json.dumps(records or {}, default=_plain)),
    }


def output_channels(output: str) -> list[str]:
    """The channel names of a three-channel output kind.

    Examples
    --------
    >>> output_channels("xyz")
    ['X', 'Y', 'Z']
    """
    return {"display": ["R", "G", "B"], "xyz": ["X", "Y", "Z"]}[output]


def _plain(value):
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    return str(value)


def exr_attributes(metadata: dict) -> dict[str, str]:
    """String attributes of the EXR header for a render's metadata.

    ``specref`` holds the whole dict as JSON; ``wavelengths``, ``units`` and ``normalisation``
    repeat the essentials for tools that read flat attributes (Fichet et al. 2021 name spectral
    channels, not their units, so the units are ours).

    Examples
    --------
    >>> sorted(exr_attributes({"units": "u", "normalisation": "n", "spectral": {
    ...     "wavelengths_nm": [400.0]}}))
    ['normalisation', 'specref', 'units', 'wavelengths']
    """
    return {
        "specref": json.dumps(metadata, sort_keys=True),
        "wavelengths": " ".join(f"{w:g}" for w in metadata["spectral"]["wavelengths_nm"]),
        "units": str(metadata["units"]),
        "normalisation": str(metadata["normalisation"]),
    }


def read_exr_metadata(path) -> dict:
    """The ``specref`` metadata of an EXR written by ``specref render``, or ``{}`` if it has none.

    Raises
    ------
    SpecrefError
        Missing or unreadable file.

    Examples
    --------
    >>> read_exr_metadata("/nonexistent.exr")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent.exr: file not found
    """
    path = Path(path)
    text = read_exr_parts(path, lambda handle: handle.header().get("specref"), header_only=True)
    if text is None:
        return {}
    try:
        return json.loads(text if isinstance(text, str) else bytes(text).decode())
    except (ValueError, UnicodeDecodeError):
        raise SpecrefError(f"{path}: the specref attribute is not JSON") from None

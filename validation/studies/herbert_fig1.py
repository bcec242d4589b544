"""Herbert et al.'s Fig. 1: one object rendered at daylight, fluorescent and tungsten.

The paper shows a product rendered in a captured panoramic environment under three illuminants. Its
inputs are not published; specref rebuilds the figure from what it ships: the venice_sunset
panorama made spectral by the shipped regression (§4, erratum E42: reflectance-like spectra),
relit by multiplying by each illuminant (normalized to Y = 1), lights the tinted polymer sphere of
``data:examples/polymer-sphere.toml`` (Eqs. (1)-(5), Herbert et al.). Each frame is shown fully
adapted to its illuminant's white (CAT02, Herbert et al.'s complete adaptation), so what differs
between the frames is what an observer adapted to each light would still see: the sphere's colour
inconstancy, which a renderer multiplying RGB colours cannot produce.
"""

from __future__ import annotations

import tempfile
import tomllib
from pathlib import Path

import numpy as np

__all__ = [
    "FIG1_LIGHTS",
    "fig1_study",
    "fig1_three_lights",
    "panorama_spectra",
    "relit_environment",
]

#: Daylight, fluorescent and tungsten, as in the paper's caption.
FIG1_LIGHTS = ("D65", "FL2", "A")
#: The object and its camera: the shipped polymer example (read from the package).
FIG1_SCENE = "examples/polymer-sphere.toml"
#: The panorama (shipped) and the box filter that shrinks it for the figure.
FIG1_PANORAMA, FIG1_BOX = "environments/venice_sunset_1k.hdr", 8


def panorama_spectra(name: str = FIG1_PANORAMA, box: int = FIG1_BOX) -> tuple:
    """A shipped RGB panorama, box-filtered, and its spectra by the shipped regression (§4).

    Negative band values are projected onto the nearest non-negative spectra of the same colour
    (erratum E106), as ``specref env spectralize`` does.

    Returns
    -------
    (ndarray of shape (H, W, 3), ndarray of shape (H, W, 41))
        The filtered RGB and its reflectance-like spectra on ``GRID_41``.

    Examples
    --------
    >>> RGB, spectra = panorama_spectra(box=64)
    >>> RGB.shape, spectra.shape, bool((spectra >= 0).all())
    ((8, 16, 3), (8, 16, 41), True)
    """
    from reference.colour.spectral_regression import model_XYZ_weights, project_nonnegative
    from reference.colour.upsampling import default_regression
    from reference.data import data_path
    from reference.geometry.camera import downsample_box
    from reference.images.formats import read_hdr

    RGB = downsample_box(read_hdr(data_path(name)), box)
    model = default_regression()
    spectra = model.predict(RGB)
    negative = (spectra < 0).any(axis=-1)
    spectra[negative] = project_nonnegative(spectra[negative], model_XYZ_weights(model))[0]
    return RGB, spectra


def fig1_study(size: int = 96) -> dict:
    """Fig. 1, Herbert et al., rebuilt: :func:`fig1_three_lights` in the shipped panorama.

    Examples
    --------
    >>> out = fig1_study(12)
    >>> sorted(out["delta_E00"]), out["sRGB"]["FL2"].shape
    (['A', 'D65', 'FL2'], (12, 12, 3))
    """
    return fig1_three_lights(panorama_spectra()[1], size)


def relit_environment(spectra, illuminant: str) -> tuple[np.ndarray, np.ndarray]:
    """Reflectance-like panorama spectra relit under ``illuminant`` normalized to Y = 1 (E42).

    Parameters
    ----------
    spectra : ndarray, shape (H, W, 41)
        Reflectance-like spectra on ``GRID_41`` (:func:`panorama_spectra`).
    illuminant : str
        A colour-science illuminant key.

    Returns
    -------
    (ndarray of shape (H, W, 41), ndarray of shape (3,))
        Radiance spectra on ``GRID_41`` and the XYZ of the light's white (a white reflector).

    Examples
    --------
    >>> env, white = relit_environment(np.ones((1, 2, 41)), "A")
    >>> env.shape, round(float(white[1]), 12)
    ((1, 2, 41), 1.0)
    """
    from reference.colour.colorimetry import band_weights
    from reference.colour.spectra import GRID_41, spectrum_from_dataset

    W_E = band_weights(GRID_41, None)
    # each band's value of the light from its folded weights (erratum E7), not a point sample:
    # FL2's mercury lines sampled at 10 nm would move its white off its chromaticity. The weights
    # can dip below 0 in a band where the CMFs are tiny (FL2 at 390 nm): held at 0 (radiance)
    W_S = band_weights(GRID_41, spectrum_from_dataset("illuminant", illuminant))
    s = np.maximum(W_S.sum(axis=1) / np.maximum(W_E.sum(axis=1), 1e-300), 0.0)
    s = s / (s @ W_E[:, 1])  # a white reflector under the light has Y = 1
    return np.asarray(spectra, dtype=np.float64) * s, s @ W_E


def fig1_three_lights(spectra, size: int = 96, lights=FIG1_LIGHTS, material=None) -> dict:
    """Render the polymer sphere in the relit panorama under each light; adapt; compare with D65.

    Parameters
    ----------
    spectra : ndarray, shape (H, W, 41)
        The panorama's reflectance-like spectra.
    size : int
        Image side, pixels (one sample per pixel).
    lights : sequence of str
        Illuminant keys, the first the reference of the comparison.
    material : dict, optional
        Keys replacing the example's ``materials.chip`` (None removes one: ``{"tint": None}``).

    Returns
    -------
    dict
        ``sRGB`` per light (encoded, adapted to D65 by CAT02 from the light's white, exposed so the
        first light's 99th percentile is 1), ``delta_E00`` per light: the sphere's mean colour
        against the first light's after adaptation (CIELAB relative to D65, Y of white 100),
        ``seconds`` per light.

    Examples
    --------
    >>> out = fig1_three_lights(np.full((8, 16, 41), 0.5), size=12, lights=("D65", "A"))
    >>> sorted(out["sRGB"]), out["sRGB"]["A"].shape, out["delta_E00"]["D65"]
    (['A', 'D65'], (12, 12, 3), 0.0)
    """
    import colour

    import shrm  # noqa: F401  (registers the polymer shaders)
    from reference.colour.colorimetry import XYZ_to_display_RGB, display_RGB_to_XYZ
    from reference.colour.spectra import GRID_41
    from reference.data import data_path
    from reference.display.encodings import encode_srgb
    from reference.images.formats import spectral_channel_names, write_exr
    from reference.scene.loader import scene_from_dict
    from reference.scene.render import render_scene

    doc = tomllib.loads(Path(data_path(FIG1_SCENE)).read_text())
    doc["render"].update(width=size, height=size, supersample=1)
    # the panorama's own 41 bands: a line spectrum (FL2) resampled onto 20 nm would change its white
    doc["spectral"] = {"start_nm": 380, "end_nm": 780, "step_nm": 10}
    chip = doc["materials"]["chip"]
    for key, value in (material or {}).items():
        chip.pop(key) if value is None else chip.update({key: value})
    adapted, seconds = {}, {}
    with tempfile.TemporaryDirectory() as folder:
        for light in lights:
            env, white = relit_environment(spectra, light)
            channels = spectral_channel_names(GRID_41.wavelengths_nm)
            doc["lights"][0]["file"] = str(write_exr(Path(folder) / f"{light}.exr", env, channels))
            result = render_scene(scene_from_dict(doc, f"Fig. 1 under {light}", folder))
            seconds[light] = result.timings["total"]
            # complete adaptation to the light's white (E42), as display RGB
            rgb = XYZ_to_display_RGB(result.XYZ, "sRGB", white, "CAT02")
            adapted[light] = (rgb, result.gbuffer.mask)
    first = lights[0]
    exposure = 1.0 / max(float(np.percentile(adapted[first][0], 99)), 1e-12)
    d65_white = display_RGB_to_XYZ(np.ones(3))

    def mean_Lab(light):
        rgb, mask = adapted[light]
        XYZ = display_RGB_to_XYZ(rgb[mask].mean(axis=0) * exposure)
        return colour.XYZ_to_Lab(XYZ / d65_white[1], colour.XYZ_to_xy(d65_white))

    reference = mean_Lab(first)
    return {
        "sRGB": {k: encode_srgb(np.clip(v[0] * exposure, 0.0, 1.0)) for k, v in adapted.items()},
        "delta_E00": {
            k: float(colour.delta_E(reference, mean_Lab(k), method="CIE 2000")) for k in lights
        },
        "seconds": seconds,
    }

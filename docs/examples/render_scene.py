"""Render a shipped example scene through the Python API, re-shade it under another light, compare.

Loads the shipped colorchecker-d65.toml (``data:examples``), renders it, writes the PNG and linear
EXR, then swaps the lamp for illuminant A and re-shades the cached G-buffer (no re-rasterizing).
Prints the white patch's XYZ under each light beside colour-science's ASTM E308 value for the same
patch and light.
"""

import dataclasses

import colour
import numpy as np

from reference.colour.spectra import spectrum_from_dataset
from reference.geometry.camera import downsample_box
from reference.scene.colorchecker import colorchecker_patch_pixels
from reference.scene.loader import load_scene
from reference.scene.render import render_scene, write_render


def white_patch_XYZ(result) -> np.ndarray:
    """XYZ at the white patch (index 18) divided by the lamp's cos(theta) there (closed form)."""
    scene, g = result.scene, result.gbuffer
    row, column = colorchecker_patch_pixels(
        scene.camera, scene.objects[0], scene.render.width, scene.render.height
    )[18]
    to_lamp = np.asarray(scene.lights[0].position) - g.position
    cos_theta = np.einsum("...i,...i->...", g.normal, to_lamp) / np.linalg.norm(to_lamp, axis=-1)
    # The render box-filters its sub-samples, so divide by their mean cosine.
    return result.XYZ[row, column] / downsample_box(cos_theta, result.supersample)[row, column]


def main(quick: bool = False):
    scene = load_scene("data:examples/colorchecker-d65.toml")
    size = {"width": 66, "height": 44, "supersample": 1} if quick else {}
    d65 = render_scene(scene, **size)
    write_render(d65, png="colorchecker-d65.png", exr="colorchecker-d65.exr")

    # Swap the lamp for illuminant A and re-shade the cached G-buffer.
    lamp = dataclasses.replace(scene.lights[0], spectrum=spectrum_from_dataset("illuminant", "A"))
    scene_a = dataclasses.replace(scene, lights=(lamp,))
    a = render_scene(scene_a, **size, gbuffer=d65.gbuffer)
    write_render(a, png="colorchecker-a.png")

    white = colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"]["white 9.5 (.05 D)"]
    white_10nm = colour.SpectralDistribution(white.values[::2], white.wavelengths[::2])
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    for name, result in (("D65", d65), ("A", a)):
        # colour-science says (as a warning) that it aligns the illuminant to the CMFs: E308 does.
        with colour.utilities.suppress_warnings(colour_runtime_warnings=True):
            expected = colour.sd_to_XYZ(
                white_10nm, cmfs, colour.SDS_ILLUMINANTS[name], method="ASTM E308"
            )
        print(f"white patch under {name}: rendered {white_patch_XYZ(result).round(5)}")
        print(f"  colour-science ASTM E308:   {(expected / 100).round(5)}")
        print(f"  shading took {result.timings['shading']:.3f} s")
    return d65, a


if __name__ == "__main__":
    main()

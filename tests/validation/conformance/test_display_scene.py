"""The display-calibrated conformance scene: its frame, its display files and its bad renders."""

from __future__ import annotations

import json

import numpy as np
import pytest

from reference.data import data_path
from reference.display.cgats import read_cal, read_ti3
from reference.images.formats import write_exr, write_png
from reference.scene.loader import load_scene
from reference.scene.render import render_scene
from validation.conformance.check import check_render
from validation.conformance.display import display_mistake_values, scene_display
from validation.conformance.references import load_reference
from validation.conformance.scenes import CALIBRATED_DISPLAY, scene_path
from validation.precompute.conformance import write_calibrated_display

NAME = "colorchecker-d65-calibrated-display"


@pytest.fixture(scope="module")
def reference(conformance_references):
    return conformance_references, load_reference(NAME, conformance_references)


def _shown_by_the_simulated_display(values):
    """XYZ relative to white that the simulated LED display shows for device values, sent
    through the calibration's tables and read by an ideal meter (the physical path, not the
    matrix-and-curve model the check uses)."""
    from reference.display.calibration import calibrate_display
    from reference.display.calibration_files import measure_through_calibration
    from reference.display.spectral import spectral_display

    c = CALIBRATED_DISPLAY
    display = spectral_display(c["primaries"])
    calibration = calibrate_display(
        display, c["white"], c["curve"], points=c["points"], seed=c["seed"]
    )
    XYZ = measure_through_calibration(display, calibration, np.vstack([values, np.ones(3)]))
    return XYZ[:-1] / XYZ[-1, 1]


def test_the_frame_specref_writes_passes_and_the_display_shows_the_chart(reference, tmp_path):
    # Source: the simulated spectral display driven through the .cal tables and measured, and
    # colour-science's CIEDE2000, both independent of the check's display model.
    import colour

    folder, ref = reference
    frame = render_scene(load_scene(scene_path(NAME))).encoded  # what the PNG holds
    found = check_render(NAME, write_png(tmp_path / f"{NAME}.png", frame), folder)
    assert found["passed"], found
    # at the patches' centres (full coverage, away from the patch borders)
    d = scene_display(NAME)
    rows, columns = np.nonzero(ref.stderr[..., 1] < 1e-9 * np.maximum(ref.XYZ[..., 1], 1e-9))
    keep = ref.XYZ[rows, columns, 1] > 0.01
    rows, columns = rows[keep], columns[keep]
    intended = ref.XYZ[rows, columns] * d.exposure
    white = colour.xy_to_XYZ(colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"])

    def dE(values):
        shown = _shown_by_the_simulated_display(values[rows, columns])
        Lab = colour.XYZ_to_Lab(shown, colour.XYZ_to_xy(white))
        return colour.delta_E(colour.XYZ_to_Lab(intended, colour.XYZ_to_xy(white)), Lab)

    quantized = np.round(frame * 255) / 255
    assert dE(quantized).mean() < 0.5
    # an sRGB frame on this display is visibly wrong: what the scene is there to catch
    assert dE(display_mistake_values("display_srgb", ref.XYZ, d)).mean() > 3.0


def test_a_16_bit_png_passes_to_its_quantization_and_previews_are_passed_over(reference, tmp_path):
    import imagecodecs

    from validation.conformance.check import check_folder

    folder, ref = reference
    values = scene_display(NAME).values(ref.XYZ)
    png = imagecodecs.png_encode(np.round(values * 65535).astype(np.uint16))
    (tmp_path / f"{NAME}.png").write_bytes(png)
    # specref render's EXR beside the frame, and a preview of another scene: not renders
    write_exr(tmp_path / f"{NAME}.exr", ref.XYZ.astype(np.float32), list("XYZ"))
    write_png(tmp_path / "colorchecker-d65.png", np.zeros((40, 60, 3)))
    found = check_folder(tmp_path, folder)
    assert [r["scene"] for r in found["scenes"]] == [NAME]
    assert found["scenes"][0]["passed"]
    assert found["scenes"][0]["block_rel_Y"] < 1e-4, found


def test_the_shipped_display_files_are_what_the_precompute_writes(tmp_path):
    made = write_calibrated_display(tmp_path)
    shipped = data_path(f"conformance/displays/{made.name}")
    np.testing.assert_array_equal(read_cal(made), read_cal(shipped))
    for a, b in zip(read_ti3(made.with_suffix(".ti3")), read_ti3(shipped.with_suffix(".ti3")),
                    strict=True):  # fmt: skip
        np.testing.assert_array_equal(a, b)
    # the metadata's figures to 1e-12: their last bits depend on the CPU that wrote them
    _assert_same_json(
        json.loads(made.with_suffix(".json").read_text()),
        json.loads(shipped.with_suffix(".json").read_text()),
    )


def _assert_same_json(made, shipped, where="json"):
    if isinstance(made, dict):
        assert made.keys() == shipped.keys(), where
        for key in made:
            _assert_same_json(made[key], shipped[key], f"{where}.{key}")
    elif isinstance(made, list):
        assert len(made) == len(shipped), where
        for i, (a, b) in enumerate(zip(made, shipped, strict=True)):
            _assert_same_json(a, b, f"{where}[{i}]")
    elif isinstance(made, float):
        assert made == pytest.approx(shipped, rel=1e-12, abs=1e-15), where
    else:
        assert made == shipped, where

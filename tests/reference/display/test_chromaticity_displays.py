"""Displays given by chromaticities and a white luminance (erratum E109), calibrated and verified.

The xy of R, G, B and white of three published colourspaces (colour-science's tables), none the
built-in display's: the stand-in spectra must have exactly those colours, and the default
instrument must calibrate the display to the targets, read by the reference meter.
"""

from __future__ import annotations

import json

import colour
import numpy as np
import pytest

from reference.display.calibration import TARGET_DUV, calibrate_display, calibration_targets
from reference.display.spectral import (
    XY_TOLERANCE,
    primaries_from_chromaticities,
    spectra_to_absolute_XYZ,
    spectral_display_from_doc,
)
from reference.errors import SpecrefError
from validation.cli import main

#: colour-science's colourspaces: sRGB (red towards the purples: no Gaussian reaches it), DCI-P3
#: and ITU-R BT.2020 (primaries on the spectrum locus: laser-like).
SPACES = ("sRGB", "DCI-P3", "ITU-R BT.2020")


def _doc(space: str, white_xy=None, **extra) -> dict:
    cs = colour.RGB_COLOURSPACES[space]
    white = cs.whitepoint if white_xy is None else white_xy
    xy = {c: list(map(float, p)) for c, p in zip("RGB", cs.primaries, strict=True)}
    return {"primaries": {"xy": xy, "white_xy": list(map(float, white))}, **extra}


def _xy(XYZ):
    XYZ = np.atleast_2d(XYZ)
    return XYZ[:, :2] / XYZ.sum(axis=1, keepdims=True)


@pytest.mark.parametrize("space", SPACES)
def test_the_stand_in_spectra_have_the_stated_colours(space):
    cs = colour.RGB_COLOURSPACES[space]
    w, spectra = primaries_from_chromaticities(cs.primaries, cs.whitepoint)
    assert (spectra >= 0).all()
    XYZ = spectra_to_absolute_XYZ(spectra, w)
    assert np.abs(_xy(XYZ) - cs.primaries).max() <= XY_TOLERANCE
    assert np.abs(_xy(XYZ.sum(axis=0)) - cs.whitepoint).max() <= XY_TOLERANCE
    # and a display of them: the white luminance stated, the white's colour (black excluded)
    display = spectral_display_from_doc(_doc(space, white_cd_m2=250.0, black_cd_m2=0.0), "d.json")
    assert display.white_XYZ[1] == pytest.approx(250.0, rel=1e-9)
    assert np.abs(_xy(display.white_XYZ) - cs.whitepoint).max() <= XY_TOLERANCE


@pytest.mark.parametrize(("space", "white", "curve"), [
    ("sRGB", "D65", "gamma2.2"),
    ("ITU-R BT.2020", "D50", "lstar"),
])  # fmt: skip
def test_the_default_instrument_calibrates_a_display_given_by_chromaticities(space, white, curve):
    display = spectral_display_from_doc(_doc(space), f"{space}.json")
    targets = calibration_targets(display, calibrate_display(display, white, curve))
    assert targets["duv"]["met"], targets["duv"]
    assert targets["duv"]["max"] <= TARGET_DUV[0]


def test_the_command_takes_a_display_file_of_chromaticities(tmp_path, capsys):
    path = tmp_path / "p3-display.json"
    path.write_text(json.dumps(_doc("DCI-P3", [0.3127, 0.3290], white_cd_m2=100.0)))
    out = tmp_path / "p3.cal"  # (its siblings: p3.cube, p3.ti3, p3.json)
    assert main(["display", "calibrate", "--display", str(path), "--white", "D65",
                 "--points", "9", "-o", str(out)]) in (0, 1)  # fmt: skip
    assert out.is_file()
    assert "p3.cal" in capsys.readouterr().out


@pytest.mark.parametrize(("primaries", "message"), [
    ({"xy": {"R": [0.8, 0.3], "G": [0.3, 0.6], "B": [0.15, 0.06]}}, "R: (0.8, 0.3) is not a"),
    ({"xy": {"R": [0.64, 0.33], "G": [0.3, 0.6], "B": [0.1, 0.1]}},
     "B: chromaticity (0.1, 0.1) is outside the spectrum locus"),
    ({"xy": {"R": [0.64, 0.33], "G": [0.3, 0.6]}}, "must be an object with R, G and B"),
    ({"xy": {"R": [0.64, 0.33], "G": [0.3, 0.6], "B": [0.15, 0.06]}, "white_xy": [0.7, 0.2]},
     "white (0.7, 0.2) is outside the primaries' triangle"),
    ({"xy": {"R": [0.64, 0.33], "G": [0.3, 0.6], "B": [1.2, -0.1]}}, "B: (1.2, -0.1) is not a"),
    ({"xy": {"R": [0.64, 0.33], "G": [0.3, 0.6], "B": [0.15, 0.06]}, "gamut": 1}, "unknown key"),
])  # fmt: skip
def test_bad_chromaticities_are_one_line(primaries, message):
    with pytest.raises(SpecrefError, match=None) as error:
        spectral_display_from_doc({"primaries": primaries}, "d.json")
    text = str(error.value)
    assert "\n" not in text
    assert text.startswith("d.json: primaries")
    assert message in text

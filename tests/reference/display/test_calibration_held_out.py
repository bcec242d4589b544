"""The default instrument on displays the loop was not designed on, read by a meter of its own.

Designed on: the built-in display (``spectral_display()``, 5 nm primaries of colour-science's
Apple Studio set). Held out: a wide-gamut LED-like display, a narrow-band laser-like display (both
on a 1 nm grid) and a CRT (Brainard's primaries), at D65 and D50 with two curves. The verifier is
the reference meter (1 nm, no band pass, no noise), checked here against colour-science's own
integration of the same spectrum.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from reference.display.calibration import (
    TARGET_DUV,
    XYZ_to_uv,
    _Reader,
    calibrate_display,
    calibration_targets,
)
from reference.display.instruments import ReferenceMeter, spectroradiometer, spectroradiometer_ideal
from reference.display.spectral import display_drives_to_spectra, spectral_display
from reference.errors import SpecrefError
from validation.cli import main

WAVELENGTHS = np.arange(380.0, 781.0, 1.0)
#: The held-out displays: keys of DISPLAY_PRIMARIES.
HELD_OUT = {"wide LED": "led_wide", "laser": "laser", "CRT": "crt_brainard"}


@pytest.mark.parametrize(("white", "curve"), [("D65", "gamma2.2"), ("D50", "lstar")])
@pytest.mark.parametrize("name", list(HELD_OUT))
def test_the_default_instrument_holds_the_white_on_held_out_displays(name, white, curve):
    display = spectral_display(HELD_OUT[name])
    targets = calibration_targets(display, calibrate_display(display, white, curve))
    if targets["reachable_above"] > TARGET_DUV[1]:  # the display's black forbids it: said so
        assert not targets["duv"]["met"]
        return
    assert targets["duv"]["met"], targets["duv"]
    assert targets["duv"]["max"] <= TARGET_DUV[0]


@pytest.mark.parametrize(("white", "curve"), [("D65", "gamma2.2"), ("D50", "lstar")])
@pytest.mark.parametrize("name", list(HELD_OUT))
def test_the_luminance_holds_where_the_whites_colour_is_out_of_reach(name, white, curve):
    # below the level where a channel reaches zero the white's chromaticity cannot be given; the
    # tone curve still can: the other channels hold the luminance (the laser-like display's
    # bluish black puts two channels at zero near 1 % of white)
    display = spectral_display(HELD_OUT[name])
    targets = calibration_targets(display, calibrate_display(display, white, curve))
    assert targets["Y"]["met"], targets["Y"]


def test_the_design_display_meets_both_targets_with_the_default_instrument():
    display = spectral_display()
    for white in ("D65", "D50", "A", "F2"):
        targets = calibration_targets(display, calibrate_display(display, white, "gamma2.2"))
        assert targets["met"], (white, targets)


def test_a_noise_free_instrument_is_read_twice_and_a_noisy_one_until_quiet():
    display = spectral_display()
    rng = np.random.default_rng(3)
    ideal = _Reader(lambda d: spectroradiometer_ideal().measure(display, d), 2e-4, 256)
    reading = ideal([[0.3, 0.3, 0.3], [1.0, 1.0, 1.0]])
    np.testing.assert_array_equal(reading.count, [2, 2])
    np.testing.assert_array_equal(reading.se_uv, [0.0, 0.0])
    noisy = _Reader(lambda d: spectroradiometer().measure(display, d, rng), 2e-4, 256)
    reading = noisy([[0.25, 0.25, 0.25], [1.0, 1.0, 1.0]])
    # the dark gray needs more readings than the white; each is quiet or at the cap
    assert reading.count[0] > reading.count[1]
    assert ((reading.se_uv <= 1e-4) | (reading.count == 256)).all()
    # the standard error is what repeating the whole measurement shows
    means = np.array([XYZ_to_uv(noisy([0.25, 0.25, 0.25]).XYZ) for _ in range(30)])
    spread = np.linalg.norm(means.std(axis=0, ddof=1))
    assert 0.5 < spread / reading.se_uv[0] < 2.0


def test_the_reference_meter_is_colour_sciences_integration_at_1_nm():
    import colour

    display = spectral_display(HELD_OUT["laser"])
    spectrum = display_drives_to_spectra(display, [0.8, 0.5, 0.3])
    sd = colour.SpectralDistribution(dict(zip(WAVELENGTHS, spectrum, strict=True)))
    cmfs = (
        colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
        .copy()
        .align(colour.SpectralShape(380, 780, 1))
    )
    expected = colour.sd_to_XYZ(sd, cmfs, method="Integration", k=683.0)
    found = ReferenceMeter().measure(display, [0.8, 0.5, 0.3])
    np.testing.assert_allclose(found, expected, rtol=2e-3)
    # the 5 nm band pass of the calibrating instruments errs on narrow lines; the meter does not
    ideal = spectroradiometer_ideal().measure(display, [1.0, 1.0, 1.0])
    exact = ReferenceMeter().measure(display, [1.0, 1.0, 1.0])
    assert np.linalg.norm(XYZ_to_uv(ideal) - XYZ_to_uv(exact)) > 1e-4


def test_a_missed_target_is_written_marked_and_said_in_one_line(tmp_path, capsys):
    # A laser-like display with a bluish black cannot give D50's chromaticity near 5 % of white
    from reference.display.spectral import primaries_laser

    w, spectra = primaries_laser()
    display = tmp_path / "laser.json"  # spelled out, as a user's file of measured primaries
    primaries = {"wavelengths_nm": w.tolist(), **dict(zip("RGB", spectra.tolist(), strict=True))}
    display.write_text(json.dumps({"primaries": primaries, "name": "laser"}))
    out = tmp_path / "d50.cal"
    code = main(
        ["display", "calibrate", "--white", "D50", "--display", str(display), "-o", str(out)]
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 1
    assert len(err) == 1, err
    assert err[0].startswith("display calibrate: Δu'v' ")
    assert "only above 7.2 % of white: its black is of another colour" in err[0]
    summary = json.loads(out.with_suffix(".json").read_text())
    assert summary["meets_targets"] is False
    assert summary["targets"]["duv"]["max"] > TARGET_DUV[0]
    for suffix in (".cal", ".cube", ".ti3", ".json"):
        assert out.with_suffix(suffix).exists()


@pytest.mark.parametrize("bad", [1, 0, -4, 2.5, "8", None, True])
def test_a_bad_reading_count_is_refused_in_one_line(bad):
    # the readings per point: an integer of at least two (two give the noise's first estimate)
    with pytest.raises(SpecrefError, match=r"^max_readings: must be an integer >= 2, got "):
        calibrate_display(spectral_display(), "D65", "gamma2.2", points=3, max_readings=bad)


def test_a_numpy_integer_reading_count_is_taken():
    # np.int64(4) is the same count as 4: the same calibration
    args = (spectral_display(), "D65", "gamma2.2")
    numpy_count = calibrate_display(*args, points=3, max_readings=np.int64(4))
    plain = calibrate_display(*args, points=3, max_readings=4)
    np.testing.assert_array_equal(numpy_count.points["G"], plain.points["G"])

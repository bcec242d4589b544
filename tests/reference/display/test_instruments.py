"""Tests of reference.display.instruments: spectroradiometer, three-filter colorimeter."""

from __future__ import annotations

import numpy as np
import pytest

from reference.display.calibration import XYZ_to_uv
from reference.display.instruments import (
    INSTRUMENTS,
    Colorimeter,
    Spectroradiometer,
    colorimeter,
    spectroradiometer,
    spectroradiometer_ideal,
)
from reference.display.spectral import display_drives_to_XYZ, spectral_display
from reference.errors import SpecrefError


def test_ideal_spectroradiometer_reads_the_truth(rng):
    d = spectral_display()
    drives = rng.uniform(0, 1, (6, 3))
    np.testing.assert_allclose(
        spectroradiometer_ideal().measure(d, drives), display_drives_to_XYZ(d, drives), rtol=1e-12
    )


@pytest.mark.parametrize("make", [spectroradiometer, colorimeter], ids=["spectro", "colorimeter"])
def test_repeated_readings_of_a_patch_equal_readings_of_every_drive(rng, make):
    # A row of repeated readings emits one spectrum per patch; the same drives with one differing
    # reading per row take the general path (each distinct drive once): same numbers, same noise
    # (to the last bits, which depend on the CPU's vector width).
    d = spectral_display()
    patches = rng.uniform(0, 1, (5, 1, 3))
    repeated = np.repeat(patches, 4, axis=1)
    general = repeated.copy()
    general[0, 0] += 1e-3
    a = make().measure(d, repeated, np.random.default_rng(3))
    b = make().measure(d, general, np.random.default_rng(3))
    np.testing.assert_allclose(a[1:], b[1:], rtol=1e-13, atol=0)
    np.testing.assert_allclose(a[0, 1:], b[0, 1:], rtol=1e-13, atol=0)


def test_ten_nm_spectroradiometer_is_close():
    # A 10 nm triangular band pass on the display's broad primaries: within 1 % in Y.
    d = spectral_display()
    meter = Spectroradiometer(step_nm=10.0, dark_noise=0.0, relative_noise=0.0)
    np.testing.assert_allclose(meter.measure(d, np.ones(3)), d.white_XYZ, rtol=1e-2)


@pytest.mark.parametrize("make", [spectroradiometer, colorimeter], ids=["spectro", "colorimeter"])
def test_noise_is_seeded(make):
    d = spectral_display()
    a = make().measure(d, np.full((4, 3), 0.3), np.random.default_rng(7))
    b = make().measure(d, np.full((4, 3), 0.3), np.random.default_rng(7))
    np.testing.assert_array_equal(a, b)
    with pytest.raises(SpecrefError, match="a noisy reading needs a seeded rng"):
        make().measure(d, np.ones(3))


@pytest.mark.parametrize("make", [spectroradiometer, colorimeter], ids=["spectro", "colorimeter"])
def test_chromaticity_noise_grows_as_luminance_falls(make):
    d = spectral_display()
    rng = np.random.default_rng(3)
    spread = []
    for level in (1.0, 0.15):
        readings = make().measure(d, np.full((400, 3), level), rng)
        spread.append(XYZ_to_uv(readings).std(axis=0).max())
    assert spread[1] > 5 * spread[0]


def test_colorimeter_exact_on_its_factory_display_and_errs_elsewhere():
    quiet = Colorimeter(dark_offset=(0.0, 0.0, 0.0), dark_noise=0.0, relative_noise=0.0)
    crt = spectral_display("crt_brainard", shift_nm=(0.0, 0.0, 0.0))
    # Source: colour-science primaries: the factory matrix is fitted on them, so mixtures are exact.
    np.testing.assert_allclose(
        quiet.measure(crt, [0.7, 0.4, 0.9]), display_drives_to_XYZ(crt, [0.7, 0.4, 0.9]), rtol=1e-10
    )
    lcd = spectral_display("apple_studio")
    miss = np.linalg.norm(XYZ_to_uv(quiet.measure(lcd, np.ones(3))) - XYZ_to_uv(lcd.white_XYZ))
    assert miss > 1e-3


def test_colorimeter_shadow_bias():
    # The uncorrected dark offset: the chromaticity error at 2 % of white is far above the one at
    # white (no noise, so only the bias shows).
    biased = Colorimeter(dark_noise=0.0, relative_noise=0.0)
    d = spectral_display()
    errors = []
    for level in (1.0, 0.17):
        reading = biased.measure(d, np.full(3, level))
        errors.append(
            np.linalg.norm(
                XYZ_to_uv(reading) - XYZ_to_uv(display_drives_to_XYZ(d, np.full(3, level)))
            )
        )
    assert errors[1] > 3 * errors[0]


def test_registry_keys():
    assert INSTRUMENTS.names() == ["spectro", "colorimeter", "ideal"]
    with pytest.raises(SpecrefError, match="unknown instrument 'photometer'"):
        INSTRUMENTS.lookup("photometer")

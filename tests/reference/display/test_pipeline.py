"""Tests of reference.display.pipeline: Eq. (1), Ferwerda, per pixel for an observer and a tilt."""

from __future__ import annotations

import numpy as np
import pytest

from reference.display.model import lfactor, virtual_display
from reference.display.pipeline import ScreenGeometry, image_to_display_counts, screen_view_angles
from reference.errors import SpecrefError


def test_view_angles_geometry():
    # Source: plane geometry: an eye 0.5 m in front of a pixel 0.5 m to its side sees it at 45°.
    g = ScreenGeometry(width_m=1.0, height_m=0.01)
    theta, phi = screen_view_angles(g, [0.25, 0.0, 0.5], 1, 2)  # pixel centres at x = ±0.25
    np.testing.assert_allclose(np.degrees(theta[0]), [45.0, 0.0], atol=1e-9)
    assert np.degrees(phi[0, 0]) == pytest.approx(0.0, abs=1e-9)


def test_tilt_turns_the_normal():
    g = ScreenGeometry(tilt=np.radians(30.0))
    # an eye along the tilted normal sees the centre pixel on axis
    eye = 0.6 * g.normal
    theta, _ = screen_view_angles(g, eye, 1, 1)
    assert theta[0, 0] == pytest.approx(0.0, abs=1e-7)


def test_behind_the_screen():
    with pytest.raises(SpecrefError, match=r"observer: \(0, 0.3, -0.2\) m is behind the screen"):
        screen_view_angles(ScreenGeometry(), [0.0, 0.3, -0.2], 4, 4)


def test_compensation_restores_the_intended_colour():
    d = virtual_display()
    image = np.full((3, 5, 3), [95.0, 100.0, 108.0])
    kwargs = {
        "E_XYZ": [950.0, 1000.0, 1080.0],
        "light_position": [0.0, 1.0, 1.0],
        "light_XYZ": [2850.0, 3000.0, 3240.0],
    }
    eye = [0.3, 0.1, 0.4]
    on = image_to_display_counts(image, d, ScreenGeometry(), eye, compensate=True, **kwargs)
    off = image_to_display_counts(image, d, ScreenGeometry(), eye, compensate=False, **kwargs)
    # 11-bit quantisation of Eq. (1): within 0.3 % compensated
    np.testing.assert_allclose(on["seen_XYZ"], image, rtol=3e-3)
    # uncompensated: the falloff of L_factor at the observer's angle (Eq. (1), Ferwerda)
    expected = lfactor(d, on["theta"], on["phi"])
    ratio = (off["seen_XYZ"][..., 1] - 0.0) / image[..., 1]
    assert (ratio < 1.0).any()
    assert np.abs(ratio - expected).max() < 0.02


def test_specular_flare_only_near_the_mirror_angle():
    d = virtual_display()
    image = np.full((1, 1, 3), 50.0)
    light = {"light_position": [0.0, 0.0, 2.0], "light_XYZ": [1000.0, 1000.0, 1000.0]}
    near = image_to_display_counts(
        image, d, ScreenGeometry(), [0.0, 0.0, 0.6], compensate=False, **light
    )
    far = image_to_display_counts(
        image, d, ScreenGeometry(), [0.5, 0.0, 0.3], compensate=False, **light
    )
    # Source: Ferwerda §3.4.3: 1.1 % of the light at the mirror angle, negligible beyond 10°.
    base = image_to_display_counts(image, d, ScreenGeometry(), [0.0, 0.0, 0.6], compensate=False)
    assert near["seen_XYZ"][0, 0, 1] - base["seen_XYZ"][0, 0, 1] == pytest.approx(11.0, rel=1e-6)
    assert far["seen_XYZ"][0, 0, 1] < near["seen_XYZ"][0, 0, 1] - 10.0

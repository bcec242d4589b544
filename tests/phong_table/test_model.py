"""Tests of phong_table.model: Eq. (7) diffuse RGB and Eq. (11) specular functions, Wang et al."""

from __future__ import annotations

import colour
import mpmath
import numpy as np
import pytest

from phong_table import SCENES
from phong_table.model import (
    SpectralPhong,
    average_exponent_Wang,
    specular_RGB,
    specular_RGB_derivative,
)
from reference.colour.spectra import DEFAULT_GRID, GRID_31
from reference.errors import SpecrefError
from reference.materials.types import LambertMaterial, PhongMaterial
from reference.scene.lights import AmbientLight, PointLight


def _colour_RGB(model: SpectralPhong, spectrum: np.ndarray) -> np.ndarray:
    """Linear sRGB of a reflected spectrum under the model's light, by colour-science."""
    sd = colour.SpectralDistribution(spectrum, DEFAULT_GRID.wavelengths_nm)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    light = model.light.spectrum.meta["colour_sd"]
    XYZ = colour.sd_to_XYZ(sd, cmfs, light, method="ASTM E308") / 100.0
    return model.light.intensity * (colour.RGB_COLOURSPACES["sRGB"].matrix_XYZ_to_RGB @ XYZ)


@pytest.mark.parametrize("scene", SCENES.names())
def test_diffuse_and_specular_match_colour_science(scene):
    # Source: colour.sd_to_XYZ (ASTM E308) of k_d(λ) and of k_s(λ) t^n(λ) under the light, then
    # colour-science's sRGB matrix: Eqs. (7) and (11), Wang et al., summed by another code.
    model = SCENES.lookup(scene).build()
    m = model.material
    np.testing.assert_allclose(model.diffuse_RGB, _colour_RGB(model, m.k_d), rtol=1e-9, atol=1e-12)
    for t in (0.3, 0.9, 1.0):
        expected = _colour_RGB(model, m.k_s * t**m.n)
        np.testing.assert_allclose(model.specular(t), expected, rtol=1e-9, atol=1e-12)


def test_distinct_exponents_give_the_same_sum(rng):
    # Property: merging the bands of equal exponent changes the sum's grouping, not its value.
    n = rng.choice([5.0, 20.0, 80.0], size=41)
    model = SpectralPhong(PhongMaterial(rng.random(41), rng.random(41), n), PointLight((0, 0, 5)))
    t = rng.random(9)
    merged = specular_RGB(t, model.specular_weights_distinct, model.n_distinct)
    np.testing.assert_allclose(merged, model.specular(t), rtol=1e-12)
    assert model.n_distinct.tolist() == [5.0, 20.0, 80.0]


@pytest.mark.parametrize("order", [1, 2, 3])
def test_specular_derivative_matches_mpmath(order):
    # Source: mpmath.diff of Σ C t^n at 30 dps; non-integer exponents and one n < order term.
    C = np.array([[0.2, 0.1, 0.0], [0.5, 0.3, 0.1], [0.1, 0.4, 0.9]])
    n = np.array([1.5, 12.25, 300.0])
    for t in (0.2, 0.7, 0.99):
        got = specular_RGB_derivative(np.array([t]), C, n, order)[0]
        with mpmath.workdps(30):
            for channel in range(3):

                def f(x, channel=channel):
                    return sum(C[k, channel] * x ** mpmath.mpf(n[k]) for k in range(3))

                expected = float(mpmath.diff(f, mpmath.mpf(t), order))
                assert got[channel] == pytest.approx(expected, rel=1e-11, abs=1e-13)


def test_specular_shapes_and_bounds():
    C = np.ones((2, 3))
    n = np.array([0.0, 4.0])
    assert specular_RGB(0.5, C, n).shape == (3,)
    assert specular_RGB(np.ones(4), C, n).shape == (4, 3)
    assert specular_RGB(np.ones((2, 5)), C, n).shape == (2, 5, 3)
    # Property: with C >= 0 the specular term increases with t; n = 0 is constant (0^0 = 1).
    t = np.linspace(0.0, 1.0, 50)
    assert (np.diff(specular_RGB(t, C, n), axis=0) >= 0).all()
    np.testing.assert_array_equal(specular_RGB(np.array([0.0, 1.0]), C, n)[:, 0], [1.0, 2.0])
    assert average_exponent_Wang([4.0]) == 4.0


def test_ambient_term():
    # Source: Eq. (1), Wang et al.: I_a k_a, here a flat k_a under the light's own spectrum, so
    # the ambient RGB is intensity × k_a × the white of that light (the diffuse RGB of k_d = 1).
    light = PointLight((0.0, 0.0, 5.0))
    m = PhongMaterial(np.ones(41), np.zeros(41), np.ones(41), k_a=np.full(41, 0.5))
    model = SpectralPhong(m, light, AmbientLight(light.spectrum, 0.2))
    np.testing.assert_allclose(model.ambient_RGB, 0.2 * 0.5 * model.diffuse_RGB, rtol=1e-12)
    assert SpectralPhong(m, light).ambient_RGB.tolist() == [0.0, 0.0, 0.0]


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"material": LambertMaterial(np.ones(41))}, "material must be a PhongMaterial"),
        ({"light": AmbientLight()}, "light must be a PointLight, got AmbientLight"),
        ({"grid": GRID_31}, "has 41 bands but the grid .* has 31; lengths must match"),
    ],
)
def test_spectral_phong_bad_input(kwargs, match):
    args = {
        "material": PhongMaterial(np.ones(41), np.ones(41), np.ones(41)),
        "light": PointLight((0.0, 0.0, 5.0)),
    }
    args.update(kwargs)
    with pytest.raises(SpecrefError, match=match):
        SpectralPhong(**args)

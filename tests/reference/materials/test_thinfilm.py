import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.materials.thinfilm import airy_reflectance, brdf_effect_pigment


def _characteristic_matrix_R(cos_0, lam, d, n_1, n_2):
    """Independent oracle: Born & Wolf's characteristic-matrix method (§1.6.2), s and p averaged.

    Uses the tilted admittances η = n cos θ (s) and n / cos θ (p) and the film's 2×2 matrix
    [[cos δ, −i sin δ / η_1], [−i η_1 sin δ, cos δ]] with δ = 2π n_1 d cos θ_1 / λ.
    """
    sin_0 = np.sqrt(1 - cos_0**2)
    cos_1 = np.sqrt(1 - (sin_0 / n_1) ** 2 + 0j)
    cos_2 = np.sqrt(1 - (sin_0 / n_2) ** 2 + 0j)
    delta = 2 * np.pi * n_1 * d * cos_1 / lam
    R = 0.0
    for eta in (lambda n, c: n * c, lambda n, c: n / c):
        e0, e1, e2 = eta(1.0, cos_0 + 0j), eta(n_1, cos_1), eta(n_2, cos_2)
        B = np.cos(delta) + (-1j * np.sin(delta) / e1) * e2
        C = -1j * e1 * np.sin(delta) + np.cos(delta) * e2
        r = (e0 * B - C) / (e0 * B + C)
        R = R + 0.5 * abs(r) ** 2
    return R


def test_airy_against_characteristic_matrix_oblique_and_absorbing(rng):
    # Source: the characteristic-matrix method above (an independent derivation); the p-wave
    # admittance n/cos θ and the Airy p-coefficients differ in sign convention, not in |r|².
    lam = np.linspace(380.0, 780.0, 9)
    for _ in range(20):
        cos_0 = rng.uniform(0.05, 1.0)
        d, n_1 = rng.uniform(0, 800), rng.uniform(1.2, 2.6)
        n_b, k_b = rng.uniform(1.3, 3.5), rng.choice([0.0, rng.uniform(0, 4)])
        ours = airy_reflectance(cos_0, lam, d, n_1, n_b, k_b)
        oracle = [_characteristic_matrix_R(cos_0, x, d, n_1, n_b + 1j * k_b) for x in lam]
        np.testing.assert_allclose(ours, oracle, rtol=1e-10, atol=1e-13)


def test_airy_closed_forms():
    # Source: Hecht, Optics §9.7: a quarter-wave film of index sqrt(n_0 n_2) reflects nothing.
    n_2 = 1.52
    n_1 = np.sqrt(n_2)
    assert airy_reflectance(1.0, [600.0], 600.0 / (4 * n_1), n_1, n_2)[0] < 1e-28
    # Half-wave film: absent layer, R = ((n_2 − 1)/(n_2 + 1))² (Hecht §9.7).
    R = airy_reflectance(1.0, [600.0], 600.0 / (2 * 2.1), 2.1, n_2)[0]
    assert pytest.approx(((n_2 - 1) / (n_2 + 1)) ** 2, rel=1e-12) == R
    # Bare surface at Brewster's angle: R_p = 0, so R = R_s/2 (Fresnel, Born & Wolf §1.5.3).
    theta_B = np.arctan(n_2)
    cos_t = np.sqrt(1 - (np.sin(theta_B) / n_2) ** 2)
    r_s = (np.cos(theta_B) - n_2 * cos_t) / (np.cos(theta_B) + n_2 * cos_t)
    assert airy_reflectance(np.cos(theta_B), [500.0], 0.0, 1.3, n_2)[0] == pytest.approx(
        r_s**2 / 2, rel=1e-12
    )
    # Grazing incidence reflects everything.
    assert airy_reflectance(0.0, [500.0], 300.0, 2.0, 1.5)[0] == pytest.approx(1.0, abs=1e-12)


def test_airy_is_a_reflectance_and_blue_shifts_with_angle():
    lam = np.linspace(380.0, 780.0, 401)
    cosines = np.cos(np.radians([0.0, 20.0, 40.0, 60.0]))
    R = airy_reflectance(cosines, lam, 250.0, 1.45, 2.5, 0.0)
    assert R.shape == (4, 401)
    assert np.all((R >= 0) & (R <= 1))
    # A first-order interference peak moves to shorter wavelengths as cos θ_1 falls (colour shift).
    peaks = lam[np.argmax(R, axis=1)]
    assert np.all(np.diff(peaks) < 0), peaks


def test_effect_pigment_colour_shifts_with_angle():
    from reference.colour.colorimetry import band_weights, spectra_to_XYZ
    from reference.colour.spectra import GRID_41
    from reference.materials.isotropic import isotropic_directions

    z = np.array([0.0, 0.0, 1.0])
    params = {"thickness_nm": 380.0, "n_film": 2.0, "n_base": 3.2, "k_base": 3.3}
    params |= {"rho_base": 0.05, "alpha": 0.15, "wavelengths_nm": GRID_41.wavelengths_nm}
    chroma = []
    for theta in np.radians([10.0, 45.0, 70.0]):
        wi, wo = isotropic_directions(theta, theta, np.pi)
        XYZ = spectra_to_XYZ(brdf_effect_pigment(wi, wo, z, **params), band_weights(GRID_41, None))
        chroma.append(XYZ[:2] / XYZ.sum())
    # The chromaticity of the mirror highlight moves by more than 0.02 in xy between angles.
    assert min(np.linalg.norm(chroma[0] - chroma[1]), np.linalg.norm(chroma[1] - chroma[2])) > 0.02


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"wavelengths_nm": [0.0]}, "wavelengths_nm: must be > 0"),
        ({"thickness_nm": -1.0}, "thickness_nm: must be >= 0"),
        ({"n_film": 0.0}, "indices must be > 0"),
        ({"k_base": np.nan}, "k_base: must be finite"),
    ],
)
def test_airy_bad_input(kwargs, match):
    args = {"wavelengths_nm": [500.0], "thickness_nm": 100.0, "n_film": 1.5, "n_base": 2.0}
    with pytest.raises(SpecrefError, match=match):
        airy_reflectance(1.0, **(args | kwargs))

import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.materials.fresnel import fresnel_dielectric, fresnel_diffuse, fresnel_lut


def _fresnel_walter(c, n):
    # Source: Walter et al. 2007, "Microfacet models for refraction", Eq. (22): the unpolarized
    # dielectric Fresnel term in the form g = sqrt(n² - 1 + c²), algebraically independent of ours.
    g = np.sqrt(n**2 - 1.0 + c**2)
    return 0.5 * ((g - c) / (g + c)) ** 2 * (1.0 + ((c * (g + c) - 1.0) / (c * (g - c) + 1.0)) ** 2)


@pytest.mark.parametrize("n", [1.1, 1.33, 1.54, 2.0, 3.0])
def test_fresnel_dielectric_matches_walter_form(n):
    c = np.linspace(1e-6, 1.0, 1001)
    np.testing.assert_allclose(fresnel_dielectric(c, n), _fresnel_walter(c, n), rtol=1e-12)


def test_fresnel_dielectric_normal_and_grazing_values():
    # Source: Born & Wolf §1.5.2: F(0°) = ((n - 1)/(n + 1))², F(90°) = 1
    n = np.array([1.33, 1.5, 1.54, 2.4])
    np.testing.assert_allclose(fresnel_dielectric(1.0, n), ((n - 1) / (n + 1)) ** 2, rtol=1e-14)
    np.testing.assert_allclose(fresnel_dielectric(0.0, n), 1.0, rtol=1e-14)


def test_fresnel_plus_transmittance_is_one():
    # Energy: T from the transmission amplitudes (Born & Wolf),
    # T = n cos θ_t / cos θ_i (t_s² + t_p²) / 2
    c = np.linspace(0.01, 1.0, 500)
    for n in (1.2, 1.54, 2.5):
        cos_t = np.sqrt(1.0 - (1.0 - c**2) / n**2)
        t_s = 2.0 * c / (c + n * cos_t)
        t_p = 2.0 * c / (n * c + cos_t)
        T = n * cos_t / c * 0.5 * (t_s**2 + t_p**2)
        np.testing.assert_allclose(fresnel_dielectric(c, n) + T, 1.0, rtol=1e-12)


def test_fresnel_diffuse_judd_values_and_stokes_relation():
    # Source: Judd 1942 (J. Res. NBS 29, 329): for n = 1.5, 0.0918 outside and 0.596 inside
    assert fresnel_diffuse(1.5) == pytest.approx(0.0918, abs=5e-5)
    assert fresnel_diffuse(1.5, "inside") == pytest.approx(0.596, abs=5e-4)
    # Radiance invariance at a lossless interface: 1 - r_i = (1 - r_e) / n²
    n = np.array([1.2, 1.54, 2.0])
    r_e, r_i = fresnel_diffuse(n), fresnel_diffuse(n, "inside")
    np.testing.assert_allclose(1.0 - r_i, (1.0 - r_e) / n**2, rtol=1e-10)


@pytest.mark.parametrize("n", [1.1, 1.54, 2.0, 3.0])
def test_fresnel_lut_within_1e6_of_closed_form(n):
    c = np.linspace(0.0, 1.0, 200_003)
    assert np.abs(fresnel_lut(n).lookup(c) - fresnel_dielectric(c, n)).max() <= 1e-6


def test_fresnel_lut_dispersive_index_shapes():
    n = np.linspace(1.56, 1.52, 41)  # a dispersive index, one column per band
    lut = fresnel_lut(n)
    assert lut.table.shape == (4097, 41)
    c = np.full((2, 3), 0.37)
    got = lut.lookup(c)
    assert got.shape == (2, 3, 41)
    np.testing.assert_allclose(got, fresnel_dielectric(c[..., None], n), atol=1e-6)
    assert fresnel_dielectric(np.ones((2, 3)), 1.5).shape == (2, 3)


@pytest.mark.parametrize("n", [1.0, 0.9, -1.5, float("nan")])
def test_index_at_most_one_is_refused(n):
    with pytest.raises(SpecrefError, match=r"n: (refractive index must be > 1|must be finite)"):
        fresnel_lut(n)
    with pytest.raises(SpecrefError, match="fresnel_dielectric: n"):
        fresnel_dielectric(0.5, n)


def test_bad_side_and_size():
    with pytest.raises(SpecrefError, match="side must be outside or inside"):
        fresnel_diffuse(1.5, "below")
    with pytest.raises(SpecrefError, match="size must be >= 2"):
        fresnel_lut(1.5, size=1)

from operator import attrgetter

import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.geometry.envmap import latlong_lookup_bilinear, latlong_pixel_directions
from reference.materials.fresnel import fresnel_dielectric
from shrm.polymer.characterization import characterize_model
from shrm.polymer.hybrid import MIRROR_FACTORS, polymer_look, polymer_maps, polymer_terms
from shrm.polymer.kubelka_munk import (
    polymer_constituents,
    polymer_K_S,
    saunderson_constants,
    slab_measured,
)

NB = 41


@pytest.fixture(scope="module")
def chips():
    return characterize_model(thickness_mm=(0.762, 1.524, 3.048), tio2_pct=(0.0, 0.1, 0.5, 1.0))


@pytest.fixture(scope="module")
def white_sky():
    return polymer_maps(np.ones((32, 64, NB)), 16.0, size=8)


def _views(count=7):
    # view directions from normal (cos 1) to grazing (cos 0) in the x-y plane, normal +y
    theta = np.linspace(0.0, np.pi / 2, count)
    V = np.stack([np.sin(theta), np.cos(theta), np.zeros_like(theta)], axis=-1)
    N = np.tile([0.0, 1.0, 0.0], (count, 1))
    return N, V


@pytest.mark.parametrize("mirror", sorted(MIRROR_FACTORS.names()))
def test_uniform_sky_closed_form(chips, white_sky, mirror):
    # Under radiance 1 from every direction every E_x is 1 (E = π for the Lambert map, the
    # normalized Phong map is 1, the mirror is 1), so Eq. (1) reduces to
    # D Tint (1 - Mod) + E_effect Mod + gloss F_r + Col_trans (1 - F_r), with F_r the exact Fresnel.
    N, V = _views()
    tint = np.linspace(0.5, 1.0, NB)
    look = polymer_look(chips, 1.2, 0.3, tint=tint, gloss=0.7, mirror=mirror, index=1.54)
    E_effect = np.full((N.shape[0], NB), 0.25)
    terms = polymer_terms(N, V, look, white_sky, Mod_effect=0.4, E_effect=E_effect)
    F = fresnel_dielectric(np.einsum("ij,ij->i", N, V), 1.54)[:, None]
    expected = look.D_polymer * tint * 0.6 + 0.25 * 0.4 + 0.7 * F + look.Col_trans * (1 - F)
    np.testing.assert_allclose(terms["I_result"], expected, atol=1e-6)


def test_F_r_is_the_exact_fresnel_within_1e6(chips, white_sky):
    N, V = _views(101)
    terms = polymer_terms(N, V, polymer_look(chips, 1.0, 0.1), white_sky)
    F = fresnel_dielectric(np.einsum("ij,ij->i", N, V), 1.54)
    assert np.abs(terms["F_r"][:, 0] - F).max() <= 1e-6


def test_D_polymer_is_the_chip_over_black_without_its_surface(chips):
    # At a grid point the look-up returns the chip; D removes the front surface's k_1 (erratum E31)
    K, S = polymer_K_S(polymer_constituents(), 0.5)
    R_black, T = slab_measured(K, S, 1.524)
    look = polymer_look(chips, 1.524, 0.5)
    np.testing.assert_allclose(look.D_polymer, R_black - saunderson_constants(1.54).k_1, atol=1e-12)
    np.testing.assert_allclose(look.Col_trans, T, atol=1e-12)


@pytest.mark.parametrize("method", MIRROR_FACTORS.values(), ids=attrgetter("name"))
def test_mirror_factors_are_in_zero_one_and_one_at_normal_view(method, rng):
    M = method.reference(*method.example_inputs(rng))
    assert np.all((M >= 0) & (M <= 1))
    F = fresnel_dielectric(np.array([1.0, 0.3]), 1.54)
    assert method.reference(np.array([1.0, 0.3]), F, F[0])[0] == pytest.approx(1.0)


def test_fresnel_mirror_factor_sharpens_towards_grazing():
    c = np.linspace(0.0, 1.0, 50)
    F = fresnel_dielectric(c, 1.54)
    M = MIRROR_FACTORS.lookup("fresnel").reference(c, F, F[-1])
    assert M[0] == pytest.approx(0.0, abs=1e-12)
    assert np.all(np.diff(M) >= 0)  # more mirror the more grazing the view


def test_mirror_term_is_the_environment_at_the_reflected_ray(chips, rng):
    # At grazing the fresnel M_s is 0: I_s = gloss E_mirror, the map itself at r = 2(N.V)N - V
    env = rng.uniform(0.2, 1.0, (16, 32, NB))
    maps = polymer_maps(env, 8.0, size=8)
    N = np.array([[0.0, 1.0, 0.0]])
    V = np.array([[1.0, 0.0, 0.0]])
    terms = polymer_terms(N, V, polymer_look(chips, 1.0, 0.1, gloss=0.5), maps)
    np.testing.assert_allclose(terms["I_s"], 0.5 * latlong_lookup_bilinear(env, -V), rtol=1e-12)


def test_transmission_takes_light_from_behind(chips):
    # Light only from the lower hemisphere; normal up, view from above. Diffuse transmission sees
    # E(-N)/π = 1, reflection sees (almost) nothing; the unscattered part sees L(-V) = 1.
    d = latlong_pixel_directions(32, 64)
    env = np.repeat((d[..., 1] < 0).astype(float)[..., None], NB, axis=-1)
    maps = polymer_maps(env, 8.0, size=8, tol=1e-3)
    N = V = np.array([[0.0, 1.0, 0.0]])
    for u in (0.0, 1.0):
        look = polymer_look(chips, 0.762, 0.0, unscattered=u)
        terms = polymer_terms(N, V, look, maps)
        np.testing.assert_allclose(terms["I_trans"][0], look.Col_trans, atol=2e-2)
        assert np.abs(terms["I_d"]).max() < 2e-2


def test_shapes_and_spectral_terms(chips, white_sky):
    N, V = _views(5)
    terms = polymer_terms(N, V, polymer_look(chips, 2.0, 0.7), white_sky, Mod_effect=np.zeros(5))
    for key in ("I_d", "I_effect", "I_s", "I_trans", "I_result"):
        assert terms[key].shape == (5, NB)
    dispersive = polymer_look(chips, 2.0, 0.7, index=np.linspace(1.56, 1.52, NB))
    assert polymer_terms(N, V, dispersive, white_sky)["F_r"].shape == (5, NB)


def test_bad_input(chips, white_sky):
    N, V = _views(3)
    with pytest.raises(SpecrefError, match=r"gloss: must be in \[0, 1\]"):
        polymer_look(chips, 1.0, 0.1, gloss=1.5)
    with pytest.raises(SpecrefError, match=r"tint: must be in \[0, 1\]"):
        polymer_look(chips, 1.0, 0.1, tint=-0.1)
    with pytest.raises(
        SpecrefError, match="unknown mirror factor 'sharp'; allowed: cosine, fresnel, none"
    ):
        polymer_look(chips, 1.0, 0.1, mirror="sharp")
    with pytest.raises(SpecrefError, match="thickness_mm: must be in"):
        polymer_look(chips, 5.0, 0.1)
    with pytest.raises(SpecrefError, match="refractive index must be > 1"):
        polymer_look(chips, 1.0, 0.1, index=1.0)
    look = polymer_look(chips, 1.0, 0.1)
    with pytest.raises(SpecrefError, match=r"Mod_effect: must be in \[0, 1\]"):
        polymer_terms(N, V, look, white_sky, Mod_effect=1.5)
    with pytest.raises(SpecrefError, match=r"normal and view must be \(N, 3\)"):
        polymer_terms(N, V[:2], look, white_sky)

"""Mod_effect: the effect pigment through its SHRM, mixed in by Eqs. (2)-(3), Herbert et al."""

import numpy as np
import pytest

from reference.colour.spectra import DEFAULT_GRID
from shrm.brdf_sh import shrm_brdf_parts
from shrm.orbit import brdf_params_on_grid
from shrm.polymer.characterization import characterize_model
from shrm.polymer.hybrid import (
    effect_radiance,
    effect_shrm,
    polymer_look,
    polymer_maps,
    polymer_terms,
)
from shrm.shrm_oracles import env_quadrature, reflected_bruteforce

#: Building the pigment's SHRM (double SH of the BRDF, frequency-space creation) takes seconds.
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def setup():
    env = np.ones((16, 32, DEFAULT_GRID.n_bands))  # a uniform white sky
    return env, effect_shrm(env, F=4, P=8, size=8)


def test_effect_radiance_is_the_pigments_reflected_radiance(setup):
    # Source: brute force, the reflection equation summed over a 64 x 128 uniform sky
    # (shrm.shrm_oracles.reflected_bruteforce). Under a uniform sky this is the thin-film
    # pigment's directional albedo; the SHRM (F = 4, P = 8) truncates its view dependence:
    # measured within 2.3 % (1.1 % at P = 12), so 5 % bounds the truncation, not noise.
    _, effect = setup
    cos = np.array([1.0, 0.8, 0.5, 0.3])
    N = np.tile([0.0, 0.0, 1.0], (4, 1))
    V = np.stack([np.sqrt(1 - cos**2), 0 * cos, cos], axis=-1)
    got = np.array([effect_radiance(effect, N[i : i + 1], V[i : i + 1])[0] for i in range(4)])
    params = brdf_params_on_grid("effect_pigment", DEFAULT_GRID)
    brdf, expand, _, _ = shrm_brdf_parts("effect_pigment", params, split=False)
    R = 2 * cos[:, None] * N - V
    truth = reflected_bruteforce(
        brdf, expand, "reflection", R, V, env_quadrature(np.ones((64, 128, 41)))
    )
    assert np.abs(got / truth - 1).max() < 0.05
    # the pigment is gonio-apparent: its colour changes with the view (not a grey constant)
    assert np.ptp(got[:, 5] / got[:, 30]) > 0.05


def test_mod_effect_mixes_the_pigment_into_the_polymer(setup):
    # Eqs. (2)-(3), Herbert et al.: I_d scales by 1 - Mod_effect, I_effect = E_effect Mod_effect,
    # and the rest of Eq. (1) does not change.
    env, effect = setup
    look = polymer_look(characterize_model(), 1.524, 0.2, gloss=0.8)
    maps = polymer_maps(env, 16.0, size=4)
    N = np.array([[0.0, 0.0, 1.0], [0.6, 0.0, 0.8]])
    V = np.tile([0.0, 0.0, 1.0], (2, 1))
    E_effect = effect_radiance(effect, N, V)
    base = polymer_terms(N, V, look, maps)
    for mod in (0.0, 0.3, 1.0):
        t = polymer_terms(N, V, look, maps, Mod_effect=mod, E_effect=E_effect)
        np.testing.assert_allclose(t["I_effect"], mod * E_effect, rtol=1e-12)
        np.testing.assert_allclose(t["I_d"], (1 - mod) * base["I_d"], rtol=1e-12)
        rest = t["I_result"] - t["I_d"] - t["I_effect"]
        np.testing.assert_allclose(rest, base["I_result"] - base["I_d"], rtol=1e-12, atol=1e-15)
    modulation_map = np.array([0.0, 1.0])  # an image: per-pixel modulation
    t = polymer_terms(N, V, look, maps, Mod_effect=modulation_map, E_effect=E_effect)
    np.testing.assert_allclose(t["I_effect"][1], E_effect[1], rtol=1e-12)
    assert np.all(t["I_effect"][0] == 0)


def test_effect_environment_must_match_the_grid():
    from reference.errors import SpecrefError

    with pytest.raises(SpecrefError, match="bands, the grid 41"):
        effect_shrm(np.ones((8, 16, 3)))

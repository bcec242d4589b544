"""The polymer's render loop: each parameter runs exactly its stages (§5.2, §8, Herbert et al.)."""

import numpy as np
import pytest

from reference.colour.spectra import SpectralGrid
from reference.errors import SpecrefError
from reference.geometry.camera import Camera
from reference.geometry.shapes import Sphere
from shrm.orbit import brdf_params_on_grid
from shrm.polymer.hybrid import PolymerMaps, polymer_look, polymer_terms
from shrm.polymer.material import polymer_characterization
from shrm.session import POLYMER_PARAMETERS, POLYMER_STAGES, RenderSession, stages_depending_on

GRID = SpectralGrid(400.0, 700.0, 20.0)

# Source: erratum E61's classification (§5.2, §8, Herbert et al.): thickness, TiO2, tint,
# transparency and Mod_effect change only the shading; gloss (the exponent) only the specular
# prefilter; the index only the Fresnel table. The per-pixel look-ups of the maps and the table
# (polymer_pixels) follow a new map or table; the effect pigment's BRDF re-creates its SHRM.
EXPECTED = {
    "thickness": ["shade"],
    "tio2": ["shade"],
    "tint": ["shade"],
    "transparency": ["shade"],
    "Mod_effect": ["shade"],
    "gloss": ["shade"],
    "gloss_exponent": ["specular_map", "polymer_pixels", "shade"],
    "index": ["fresnel_lut", "polymer_pixels", "shade"],
    "effect": ["brdf_coeffs", "shrm_create", "extract", "polymer_pixels", "shade"],
}
NEW_VALUES = {
    "thickness": 0.9,
    "tio2": 1.0,
    "tint": "pb-orange",
    "transparency": 0.5,
    "Mod_effect": 0.4,
    "gloss": 0.5,
    "gloss_exponent": 20.0,
    "index": 1.6,
    "effect": {"name": "lafortune", "params": brdf_params_on_grid("lafortune", GRID)},
}


def polymer_state(rng, size=12):
    return {
        "illuminant": np.ones(GRID.n_bands),
        "environment": rng.uniform(0.1, 2.0, (16, 32, GRID.n_bands)),
        "viewpoint": Camera(eye=(0.0, 1.0, 5.0), projection="orthographic", extent=2.4),
        "gloss": 64.0,
        "brdf": {"name": "ggx", "params": brdf_params_on_grid("ggx", GRID)},
        "index": 1.54,
        "dynamic": {"thickness": 1.524, "tio2": 0.5, "Mod_effect": 0.2},
        "config": {
            "size": 8,
            "width": size,
            "height": size,
            "objects": [Sphere((0.0, 0.0, 0.0), 1.0)],
            "grid": [GRID.start_nm, GRID.end_nm, GRID.step_nm],
            "light_order": 8,
            "F_max": 8,
            "P_max": 4,
        },
    }


def changed(state, parameter):
    key = POLYMER_PARAMETERS[parameter]
    value = NEW_VALUES[parameter]
    if key == "dynamic":
        return {"dynamic": {**state["dynamic"], parameter: value}}
    return {key: value}


def test_every_polymer_parameter_is_classified():
    assert set(POLYMER_PARAMETERS) == set(EXPECTED)
    for parameter, key in POLYMER_PARAMETERS.items():
        assert stages_depending_on(POLYMER_STAGES, key) == EXPECTED[parameter], parameter


def test_each_change_runs_exactly_its_stages(rng):
    session = RenderSession(polymer_state(rng), POLYMER_STAGES)
    first = session.render()["shade"]["pixels"]
    assert all(count == 1 for count in session.executions.values())
    for parameter in EXPECTED:
        before = dict(session.executions)
        session.update(**changed(session.state, parameter))
        image = session.render()["shade"]["pixels"]
        ran = [s for s in session.executions if session.executions[s] > before[s]]
        assert ran == EXPECTED[parameter], parameter
        assert sorted(session.frame_times[-1]) == sorted(EXPECTED[parameter]), parameter
        assert not np.array_equal(image, first), f"{parameter} changed nothing"
        first = image


def test_session_frame_is_the_readable_model(rng):
    # Source: shrm.polymer.hybrid.polymer_terms (the readable Eqs. (1)-(5)) on the session's own
    # maps, G-buffer and effect radiance; the session factors it into per-pixel parts and per-frame
    # spectra, which must give the same sum.
    state = polymer_state(rng)
    state["dynamic"] = {
        "thickness": 0.9,
        "tio2": 0.3,
        "tint": 0.7,
        "transparency": 0.3,
        "Mod_effect": 0.25,
        "gloss": 0.8,
    }
    session = RenderSession(state, POLYMER_STAGES)
    out = session.render()
    g = out["gbuffer"]["gbuffer"]
    sel = g.mask
    n = g.normal[sel]
    v = np.broadcast_to(state["viewpoint"].basis()[2], n.shape)
    maps = PolymerMaps(
        out["diffuse_map"]["cube"],
        out["specular_map"]["cube"],
        out["color_manage"]["radiance"],
        64.0,
    )
    look = polymer_look(
        polymer_characterization(None, GRID), 0.9, 0.3, 0.7, 0.8, unscattered=0.3, index=1.54
    )
    E_effect = out["polymer_pixels"]["parts"]["E_effect"]
    expected = polymer_terms(n, v, look, maps, 0.25, E_effect)["I_result"]
    np.testing.assert_allclose(out["shade"]["pixels"], expected, rtol=1e-12, atol=1e-14)


def test_bad_dynamic_values_are_refused(rng):
    state = {**polymer_state(rng), "brdf": None}
    for bad, message in (
        ({"thickness": -1.0}, r"thickness_mm: must be in"),
        ({"Mod_effect": 1.5}, r"Mod_effect: must be in \[0, 1\]"),
        ({"tint": "lemon"}, r"unknown tint 'lemon'; closest: pb-lemon"),
    ):
        session = RenderSession({**state, "dynamic": bad}, POLYMER_STAGES)
        with pytest.raises(SpecrefError, match=message):
            session.render()
    with pytest.raises(SpecrefError, match=r"must be > 1"):
        RenderSession({**state, "index": 1.0}, POLYMER_STAGES).render()

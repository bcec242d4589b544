import numpy as np
import pytest

from reference.errors import SpecrefError
from shrm.cache import Cache
from shrm.orbit import orbit_camera
from shrm.session import (
    HERBERT_STAGES,
    RenderSession,
    Stage,
    stages_depending_on,
)

ALL = [s.name for s in HERBERT_STAGES]


def _ran(session, before):
    return sorted(k for k, v in session.executions.items() if v != before[k])


def _step(session, **changes):
    before = dict(session.executions)
    session.update(**changes)
    session.render()
    return _ran(session, before)


def test_each_kind_of_change_runs_exactly_its_dependent_stages(state, tmp_path):
    session = RenderSession(state, cache=Cache(tmp_path))
    before = dict(session.executions)
    session.render()
    assert _ran(session, before) == sorted(ALL)
    assert _step(session) == []  # nothing changed: nothing runs
    assert _step(session, viewpoint=orbit_camera(1, 8)) == ["extract", "gbuffer", "shade"]
    assert _step(session, gloss=16.0) == ["shade", "specular_map"]
    assert _step(session, dynamic={"k_d": 0.5, "k_s": 0.2, "k_e": 1.0}) == ["shade"]
    brdf = {"name": "ggx", "params": {"rho_d": 0.2, "F_0": 0.04, "alpha": 0.4}}
    assert _step(session, brdf=brdf) == ["brdf_coeffs", "extract", "shade", "shrm_create"]
    env_stages = ["color_manage", "sh_project", "diffuse_map", "specular_map", "shrm_create"]
    env_stages = sorted([*env_stages, "extract", "shade"])
    assert _step(session, illuminant=state["illuminant"] * 0.5) == env_stages
    assert _step(session, environment=state["environment"][::-1].copy()) == env_stages
    # The expected sets are the stage graph's own dependency closure, as data
    assert sorted(stages_depending_on(HERBERT_STAGES, "illuminant")) == env_stages
    assert sorted(stages_depending_on(HERBERT_STAGES, "viewpoint")) == [
        "extract",
        "gbuffer",
        "shade",
    ]


def test_a_change_back_is_served_from_the_cache(state, tmp_path):
    session = RenderSession(state, cache=Cache(tmp_path), memory=2)
    session.render()
    first = session.render()["shade"]["radiance"].copy()
    session.update(illuminant=state["illuminant"] * 0.5)
    session.render()
    hits_before = dict(session.hits)
    # Back to the first illuminant: every stage is served from memory, none runs.
    assert _step(session, illuminant=state["illuminant"]) == []
    assert session.hits["shrm_create"] == hits_before["shrm_create"] + 1
    np.testing.assert_array_equal(session.render()["shade"]["radiance"], first)
    # A new session on the same scene loads the expensive stages from the persistent cache.
    fresh = RenderSession(state, cache=Cache(tmp_path))
    fresh.render()
    persistent = [s.name for s in HERBERT_STAGES if s.persistent]
    assert all(fresh.executions[name] == 0 for name in persistent)
    assert all(fresh.hits[name] == 1 for name in persistent)
    np.testing.assert_allclose(fresh.render()["shade"]["radiance"], first, rtol=0, atol=0)


def test_memory_eviction_falls_back_to_the_persistent_cache(state, tmp_path):
    session = RenderSession(state, cache=Cache(tmp_path), memory=1)
    session.render()
    session.update(gloss=8.0)
    session.render()
    assert _step(session, gloss=state["gloss"]) == ["shade"]  # specular map from disk


def test_stage_graph_is_checked():
    run = lambda state, inputs: {}  # noqa: E731
    with pytest.raises(SpecrefError, match="uses 'b', which does not come before it"):
        RenderSession({}, [Stage("a", (), ("b",), run), Stage("b", (), (), run)])
    with pytest.raises(SpecrefError, match="unknown state key of stage 'a' 'colour'"):
        RenderSession({}, [Stage("a", ("colour",), (), run)])
    with pytest.raises(SpecrefError, match="unknown scene state key 'zoom'"):
        RenderSession({}, [Stage("a", (), (), run)]).update(zoom=2)
    with pytest.raises(SpecrefError, match=r"stage 'a' needs state \['gloss'\]"):
        RenderSession({}, [Stage("a", ("gloss",), (), run)]).render()

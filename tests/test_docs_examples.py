"""Every example runs: each shipped scene (data:examples/*.toml) renders, each script runs."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

import phong_table  # noqa: F401  (registers its shaders, as `specref render` does)
import shrm  # noqa: F401  (registers the environment-light shaders)
from reference.data import data_path
from reference.scene.loader import load_scene
from reference.scene.render import render_scene

EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"
SCENES = sorted(data_path("examples").glob("*.toml"))
SCRIPTS = sorted(EXAMPLES.glob("*.py"))


def test_the_examples_are_there():
    names = {p.name for p in SCENES + SCRIPTS}
    assert {"phong-sphere.toml", "colorchecker-d65.toml", "colorchecker-a.toml"} <= names
    assert "render_scene.py" in names


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.name)
def test_example_scene_renders(path):
    scene = load_scene(path)
    result = render_scene(scene, width=24, supersample=1)
    assert result.XYZ.shape[1] == 24
    assert np.isfinite(result.XYZ).all()
    assert result.gbuffer.mask.any(), f"{path.name}: nothing visible"
    assert result.encoded.min() >= 0
    assert result.encoded.max() <= 1
    assert result.encoded[result.gbuffer.mask].max() > 0, f"{path.name}: the objects are black"


@pytest.mark.parametrize("path", SCRIPTS, ids=lambda p: p.name)
def test_example_script_runs(path, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    spec = importlib.util.spec_from_file_location(f"docs_example_{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.main(quick=True)

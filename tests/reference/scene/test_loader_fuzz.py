"""Hypothesis fuzzes the scene loader: it returns a Scene or raises SpecrefError, nothing else.

Three sources of input, under a derandomized profile (the same examples on every run):
random TOML-like structures built from the scene vocabulary, valid scenes with random mutations
(values replaced, keys deleted or added), and random text.
"""

from __future__ import annotations

import copy
import datetime as dt
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from reference.data import data_path
from reference.errors import SpecrefError
from reference.images.formats import write_exr
from reference.scene.loader import Scene, loads_scene, scene_from_dict

EXAMPLES = data_path("examples")

FUZZ = settings(
    derandomize=True,
    database=None,
    deadline=None,
    max_examples=120,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)

# Words the loader knows, so random structures reach past the first key check.
KEYS = [
    "title", "description", "spectral", "camera", "render", "display", "materials", "objects",
    "lights", "grid", "start_nm", "end_nm", "step_nm", "observer", "weights", "eye", "target",
    "up", "projection", "fov_deg", "extent", "width", "height", "supersample", "background",
    "options", "colourspace", "encoding", "exposure", "chromatic_adaptation", "white", "type",
    "k_d", "k_s", "n", "k_a", "set", "gap", "gap_width", "material", "center", "radius", "point",
    "normal", "u_axis", "size", "position", "spectrum", "intensity", "attenuation", "file",
    "constant", "illuminant", "light_source", "colorchecker", "csv", "column", "row", "scale",
    "wavelengths", "values", "extrapolation", "interpolation", "grey", "scale", "translate",
    "cull_backfaces",
]  # fmt: skip
WORDS = [
    "lambert", "phong", "colorchecker", "sphere", "plane", "rectangle", "point", "ambient",
    "environment", "D65", "A", "FL2", "dark skin", "BabelColor Average", "41", "31", "srgb",
    "sRGB", "Bradford", "none", "orthographic", "perspective", "grey", "constant", "sprague",
    "r.csv", "rgb.exr", "missing.hdr", "astm_e308", "point", "mesh", "quad.obj",
]  # fmt: skip

scalars = st.one_of(
    st.sampled_from([0, -1, -0.0, 1e-320, 1e308, 2**63 - 1, float("nan"), float("inf")]),
    st.booleans(),
    st.integers(-(2**63), 2**63 - 1),
    st.integers(-5, 5000),
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(-1e3, 1e3),
    st.text(max_size=8),
    st.sampled_from(WORDS),
    st.datetimes(min_value=dt.datetime(1970, 1, 1), max_value=dt.datetime(2100, 1, 1)),
    st.dates(),
    st.times(),
)
keys = st.one_of(st.sampled_from(KEYS), st.text(max_size=6))
values = st.recursive(
    scalars,
    lambda children: st.one_of(
        st.lists(children, max_size=5), st.dictionaries(keys, children, max_size=5)
    ),
    max_leaves=25,
)
documents = st.dictionaries(keys, values, max_size=8)


@pytest.fixture(scope="module")
def base_dir(tmp_path_factory) -> Path:
    """Files that fuzzed scenes may name: a CSV spectrum, an RGB environment map, an OBJ mesh."""
    folder = tmp_path_factory.mktemp("fuzz")
    (folder / "r.csv").write_text("nm,R\n380,0.2\n780,0.6\n")
    write_exr(folder / "rgb.exr", np.full((4, 8, 3), 0.5))
    (folder / "quad.obj").write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
    return folder


RICH = """
title = "rich"
[spectral]
grid = "41"
[camera]
eye = [0, 1, 5]
[render]
width = 16
height = 8
background = "environment"
[render.options]
environment = "bruteforce"
[display]
chromatic_adaptation = "Bradford"
[materials.a]
type = "phong"
k_d = { csv = "r.csv" }
k_s = { wavelengths = [380, 780], values = [0.1, 0.9] }
n = { constant = 20 }
k_a = { colorchecker = "dark skin" }
[materials.b]
type = "colorchecker"
gap = { illuminant = "D65", extrapolation = "constant" }
[[objects]]
type = "sphere"
material = "a"
[[objects]]
type = "rectangle"
size = [1, 1]
material = "b"
[[objects]]
type = "mesh"
file = "quad.obj"
scale = 2
translate = [0, 0, -1]
material = "a"
[[lights]]
type = "point"
position = [0, 2, 2]
spectrum = { light_source = "Natural", extrapolation = "zero" }
[[lights]]
type = "environment"
file = "rgb.exr"
"""

VALID = [tomllib.loads(RICH)] + [tomllib.loads(p.read_text()) for p in EXAMPLES.glob("*.toml")]


def load_or_refuse(document, base_dir):
    """The property: a Scene, or a one-line SpecrefError that names the file."""
    try:
        scene = scene_from_dict(document, "fuzz.toml", base_dir)
    except SpecrefError as error:
        message = str(error)
        assert "\n" not in message
        assert message.startswith("fuzz.toml: "), message
        return None
    assert isinstance(scene, Scene)
    return scene


def test_valid_bases_load(base_dir):
    # The rich base names files in base_dir; the examples name theirs relative to their folder.
    assert isinstance(load_or_refuse(copy.deepcopy(VALID[0]), base_dir), Scene)
    for document in VALID[1:]:
        assert isinstance(load_or_refuse(copy.deepcopy(document), EXAMPLES), Scene)


@FUZZ
@given(document=documents)
def test_random_structures(document, base_dir):
    load_or_refuse(document, base_dir)


def _mutate(data, document: dict) -> dict:
    document = copy.deepcopy(document)
    for _ in range(data.draw(st.integers(1, 3), label="mutations")):
        # Walk down from the root to a random container.
        node = document
        while True:
            children = (
                [k for k, v in node.items() if isinstance(v, dict | list)]
                if isinstance(node, dict)
                else [i for i, v in enumerate(node) if isinstance(v, dict | list)]
            )
            # Stop with probability 1/4, so that most mutations land below the top level.
            if not children or data.draw(st.integers(0, 3), label="stop") == 0:
                break
            node = node[data.draw(st.sampled_from(children), label="descend")]
        slots = list(node) if isinstance(node, dict) else list(range(len(node)))
        operation = data.draw(st.sampled_from(["replace", "delete", "add"]), label="operation")
        if operation == "add" or not slots:
            if isinstance(node, dict):
                node[data.draw(keys, label="new key")] = data.draw(values, label="new value")
            else:
                node.append(data.draw(values, label="new item"))
            continue
        slot = data.draw(st.sampled_from(slots), label="slot")
        if operation == "delete":
            del node[slot]
        else:
            node[slot] = data.draw(values, label="value")
    return document


@FUZZ
@given(data=st.data(), which=st.integers(0, len(VALID) - 1))
def test_mutated_valid_scenes(data, which, base_dir):
    load_or_refuse(_mutate(data, VALID[which]), base_dir)


@settings(FUZZ, max_examples=60)
@given(text=st.one_of(st.text(max_size=60), st.sampled_from(["[camera", "a = ", "[[objects]]\n"])))
def test_random_text(text):
    try:
        scene = loads_scene(text, "fuzz.toml")
    except SpecrefError as error:
        message = str(error)
    else:
        assert isinstance(scene, Scene)
        return
    assert message.startswith("fuzz.toml: ")

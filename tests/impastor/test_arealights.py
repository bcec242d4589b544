"""Tests of impastor.arealights: plane lights, bad input, the light-plane lookup Eqs. (5)-(8)."""

from __future__ import annotations

import numpy as np
import pytest

from impastor.arealights import PlaneLight, light_plane_lookup, light_plane_uv
from reference.errors import SpecrefError


def _ceiling(image, size=(1.2, 0.8)):
    return PlaneLight(image, (-0.6, 0.6, -1.0), (1, 0, 0), (0, 0, 1), *size)


def test_light_plane_uv_round_trip(rng):
    plane = _ceiling(np.ones((4, 4)))
    p = np.stack([rng.uniform(-0.2, 0.2, 50), np.zeros(50), rng.uniform(-0.2, 0.2, 50)], -1)
    ab = rng.uniform(0, 1, (50, 2))
    # Points on the light from (a, b) by the definition of o_TL, A, B, l_A, l_B (Fig. 7).
    target = plane.pixel_positions(ab[:, 1] * 4, ab[:, 0] * 4)
    d = target - p
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    a, b, dist = light_plane_uv(plane, p, d)
    np.testing.assert_allclose(np.stack([a, b], -1), ab, atol=1e-12)
    np.testing.assert_allclose(dist, np.linalg.norm(target - p, axis=-1), rtol=1e-12)


def test_light_plane_misses_and_back_side():
    plane = _ceiling(np.ones((4, 4)))
    _a, _b, d = light_plane_uv(plane, [0.0, 0.0, 0.0], [0.0, -1.0, 0.0])
    assert np.isinf(d)
    above = light_plane_lookup(plane, [[0.0, 1.0, -0.5]], [[0.0, -1.0, 0.0]])
    assert above[0, 0] == 0.0  # from behind the emitting side


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"image": -np.ones((2, 2))}, "radiance must be >= 0"),
        ({"image": np.full((2, 2), np.nan)}, "must be finite"),
        ({"B": (1, 0, 0)}, "A and B must be orthogonal"),
        ({"l_A": 0.0}, "l_A: must be > 0"),
    ],
)
def test_plane_light_bad_input(kwargs, match):
    args = {"image": np.ones((2, 2)), "origin": (0, 1, 0), "A": (1, 0, 0), "B": (0, 0, 1),
            "l_A": 1.0, "l_B": 1.0}  # fmt: skip
    args.update(kwargs)
    with pytest.raises(SpecrefError, match=match):
        PlaneLight(**args)

"""Tests of phong_table.table: building and reading the specular table of Eq. (11), Wang et al."""

from __future__ import annotations

import numpy as np
import pytest

from phong_table import INTERPOLATION_METHODS, PLACEMENT_METHODS
from phong_table.scenes import constant_material
from phong_table.table import build_table, check_interpolation, zero_below
from reference.errors import SpecrefError


@pytest.mark.parametrize("placement", PLACEMENT_METHODS.names())
def test_table_nodes_and_values(placement):
    # Identities by construction: t_0 = 0, t_m = 1, strictly increasing; the values are Eq. (11)
    # itself at the nodes (Source: SpectralPhong.specular, checked against colour-science in
    # tests/phong_table/test_model.py).
    model = constant_material(40.0)
    table = build_table(model, 16, placement)
    assert table.entries == 16
    assert table.nodes[0] == 0.0
    assert table.nodes[-1] == 1.0
    assert (np.diff(table.nodes) > 0).all()
    np.testing.assert_allclose(table.values, model.specular(table.nodes), rtol=1e-12, atol=1e-300)
    np.testing.assert_allclose(table.inv_width, 1.0 / np.diff(table.nodes), rtol=1e-12)


@pytest.mark.parametrize("interpolation", INTERPOLATION_METHODS.names())
def test_lookup_reproduces_the_nodes_and_converges(interpolation):
    # Properties: every interpolation passes through the tabulated values, and its error against
    # the exact function falls when the table grows.
    model = constant_material(40.0)
    small, large = (build_table(model, m, "uniform") for m in (16, 64))
    np.testing.assert_allclose(
        small.lookup(small.nodes, interpolation), small.values, rtol=1e-12, atol=1e-15
    )
    t = np.linspace(0.0, 1.0, 501)
    errors = [
        np.abs(tab.lookup(t, interpolation) - model.specular(t)).max() for tab in (small, large)
    ]
    assert errors[1] < errors[0]
    assert small.lookup(0.5, interpolation).shape == (3,)
    assert small.lookup(np.ones((2, 4)), interpolation).shape == (2, 4, 3)


def test_zero_below_is_where_every_interpolation_is_zero():
    # Property: a high exponent underflows t^n to 0 over most of [0, 1]; below zero_below every
    # interpolation reads exactly 0, and the table records the same point.
    model = constant_material(2000.0)
    table = build_table(model, 64, "uniform")
    z = zero_below(table.nodes, table.values)
    assert 0.0 < z < 1.0
    assert table.zero_below == z
    t = np.linspace(0.0, z, 50, endpoint=False)
    for interpolation in INTERPOLATION_METHODS.names():
        assert (table.lookup(t, interpolation) == 0.0).all(), interpolation


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: build_table(constant_material(3.0), 4, "random"), "unknown placement 'random'"),
        (lambda: build_table(constant_material(3.0), 0, "uniform"), "entries"),
        (
            lambda: build_table(constant_material(3.0), 10, "importance", segments=3),
            "segments",
        ),
        (lambda: check_interpolation("cubic", 8), "unknown interpolation 'cubic'"),
        (lambda: check_interpolation("parabolic", 2), "parabolic interpolation needs entries >= 3"),
    ],
)
def test_table_bad_input(call, match):
    with pytest.raises(SpecrefError, match=match):
        call()

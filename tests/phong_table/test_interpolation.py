import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

from phong_table import INTERPOLATION_METHODS, build_table
from phong_table.interpolation import (
    interpolate_monotone,
    interpolate_parabolic,
    interpolate_parabolic_w,
    pchip_slopes,
)
from phong_table.scenes import SCENES, constant_material
from reference.errors import SpecrefError


def _nodes(rng, m=30):
    return np.concatenate([[0.0], np.sort(rng.uniform(0.0, 1.0, m - 1)), [1.0]])


def test_parabolic_is_exact_for_quadratics(rng):
    nodes = _nodes(rng)
    a, b, c = rng.normal(size=(3, 3))
    values = a + b * nodes[:, None] + c * nodes[:, None] ** 2
    t = rng.uniform(0.0, 1.0, 200)
    np.testing.assert_allclose(
        interpolate_parabolic(nodes, values, t),
        a + b * t[:, None] + c * t[:, None] ** 2,
        rtol=1e-9,
        atol=1e-9,
    )


def test_parabolic_w_is_exact_for_quadratics_in_w(rng):
    # nodes uniform in w = t^(an+1) (importance, p = m): values quadratic in w are reproduced
    an = 3.0
    nodes = (np.arange(21) / 20) ** (1 / (an + 1))
    w_nodes = nodes ** (an + 1)
    values = np.stack([1 + 2 * w_nodes - w_nodes**2] * 3, axis=-1)
    t = rng.uniform(0.0, 1.0, 100)
    w = t ** (an + 1)
    np.testing.assert_allclose(
        interpolate_parabolic_w(nodes, values, t, an)[:, 0],
        1 + 2 * w - w**2,
        rtol=1e-10,
        atol=1e-12,
    )


def test_parabolic_w_has_no_overflow_where_w_underflows():
    # an = 2000: t^(an+1) < 1e-308 for t < 0.7; the guard keeps every value finite
    model = constant_material(2000.0)
    for placement in ("uniform", "importance", "error"):
        table = build_table(model, 50, placement)
        f = table.lookup(np.linspace(0.0, 1.0, 5001), "parabolic_w")
        assert np.isfinite(f).all()


def test_monotone_equals_scipy_pchip(rng):
    # independent implementation: scipy.interpolate.PchipInterpolator
    for scene in ("R1", "R2", "R3", "bimodal"):
        table = build_table(SCENES.lookup(scene).build(), 60, "error")
        t = rng.uniform(0.0, 1.0, 2000)
        expected = PchipInterpolator(table.nodes, table.values)(t)
        np.testing.assert_allclose(table.lookup(t, "monotone"), expected, rtol=0, atol=1e-12)
    nodes = _nodes(rng)
    values = rng.normal(size=(nodes.size, 3))
    t = rng.uniform(0.0, 1.0, 500)
    np.testing.assert_allclose(
        interpolate_monotone(nodes, values, t),
        PchipInterpolator(nodes, values)(t),
        rtol=0,
        atol=1e-12,
    )
    np.testing.assert_allclose(
        pchip_slopes(nodes, values),
        PchipInterpolator(nodes, values).derivative()(nodes),
        rtol=1e-10,
        atol=1e-10,
    )


def test_monotone_never_overshoots(rng):
    nodes = _nodes(rng)
    table_values = rng.normal(size=(nodes.size, 3))
    s = (np.arange(64) + 0.5) / 64
    t = (nodes[:-1, None] + s * np.diff(nodes)[:, None]).ravel()
    i = np.repeat(np.arange(nodes.size - 1), 64)
    f = interpolate_monotone(nodes, table_values, t)
    low = np.minimum(table_values[i], table_values[i + 1])
    high = np.maximum(table_values[i], table_values[i + 1])
    assert (f >= low).all()
    assert (f <= high).all()


def test_overshoot_of_each_interpolation():
    table = build_table(constant_material(2000.0), 200, "importance")
    assert table.overshoot("monotone") == 0.0
    assert table.overshoot("linear") == 0.0
    # the literal t-parabola overshoots by more than the peak in the wide first interval
    assert table.overshoot("parabolic") > 1.0


@pytest.mark.parametrize("interpolation", INTERPOLATION_METHODS.names())
def test_lookup_at_nodes_returns_the_values(interpolation):
    table = build_table(SCENES.lookup("R1").build(), 40, "error")
    np.testing.assert_allclose(
        table.lookup(table.nodes, interpolation), table.values, rtol=1e-9, atol=1e-12
    )


def test_bad_interpolation_arguments():
    table = build_table(constant_material(10.0), 2, "uniform")
    with pytest.raises(SpecrefError, match="parabolic interpolation needs entries >= 3, got 2"):
        table.lookup([0.5], "parabolic")
    with pytest.raises(SpecrefError, match="unknown interpolation 'cubic'"):
        table.lookup([0.5], "cubic")

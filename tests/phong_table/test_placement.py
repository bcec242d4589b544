import numpy as np
import pytest

from phong_table import PLACEMENT_METHODS, build_table
from phong_table.placement import (
    importance_ratio_Wang,
    inverse_importance_ratio_Wang,
    table_error,
    table_importance_Wang,
    table_uniform,
)
from phong_table.scenes import SCENES, constant_material
from reference.errors import SpecrefError


def test_ir_of_iir_is_identity(rng):
    # closed form: ir(iir(w)) = w (Eqs. (14)-(15), Wang et al.)
    w = rng.uniform(0.0, 1.0, 50)
    for an in (0.0, 1.0, 37.5, 2000.0):
        np.testing.assert_allclose(
            importance_ratio_Wang(inverse_importance_ratio_Wang(w, an), an),
            w,
            rtol=1e-12,
            atol=1e-15,
        )


@pytest.mark.parametrize("placement", PLACEMENT_METHODS.names())
@pytest.mark.parametrize("scene", SCENES.names())
@pytest.mark.parametrize("entries", [1, 3, 25, 200, 800])
def test_nodes_are_monotone_from_0_to_1(placement, scene, entries):
    nodes = build_table(SCENES.lookup(scene).build(), entries, placement).nodes
    assert nodes.shape == (entries + 1,)
    assert nodes[0] == 0.0
    assert nodes[-1] == 1.0
    assert (np.diff(nodes) > 0).all()


@pytest.mark.parametrize("n", [0.0, 1.0, 10.0, 500.0, 2000.0])
def test_importance_nodes_constant_exponent_closed_form(n):
    # closed form: t_q = (q/m)^(1/(n+1)) for p = m
    m = 40
    nodes = table_importance_Wang(constant_material(n), m)
    np.testing.assert_allclose(nodes, (np.arange(m + 1) / m) ** (1.0 / (n + 1.0)), rtol=1e-14)


def test_importance_one_segment_is_exactly_uniform():
    model = SCENES.lookup("R2").build()
    for m in (7, 25, 200):
        assert np.array_equal(table_importance_Wang(model, m, segments=1), table_uniform(None, m))


@pytest.mark.parametrize("placement", PLACEMENT_METHODS.names())
@pytest.mark.parametrize("n", [1.0, 7.0, 350.0])
def test_table_reproduces_t_to_the_n_at_the_nodes(placement, n):
    # with a constant n, f_sp(t) = f_sp(1) t^n (closed form); the tabulated values match it
    model = constant_material(n)
    table = build_table(model, 50, placement)
    expected = model.specular(1.0)[None, :] * np.power(table.nodes, n)[:, None]
    np.testing.assert_allclose(table.values, expected, rtol=1e-13, atol=1e-16)


def test_error_placement_kernel_equals_numpy():
    for scene in SCENES.names():
        model = SCENES.lookup(scene).build()
        compiled = PLACEMENT_METHODS.lookup("error").compiled(model, 200)
        np.testing.assert_allclose(compiled, table_error(model, 200), rtol=0, atol=1e-12)


def test_error_placement_has_a_density_floor():
    # the floor keeps a uniform share: no interval exceeds (1 + floor)/(floor m)
    nodes = table_error(constant_material(5000.0), 50)
    assert np.diff(nodes).max() <= (1 + 0.1) / (0.1 * 50) + 1e-12


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"entries": 10, "placement": "importance", "segments": 3}, "must divide entries = 10"),
        ({"entries": 0, "placement": "uniform"}, r"entries: must be an integer in \[1,"),
        ({"entries": 10, "placement": "best"}, "unknown placement 'best'"),
        ({"entries": 10, "placement": "error", "segments": 2}, "only the importance placement"),
    ],
)
def test_bad_table_arguments(kwargs, match):
    with pytest.raises(SpecrefError, match=match):
        build_table(constant_material(10.0), **kwargs)


@pytest.mark.parametrize(
    "t_range", [(0.0, 1.0), (0.78, 1.0), (0.3, 0.97), (0.2, 0.2), (1e-6, 0.999999), (0.5, 0.6)]
)
@pytest.mark.parametrize("entries", [4, 25, 200])
def test_seen_range_nodes_are_monotone_sized_and_twins_agree(t_range, entries):
    model = SCENES.lookup("R2").build()
    nodes = table_error(model, entries, t_range=t_range)
    assert nodes.size == entries + 1
    assert nodes[0] == 0.0
    assert nodes[-1] == 1.0
    assert (np.diff(nodes) > 0).all()
    # below the seen range: at most node 0 and the margin's node
    if t_range[0] < t_range[1]:
        assert (nodes < t_range[0]).sum() <= 2
    compiled = PLACEMENT_METHODS.lookup("error").compiled(model, entries, t_range=t_range)
    np.testing.assert_allclose(compiled, nodes, rtol=0, atol=1e-12)


@pytest.mark.parametrize("view", ["far", "near"])
def test_pixel_weighted_nodes_twins_agree_and_follow_the_pixels(view):
    from phong_table.placement import pixel_density
    from phong_table.render import shading_buffer, sphere_gbuffer

    model = SCENES.lookup("R1").build()
    buffer = shading_buffer(sphere_gbuffer(view, 64), model)
    t_range, t_density = buffer.t_range, buffer.t_density
    np.testing.assert_array_equal(t_density, pixel_density(buffer.t, t_range))
    nodes = table_error(model, 50, t_range=t_range, t_density=t_density)
    compiled = PLACEMENT_METHODS.lookup("error").compiled
    np.testing.assert_allclose(
        compiled(model, 50, t_range=t_range, t_density=t_density), nodes, rtol=0, atol=1e-12
    )
    assert nodes[0] == 0.0
    assert nodes[-1] == 1.0
    assert (np.diff(nodes) > 0).all()
    # more nodes where more pixels are: a density that is all in the upper half of the range
    # moves nodes up against one all in the lower half
    lo, hi = t_range
    upper = np.r_[np.zeros(32), np.ones(32)] * 2 / (hi - lo)
    lower = upper[::-1].copy()
    up = table_error(model, 50, t_range=t_range, t_density=upper)
    down = table_error(model, 50, t_range=t_range, t_density=lower)
    middle = 0.5 * (lo + hi)
    assert (up > middle).sum() > (down > middle).sum()


def test_bad_pixel_density():
    with pytest.raises(SpecrefError, match="t_density: must be >= 0"):
        table_error(constant_material(10.0), 10, t_range=(0.2, 0.7), t_density=[1.0, -1.0])
    with pytest.raises(SpecrefError, match="t_density: must be >= 0"):
        table_error(constant_material(10.0), 10, t_density=[1.0])


def test_bad_seen_range():
    with pytest.raises(SpecrefError, match="t_range: must be 0 <= t_lo <= t_hi <= 1"):
        table_error(constant_material(10.0), 10, t_range=(0.7, 0.2))


def _one_band(n_band=1e4, n_other=10.0, band=17):
    from phong_table.scenes import spectral_phong_unit_peak

    bands = 41
    k_s = np.zeros(bands)
    k_s[band] = 0.8
    n = np.full(bands, n_other)
    n[band] = n_band
    return spectral_phong_unit_peak(np.full(bands, 0.2), k_s, n, "D65", "one band")


@pytest.mark.parametrize("t_range", [None, (0.78, 1.0)])
@pytest.mark.parametrize("scene", ["R2", "bimodal", "one band"])
def test_graded_nodes_twins_agree_and_neighbouring_widths_stay_alike(scene, t_range):
    from phong_table.placement import ERROR_GRADING

    model = _one_band() if scene == "one band" else SCENES.lookup(scene).build()
    for entries in (25, 200):
        graded = table_error(model, entries, t_range=t_range, interpolation="parabolic")
        compiled = PLACEMENT_METHODS.lookup("error").compiled
        np.testing.assert_allclose(
            compiled(model, entries, t_range=t_range, interpolation="parabolic"),
            graded,
            rtol=0,
            atol=1e-12,
        )
        # linear and monotone keep the ungraded nodes
        np.testing.assert_array_equal(
            table_error(model, entries, t_range=t_range, interpolation="monotone"),
            table_error(model, entries, t_range=t_range),
        )
        # |dw/dt| <= g: a width at most 1/(1 - g) times its neighbour's, up to the fine grid's
        # resolution (factor 1.25 of slack) and the margins of the seen range (place_seen)
        h = np.diff(graded)
        inner = slice(2, -2) if t_range else slice(None)
        ratio = np.maximum(h[1:] / h[:-1], h[:-1] / h[1:])[inner]
        assert ratio.max() <= 1.25 / (1 - ERROR_GRADING), (entries, ratio.max())

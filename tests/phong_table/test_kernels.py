import numpy as np
import pytest

from phong_table import INTERPOLATION_METHODS, PLACEMENT_METHODS, RENDER_METHODS, build_table
from phong_table.render import shade_pixels, shading_buffer, sphere_gbuffer
from phong_table.scenes import SCENES
from phong_table.table import tabulate


def _close(a, b):
    # twins agree to ~1e-12 of the image's peak
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * max(1.0, np.abs(b).max()))


@pytest.mark.parametrize("scene", ["R1", "R2", "R3", "bimodal"])
@pytest.mark.parametrize("view", ["far", "near"])
def test_geometry_and_exact_kernels_equal_numpy(scene, view):
    model = SCENES.lookup(scene).build()
    geometry = sphere_gbuffer(view, 24)
    compiled, reference = (
        shading_buffer(geometry, model, True),
        shading_buffer(geometry, model, False),
    )
    for key in ("cos_theta", "t", "f_att"):
        _close(getattr(compiled, key), getattr(reference, key))
    _close(
        shade_pixels(compiled, model, "exact"),
        shade_pixels(reference, model, "exact", compiled=False),
    )


@pytest.mark.parametrize("placement", PLACEMENT_METHODS.names())
@pytest.mark.parametrize("interpolation", INTERPOLATION_METHODS.names())
@pytest.mark.parametrize("scene", ["R2", "R3", "n2000"])
def test_table_kernel_equals_numpy(placement, interpolation, scene):
    model = SCENES.lookup(scene).build()
    buffer = shading_buffer(sphere_gbuffer("near", 24), model, False)
    for entries in (3, 64):
        table = build_table(model, entries, placement, compiled=True)
        compiled = shade_pixels(buffer, model, "table", table, interpolation)
        reference = shade_pixels(buffer, model, "table", table, interpolation, compiled=False)
        _close(compiled, reference)


def test_the_registered_table_kernel_is_each_interpolations_kernel():
    # RENDER_METHODS' twin takes the interpolation's code and calls its kernel (TABLE_KERNELS),
    # which the render path calls directly: the same pixels, bit for bit
    from phong_table import _kernels
    from phong_table.render import _buffer_inputs

    model = SCENES.lookup("R2").build()
    buffer = shading_buffer(sphere_gbuffer("near", 16), model, False)
    table = build_table(model, 32, "error", compiled=True)
    rows = _buffer_inputs(buffer)
    head = (model.diffuse_RGB, model.ambient_RGB, table.nodes, table.values, table.inv_width,
            table.cubic, table.guide, table.steps, table.uniform)  # fmt: skip
    tail = (table.an + 1.0, table.zero_below)
    for name in INTERPOLATION_METHODS.names():
        code = INTERPOLATION_METHODS.lookup(name).code
        out = np.empty((buffer.t.size, 3))
        registered = RENDER_METHODS.lookup("table").kernel(*rows, *head, code, *tail, out.copy())
        direct = _kernels.TABLE_KERNELS[code](*rows, *head, *tail, out)
        np.testing.assert_array_equal(registered, direct)
        _close(direct, shade_pixels(buffer, model, "table", table, name, compiled=False))


def test_table_kernel_on_exact_node_hits():
    # pixels exactly on nodes and at 0 and 1 find the same interval as searchsorted
    model = SCENES.lookup("R1").build()
    table = build_table(model, 50, "error")
    t = np.concatenate([table.nodes, [0.0, 1.0, np.nextafter(1.0, 0.0)]])
    from phong_table.render import ShadingBuffer

    buffer = ShadingBuffer(None, np.full(t.size, 0.5), t, np.ones(t.size))
    for interpolation in INTERPOLATION_METHODS.names():
        _close(
            shade_pixels(buffer, model, "table", table, interpolation),
            shade_pixels(buffer, model, "table", table, interpolation, compiled=False),
        )


@pytest.mark.parametrize("placement", PLACEMENT_METHODS.names())
def test_table_kernel_does_not_depend_on_pixel_order(placement):
    # The kernel tries the previous pixel's interval first; in any pixel order (raster, sorted,
    # reversed, random, and alternating between the ends) each pixel finds its own interval.
    from phong_table.render import ShadingBuffer

    model = SCENES.lookup("R3").build()
    table = build_table(model, 64, placement)
    rng = np.random.default_rng(4)
    raster = shading_buffer(sphere_gbuffer("near", 32), model, False).t
    ends = np.ravel(np.column_stack([np.linspace(0.7, 1.0, 500), np.linspace(1.0, 0.7, 500)]))
    orders = [raster, np.sort(raster), np.sort(raster)[::-1], rng.permutation(raster), ends]
    for t in orders:
        buffer = ShadingBuffer(None, np.full(t.size, 0.5), t, np.ones(t.size))
        for interpolation in INTERPOLATION_METHODS.names():
            expected = table.lookup(t, interpolation)
            RGB = shade_pixels(buffer, model, "table", table, interpolation)
            _close(RGB, shade_pixels(buffer, model, "table", table, interpolation, compiled=False))
            _close((RGB - model.ambient_RGB) - 0.5 * model.diffuse_RGB, expected)


@pytest.mark.parametrize("scene", ["R3", "n2000"])
def test_table_kernel_skips_only_where_every_interpolation_is_zero(scene):
    # High exponents: t^n underflows below ~0.6-0.7, so the table's leading values are exactly 0.
    model = SCENES.lookup(scene).build()
    buffer = shading_buffer(sphere_gbuffer("far", 48), model, False)
    for placement in PLACEMENT_METHODS.names():
        table = build_table(model, 64, placement, compiled=True)
        if placement != "importance":  # its first node is above 0.99: no run of zeros to skip
            assert 0.3 < table.zero_below < 1.0
            assert (buffer.t < table.zero_below).mean() > 0.5  # most pixels skip the lookup
        t = np.linspace(0.0, table.zero_below, 4001, endpoint=False)
        for interpolation in INTERPOLATION_METHODS.names():
            assert not table.lookup(t, interpolation).any()
            compiled = shade_pixels(buffer, model, "table", table, interpolation)
            reference = shade_pixels(buffer, model, "table", table, interpolation, compiled=False)
            _close(compiled, reference)
    # a material whose specular is never 0 has no skip
    assert build_table(SCENES.lookup("R1").build(), 64, "error").zero_below == -1.0


def test_tabulate_kernel_equals_numpy():
    entry = RENDER_METHODS.lookup("tabulate")
    for scene in SCENES.names():
        model = SCENES.lookup(scene).build()
        nodes = build_table(model, 100, "error").nodes
        a = entry.reference(nodes, model.specular_weights, model.n, 16)
        b = entry.kernel(nodes, model.specular_weights, model.n, 16)
        for x, y in zip(a[:4], b[:4], strict=True):
            np.testing.assert_allclose(y, x, rtol=1e-9, atol=1e-12 * max(1.0, np.abs(x).max()))
        assert a[5] == b[5]
        assert np.abs(a[4] - b[4]).max() <= 1  # the index may differ at a cell edge by rounding
    assert tabulate is entry.reference


@pytest.mark.parametrize("scene", ["R1", "R2", "R3", "bimodal"])
def test_merged_exponents_give_the_same_table(scene):
    # build_table sums the weights of equal exponents (SpectralPhong.n_distinct): the same f_sp
    model = SCENES.lookup(scene).build()
    assert model.n_distinct.size == np.unique(model.n).size
    np.testing.assert_allclose(
        model.specular_weights_distinct.sum(axis=0), model.specular_weights.sum(axis=0), rtol=1e-14
    )
    for compiled in (False, True):
        table = build_table(model, 64, "error", compiled=compiled)
        exact = model.specular(table.nodes)
        np.testing.assert_allclose(table.values, exact, rtol=1e-13, atol=1e-300)


def test_table_kernel_flushes_only_negligible_entries():
    # R3's far table holds cubic coefficients near the smallest normal double (E38): the kernel
    # reads them as 0 and still agrees with the NumPy reference (which keeps them); the table does
    # hold such entries, so the flush is exercised
    from phong_table._kernels import TABLE_FLUSH

    model = SCENES.lookup("R3").build()
    buffer = shading_buffer(sphere_gbuffer("far", 64), model)
    table = build_table(
        model, 200, "error", compiled=True, t_range=buffer.t_range, t_density=buffer.t_density
    )
    tiny = (np.abs(table.cubic) < TABLE_FLUSH) & (table.cubic != 0.0)
    assert tiny.any()
    compiled = shade_pixels(buffer, model, "table", table, "monotone")
    reference = shade_pixels(buffer, model, "table", table, "monotone", compiled=False)
    assert np.abs(compiled - reference).max() < 1e-12 * np.abs(reference).max()


@pytest.mark.parametrize("view", ["far", "near"])
def test_build_step_kernels_equal_numpy(view):
    # the small steps of the compiled build (fine grid and pixel weights, the zero run, the node
    # check) against their NumPy twins, on the views' pixel densities and on edge cases
    from phong_table import _kernels
    from phong_table.placement import _FINE_GRID, _fine_weights
    from phong_table.table import increasing, zero_below

    model = SCENES.lookup("R3").build()
    buffer = shading_buffer(sphere_gbuffer(view, 48), model)
    rng = np.random.default_rng(17)
    r_lo, r_hi = buffer.t_range
    cases = [
        (0.0, 1.0, (r_lo, r_hi), buffer.t_density),
        (r_lo, r_hi, (r_lo, r_hi), buffer.t_density),
        (0.3, 0.9, (0.4, 0.8), rng.uniform(0.0, 3.0, 7)),
        (0.0, 1.0, (0.25, 0.5), np.array([2.0])),  # one cell: constant inside the range
        (0.1, 0.6, (0.2, 0.2), np.array([1.0, 3.0])),  # a single t
        (0.0, 1.0, None, None),
    ]
    for t_lo, t_hi, t_range, density in cases:
        t_fine, p = _fine_weights(t_lo, t_hi, t_range, density)
        lo, hi = (0.0, 1.0) if t_range is None else t_range
        cells = np.zeros(0) if density is None else np.asarray(density, dtype=np.float64)
        k_fine, k_p = _kernels._fine_weights_kernel(_FINE_GRID, t_lo, t_hi, lo, hi, cells)
        np.testing.assert_array_equal(k_fine, t_fine)
        assert k_p.shape == p.shape
        if p.size:
            _close(k_p, p)
        assert density is None or lo == hi or (p > 0).any()
    for placement in ("uniform", "importance", "error"):
        table = build_table(model, 64, placement)
        assert _kernels._zero_below_kernel(table.nodes, table.values) == zero_below(
            table.nodes, table.values
        )
    zeros = np.zeros((5, 3))
    nodes = np.linspace(0.0, 1.0, 5)
    assert _kernels._zero_below_kernel(nodes, zeros) == zero_below(nodes, zeros) == 0.75
    assert build_table(model, 64, "error", compiled=True).zero_below > 0.0
    for nodes in (
        np.linspace(0.0, 1.0, 9),
        [0.0, 0.5, 0.5, 1.0],
        [0.0, 0.6, 0.4, 1.0],
        [0.1, 0.5, 1.0],
        [0.0, 0.5, 0.9],
    ):
        nodes = np.asarray(nodes, dtype=np.float64)
        assert _kernels._increasing_kernel(nodes) == increasing(nodes)

"""Tests of shrm.accuracy: the SH order from a per-pixel accuracy of Y, and bright texels."""

from __future__ import annotations

import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.geometry.envmap import latlong_pixel_directions
from shrm.accuracy import (
    accuracy_order,
    bright_texels,
    degree_power,
    sparse_convolution,
    truncation_error,
)
from shrm.prefilter import prefilter_bruteforce
from shrm.sh import n_coefficients
from shrm.transform import project_latlong, synthesize_latlong


def test_degree_power_is_parseval(rng):
    # Source: Parseval, ∫ f² dω = Σ_l C_l, the integral by Fejér-1 quadrature of the synthesized
    # (band-limited, so exactly integrated) map.
    from shrm.sh import fejer1_weights

    L, H = 6, 16
    c = rng.standard_normal(n_coefficients(L))
    f = synthesize_latlong(c, H)
    w = np.repeat(fejer1_weights(H)[:, None] * (2 * np.pi / (2 * H)), 2 * H, axis=1)
    assert degree_power(c).sum() == pytest.approx(float(np.sum(f**2 * w)), rel=1e-12)


def test_smooth_sky_keeps_a_low_order():
    # "Model no more than a scene needs": a sky of degrees 0..2 needs at most order 2 whatever
    # the tolerance (its truncation at 2 is exact).
    d = latlong_pixel_directions(64, 128)
    sky = 1.0 + 0.4 * d[..., 1] + 0.2 * d[..., 0] * d[..., 2]
    for tol in (1e-2, 1e-4):
        assert accuracy_order(sky, "lambert", tol).order <= 2


def test_order_grows_as_the_tolerance_falls():
    rng = np.random.default_rng(11)
    sky = 0.5 + rng.random((64, 128))
    orders = [accuracy_order(sky, "phong:16", tol).order for tol in (5e-2, 1e-2, 2e-3)]
    assert orders == sorted(orders)
    assert orders[0] < orders[-1]


def test_truncation_error_is_zero_at_the_band_limit(rng):
    c = np.abs(rng.standard_normal(n_coefficients(5)))
    c[0] = 20.0  # positive everywhere
    assert truncation_error(c, 5) == (0.0, 0.0)
    assert truncation_error(c, 2)[1] > 0.0


def test_bright_texels_plus_residual_is_the_whole_map():
    # Source: brute force: the exact part (sparse_convolution) plus the residual map's brute-force
    # convolution equals the whole map's brute-force convolution (linearity), to rounding.
    rng = np.random.default_rng(2)
    Y = 0.1 + rng.random((32, 64))
    Y[5, 7], Y[20, 40] = 5e3, 2e3
    b = bright_texels(Y)
    assert sorted(b.index.tolist()) == [5 * 64 + 7, 20 * 64 + 40]
    n = np.array([[0.0, 1.0, 0.0], [0.6, 0.0, 0.8], [0.0, -1.0, 0.0]])
    exact = sparse_convolution(b.exact_part(Y[..., None]), b.directions, b.weights, "lambert", n)
    residual = prefilter_bruteforce((Y * b.scale)[..., None], "lambert", n)
    whole = prefilter_bruteforce(Y[..., None], "lambert", n)
    np.testing.assert_allclose(exact + residual, whole, rtol=1e-12)


def test_a_bright_texel_is_lit_exactly_and_the_order_stays_low():
    # A single texel with most of the power: exact, and the residual (a uniform sky) needs order 0;
    # the chosen order meets the bound at held-out directions against brute force.
    Y = np.full((64, 128), 0.2)
    Y[20, 30] = 1e5
    b = bright_texels(Y)
    choice = accuracy_order(Y, "lambert", bright=b)
    assert choice.exact_texels == 1
    assert choice.order == 0
    n = np.random.default_rng(4).standard_normal((200, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    whole = prefilter_bruteforce(Y[..., None], "lambert", n)[:, 0]
    approx = np.pi * 0.2 * np.ones(200)  # order 0 of a sky of 0.2, plus the texel exactly
    approx += sparse_convolution(b.exact_part(Y[..., None]), b.directions, b.weights, "lambert", n)[
        :, 0
    ]
    lit = whole >= 0.01 * whole.max()
    assert np.max(np.abs(approx - whole)[lit] / whole[lit]) < 2e-2


def test_accuracy_order_bad_input():
    with pytest.raises(SpecrefError, match="--accuracy: must be a relative error in"):
        accuracy_order(np.ones((4, 8)), "lambert", 0.0)
    with pytest.raises(SpecrefError, match=r"sky: luminance must be \(H, W\)"):
        accuracy_order(np.ones((4, 8, 3)), "lambert", where="sky")


def test_project_of_the_residual_is_what_the_order_sees():
    # The estimate projects the residual: a map that is all bright texel has a flat residual.
    Y = np.full((16, 32), 1.0)
    Y[3, 3] = 1e6
    b = bright_texels(Y)
    c = project_latlong((Y * b.scale)[..., None], 3)[0]
    assert np.abs(c[1:]).max() < 1e-12

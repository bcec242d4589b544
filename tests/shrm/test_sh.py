import json
import os
from operator import attrgetter
from pathlib import Path

import numpy as np
import pytest

from reference.errors import SpecrefError
from shrm.sh import (
    PLAIN_ORDER_LIMIT,
    directions_to_theta_phi,
    fejer1_weights,
    latlong_ring_angles,
    legendre_recurrence_coefficients,
    legendre_table,
    ring_cosines,
    sh_basis,
    sh_degrees_orders,
    sh_evaluate,
)
from shrm.transform import (
    SH_KERNELS,
)

DATA = Path(__file__).resolve().parents[2] / "validation" / "data" / "sh_basis.json"


def _points():
    data = json.loads(DATA.read_text())
    return data, np.array(data["points"])


def _basis_at(l, m, theta, phi, method):
    L, am = int(l), abs(int(m))
    lam = legendre_table(L, [theta], method, orders=[am])[L - am, 0]
    if m == 0:
        return lam
    return np.sqrt(2.0) * lam * (np.cos(am * phi) if m > 0 else np.sin(am * phi))


@pytest.mark.parametrize(("l_max", "tolerance"), [(200, 5e-13), (1000, 1e-11)])
def test_sh_basis_matches_mpmath_at_hard_points(l_max, tolerance):
    # Source: mpmath 50 dps, checked at 80 (validation/precompute/sh_basis.py -> sh_basis.json).
    # Points: θ within 1e-12..1e-1 of 0 and π (sin^m θ underflows), sin θ = 1/e, the equator.
    # Bounds: ≤ 5e-13 (l ≤ 200) and ≤ 1e-11 (l ≤ 1000), absolute / sqrt((2l+1)/4π).
    data, points = _points()
    assert data["dps"] == 50
    assert data["check_dps"] == 80
    rows = points[(points[:, 0] <= l_max) & (points[:, 0] > (l_max // 5 if l_max > 200 else -1))]
    for l, m, theta, phi, value in rows:
        got = _basis_at(l, m, theta, phi, "auto")
        scale = np.sqrt((2 * l + 1) / (4 * np.pi))
        assert abs(got - value) / scale <= tolerance, (l, m, theta)


def test_scaled_recurrence_beyond_plain_limit_and_plain_failure():
    # Source: mpmath (sh_basis.json). Near l ≈ 1930 at sin θ ≈ 1/e the plain recurrence's sectoral
    # start underflows while Y_lm is O(1); the scaled (extended-exponent) recurrence stays accurate.
    _, points = _points()
    rows = points[points[:, 0] >= 1500]
    worst_scaled, worst_plain = 0.0, 0.0
    for l, m in sorted({(int(r[0]), int(r[1])) for r in rows}):
        sel = rows[(rows[:, 0] == l) & (rows[:, 1] == m)]
        theta, phi, value = sel[:, 2], sel[0, 3], sel[:, 4]
        am = abs(m)
        trig = 1.0 if m == 0 else np.sqrt(2.0) * (np.cos(am * phi) if m > 0 else np.sin(am * phi))
        scale = np.sqrt((2 * l + 1) / (4 * np.pi))
        for method in ("scaled", "plain"):
            got = trig * legendre_table(l, theta, method, orders=[am])[l - am]
            err = np.abs(got - value).max() / scale
            if method == "scaled":
                worst_scaled = max(worst_scaled, err)
            else:
                worst_plain = max(worst_plain, err)
    assert worst_scaled <= 1e-11
    assert worst_plain > 1e-3  # the documented failure of the plain float64 recurrence
    assert PLAIN_ORDER_LIMIT < 1930


def test_sh_basis_closed_forms_l1():
    # Source: closed form, Y_1,-1 = -c x, Y_10 = c y, Y_11 = c z with c = sqrt(3/4π).
    rng = np.random.default_rng(5)
    d = rng.normal(size=(20, 3))
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    c = np.sqrt(3 / (4 * np.pi))
    Y = sh_basis(1, d)
    np.testing.assert_allclose(Y[:, 1:], c * np.stack([-d[:, 0], d[:, 1], d[:, 2]], -1), atol=1e-15)


def test_sh_basis_shapes():
    assert sh_basis(2, [0.0, 1.0, 0.0]).shape == (9,)
    assert sh_basis(2, np.ones((2, 3, 3)) / np.sqrt(3)).shape == (2, 3, 9)


def test_orthonormality_gauss_legendre_at_L1000():
    # Gauss–Legendre in cos θ (exact for degree ≤ 2n-1) for a sample of orders m; the φ integral is
    # exact analytically (2π for m = 0, π·(√2)² for m > 0). ∫ Y_lm Y_l'm dω = δ_ll'.
    L = 1000
    x, w = np.polynomial.legendre.leggauss(L + 2)
    orders = (0, 1, 500, 999, 1000)
    table = legendre_table(L, np.arccos(x), orders=orders)
    start = 0
    worst = 0.0
    for m in orders:
        block = table[start : start + L + 1 - m]
        gram = 2 * np.pi * (block * w) @ block.T
        worst = max(worst, np.abs(gram - np.eye(L + 1 - m)).max())
        start += L + 1 - m
    # Bound from the basis accuracy at l = 1000 (1e-11 · sqrt((2L+1)/4π) per value, twice).
    assert worst < 2 * 1e-11 * np.sqrt((2 * L + 1) / (4 * np.pi))


def test_fejer1_weights_match_ducc0():
    # Source: ducc0.sht.experimental.get_gridweights("F1", n), weights summing to 4π per ring.
    import ducc0

    for n in (1, 4, 7, 64):
        ours = fejer1_weights(n) * 2 * np.pi
        np.testing.assert_allclose(
            ours, ducc0.sht.experimental.get_gridweights("F1", n), rtol=1e-13
        )


def test_fejer1_exact_for_polynomials():
    # Source: closed form ∫_{-1}^{1} x^k dx = 2/(k+1) for even k; Fejér-1 is exact for degree < n.
    n = 9
    x = np.cos(latlong_ring_angles(n))
    for k in range(0, n, 2):
        assert abs(fejer1_weights(n) @ x**k - 2 / (k + 1)) < 1e-14


@pytest.mark.parametrize("method", SH_KERNELS.values(), ids=attrgetter("name"))
def test_numba_twins_equal_numpy(method, rng):
    args = method.example_inputs(rng)
    if method.name == "legendre_table":
        L, theta = args
        for scaled in ("plain", "scaled"):
            for orders in (None, [0, 3, L]):
                ref = method.reference(L, theta, scaled, orders)
                out = method.reference(L, theta, scaled, orders, backend="numba")
                np.testing.assert_allclose(out, ref, rtol=1e-12, atol=1e-14)
    elif method.name == "legendre_analysis":
        L, theta, w, F_cos, F_sin = args
        ref = method.reference(L, theta, w, F_cos, F_sin)
        A, B = legendre_recurrence_coefficients(L)
        out = np.zeros(((L + 1) ** 2, 2))
        method.kernel(L, *ring_cosines(theta), np.sin(theta), w, A, B, F_cos, F_sin, False, out)
        np.testing.assert_allclose(out.T, ref, rtol=1e-12, atol=1e-14)
    elif method.name == "legendre_synthesis":
        L, theta, c = args
        G_cos, G_sin = method.reference(L, theta, c)
        A, B = legendre_recurrence_coefficients(L)
        out_c, out_s = np.zeros_like(G_cos), np.zeros_like(G_sin)
        method.kernel(
            L,
            *ring_cosines(theta),
            np.sin(theta),
            A,
            B,
            np.ascontiguousarray(c.T),
            True,
            out_c,
            out_s,
        )
        np.testing.assert_allclose(out_c, G_cos, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(out_s, G_sin, rtol=1e-12, atol=1e-14)
    else:
        c, d = args
        np.testing.assert_allclose(
            sh_evaluate(c, d, backend="numba"), method.reference(c, d), rtol=1e-12, atol=1e-14
        )


def test_degrees_orders_inverse_of_index():
    l, m = sh_degrees_orders(5)
    assert np.array_equal(l * l + l + m, np.arange(36))


def test_directions_on_poles_are_finite():
    theta, _ = directions_to_theta_phi([[0.0, 1.0, 0.0], [0.0, -1.0, 0.0]])
    assert np.array_equal(theta, [0.0, np.pi])
    assert np.isfinite(sh_basis(50, [[0.0, 1.0, 0.0], [0.0, -1.0, 0.0]])).all()


def test_order_above_limit_refused():
    with pytest.raises(SpecrefError, match="3000"):
        legendre_table(3001, [0.5])


def test_precomputed_sample_regenerates():
    # Regenerate a sample of sh_basis.json with the script and compare.
    from validation.precompute.sh_basis import compute

    _, points = _points()
    rows = compute(degrees=(100, 2000), thetas=(1e-6, 0.377))
    table = {(r[0], r[1], r[2]): r[4] for r in points.tolist()}
    for l, m, theta, _, value in rows:
        assert table[(l, m, theta)] == value


@pytest.mark.xslow
def test_order_2200_limit_demo():
    # The whole table at L = 2200: at sin θ = 0.84 nothing underflows and the two recurrences agree;
    # at sin θ = 1/e the plain one's sectoral start underflows (m ≳ 740, l ≳ 2020) and it fails,
    # which the scaled one does not (xslow: two 2.4M-entry tables in NumPy).
    theta = np.array([0.377, 1.0])
    plain = legendre_table(2200, theta, "plain")
    scaled = legendre_table(2200, theta, "scaled")
    assert np.abs(plain[:, 1] - scaled[:, 1]).max() < 1e-10
    assert np.abs(plain[:, 0] - scaled[:, 0]).max() > 1e-3
    assert os.environ.get("SPECREF_XSLOW")

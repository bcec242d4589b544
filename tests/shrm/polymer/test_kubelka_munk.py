import numpy as np
import pytest
from scipy.linalg import expm

from reference.colour.spectra import GRID_31
from reference.errors import SpecrefError
from shrm.polymer.kubelka_munk import (
    DEFAULT_CONSTITUENTS,
    km_invert,
    km_over_backing,
    km_R_infinity,
    km_slab,
    polymer_constituents,
    polymer_K_S,
    saunderson_constants,
    slab_measured,
)


def _two_flux_ode(K, S, d, i_in=1.0, r_top=0.0, r_bottom=0.0, nodes=64):
    """Independent solution of the KM equations di/dx = -(K+S)i + Sj, dj/dx = (K+S)j - Si.

    Solved as a boundary-value problem with the matrix exponential (scipy), boundary conditions
    i(0) = i_in + r_top j(0), j(d) = r_bottom i(d); the absorbed flux A = K ∫ (i + j) dx comes from
    Gauss-Legendre quadrature of the profile, never from 1 - R - T.
    """
    M = np.array([[-(K + S), S], [-S, K + S]])
    E = expm(M * d)
    # j(d) = r_bottom i(d) with (i, j)(d) = E (i0, j0) and i0 = i_in + r_top j0: solve for j0
    a = E[1, 0] - r_bottom * E[0, 0]
    b = E[1, 1] - r_bottom * E[0, 1]
    j0 = -a * i_in / (a * r_top + b)
    y0 = np.array([i_in + r_top * j0, j0])
    x, w = np.polynomial.legendre.leggauss(nodes)
    x, w = 0.5 * d * (x + 1.0), 0.5 * d * w
    profile = np.array([expm(M * xi) @ y0 for xi in x])
    A = K * (w * profile.sum(axis=1)).sum()
    yd = E @ y0
    return y0, yd, A


CASES = [(0.3, 2.0, 0.762), (0.05, 8.0, 1.524), (1.2, 0.4, 3.048), (0.0, 3.0, 1.0), (0.7, 0.0, 1.0)]


@pytest.mark.parametrize(("K", "S", "d"), CASES)
def test_km_slab_matches_the_ode_and_R_plus_T_plus_A_is_one(K, S, d):
    # Source: the two-flux ODE solved by scipy.linalg.expm (above), not Kubelka's closed form
    (_, j0), (i_d, _), A = _two_flux_ode(K, S, d)
    R_0, T = km_slab(K, S, d)
    assert pytest.approx(j0, abs=1e-12) == R_0
    assert pytest.approx(i_d, abs=1e-12) == T
    assert pytest.approx(1.0, abs=1e-12) == R_0 + T + A


@pytest.mark.parametrize(("K", "S", "d"), CASES)
def test_slab_measured_matches_the_ode_with_surfaces(K, S, d):
    # The chip in air: front surface k_1 outside / k_2 inside, back surface k_2 inside
    c = saunderson_constants(1.54)
    k_1, k_2 = float(c.k_1), float(c.k_2)
    (_, j0), (i_d, _), A = _two_flux_ode(K, S, d, 1.0 - k_1, k_2, k_2)
    R, T = slab_measured(K, S, d, n=1.54)
    assert pytest.approx(k_1 + (1.0 - k_2) * j0, abs=1e-12) == R
    assert pytest.approx((1.0 - k_2) * i_d, abs=1e-12) == T
    assert pytest.approx(1.0, abs=1e-12) == R + T + A


@pytest.mark.parametrize("R_g", [0.2, 0.9])
def test_km_over_backing_matches_the_ode(R_g):
    K, S, d = 0.4, 2.5, 0.8
    (_, j0), _, _ = _two_flux_ode(K, S, d, r_bottom=R_g)
    assert km_over_backing(*km_slab(K, S, d), R_g) == pytest.approx(j0, abs=1e-12)


def test_thin_limit_is_the_bare_surfaces():
    # d → 0: the body vanishes (R_0 → 0, T → 1) and the chip reduces to its two surfaces, whose
    # closed form (sum of the interreflections between them) is R = k_1 + (1-k_1) k_2/(1+k_2),
    # T = (1-k_1)/(1+k_2).
    K, S = polymer_K_S(polymer_constituents(GRID_31), 1.0)
    R_0, T_0 = km_slab(K, S, 1e-12)
    np.testing.assert_allclose(R_0, 0.0, atol=1e-10)
    np.testing.assert_allclose(T_0, 1.0, atol=1e-10)
    c = saunderson_constants(1.54)
    R, T = slab_measured(K, S, 0.0)
    np.testing.assert_allclose(R, c.k_1 + (1 - c.k_1) * c.k_2 / (1 + c.k_2), rtol=1e-14)
    np.testing.assert_allclose(T, (1 - c.k_1) / (1 + c.k_2), rtol=1e-14)


def test_thick_limit_is_R_infinity():
    # Source: Kubelka & Munk 1931, R_∞ = 1 + K/S - sqrt((K/S)² + 2 K/S), written here as printed
    K, S = polymer_K_S(polymer_constituents(GRID_31), [0.0, 0.5, 2.0])
    ratio = K / S
    R_inf = 1.0 + ratio - np.sqrt(ratio**2 + 2.0 * ratio)
    R_0, T = km_slab(K, S, 1e4)
    np.testing.assert_allclose(R_0, R_inf, rtol=1e-9)
    np.testing.assert_allclose(km_R_infinity(K, S), R_inf, rtol=1e-9)
    assert np.all(T < 1e-12)
    # Over any backing, an opaque layer shows R_∞ whatever lies behind it
    np.testing.assert_allclose(km_over_backing(R_0, T, 0.8), R_inf, rtol=1e-9)


def test_closed_forms_without_absorption_or_scattering():
    # Source: Kubelka 1948: K = 0 gives R_0 = Sd/(1 + Sd); S = 0 is Beer-Lambert T = exp(-Kd)
    S, d = np.array([0.5, 2.0, 40.0]), 0.7
    R_0, T = km_slab(0.0, S, d)
    np.testing.assert_allclose(R_0, S * d / (1 + S * d), rtol=1e-14)
    np.testing.assert_allclose(T, 1 / (1 + S * d), rtol=1e-14)
    R_0, T = km_slab(np.array([0.1, 3.0]), 0.0, d)
    np.testing.assert_allclose(T, np.exp(-np.array([0.1, 3.0]) * d), rtol=1e-14)


def test_inversion_round_trip_within_1e9():
    rng = np.random.default_rng(14)
    K = rng.uniform(0.0, 1.5, (3, 41))
    S = rng.uniform(0.05, 3.0, (3, 41))
    d = 0.762
    R_g_white = np.linspace(0.85, 0.92, 41)
    R_b, _ = slab_measured(K, S, d)
    R_w, _ = slab_measured(K, S, d, R_g=R_g_white)
    K_i, S_i = km_invert(R_b, R_w, d, R_g_white=R_g_white)
    np.testing.assert_allclose(K_i, K, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(S_i, S, rtol=1e-9, atol=1e-9)


def test_inversion_predicts_another_thickness():
    # The point of the inverse: measure at 0.03", predict the 0.120" chip
    K, S = polymer_K_S(polymer_constituents(GRID_31), 0.05)
    R_b, _ = slab_measured(K, S, 0.762)
    R_w, _ = slab_measured(K, S, 0.762, R_g=0.9)
    K_i, S_i = km_invert(R_b, R_w, 0.762, R_g_white=0.9)
    np.testing.assert_allclose(
        slab_measured(K_i, S_i, 3.048)[0], slab_measured(K, S, 3.048)[0], atol=1e-9
    )


def test_shapes_broadcast():
    c = polymer_constituents(GRID_31)
    K, S = polymer_K_S(c, np.zeros((2, 3)))
    assert K.shape == (2, 3, 31)
    R, T = slab_measured(K, S, np.array([0.762, 1.524, 3.048])[:, None], R_g=0.5)
    assert R.shape == T.shape == (2, 3, 31)
    assert np.shape(km_slab(1.0, 1.0, 1.0)[0]) == ()


@pytest.mark.parametrize("bad", [-0.1, float("nan")])
def test_bad_thickness_K_S_and_load(bad):
    c = polymer_constituents(GRID_31)
    with pytest.raises(SpecrefError, match=r"km_slab: d \(thickness, mm\)"):
        km_slab(1.0, 1.0, bad)
    with pytest.raises(SpecrefError, match=r"km_slab: K"):
        km_slab(bad, 1.0, 1.0)
    with pytest.raises(SpecrefError, match=r"km_slab: S"):
        km_slab(1.0, bad, 1.0)
    with pytest.raises(SpecrefError, match="polymer_K_S: tio2_pct"):
        polymer_K_S(c, bad)
    with pytest.raises(SpecrefError, match=r"km_invert: d \(thickness, mm\)"):
        km_invert(0.1, 0.2, bad)


def test_inversion_refuses_white_below_black():
    with pytest.raises(SpecrefError, match="over white must exceed reflectance over black"):
        km_invert(np.array([0.3, 0.4]), np.array([0.5, 0.35]), 1.0)
    with pytest.raises(SpecrefError, match="R_g_white must exceed R_g_black"):
        km_invert(0.3, 0.5, 1.0, R_g_black=0.5, R_g_white=0.4)


def test_constituents_file_errors(tmp_path):
    path = tmp_path / "c.toml"
    path.write_text("[base]\nindex = 1.5\n")
    with pytest.raises(SpecrefError, match=r"c.toml: missing table \[tio2\]"):
        polymer_constituents(GRID_31, path)
    text = DEFAULT_CONSTITUENTS.read_text()
    path.write_text(text.replace("index = 1.54", "index = 0.9"))
    with pytest.raises(SpecrefError, match=r"base\.index: must be a number in \[1, 3\]"):
        polymer_constituents(GRID_31, path)
    path.write_text(text.replace("index = 1.54", "index = 1"))
    with pytest.raises(SpecrefError, match=r"base\.index: must be > 1"):
        polymer_constituents(GRID_31, path)
    path.write_text(text.replace("K_0 = 0.02", "K_0 = -0.02"))
    with pytest.raises(SpecrefError, match=r"base\.K_0: must be a number in \[0, 10000\] \(1/mm\)"):
        polymer_constituents(GRID_31, path)
    # 1e308 made infinite K or S, refused by km_slab naming neither the file nor the key
    for key, value in (("S_exponent = 2.0", "S_exponent = 1e308"), ("K_0 = 0.02", "K_0 = 1e308")):
        path.write_text(text.replace(key, value))
        name = key.split()[0]
        with pytest.raises(SpecrefError, match=rf"c.toml: base\.{name}: must be a number in \["):
            polymer_constituents(GRID_31, path)


def test_shipped_constituents_look_like_hdpe_and_tio2():
    c = polymer_constituents()
    wl = c.grid.wavelengths_nm
    assert np.all(np.diff(c.K_base) < 0)  # absorption rising towards the blue: yellowish
    assert c.K_TiO2[wl == 380][0] > 100 * c.K_TiO2[wl == 450][0]  # the band gap below ~410 nm
    assert c.S_TiO2[wl == 560][0] > 10 * c.S_base[wl == 560][0]


def test_a_tint_is_a_dye_that_scales_the_opaque_reflectance(rng):
    # Source: Kubelka & Munk's closed forms. The dye keeps S and sets K so that R_∞ is tint times
    # the untinted R_∞; then a thick slab (km_slab at d → ∞) reflects that, and a thin one
    # transmits less than untinted (the dye absorbs on the way through).
    from shrm.polymer.kubelka_munk import km_R_infinity, km_slab, km_tinted_K, polymer_K_S

    K, S = polymer_K_S(polymer_constituents(), 0.5)
    tint = rng.uniform(0.05, 1.0, K.shape)
    K_t = km_tinted_K(K, S, tint)
    np.testing.assert_allclose(km_R_infinity(K_t, S), tint * km_R_infinity(K, S), rtol=1e-12)
    assert (K_t >= K).all()
    np.testing.assert_array_equal(km_tinted_K(K, S, 1.0), K)
    R_thick, _ = km_slab(K_t, S, 1e3)
    np.testing.assert_allclose(R_thick, tint * km_R_infinity(K, S), rtol=1e-9)
    _, T_thin = km_slab(K_t, S, 0.2)
    _, T_clear = km_slab(K, S, 0.2)
    assert (T_thin <= T_clear + 1e-15).all()
    # with the front surface (Saunderson): the opaque chip's reflectance seen from outside is
    # what the tint scales, as the hybrid's tint scales its diffuse term
    r = 0.6

    def outside(K_):
        R = km_R_infinity(K_, S)
        return (1 - r) * R / (1 - r * R)

    np.testing.assert_allclose(outside(km_tinted_K(K, S, tint, r)), tint * outside(K), rtol=1e-12)
    # no scattering: no body to tint; tint 0: held at the smallest opaque reflectance
    np.testing.assert_array_equal(km_tinted_K([0.3], [0.0], [0.5]), [0.3])
    assert np.isfinite(km_tinted_K(K, S, 0.0)).all()


@pytest.mark.parametrize("tint", [-0.1, 1.5, np.nan])
def test_a_tint_outside_0_1_is_refused(tint):
    from shrm.polymer.kubelka_munk import km_tinted_K

    with pytest.raises(SpecrefError, match="km_tinted_K: tint"):
        km_tinted_K([0.1], [10.0], [tint])

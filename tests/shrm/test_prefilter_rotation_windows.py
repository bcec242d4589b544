import numpy as np
import pytest

from reference.cubemap import cubemap_texel_directions
from reference.errors import SpecrefError
from reference.images import read_hdr
from shrm.prefilter import (
    BRUTEFORCE_METHODS,
    adaptive_order,
    kernel_table,
    lambert_Lambda_closed_form,
    parse_kernel,
    phong_Lambda_gaussian,
    prefilter_bruteforce,
    prefilter_coefficients,
    prefilter_environment,
)
from shrm.rotation import rotate_coefficients, rotation_matrix, sh_rotation_blocks
from shrm.sh import project_latlong, sh_evaluate, synthesize_latlong
from shrm.windows import apply_window, parse_window, ringing_statistics, window_gaussian
from validation.oracles import lambert_Lambda_mp, phong_Lambda_mp


def test_lambert_Lambda_closed_form_and_mpmath():
    # Source: Ramamoorthi & Hanrahan 2001, Eq. (8) (closed form) and mpmath quadrature.
    quad = parse_kernel("lambert").Lambda(40)
    np.testing.assert_allclose(quad, lambert_Lambda_closed_form(40), rtol=1e-12, atol=1e-14)
    for l in (0, 1, 2, 4, 10):
        assert abs(quad[l] - lambert_Lambda_mp(l)) <= 1e-12 * max(1.0, abs(quad[l]))


@pytest.mark.parametrize("s", [1.0, 32.0, 7.5])
def test_phong_Lambda_matches_mpmath(s):
    # Source: mpmath quadrature of (s+1) ∫ t^s P_l(t) dt, 50 dps.
    Lam = parse_kernel(f"phong:{s}").Lambda(20)
    for l in (0, 1, 5, 20):
        assert abs(Lam[l] - phong_Lambda_mp(l, s)) <= 1e-12


def test_gaussian_approximation_is_percent_level_off():
    # exp(-l²/2s) is the textbook approximation; exact Λ_l differ by a few percent at moderate l.
    exact = parse_kernel("phong:32").Lambda(30)
    approx = phong_Lambda_gaussian(32, 30)
    assert np.abs(approx - exact).max() > 0.01


def test_adaptive_order_lambert_is_cheap():
    assert adaptive_order("lambert", 1e-2) < 20 < adaptive_order("phong:256", 1e-2) < 100


@pytest.mark.parametrize(
    ("kernel", "bound"), [("phong:32", 1e-11), ("phong:256", 2e-9), ("lambert", 5e-4)]
)
def test_frequency_matches_bruteforce_at_L100(kernel, bound, shared_data):
    # Same Fejér-1 weights: the two differ only by the kernel's truncation at L = 100 (addition
    # theorem). Bounds are the targets, on venice_sunset (downsampled 4×, one channel).
    image = read_hdr(shared_data / "environments" / "venice_sunset_1k.hdr")[::4, ::4, :1].copy()
    d = cubemap_texel_directions(8)
    coeffs = prefilter_coefficients(project_latlong(image, 100), parse_kernel(kernel).Lambda(100))
    frequency = sh_evaluate(coeffs, d, backend="numba")
    brute = prefilter_bruteforce(image, kernel, d)
    assert np.abs(frequency - brute).max() / np.abs(brute).max() <= bound


@pytest.mark.parametrize("method", BRUTEFORCE_METHODS.values(), ids=lambda m: m.name)
def test_bruteforce_twins(method, rng, tmp_path):
    if method.example_inputs is None:
        path = tmp_path / "lobe.csv"
        path.write_text("angle_rad,value\n0,1\n0.5,0.6\n1.2,0.0\n")
        d = rng.normal(size=(5, 3))
        args = (
            rng.random((8, 16, 2)),
            kernel_table(path),
            d / np.linalg.norm(d, axis=-1, keepdims=True),
        )
    else:
        args = method.example_inputs(rng)
    np.testing.assert_allclose(
        prefilter_bruteforce(*args, backend="numba"),
        prefilter_bruteforce(*args, backend="numpy"),
        rtol=1e-12,
        atol=1e-14,
    )


def test_table_kernel_matches_phong_lobe(tmp_path):
    # A finely tabulated cos^4 lobe reproduces the analytic Λ_l (quadrature vs closed lobe).
    g = np.linspace(0, np.pi / 2, 2001)
    path = tmp_path / "cos4.csv"
    path.write_text(
        "angle_rad,value\n"
        + "\n".join(f"{float(a)!r},{float(5 / (2 * np.pi) * np.cos(a) ** 4)!r}" for a in g)
    )
    np.testing.assert_allclose(
        kernel_table(path).Lambda(8), parse_kernel("phong:4").Lambda(8), atol=2e-6
    )


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("angle_rad,value\n0,1\n4,1\n", "at most π"),
        ("angle_rad,value\n0.1,1\n1,1\n", "from 0"),
        ("angle_rad,value\n0,1\n1,-1\n", ">= 0"),
        ("angle_rad,value\n0,1\nx,y\n", "row 3"),
    ],
)
def test_kernel_table_bad_input(text, message, tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(SpecrefError, match=message):
        kernel_table(path)


@pytest.mark.parametrize(
    ("spec", "message"), [("ward", "unknown kernel"), ("phong", "needs"), ("phong:x", "number")]
)
def test_parse_kernel_bad(spec, message):
    with pytest.raises(SpecrefError, match=message):
        parse_kernel(spec)


def test_prefilter_environment_white_furnace():
    # Uniform radiance 1: irradiance π everywhere, Phong map 1 (Λ_0 = 1).
    image = np.ones((32, 64, 2))
    assert np.allclose(prefilter_environment(image, "lambert", size=4).values, np.pi, atol=1e-12)
    assert np.allclose(prefilter_environment(image, "phong:10", size=4).values, 1.0, atol=1e-12)
    with pytest.raises(SpecrefError, match=">= 0"):
        prefilter_environment(-image, "lambert")


def test_rotation_matches_projection_of_rotated_map_L100(rng):
    # Source: projecting the rotated band-limited map (Fejér-1 exact for 2L < H).
    L, H = 100, 202
    c = rng.normal(size=(1, (L + 1) ** 2)) / (L + 1)
    R = rotation_matrix([0.3, -0.5, 0.8], 2.2)
    from reference.envmap import latlong_pixel_directions

    d = latlong_pixel_directions(H, 2 * H)
    rotated = project_latlong(sh_evaluate(c, d @ R, backend="ducc0"), L, backend="ducc0")
    assert np.abs(rotate_coefficients(c, R) - rotated).max() < 1e-11


def test_rotation_composes_and_inverts(rng):
    L = 30
    c = rng.normal(size=(2, (L + 1) ** 2))
    R1, R2 = rotation_matrix([1, 2, 3], 1.3), rotation_matrix([-2, 0, 1], 2.9)
    np.testing.assert_allclose(
        rotate_coefficients(rotate_coefficients(c, R2), R1),
        rotate_coefficients(c, R1 @ R2),
        atol=1e-12,
    )
    np.testing.assert_allclose(rotate_coefficients(rotate_coefficients(c, R1), R1.T), c, atol=1e-12)
    for D in sh_rotation_blocks(R1, L):
        np.testing.assert_allclose(D @ D.T, np.eye(D.shape[0]), atol=1e-13)
    with pytest.raises(SpecrefError, match="orthogonal"):
        rotate_coefficients(c, 2 * np.eye(3))


def test_windows_and_ringing(shared_data):
    # The default Gaussian window (σ = π/L) leaves no negative pixel on venice_sunset at L = 100;
    # the plain truncation rings below zero.
    image = read_hdr(shared_data / "environments" / "venice_sunset_1k.hdr")
    c = project_latlong(image, 100, backend="ducc0")
    none = ringing_statistics(synthesize_latlong(c, 512, backend="ducc0"))
    gauss = ringing_statistics(
        synthesize_latlong(apply_window(c, "gaussian"), 512, backend="ducc0")
    )
    assert none["negative_share"] > 0.01
    assert gauss["negative_share"] == 0.0
    assert window_gaussian(100)[1] == pytest.approx(np.exp(-((np.pi / 100) ** 2)))
    with pytest.raises(SpecrefError, match="unknown window"):
        parse_window("hamming")
    with pytest.raises(SpecrefError, match="no parameter"):
        parse_window("hanning:3")

"""MERL BRDF files (Matusik et al. 2003): layout, half/difference angles, lookup, CLI.

Two MERL files are written once for the module (35 MB each): a Lambertian with a different ρ per
channel and a metal-like GGX, both from closed forms written here or in
``reference.materials.isotropic``; the tests read them back and compare with the closed forms.
"""

import math

import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.materials.isotropic import brdf_ggx, isotropic_angles, isotropic_directions
from reference.materials.merl import (
    MERL_BYTES,
    MERL_SCALES,
    MERLBRDF,
    brdf_merl,
    directions_to_half_diff,
    half_diff_to_directions,
    half_diff_to_merl_coordinates,
    merl_albedo,
    merl_to_brdf_table,
    read_merl_brdf,
    tabulate_merl,
    write_merl_brdf,
)
from reference.materials.table import brdf_tabulated, read_brdf_table
from validation.cli import main

Z = np.array([0.0, 0.0, 1.0])
RHO = np.array([0.2, 0.5, 0.8])
#: A metal-like GGX: a narrow lobe (α 0.15, peak 3.2 1/sr in red) over a dim diffuse base.
GGX = {"rho_d": np.array([0.05, 0.1, 0.2]), "F_0": np.array([0.9, 0.6, 0.3]), "alpha": 0.15}
N_BINS = 90 * 90 * 180


def lambertian(wi, wo, normal, rho):
    # Source: closed form, Lambert's BRDF ρ/π above the horizon, 0 below.
    above = (wi @ normal > 0) & (wo @ normal > 0)
    return np.where(above[..., None], np.asarray(rho) / np.pi, 0.0)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("merl")
    return {
        "lambert": write_merl_brdf(folder / "lambert.binary", lambertian, {"rho": RHO}),
        "ggx": write_merl_brdf(folder / "ggx.binary", brdf_ggx, GGX),
    }


@pytest.fixture(scope="module")
def lambert(files):
    return read_merl_brdf(files["lambert"])


@pytest.fixture(scope="module")
def ggx(files):
    return read_merl_brdf(files["ggx"])


def _upper(rng, n, max_deg=89.0):
    """Random direction pairs above the horizon, θ up to ``max_deg``, any azimuths."""
    theta = np.arccos(rng.uniform(np.cos(np.radians(max_deg)), 1.0, (2, n)))
    phi = rng.uniform(0.0, 2 * np.pi, (2, n))
    wi, wo = (
        np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)
        for t, p in zip(theta, phi, strict=True)
    )
    return wi, wo


def _random_rotation(rng):
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q * np.linalg.det(q)


# --- half/difference angles --------------------------------------------------------------------


def test_half_diff_closed_forms_in_the_plane_of_incidence():
    # Source: closed form. ω_i at θ_a on one side of the normal, ω_o at θ_b < θ_a on the other:
    # h lies (θ_a − θ_b)/2 from the normal, ω_i is (θ_a + θ_b)/2 from h, on h's far side (φ_d 0).
    a, b = np.radians([50.0, 70.0, 10.0]), np.radians([20.0, 70.0, 0.0])
    wi = np.stack([np.sin(a), 0 * a, np.cos(a)], -1)
    wo = np.stack([-np.sin(b), 0 * b, np.cos(b)], -1)
    theta_h, theta_d, phi_d = directions_to_half_diff(wi, wo)
    np.testing.assert_allclose(theta_h, (a - b) / 2, atol=1e-14)
    np.testing.assert_allclose(theta_d, (a + b) / 2, atol=1e-14)
    np.testing.assert_allclose(phi_d[theta_h > 0], 0.0, atol=1e-14)
    # The retro-reflection pair ω_i = ω_o: θ_d = 0, θ_h = θ_i.
    theta_h, theta_d, _ = directions_to_half_diff(wi, wi)
    np.testing.assert_allclose([theta_h, theta_d], [a, 0 * a], atol=1e-7)


def test_half_diff_round_trips_and_is_frame_independent(rng):
    n = 2000
    angles = (
        rng.uniform(0, np.pi / 2, n),
        rng.uniform(0, np.pi / 2, n),
        rng.uniform(-np.pi, np.pi, n),
    )
    back = directions_to_half_diff(*half_diff_to_directions(*angles))
    np.testing.assert_allclose(np.array(back), np.array(angles), atol=1e-12)
    # Directions → angles → directions gives the pair back up to a rotation about the normal.
    wi, wo = _upper(rng, n)
    wi2, wo2 = half_diff_to_directions(*directions_to_half_diff(wi, wo))
    np.testing.assert_allclose(
        np.array(isotropic_angles(wi2, wo2, Z)), np.array(isotropic_angles(wi, wo, Z)), atol=1e-7
    )
    # θ_h and θ_d against their definitions; all three unchanged in a rotated frame.
    h = (wi + wo) / np.linalg.norm(wi + wo, axis=-1, keepdims=True)
    theta_h, theta_d, phi_d = directions_to_half_diff(wi, wo)
    np.testing.assert_allclose(np.cos(theta_h), h[:, 2], atol=1e-14)
    np.testing.assert_allclose(np.cos(theta_d), np.sum(wi * h, -1), atol=1e-14)
    R = _random_rotation(rng)
    rotated = directions_to_half_diff(wi @ R.T, wo @ R.T, R @ Z)
    np.testing.assert_allclose(np.array(rotated[:2]), np.array([theta_h, theta_d]), atol=1e-12)
    wrapped = np.angle(np.exp(1j * (rotated[2] - phi_d)))
    np.testing.assert_allclose(wrapped, 0.0, atol=1e-9)
    # Reciprocity: exchanging ω_i and ω_o keeps θ_h, θ_d and turns φ_d into φ_d ± π.
    swapped = directions_to_half_diff(wo, wi)
    np.testing.assert_allclose(np.array(swapped[:2]), np.array([theta_h, theta_d]), atol=1e-14)
    np.testing.assert_allclose(np.cos(swapped[2] - phi_d), -1.0, atol=1e-12)


def test_shapes_broadcast():
    wi, wo = half_diff_to_directions(np.zeros((2, 1)), np.full(4, 0.3), 0.0)
    assert wi.shape == wo.shape == (2, 4, 3)
    assert all(a.shape == (2, 4) for a in directions_to_half_diff(wi, wo))
    m = MERLBRDF(np.full((90, 90, 180, 3), 0.1))
    assert brdf_merl(Z, Z, Z, m).shape == (3,)
    assert brdf_merl(wi, wo, Z, m).shape == (2, 4, 3)


# --- the file's layout, against MERL's own reader -----------------------------------------------


def _brdfread_lookup(raw, theta_in, fi_in, theta_out, fi_out):
    """BRDFRead.cpp's ``lookup_brdf_val``, step by step as MERL's reader does it, one pair."""

    def rotate_vector(v, axis, angle):
        # Rodrigues: v cos + axis (axis·v)(1 − cos) + (axis × v) sin
        v, axis = np.asarray(v), np.asarray(axis)
        c, s = math.cos(angle), math.sin(angle)
        return v * c + axis * (axis @ v) * (1 - c) + np.cross(axis, v) * s

    def direction(theta, fi):
        sin = math.sin(theta)
        return np.array([sin * math.cos(fi), sin * math.sin(fi), math.cos(theta)])

    in_vec, out_vec = direction(theta_in, fi_in), direction(theta_out, fi_out)
    half = (in_vec + out_vec) / np.linalg.norm(in_vec + out_vec)
    theta_half, fi_half = math.acos(half[2]), math.atan2(half[1], half[0])
    temp = rotate_vector(in_vec, [0.0, 0.0, 1.0], -fi_half)
    diff = rotate_vector(temp, [0.0, 1.0, 0.0], -theta_half)
    theta_diff, fi_diff = math.acos(diff[2]), math.atan2(diff[1], diff[0])
    i_h = min(max(int(math.sqrt(theta_half / (math.pi / 2) * 90 * 90)), 0), 89)
    i_d = min(max(int(theta_diff / (math.pi / 2) * 90), 0), 89)
    if fi_diff < 0:
        fi_diff += math.pi
    i_p = min(max(int(fi_diff / math.pi * 180), 0), 179)
    index = i_p + i_d * 180 + i_h * 180 * 90
    return np.array([raw[index + c * N_BINS] for c in range(3)]) * MERL_SCALES


def test_nearest_lookup_equals_merls_reader(files, ggx, rng):
    # Source: MERL's BRDFRead.cpp (read_brdf, lookup_brdf_val, the three index functions),
    # ported above as scalar code on the raw bytes: the layout, the channel order, the scales and
    # the bins agree exactly.
    raw = np.fromfile(files["ggx"], dtype="<f8", offset=12)
    assert np.fromfile(files["ggx"], dtype="<i4", count=3).tolist() == [90, 90, 180]
    theta = np.arccos(rng.uniform(0.05, 1.0, (2, 400)))
    fi = rng.uniform(0, 2 * np.pi, (2, 400))
    pairs = zip(theta[0], fi[0], theta[1], fi[1], strict=True)
    expected = np.array([_brdfread_lookup(raw, *p) for p in pairs])
    wi, wo = (
        np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)
        for t, p in zip(theta, fi, strict=True)
    )
    got = brdf_merl(wi, wo, Z, ggx, "nearest")
    has_data = (expected >= 0).all(axis=1)
    assert has_data.mean() > 0.95
    np.testing.assert_array_equal(got[has_data], expected[has_data])
    # BRDFRead.cpp's bins are floor(u) of the continuous coordinates.
    u = half_diff_to_merl_coordinates(*directions_to_half_diff(wi, wo))
    assert all((c >= 0).all() for c in u)


def test_values_at_bin_centres_are_the_analytic_brdf(files, ggx, rng):
    # Source: the GGX of reference.materials.isotropic (Eq. (20), Walter et al. 2007) at the bin
    # centres u = k + ½, inverted here from BRDFRead.cpp's index functions.
    raw = np.fromfile(files["ggx"], dtype="<f8", offset=12).reshape(3, 90, 90, 180)
    k_h, k_d, k_p = rng.integers(0, 90, 300), rng.integers(0, 90, 300), rng.integers(0, 180, 300)
    theta_h = (np.pi / 2) * ((k_h + 0.5) / 90) ** 2
    theta_d, phi_d = (np.pi / 2) * (k_d + 0.5) / 90, np.pi * (k_p + 0.5) / 180
    wi, wo = half_diff_to_directions(theta_h, theta_d, phi_d)
    above = (wi[:, 2] > 0) & (wo[:, 2] > 0)
    exact = brdf_ggx(wi, wo, Z, **GGX)
    stored = raw[:, k_h, k_d, k_p].T * MERL_SCALES
    np.testing.assert_allclose(stored[above], exact[above], rtol=1e-15)
    np.testing.assert_array_equal(raw[:, k_h[~above], k_d[~above], k_p[~above]], -1.0)
    # The trilinear lookup at a centre returns that bin (weights 0 or 1 up to round-off).
    np.testing.assert_allclose(brdf_merl(wi, wo, Z, ggx)[above], exact[above], rtol=1e-10)


# --- golden values between the bins --------------------------------------------------------------


def test_lambertian_read_back_is_rho_over_pi(lambert, rng):
    # Source: closed form ρ/π. Every pair above the horizon has a bin with data among its eight
    # neighbours, and renormalized trilinear weights reproduce a constant exactly.
    wi, wo = _upper(rng, 20000, max_deg=89.9)
    np.testing.assert_allclose(
        brdf_merl(wi, wo, Z, lambert), np.broadcast_to(RHO / np.pi, (20000, 3)), rtol=1e-12
    )
    assert (brdf_merl(-wi, wo, Z, lambert) == 0).all()


def _cell_corners(wi, wo):
    """The analytic GGX at the eight bin centres around each pair, and which have data.

    The corners are the bin centres ``u = k + ½`` next to the pair's coordinates (clamped in θ,
    periodic in φ_d): one bin apart, i.e. Δθ_h = π(k + 1)/8100 (0.02° near the peak to 2° at
    grazing half vectors), Δθ_d = 1°, Δφ_d = 1°.
    """
    theta_h, theta_d, phi_d = directions_to_half_diff(wi, wo)
    # BRDFRead.cpp's coordinates, continuous
    s_h = 90 * np.sqrt(theta_h / (np.pi / 2)) - 0.5
    s_d = 90 * theta_d / (np.pi / 2) - 0.5
    s_p = 180 * np.mod(phi_d, np.pi) / np.pi - 0.5
    low_h = np.minimum(np.floor(np.clip(s_h, 0, 89)), 88)
    low_d = np.minimum(np.floor(np.clip(s_d, 0, 89)), 88)
    low_p = np.floor(s_p)
    values, valid = [], []
    for k_h in (low_h, low_h + 1):
        for k_d in (low_d, low_d + 1):
            for k_p in (low_p, low_p + 1):
                corner = half_diff_to_directions(
                    (np.pi / 2) * ((k_h + 0.5) / 90) ** 2,
                    (np.pi / 2) * (k_d + 0.5) / 90,
                    np.pi * (np.mod(k_p, 180) + 0.5) / 180,
                )
                values.append(brdf_ggx(*corner, Z, **GGX))
                valid.append((corner[0][:, 2] > 0) & (corner[1][:, 2] > 0))
    return np.array(values), np.array(valid)


def test_trilinear_is_within_the_bin_quantization_bound(ggx, rng):
    # Source: the GGX closed form (Eq. (20), Walter et al. 2007). The read-back is a convex
    # combination of the BRDF at the eight bin centres around the pair, so it differs from the
    # BRDF at the pair by at most the largest difference between the BRDF there and at those
    # centres, one bin width away (_cell_corners): the quantization bound of the MERL grid.
    wi, wo = _upper(rng, 4000, max_deg=85.0)
    exact = brdf_ggx(wi, wo, Z, **GGX)
    corners, valid = _cell_corners(wi, wo)
    spread = np.where(valid[..., None], np.abs(corners - exact), 0.0).max(axis=0)
    error = np.abs(brdf_merl(wi, wo, Z, ggx) - exact)
    assert (error <= spread + 1e-12 * exact).all()
    # Measured here (θ up to 85°): relative error median 6.3e-4, 90th percentile 2.2e-3, largest
    # 1.6 %; BRDFRead.cpp's nearest bin: median 7.0e-3, largest 12 %.
    relative = error / exact
    assert np.median(relative) < 2e-3
    assert relative.max() < 0.05
    nearest = np.abs(brdf_merl(wi, wo, Z, ggx, "nearest") - exact) / exact
    assert np.median(nearest) > 5 * np.median(relative)


def test_reciprocity(ggx, rng):
    wi, wo = _upper(rng, 5000)
    for interpolation in ("trilinear", "nearest"):
        f, g = (brdf_merl(a, b, Z, ggx, interpolation) for a, b in ((wi, wo), (wo, wi)))
        # Trilinear is continuous, so ±1 ulp of φ_d moves it by ~1e-14; nearest can switch bins
        # when φ_d lands on a bin edge, which random pairs do not.
        np.testing.assert_allclose(f, g, rtol=1e-12)


def _albedo_gauss_legendre(f, theta_i, order):
    """∫ f cos θ_o dω_o: Gauss–Legendre in μ = cos θ_o on [0, 1] × the midpoint rule in φ."""
    x, w = np.polynomial.legendre.leggauss(order)
    mu, w_mu = (x + 1) / 2, w / 2
    phi = 2 * np.pi * (np.arange(4 * order) + 0.5) / (4 * order)
    wi, wo = isotropic_directions(theta_i, np.arccos(mu)[:, None], phi[None, :])
    values = f(np.broadcast_to(wi, wo.shape), wo)
    return np.einsum("tpc,t->c", values, w_mu * mu) * 2 * np.pi / phi.size


def test_white_furnace_of_the_read_back_lambertian(lambert, rng):
    # Source: closed form, the albedo of a Lambertian is ρ at every incidence.
    for theta_deg in (0.0, 30.0, 60.0, 85.0):
        theta_i = np.radians(theta_deg)

        def f(wi, wo):
            return brdf_merl(wi, wo, Z, lambert)

        a1, a2 = (_albedo_gauss_legendre(f, theta_i, k) for k in (24, 48))
        # Quadrature error estimated by doubling the order: 0 to round-off (f is constant).
        np.testing.assert_allclose(a2, RHO, atol=np.abs(a2 - a1).max() + 1e-12)
        np.testing.assert_allclose(merl_albedo(lambert, theta_i), RHO, rtol=1e-12)
        # With cosine-weighted samples, f cos θ / pdf = π f: mean ρ within 5 σ̂/√N.
        u = rng.random((2, 4096))
        r, p = np.sqrt(u[0]), 2 * np.pi * u[1]
        wo = np.stack([r * np.cos(p), r * np.sin(p), np.sqrt(1 - u[0])], -1)
        wi = np.array([np.sin(theta_i), 0.0, np.cos(theta_i)])
        samples = np.pi * f(np.broadcast_to(wi, wo.shape), wo)
        sigma = samples.std(axis=0, ddof=1) / np.sqrt(u.shape[1])
        assert (np.abs(samples.mean(axis=0) - RHO) <= 5 * sigma + 1e-12).all()


# --- into rendering ------------------------------------------------------------------------------


def test_table_conversion_error_on_the_analytic_brdf(ggx, rng):
    # Source: the GGX closed form. The table (trilinear in θ_i, θ_o, Δφ) of the read-back MERL
    # BRDF; its error falls with the steps. Measured (θ up to 80°): relative error median 8.1e-3
    # at 5°/15°, 1.6e-3 at 2°/4° (90th percentile 0.8 %, largest 30-60 % on the lobe's peak,
    # which a 2° step does not resolve for α = 0.15).
    wi, wo = _upper(rng, 3000, max_deg=80.0)
    exact = brdf_ggx(wi, wo, Z, **GGX)
    medians = []
    for theta_step, phi_step in ((5.0, 15.0), (2.0, 4.0)):
        table = merl_to_brdf_table(ggx, np.eye(3), [450.0, 550.0, 650.0], theta_step, phi_step)
        relative = np.abs(brdf_tabulated(wi, wo, Z, table) - exact) / exact
        medians.append(np.median(relative))
    assert medians[1] < 5e-3, medians
    assert medians[1] < medians[0] / 2, medians


def test_conversion_mixes_channels_into_bands(lambert):
    basis = np.array([[1.0, 0.0], [0.0, 2.0], [1.0, 1.0]])
    table = merl_to_brdf_table(lambert, basis, [500.0, 600.0], 45.0, 90.0)
    # Source: closed form ρ/π per channel, times the matrix.
    np.testing.assert_allclose(table.values[0, 1, 2], RHO / np.pi @ basis, rtol=1e-12)
    assert table.values.shape == (3, 3, 3, 2)
    assert table.name == "lambert"
    with pytest.raises(SpecrefError, match=r"RGB_to_bands: must have shape \(3, C\)"):
        merl_to_brdf_table(lambert, np.eye(2), [500.0, 600.0])
    with pytest.raises(SpecrefError, match="theta step: must divide 90 degrees, got 7"):
        merl_to_brdf_table(lambert, np.eye(3), [1.0, 2.0, 3.0], 7.0)
    with pytest.raises(SpecrefError, match="at most 753,571"):
        merl_to_brdf_table(lambert, np.eye(3), [1.0, 2.0, 3.0], 0.5, 1.0)


# --- bad input ------------------------------------------------------------------------------------


def _header(dims=(90, 90, 180)):
    return np.array(dims, dtype="<i4").tobytes()


@pytest.mark.parametrize(
    ("case", "match"),
    [
        ("short", r"short\.binary: truncated MERL BRDF: 8 bytes, shorter than its 12-byte header"),
        ("dims", r"dims\.binary: MERL header: dimensions \(90, 90, 360\); a MERL BRDF has"),
        ("truncated", r"truncated\.binary: 8,012 bytes; .* has 34,992,012 .*: truncated$"),
        ("extra", r"extra\.binary: 34,992,020 bytes; .*: extra bytes at the end$"),
        ("nan", r"nan\.binary: 2 NaN or infinite values .*first: green, theta_h bin 3, theta_d"),
        ("negative", r"negative\.binary: no MERL value with data \(all are negative\)"),
        # 1e308 was read (brdf check printed an albedo of 300 digits)
        (
            "huge",
            r"huge\.binary: albedo at normal incidence 2\.094e\+305 in red; .*\(<= 1\.5 allowed",
        ),
        ("bright", r"bright\.binary: albedo at normal incidence 2 in red"),
        ("missing", r"missing\.binary: file not found"),
        ("folder", r"folder\.binary: unreadable MERL BRDF"),
    ],
)
def test_bad_files_give_one_line_naming_the_file(files, tmp_path, case, match):
    path = tmp_path / f"{case}.binary"
    good = files["lambert"].read_bytes()
    if case == "short":
        path.write_bytes(_header()[:8])
    elif case == "dims":
        path.write_bytes(_header((90, 90, 360)) + b"\0" * 64)
    elif case == "truncated":
        path.write_bytes(good[:8012])
    elif case == "extra":
        path.write_bytes(good + b"\0" * 8)
    elif case == "nan":
        values = np.frombuffer(good, "<f8", offset=12).reshape(3, 90, 90, 180).copy()
        values[1, 3, 4, 5] = np.nan
        values[2, 0, 0, 0] = np.inf
        path.write_bytes(_header() + values.tobytes())
    elif case == "negative":
        path.write_bytes(_header() + np.full(3 * N_BINS, -1.0).tobytes())
    elif case == "huge":
        path.write_bytes(_header() + np.full(3 * N_BINS, 1e308).tobytes())
    elif case == "bright":  # a Lambertian BRDF of albedo 2 in every channel
        stored = np.broadcast_to((2.0 / np.pi / MERL_SCALES)[:, None], (3, N_BINS))
        path.write_bytes(_header() + np.ascontiguousarray(stored).tobytes())
    elif case == "folder":
        path.mkdir()
    with pytest.raises(SpecrefError, match=match) as error:
        read_merl_brdf(path)
    assert "\n" not in str(error.value)


def test_bad_values_and_arguments_are_refused(tmp_path):
    with pytest.raises(SpecrefError, match=r"values: must have shape \(90, 90, 180, 3\)"):
        MERLBRDF(np.ones((90, 90, 180)))
    with pytest.raises(SpecrefError, match="values: must be finite"):
        MERLBRDF(np.full((90, 90, 180, 3), np.nan))
    with pytest.raises(SpecrefError, match="unknown MERL interpolation 'cubic'"):
        brdf_merl(Z, Z, Z, MERLBRDF(np.zeros((90, 90, 180, 3))), "cubic")
    with pytest.raises(SpecrefError, match="merl: must be a MERLBRDF"):
        brdf_merl(Z, Z, Z, np.zeros((90, 90, 180, 3)))
    with pytest.raises(SpecrefError, match="must be finite and >= 0 above the horizon"):
        tabulate_merl(lambda wi, wo, n: -np.ones((*wi.shape[:-1], 1)))
    with pytest.raises(SpecrefError, match="must give 1 or 3 channels, got 2"):
        tabulate_merl(lambda wi, wo, n: np.ones((*wi.shape[:-1], 2)))
    assert not list(tmp_path.iterdir())


def test_write_read_round_trip_is_exact_for_values(tmp_path, rng):
    values = rng.uniform(0.0, 0.3, (90, 90, 180, 3))  # albedo about 0.47: read back (<= 1.5)
    values[0, 0, :3] = -1.0  # no data
    path = write_merl_brdf(tmp_path / "r.binary", values)
    assert path.stat().st_size == MERL_BYTES
    back = read_merl_brdf(path)
    np.testing.assert_allclose(back.values, np.where(values >= 0, values, -MERL_SCALES), rtol=1e-15)
    assert back.name == "r"
    assert not list(tmp_path.glob(".*.tmp"))
    again = read_merl_brdf(write_merl_brdf(tmp_path / "s.binary", back))
    np.testing.assert_allclose(again.values, back.values, rtol=1e-15)


# --- the command line ---------------------------------------------------------------------------


def test_cli_check_and_convert(files, tmp_path, capsys):
    assert main(["brdf", "check", str(files["lambert"])]) == 0
    out = capsys.readouterr().out
    # Source: closed form, a Lambertian's albedo is ρ; the bins with data are those with both
    # directions above the horizon at the bin centre.
    assert "MERL BRDF" in out
    assert "of 1,458,000 bins with data" in out
    assert "albedo at normal incidence R 0.2000 G 0.5000 B 0.8000" in out
    table_path = tmp_path / "ggx.txt"
    argv = ["brdf", "convert", str(files["ggx"]), "-o", str(table_path)]
    assert main([*argv, "--theta-step", "30", "--phi-step", "90", "--step-nm", "100"]) == 0
    table = read_brdf_table(table_path)
    assert table.values.shape == (4, 4, 3, 5)
    np.testing.assert_array_equal(table.wavelengths_nm, [380.0, 480.0, 580.0, 680.0, 780.0])
    assert "wrote" in capsys.readouterr().out
    assert main(["brdf", "check", str(table_path)]) == 0


def test_cli_bad_merl_files_exit_2_in_one_line_and_write_nothing(files, tmp_path, capsys):
    bad = tmp_path / "bad.binary"
    bad.write_bytes(_header() + b"\0" * 80)
    out = tmp_path / "out.txt"
    for argv in (["brdf", "check", str(bad)], ["brdf", "convert", str(bad), "-o", str(out)]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1, err
        assert "bad.binary: 92 bytes" in err
        assert "Traceback" not in err
    assert not out.exists()
    # The write policy: the output may not be the input.
    before = files["ggx"].stat().st_mtime_ns
    assert main(["brdf", "convert", str(files["ggx"]), "-o", str(files["ggx"])]) == 2
    assert "is also an input of this command" in capsys.readouterr().err
    assert files["ggx"].stat().st_mtime_ns == before

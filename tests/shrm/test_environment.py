"""Tests of shrm.environment: spectral radiance, the Phong Λ_l and the environment shaders."""

from __future__ import annotations

import numpy as np
import pytest

from reference.colour.spectra import GRID_31, GRID_41
from reference.errors import SpecrefError
from reference.geometry.camera import Camera
from reference.geometry.gbuffer import render_gbuffer
from reference.geometry.shapes import Sphere
from reference.images.formats import read_hdr
from reference.materials.types import LambertMaterial, PhongMaterial
from reference.scene.lights import EnvironmentLight
from reference.scene.shading import SHADERS, ShadingContext, Surface, shade_gbuffer
from shrm.environment import (
    environment_spectral_radiance,
    phong_environment_Lambda,
    shade_lambert_environment,
    shade_phong_environment,
)
from validation.studies.oracles import phong_Lambda_mp


def _up_surface(n=1):
    up = np.tile([0.0, 1.0, 0.0], (n, 1))
    return Surface(np.zeros((n, 3)), up, up.copy(), np.zeros((n, 2)))


def test_environment_spectral_radiance_interpolates_spectral_maps():
    # Source: closed form. A map whose three bands (400, 550, 700 nm) lie on the line a + bλ is
    # interpolated linearly, so the grid gets that line, held constant beyond the map's bands.
    wl = np.array([400.0, 550.0, 700.0])
    line = lambda lam: 0.2 + 1e-3 * (lam - 400.0)  # noqa: E731
    image = np.broadcast_to(line(wl), (2, 4, 3)).copy()
    light = EnvironmentLight(image, wl, intensity=3.0)
    got = environment_spectral_radiance(light, GRID_41)
    assert got.shape == (2, 4, 41)
    lam = np.clip(GRID_41.wavelengths_nm, 400.0, 700.0)
    np.testing.assert_allclose(got, np.broadcast_to(3.0 * line(lam), got.shape), rtol=1e-13)


def test_environment_spectral_radiance_of_rgb_white_is_d65_shaped():
    # Source: colour-science's D65 (reference.colour.spectra dataset), normalized to Y = 1 on the
    # grid:
    # an RGB white texel v becomes v · D65(λ)/Y(D65) (Mallett 2019 basis, flat to 1e-5).
    from reference.colour.spectra import resample_spectrum, spectrum_from_dataset

    D = resample_spectrum(spectrum_from_dataset("illuminant", "D65"), GRID_31, "constant")
    from reference.colour.colorimetry import band_weights

    D = D / (D @ band_weights(GRID_31, None)[:, 1])
    got = environment_spectral_radiance(EnvironmentLight(np.full((2, 4, 3), 2.0)), GRID_31)
    np.testing.assert_allclose(got, np.broadcast_to(2.0 * D, got.shape), rtol=1e-4)


@pytest.mark.parametrize("n", [1.0, 8.0, 100.0])
def test_phong_environment_Lambda_matches_mpmath(n):
    # Source: mpmath, 50 dps (validation/studies/oracles.py: phong_Lambda_mp), times the 2/(n+1) of
    # the un-normalized lobe max(t, 0)^n / π.
    order = 6
    Lam = phong_environment_Lambda([n, n], order)
    assert Lam.shape == (2, order + 1)
    expected = [2.0 / (n + 1.0) * phong_Lambda_mp(l, n) for l in range(order + 1)]
    np.testing.assert_allclose(Lam[0], expected, rtol=1e-10, atol=1e-15)
    np.testing.assert_array_equal(Lam[0], Lam[1])


def test_environment_shaders_are_registered():
    assert SHADERS.lookup("LambertMaterial/EnvironmentLight").reference is shade_lambert_environment
    assert SHADERS.lookup("PhongMaterial/EnvironmentLight").reference is shade_phong_environment


def _uniform_sky(height: int, environment: str, k_d: float = 1.0, n: float = 3.0):
    """XYZ of a Lambertian (k_d) and a pure Phong (k_s = 1, exponent n) surface under L = 1."""
    env = EnvironmentLight(np.full((height, 2 * height, 3), 1.0))
    ctx = ShadingContext(options={"environment": environment})
    diffuse = shade_lambert_environment(_up_surface(), LambertMaterial(np.full(41, k_d)), env, ctx)
    phong = PhongMaterial(np.zeros(41), np.ones(41), np.full(41, n))
    return diffuse[0], shade_phong_environment(_up_surface(), phong, env, ctx)[0]


def test_white_furnace_under_a_uniform_sky():
    # Property: under a sky of uniform radiance L = 1, E = π, so k_d E/π = k_d; the Phong lobe
    # max(t, 0)^n/π integrates to 2/(n+1). The sky is a white RGB texel, i.e. D65 with Y = 1.
    # Source: colour-science's D65 white point (CIE 1931 2°); 2e-3: our 10 nm grid vs its table.
    import colour

    xy = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]
    white, specular = _uniform_sky(16, "frequency")
    assert white[1] == pytest.approx(1.0, rel=1e-9)  # ducc0 transforms: 1e-10 observed
    np.testing.assert_allclose(white, colour.xy_to_XYZ(xy), rtol=2e-3)
    np.testing.assert_allclose(specular, 2.0 / (3.0 + 1.0) * white, rtol=1e-9)
    half, _ = _uniform_sky(16, "frequency", k_d=0.5)
    np.testing.assert_allclose(half, 0.5 * white, rtol=1e-12)


def test_bruteforce_under_a_uniform_sky_converges():
    # The oracle integrates the map by pixel solid angles (a midpoint rule). Observed relative
    # errors of Y for H = 16, 32, 64: 3.2e-3, 8.0e-4, 2.0e-4, i.e. second order.
    errors = []
    for height in (16, 32):
        white, specular = _uniform_sky(height, "bruteforce")
        errors.append(abs(white[1] - 1.0))
        assert specular[1] == pytest.approx(0.5, rel=4 * errors[-1])
    assert errors[0] / errors[1] > 3.5
    assert errors[1] < 1e-3


def test_bruteforce_over_texels_is_the_white_furnace_at_any_height():
    # irradiance_quadrature = "texels": each texel's cosine integrated (shrm.texel_irradiance),
    # so a uniform sky gives k_d exactly however few rows the map has, where the Fejér brute
    # force above is off by 3.2e-3 at 16 rows
    env = EnvironmentLight(np.full((4, 8, 3), 1.0))
    up = _up_surface()
    lambert = LambertMaterial(np.full(41, 0.5))
    options = {"environment": "bruteforce"}
    fejer = shade_lambert_environment(up, lambert, env, ShadingContext(options=options))[0]
    options = {**options, "irradiance_quadrature": "texels"}
    texels = shade_lambert_environment(up, lambert, env, ShadingContext(options=options))[0]
    white, _ = _uniform_sky(16, "frequency")
    np.testing.assert_allclose(texels, 0.5 * white, rtol=1e-8)
    assert abs(fejer[1] / texels[1] - 1) > 1e-2
    from reference.scene.loader import loads_scene

    with pytest.raises(SpecrefError, match="irradiance_quadrature: unknown value 'exact'") as error:
        loads_scene('[render.options]\nirradiance_quadrature = "exact"\n')
    assert "\n" not in str(error.value)


def test_environment_shaders_frequency_vs_bruteforce(package_data):
    image = read_hdr(package_data / "environments" / "studio_small_03_1k.hdr")[::8, ::8].copy()
    env = EnvironmentLight(image, name="studio")
    g = render_gbuffer([Sphere()], Camera(eye=(0, 0, 5)), 12, 12)
    k = np.linspace(0.2, 0.8, 41)
    for material in (LambertMaterial(k), PhongMaterial(k, 0.5 * k, np.full(41, 20.0))):
        brute = shade_gbuffer(
            g, [material], [env], ShadingContext(options={"environment": "bruteforce"})
        )
        errors = []
        for tol in (1e-2, 1e-3):
            fast = shade_gbuffer(
                g, [material], [env], ShadingContext(options={"environment_tol": tol})
            )
            errors.append(np.abs(fast - brute).max() / brute.max())
        # The frequency path converges to the oracle as the adaptive order's tolerance falls; the
        # kernel's relative L2 tail bounds the error only on average, so allow 3× the tolerance.
        assert errors[1] < errors[0] / 4
        assert errors[0] <= 3e-2


def test_environment_shading_bad_input():
    env = EnvironmentLight(np.ones((4, 8, 3)))
    flat = Surface(np.zeros((1, 1, 3)), np.ones((1, 1, 3)), np.ones((1, 1, 3)), np.zeros((1, 1, 2)))
    with pytest.raises(SpecrefError, match=r"surface arrays must be \(N, 3\)"):
        shade_lambert_environment(flat, LambertMaterial(np.ones(41)), env, ShadingContext())
    with pytest.raises(SpecrefError, match="unknown RGB upsampling 'smits'"):
        environment_spectral_radiance(env, GRID_41, "smits")


@pytest.mark.parametrize(("placement", "H"), [("centred", 32), ("mitsuba", 32), ("mitsuba", 48)])
def test_texel_placement_changes_irradiance_as_predicted(placement, H):
    # Source: closed forms. Row j of a grey map holds theta_j = j pi/(H - 1). Read as Mitsuba 3
    # reads it (rows at v = j/(H-1), linear between them) the radiance is L(theta) = theta exactly;
    # read with specref's centred rows (theta = (j + 1/2) pi/H) it is (H theta - pi/2)/(H - 1).
    # Irradiance of L = theta: pi^2/4 at the +y normal, 3 pi^2/4 at -y (2 pi int theta |cos| sin);
    # of L = 1: pi. The two readings differ by (H - 2)/(H - 1) at +y. Brute force integrates the
    # map with exact pixel solid angles at centres (midpoint rule, error ~ (pi/H)^2/24 ~ 4e-4).
    theta = np.arange(H) * np.pi / (H - 1)
    image = np.broadcast_to(theta[:, None, None], (H, 2 * H, 3)).copy()
    light = EnvironmentLight(image, texel_placement=placement)
    normals = np.array([[0.0, 1.0, 0.0], [0.0, -1.0, 0.0]])
    surface = Surface(np.zeros((2, 3)), normals, normals.copy(), np.zeros((2, 2)))
    ctx = ShadingContext(options={"environment": "bruteforce"})
    Y = shade_lambert_environment(surface, LambertMaterial(np.ones(41)), light, ctx)[:, 1]
    E_theta = np.array([np.pi**2 / 4, 3 * np.pi**2 / 4])
    if placement == "mitsuba":
        expected = E_theta / np.pi  # Y = E/pi for a white Lambertian, radiance Y = L
    else:
        expected = (H * E_theta - np.pi / 2 * np.pi) / (H - 1) / np.pi
    np.testing.assert_allclose(Y, expected, rtol=2e-3)
    ratio_up = (H - 2) / (H - 1)  # centred over mitsuba at +y: 3 % at H = 32, well above 2e-3
    assert abs(ratio_up - 1) > 10 * 2e-3

import colour
import numpy as np
import pytest

from reference.colour.spectra import GRID_31, GRID_41, spectrum_from_dataset
from reference.errors import SpecrefError
from reference.geometry.camera import Camera
from reference.geometry.gbuffer import render_gbuffer
from reference.geometry.shapes import Sphere
from reference.materials.types import LambertMaterial, PhongMaterial
from reference.scene.lights import AmbientLight, PointLight
from reference.scene.shading import (
    SHADERS,
    ShadingContext,
    Surface,
    phong_cosines,
    phong_spectral_exact,
    shade_gbuffer,
)


def test_phong_cosines_against_reflection_geometry(rng):
    N = rng.normal(size=(200, 3))
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    L = rng.normal(size=(200, 3))
    L /= np.linalg.norm(L, axis=1, keepdims=True)
    V = rng.normal(size=(200, 3))
    V /= np.linalg.norm(V, axis=1, keepdims=True)
    cos_theta, t = phong_cosines(N, L, V)
    # Source: the mirror direction of L about N, built by Householder reflection.
    R = -(np.eye(3) - 2 * np.einsum("ni,nj->nij", N, N)) @ L[..., None]
    NL = (N * L).sum(1)
    lit = NL > 0
    np.testing.assert_allclose(cos_theta[lit], NL[lit], rtol=1e-14)
    np.testing.assert_allclose(t[lit], np.clip((R[..., 0] * V).sum(1), 0, 1)[lit], atol=1e-14)
    assert (cos_theta[~lit] == 0).all()
    assert (t[~lit] == 0).all()


def test_phong_spectral_exact_values_and_shapes(rng):
    k_d, k_s, n = rng.uniform(0, 1, 5), rng.uniform(0, 1, 5), rng.uniform(0, 100, 5)
    for shape in [(), (7,), (2, 3)]:
        c, t, f = (rng.uniform(0, 1, shape) for _ in range(3))
        out = phong_spectral_exact(c, t, k_d, k_s, n, f)
        assert out.shape == (*shape, 5)
        # Source: Eq. (2), Wang et al., one band at a time with math.pow.
        i = (0,) * len(shape)
        expected = [f[i] * (k_d[b] * c[i] + k_s[b] * float(t[i]) ** n[b]) for b in range(5)]
        np.testing.assert_allclose(out[i], expected, rtol=1e-13)


def test_phong_shader_matches_colour_sd_to_XYZ_per_pixel(rng):
    # The exact render against a direct colour-science evaluation of Eq. (2) on a few pixels.
    grid = GRID_41
    k_d, k_s = rng.uniform(0, 0.5, 41), rng.uniform(0, 0.5, 41)
    n = np.linspace(5, 500, 41)
    material = PhongMaterial(k_d, k_s, n)
    light = PointLight(
        (2.0, 3.0, 4.0), spectrum_from_dataset("illuminant", "D50"), 1.5, (1, 0.1, 0)
    )
    g = render_gbuffer([Sphere()], Camera(eye=(0, 0, 5), fov_deg=30), 16, 16)
    XYZ = shade_gbuffer(g, [material], [light], ShadingContext(grid))
    sd_light = colour.SDS_ILLUMINANTS["D50"]
    white = colour.sd_to_XYZ(
        colour.SpectralDistribution(np.ones(41), grid.wavelengths_nm),
        illuminant=sd_light,
        method="ASTM E308",
    )
    for j, i in [(8, 8), (5, 9), (10, 6)]:
        N, p, V = g.normal[j, i], g.position[j, i], g.view[j, i]
        Ldir = np.array([2.0, 3.0, 4.0]) - p
        dist = np.linalg.norm(Ldir)
        Ldir /= dist
        cos_theta = max(N @ Ldir, 0)
        R = 2 * (N @ Ldir) * N - Ldir
        t = min(max(R @ V, 0), 1) if cos_theta > 0 else 0.0
        f_att = min(1 / (1 + 0.1 * dist), 1)
        R_lambda = f_att * (k_d * cos_theta + k_s * t**n)
        sd = colour.SpectralDistribution(R_lambda, grid.wavelengths_nm)
        # Source: colour.sd_to_XYZ(ASTM E308), normalised so that the white diffuser has Y = 1.
        expected = 1.5 * colour.sd_to_XYZ(sd, illuminant=sd_light, method="ASTM E308") / white[1]
        np.testing.assert_allclose(XYZ[j, i], expected, rtol=1e-10)


def test_white_lambert_facing_light_has_light_white():
    grid = GRID_31
    light = PointLight((0.0, 0.0, 5.0), spectrum_from_dataset("illuminant", "A"), 2.0)
    s = Surface(
        np.zeros((1, 3)), np.array([[0.0, 0, 1]]), np.array([[0.0, 0, 1]]), np.zeros((1, 2))
    )
    XYZ = SHADERS.lookup("LambertMaterial/PointLight").reference(
        s, LambertMaterial(np.ones(31)), light, ShadingContext(grid)
    )
    # Source: CIE 015:2018 Table T.3, illuminant A white (x, y) = (0.44757, 0.40745), scaled to Y =
    # 2.
    assert XYZ[0, 1] == pytest.approx(2.0, rel=1e-12)
    np.testing.assert_allclose(colour.XYZ_to_xy(XYZ[0]), [0.44757, 0.40745], atol=1e-4)


def test_lights_add_linearly():
    g = render_gbuffer([Sphere()], Camera(eye=(0, 0, 5)), 12, 12)
    m = [PhongMaterial(np.full(41, 0.4), np.full(41, 0.3), np.full(41, 30.0), np.full(41, 0.1))]
    a = PointLight((3.0, 1.0, 4.0))
    b = PointLight((-2.0, 2.0, 3.0), spectrum_from_dataset("illuminant", "A"))
    amb = AmbientLight(intensity=0.3)
    both = shade_gbuffer(g, m, [a, b, amb])
    separate = shade_gbuffer(g, m, [a]) + shade_gbuffer(g, m, [b]) + shade_gbuffer(g, m, [amb])
    np.testing.assert_allclose(both, separate, rtol=1e-13, atol=1e-15)
    assert (both[~g.mask] == 0).all()


def test_shade_gbuffer_bad_input():
    g = render_gbuffer([Sphere()], Camera(), 4, 4)
    with pytest.raises(SpecrefError, match="has 31 bands but the grid 380-780/10 has 41"):
        shade_gbuffer(g, [LambertMaterial(np.ones(31))], [PointLight()])

    class Spotlight:
        pass

    with pytest.raises(SpecrefError, match="unknown shader 'LambertMaterial/Spotlight'"):
        shade_gbuffer(g, [LambertMaterial(np.ones(41))], [Spotlight()])

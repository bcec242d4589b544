import colour
import numpy as np
import pytest

from phong_table import SCENES, SpectralPhong, render_sphere
from phong_table.render import light_geometry, sphere_gbuffer
from phong_table.scenes import constant_material, highlight_point, spectral_phong_unit_peak
from reference.colour.spectra import DEFAULT_GRID


@pytest.mark.parametrize("scene", ["R1", "R3"])
def test_exact_render_matches_colour_sd_to_XYZ_per_pixel(scene):
    # independent oracle: colour.sd_to_XYZ (ASTM E308) of the per-pixel spectrum of Eq. (2), then
    # colour-science's sRGB matrix, on a few pixels
    model = SCENES.lookup(scene).build()
    image = render_sphere(model, "near", "exact", resolution=16)
    geometry = sphere_gbuffer("near", 16)
    ct, t, f_att = light_geometry(
        geometry.position,
        geometry.normal,
        geometry.view,
        model.light.position,
        model.light.attenuation,
    )
    m = model.material
    light = model.light.spectrum.meta["colour_sd"]
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    M = colour.RGB_COLOURSPACES["sRGB"].matrix_XYZ_to_RGB
    pixels = np.flatnonzero(geometry.gbuffer.mask.ravel())
    for k in (0, 57, 130, 200, pixels.size - 1):
        spectrum = f_att[k] * (m.k_d * ct[k] + m.k_s * t[k] ** m.n)
        sd = colour.SpectralDistribution(spectrum, DEFAULT_GRID.wavelengths_nm)
        XYZ = colour.sd_to_XYZ(sd, cmfs, light, method="ASTM E308") / 100.0
        expected = model.light.intensity * (M @ XYZ)
        got = image.reshape(-1, 3)[pixels[k]]
        np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-12)


def test_highlight_point_has_t_equal_1():
    p = highlight_point()
    light, eye = np.array([2.5, 3.0, 4.0]), np.array([0.0, 0.0, 4.5])
    _, t, _ = light_geometry(
        p[None], p[None], ((eye - p) / np.linalg.norm(eye - p))[None], light, [1, 0, 0]
    )
    assert t[0] == pytest.approx(1.0, abs=1e-12)


def test_unit_peak_normalisation():
    model = spectral_phong_unit_peak(np.full(41, 0.2), np.full(41, 0.5), np.full(41, 50.0), "A")
    assert float((model.diffuse_RGB + model.specular(1.0)).max()) == pytest.approx(1.0, rel=1e-12)
    assert isinstance(constant_material(3.0), SpectralPhong)

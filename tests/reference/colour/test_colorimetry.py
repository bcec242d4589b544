import colour
import numpy as np
import pytest

from reference.colour.colorimetry import (
    BAND_WEIGHT_METHODS,
    ROWS_PER_THREAD,
    XYZ_to_display_RGB,
    XYZ_to_Lab,
    XYZ_to_RGB_matrix,
    band_weights,
    band_weights_ASTM_E308,
    delta_E_00,
    display_RGB_to_XYZ,
    spectra_to_RGB_matrix,
    spectra_to_XYZ,
    white_XYZ,
)
from reference.colour.spectra import (
    GRID_31,
    GRID_41,
    SpectralGrid,
    make_spectrum,
    resample_spectrum,
    spectrum_from_dataset,
)
from reference.errors import SpecrefError
from validation.studies.metrics import colorchecker_delta_E

CMFS = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
PATCHES = colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"]
LIGHTS = ("D65", "A", "D50", "FL2")


@pytest.mark.parametrize("grid", [GRID_41, GRID_31], ids=["41", "31"])
@pytest.mark.parametrize("light", LIGHTS)
def test_band_weights_reproduce_colour_astm_e308_exactly(grid, light):
    W = band_weights(grid, spectrum_from_dataset("illuminant", light))
    sd_light = colour.SDS_ILLUMINANTS[light]
    for name, sd in PATCHES.items():
        R = resample_spectrum(make_spectrum(sd.wavelengths, sd.values, name), grid)
        sd10 = colour.SpectralDistribution(R, grid.wavelengths_nm)
        # Source: colour.sd_to_XYZ(method="ASTM E308") on the same 10 nm data (Y = 100 scale)
        expected = colour.sd_to_XYZ(sd10, CMFS, sd_light, method="ASTM E308")
        np.testing.assert_allclose(100 * spectra_to_XYZ(R, W), expected, rtol=0, atol=1e-9)


# Source of the targets: ours, for the band weights of erratum E7 (ΔE00 against colour.sd_to_XYZ
# on the native 5 nm N Ohta data).
TARGETS = {"D65": (0.03, 0.10), "A": (0.03, 0.10), "D50": (0.03, 0.10), "FL2": (0.06, 0.15)}


@pytest.mark.parametrize("grid", [GRID_41, GRID_31], ids=["41", "31"])
@pytest.mark.parametrize("light", LIGHTS)
def test_band_weights_accuracy_against_5nm_truth(grid, light):
    dE = colorchecker_delta_E(grid, light, "astm_e308")
    mean_max, max_max = TARGETS[light]
    assert dE.mean() <= mean_max
    assert dE.max() <= max_max


def test_colorchecker_delta_E_independent_recomputation():
    # The metric itself, recomputed directly with colour-science for one patch under FL2.
    grid, light = GRID_41, "FL2"
    sd_light = colour.SDS_ILLUMINANTS[light]
    sd = PATCHES["orange"]
    white = colour.sd_to_XYZ(
        colour.SpectralDistribution(np.ones(81), sd.wavelengths), CMFS, sd_light
    )
    truth = colour.sd_to_XYZ(sd, CMFS, sd_light)
    sd10 = colour.SpectralDistribution(sd.values[::2], sd.wavelengths[::2])
    mine = colour.sd_to_XYZ(sd10, CMFS, sd_light, method="ASTM E308")
    xy = colour.XYZ_to_xy(white)
    expected = colour.delta_E(
        colour.XYZ_to_Lab(mine / 100, xy), colour.XYZ_to_Lab(truth / 100, xy), method="CIE 2000"
    )
    index = list(PATCHES).index("orange")
    assert colorchecker_delta_E(grid, light)[index] == pytest.approx(expected, rel=1e-9)


@pytest.mark.parametrize("grid", [GRID_41, GRID_31], ids=["41", "31"])
def test_point_sampling_misses_fl2_lines(grid):
    # Erratum E7: point-sampled light × CMF misses FL2's mercury lines (E7: 4.0 mean, 9.0 max).
    dE_point = colorchecker_delta_E(grid, "FL2", "point")
    dE_e308 = colorchecker_delta_E(grid, "FL2", "astm_e308")
    assert dE_point.mean() > 3.0
    assert dE_point.max() > 7.0
    assert dE_e308.mean() < dE_point.mean() / 50


@pytest.mark.parametrize("method", BAND_WEIGHT_METHODS.values(), ids=lambda m: m.name)
@pytest.mark.parametrize("grid", [GRID_41, GRID_31, SpectralGrid(400, 700, 5)], ids=str)
def test_band_weights_white_has_Y_1(method, grid):
    W = band_weights(grid, spectrum_from_dataset("illuminant", "A"), method.name)
    assert W.shape == (grid.n_bands, 3)
    assert W[:, 1].sum() == pytest.approx(1.0, rel=1e-12)
    assert (W[:, 1] >= -1e-6).all()


def test_band_weights_white_matches_illuminant_chromaticity():
    # Source: CIE 015:2018 Table T.3, the chromaticity of illuminant A (x, y) = (0.44757, 0.40745).
    W = band_weights(GRID_41, spectrum_from_dataset("illuminant", "A"))
    xy = colour.XYZ_to_xy(white_XYZ(W))
    np.testing.assert_allclose(xy, [0.44757, 0.40745], atol=5e-5)


def test_band_weights_equal_energy_and_cache():
    W = band_weights(GRID_31, None)
    assert band_weights(GRID_31, None) is W
    assert not W.flags.writeable
    # Source: illuminant E has chromaticity (1/3, 1/3) by definition.
    np.testing.assert_allclose(colour.XYZ_to_xy(white_XYZ(W)), [1 / 3, 1 / 3], atol=2e-4)


def test_band_weights_10_degree_observer_differs():
    light = spectrum_from_dataset("illuminant", "D65")
    W2 = band_weights(GRID_41, light)
    W10 = band_weights(GRID_41, light, observer="CIE 1964 10 Degree Standard Observer")
    # Source: CIE 015:2018 Table T.3: D65 white (x, y) = (0.31382, 0.33100) for the 10° observer.
    np.testing.assert_allclose(colour.XYZ_to_xy(white_XYZ(W10)), [0.31382, 0.33100], atol=5e-5)
    assert not np.allclose(W2, W10)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"method": "gauss"}, "unknown band-weight method 'gauss'; allowed: astm_e308, point"),
        ({"observer": "CIE 2015"}, "unknown observer"),
        ({"grid": SpectralGrid(350, 780, 10)}, "practice range 360-780"),
        ({"grid": SpectralGrid(385, 775, 10)}, r"start on 360 \+ k·step"),
    ],
)
def test_band_weights_bad_input(kwargs, match):
    kwargs = {"grid": GRID_41, **kwargs}
    with pytest.raises(SpecrefError, match=match):
        band_weights(**kwargs)


def test_band_weights_ASTM_E308_equals_registry_dispatch():
    light = spectrum_from_dataset("illuminant", "D50")
    np.testing.assert_array_equal(
        band_weights_ASTM_E308(GRID_41, light), band_weights(GRID_41, light)
    )


@pytest.mark.parametrize("shape", [(41,), (7, 41), (2, 3, 41)])
def test_spectra_to_XYZ_shapes(rng, shape):
    W = band_weights(GRID_41, None)
    R = rng.uniform(0, 1, shape)
    XYZ = spectra_to_XYZ(R, W)
    assert XYZ.shape == (*shape[:-1], 3)
    # Linearity, element by element (a sum over bands).
    np.testing.assert_allclose(XYZ[..., 1], (R * W[:, 1]).sum(axis=-1), rtol=1e-13)


def test_spectra_to_XYZ_band_mismatch():
    with pytest.raises(SpecrefError, match="have \\(31,\\) bands but the weights have 41"):
        spectra_to_XYZ(np.ones(31), band_weights(GRID_41, None))


def test_spectra_to_XYZ_row_blocks_dtype_and_out(rng):
    # Two row blocks on two threads give the one-block product; float32 stays float32.
    W = band_weights(GRID_41, spectrum_from_dataset("illuminant", "D65"))
    spectra = rng.random((3, 2 * ROWS_PER_THREAD // 3 + 1, 41))
    one = spectra_to_XYZ(spectra, W, threads=1)
    np.testing.assert_allclose(spectra_to_XYZ(spectra, W, threads=2), one, rtol=1e-14, atol=0)
    np.testing.assert_allclose(one[1, 7], spectra[1, 7] @ W, rtol=1e-14)
    single = spectra_to_XYZ(spectra.astype(np.float32), W)
    assert single.dtype == np.float32
    np.testing.assert_allclose(single, one, rtol=2e-6)
    out = np.empty((3, spectra.shape[1], 3))
    assert spectra_to_XYZ(spectra, W, out=out) is out
    with pytest.raises(SpecrefError, match="out must be a C-contiguous float64"):
        spectra_to_XYZ(spectra, W, out=np.empty((3, 3)))
    with pytest.raises(SpecrefError, match="threads must be >= 1"):
        spectra_to_XYZ(spectra, W, threads=0)
    with pytest.raises(SpecrefError, match=r"weights must be \(n_bands, 3\)"):
        spectra_to_XYZ(spectra, W[:, :2])


def test_XYZ_to_RGB_matrix_is_IEC_sRGB():
    # Source: IEC 61966-2-1:1999, the XYZ to linear sRGB matrix (4 decimals as published).
    expected = np.array(
        [[3.2406, -1.5372, -0.4986], [-0.9689, 1.8758, 0.0415], [0.0557, -0.2040, 1.0570]]
    )
    np.testing.assert_allclose(XYZ_to_RGB_matrix("sRGB"), expected, atol=6e-5)


def test_XYZ_RGB_round_trip(rng):
    XYZ = rng.uniform(0, 1, (4, 5, 3))
    for space in ("sRGB", "Display P3", "Adobe RGB (1998)"):
        back = display_RGB_to_XYZ(XYZ_to_display_RGB(XYZ, space), space)
        np.testing.assert_allclose(back, XYZ, rtol=1e-12, atol=1e-14)


def test_chromatic_adaptation_maps_light_white_to_display_white():
    W = band_weights(GRID_41, spectrum_from_dataset("illuminant", "A"))
    white = white_XYZ(W)
    for transform in ("Bradford", "CAT02", "Von Kries"):
        RGB = XYZ_to_display_RGB(white, "sRGB", white, transform)
        np.testing.assert_allclose(RGB, [1, 1, 1], atol=2e-4)
    raw = XYZ_to_display_RGB(white, "sRGB")
    assert raw[0] > 1.2 > raw[2]  # colorimetric: illuminant A looks orange on a D65 display
    with pytest.raises(SpecrefError, match="needs white_XYZ_in"):
        XYZ_to_RGB_matrix("sRGB", None, "Bradford")
    with pytest.raises(SpecrefError, match="unknown chromatic adaptation 'bradfrod'"):
        XYZ_to_RGB_matrix("sRGB", white, "bradfrod")
    with pytest.raises(SpecrefError, match="unknown colourspace 'sRBG'"):
        XYZ_to_RGB_matrix("sRBG")


def test_spectra_to_RGB_matrix_is_weights_times_XYZ_to_RGB(rng):
    # Eq. (9), Wang et al.: the product of the band weights and the XYZ-to-RGB matrix.
    W = band_weights(GRID_41, spectrum_from_dataset("illuminant", "D65"))
    M = spectra_to_RGB_matrix(W)
    R = rng.uniform(0, 1, (10, 41))
    np.testing.assert_allclose(R @ M, XYZ_to_display_RGB(spectra_to_XYZ(R, W)), rtol=1e-12)
    # sRGB's white is D65 rounded to (0.3127, 0.3290); the spectral D65 white differs by ~2e-4.
    np.testing.assert_allclose(np.ones(41) @ M, [1, 1, 1], atol=5e-4)


def test_Lab_and_delta_E_00_published_values():
    # Source: Sharma, Wu & Dalal (2005), CIEDE2000 test data, pairs 1, 7 and 17.
    pairs = [
        ([50.0, 2.6772, -79.7751], [50.0, 0.0, -82.7485], 2.0425),
        ([50.0, 0.0, 0.0], [50.0, -1.0, 2.0], 2.3669),
        ([50.0, 2.5, 0.0], [56.0, -27.0, -3.0], 31.9030),
    ]
    for Lab_1, Lab_2, expected in pairs:
        assert float(delta_E_00(Lab_1, Lab_2)) == pytest.approx(expected, abs=5e-5)
    # Source: CIE 015 definition: the reference white has L* = 100, a* = b* = 0.
    np.testing.assert_allclose(
        XYZ_to_Lab([0.9, 1.0, 1.1], [0.9, 1.0, 1.1]), [100, 0, 0], atol=1e-10
    )

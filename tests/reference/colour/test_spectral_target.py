"""Tests of reference.colour.spectral_target: synthetic targets, look-alikes, target files."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reference.colour.spectra import GRID_41
from reference.colour.spectral_target import (
    CAMERAS,
    HELD_OUT_SETS,
    OTHER_TEST_SET,
    TRAINING_SET,
    camera_noise,
    camera_RGB,
    product_augmentation,
    product_patches,
    read_target,
    reflectance_set,
)
from reference.errors import SpecrefError


@pytest.mark.parametrize("camera", CAMERAS.names())
def test_white_diffuser_is_one(camera):
    for illuminant in ("D65", "A"):
        assert_allclose(camera_RGB(np.ones(81), camera, illuminant), 1.0, rtol=1e-12)


def test_sRGB_camera_against_colour_science():
    # Source: colour-science's sd_to_XYZ (CIE 1931 2°, D65) and XYZ_to_RGB(sRGB), linear.
    import colour

    _, spectra = reflectance_set("ColorChecker N Ohta")
    sd = next(iter(colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"].values()))  # dark skin
    XYZ = colour.sd_to_XYZ(sd, illuminant=colour.SDS_ILLUMINANTS["D65"]) / 100
    expected = colour.XYZ_to_RGB(XYZ, "sRGB", apply_cctf_encoding=False)
    assert_allclose(camera_RGB(spectra[0], "sRGB"), expected, atol=2e-3)


def test_training_set_has_no_look_alikes():
    _, training = reflectance_set(TRAINING_SET, GRID_41)
    for name in HELD_OUT_SETS:
        _, held = reflectance_set(name, GRID_41)
        rms = np.sqrt(((training[:, None] - held[None]) ** 2).mean(axis=-1))
        assert rms.min() >= 0.03


def _independent_lookalike(spectra_41, references_41):
    """E40's rule written out again: RMS < 0.03 or ΔE94 (colour-science, D65, 10 nm) < 2."""
    import colour

    shape = colour.SpectralShape(380, 780, 10)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
    ill = colour.SDS_ILLUMINANTS["D65"].copy().align(shape)

    def Lab(values):
        msds = colour.MultiSpectralDistributions(values.T, shape.wavelengths)
        XYZ = colour.msds_to_XYZ(msds, cmfs, ill, method="Integration") / 100
        white = colour.XYZ_to_xy(colour.sd_to_XYZ(colour.sd_ones(shape), cmfs, ill) / 100)
        return colour.XYZ_to_Lab(XYZ, white)

    rms = np.sqrt(((spectra_41[:, None] - references_41[None]) ** 2).mean(-1)).min(1)
    dE = colour.delta_E(Lab(spectra_41)[:, None], Lab(references_41)[None], method="CIE 1994")
    return (rms < 0.03) | (dE.min(1) < 2.0)


def test_products_are_realizable_and_no_test_look_alikes():
    # Erratum E44: the products R_i R_j (i < j) of the training patches are reflectances in
    # [0, 1], and none is a look-alike of a patch of a held-out set or of the CIE 2017 samples
    # (checked by the rule written out again with colour-science's Lab, ΔE94 1.5 of margin off).
    import colour

    _, R = reflectance_set(TRAINING_SET)
    RGB, products = product_augmentation(R, "Nikon 5100 (NPL)")(np.arange(len(R)), None)
    n = len(R)
    assert len(products) < n * (n - 1) // 2
    assert len(products) > 0.8 * n * (n - 1) // 2
    assert products.shape[1] == 41
    assert RGB.shape == (len(products), 3)
    assert products.min() >= min(R.min(), 0) * R.max()
    assert products.max() <= R.max() ** 2
    cie2017 = colour.quality.cfi2017.load_TCS_CIE2017(colour.SpectralShape(380, 780, 5))
    tests = [reflectance_set(name, GRID_41)[1] for name in HELD_OUT_SETS]
    tests.append(np.asarray(cie2017.values).T[:, ::2])
    rng = np.random.default_rng(4)
    pick = products[rng.choice(len(products), 400, replace=False)]
    assert not _independent_lookalike(pick, np.concatenate(tests)).any()


def test_products_of_a_fold_avoid_its_held_out_patches():
    # In cross-validation the fold's held-out patches play the held-out sets' part: no product
    # of the other patches may be their look-alike; the same set without them has some.
    _, R = reflectance_set(TRAINING_SET)
    train, held = np.arange(30, 80), np.arange(0, 30)
    augment = product_augmentation(R, "Nikon 5100 (NPL)")
    _, with_held = augment(train, held)
    _, without = augment(train, None)
    assert not _independent_lookalike(with_held, R[held][:, ::2]).any()
    assert _independent_lookalike(without, R[held][:, ::2]).any()
    assert len(product_patches(R[train])) == 50 * 49 // 2


def test_other_test_set_has_no_training_look_alikes():
    _, training = reflectance_set(TRAINING_SET, GRID_41)
    _, other = reflectance_set(OTHER_TEST_SET, GRID_41)
    assert not _independent_lookalike(other, training).any()


def test_noise_is_seeded_and_sized():
    a = camera_noise(np.full((4000, 3), 1.0), np.random.default_rng(3))
    b = camera_noise(np.full((4000, 3), 1.0), np.random.default_rng(3))
    assert_allclose(a, b)
    # Source: sqrt(0.005² + 0.001²) = 0.0051 for unit RGB
    assert a.std() == pytest.approx(np.hypot(0.005, 0.001), rel=0.05)


def test_read_target_pair(tmp_path):
    (tmp_path / "rgb.csv").write_text("# camera\nname,R,G,B\na,0.1,0.2,0.3\nb,0.3,0.2,0.1\n")
    (tmp_path / "s.csv").write_text("name,370,790\na,0.2,0.6\nb,0.4,0.4\n")
    RGB, spectra = read_target(tmp_path / "rgb.csv", tmp_path / "s.csv")
    assert RGB.shape == (2, 3)
    assert spectra.shape == (2, 41)
    assert_allclose(spectra[0, [0, -1]], [0.2 + 0.4 * 10 / 420, 0.6 - 0.4 * 10 / 420])


def test_read_target_refuses_missing_columns(tmp_path):
    (tmp_path / "t.csv").write_text("R,G,380,780\n0.1,0.2,0.3,0.4\n")
    with pytest.raises(SpecrefError, match=r"t.csv: no column B"):
        read_target(tmp_path / "t.csv")

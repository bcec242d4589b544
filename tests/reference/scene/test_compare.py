"""Tests of reference.scene.compare (``specref compare``): per-pixel differences."""

from __future__ import annotations

import numpy as np
import pytest

from reference.colour.colorimetry import band_weights
from reference.colour.spectra import GRID_41
from reference.errors import SpecrefError
from reference.images.formats import read_exr, spectral_channel_names, write_exr, write_png
from reference.scene.compare import XYZ_to_uv_prime, compare_files, compare_images, exr_to_XYZ

WHITE = np.array([0.95047, 1.0, 1.08883])


def _xyz(tmp_path, name, image, extra=None):
    channels = ["X", "Y", "Z"]
    if extra is not None:
        image = np.concatenate([image, extra[..., None]], axis=-1)
        channels.append("Y.stderr")
    return write_exr(tmp_path / name, image, channels)


def test_uv_prime_matches_colour_science():
    # Source: colour.xy_to_Luv_uv (CIE 1976 UCS).
    import colour

    XYZ = np.array([[0.2, 0.3, 0.4], [0.9, 0.5, 0.1]])
    expected = colour.xy_to_Luv_uv(colour.XYZ_to_xy(XYZ))
    np.testing.assert_allclose(XYZ_to_uv_prime(XYZ), expected, rtol=1e-12)


def test_luminance_scale_changes_y_not_chromaticity(tmp_path):
    # Source: closed form. A = 1.02 B: relative error of Y 0.02, Δu'v' 0; ΔE00 against
    # colour-science's CIEDE2000 of the two Lab values (white: D65 at Y = 1).
    import colour

    rng = np.random.default_rng(3)
    B = 0.2 + rng.random((4, 5, 3)) * 0.5
    summary, difference, names = compare_images(
        _xyz(tmp_path, "a.exr", 1.02 * B), _xyz(tmp_path, "b.exr", B)
    )
    assert names == ["relative_error_Y", "delta_E00", "delta_uv"]
    assert summary["pixels"] == 20
    # float32 storage: 1e-6
    assert summary["relative_error_Y"]["max"] == pytest.approx(0.02, abs=1e-6)
    assert summary["delta_uv"]["max"] < 1e-6
    a32, b32 = (read_exr(tmp_path / n)[0] for n in ("a.exr", "b.exr"))
    xy = colour.XYZ_to_xy(WHITE)
    dE = colour.delta_E(colour.XYZ_to_Lab(a32, xy), colour.XYZ_to_Lab(b32, xy), method="CIE 2000")
    np.testing.assert_allclose(difference[..., 1], dE, rtol=1e-10)


def test_z_scores_from_the_reference_standard_error(tmp_path):
    # Source: closed form: A = B + 2σ in Y gives z = 2 at every pixel.
    B = np.broadcast_to(WHITE, (3, 3, 3)).copy()
    sigma = np.full((3, 3), 0.01)
    A = B.copy()
    A[..., 1] += 2 * sigma
    summary, difference, names = compare_images(
        _xyz(tmp_path, "a.exr", A), _xyz(tmp_path, "b.exr", B, sigma)
    )
    assert names[-1] == "z"
    np.testing.assert_allclose(difference[..., -1], 2.0, rtol=1e-4)
    assert summary["z"]["share_within_3"] == 1.0


def test_spectral_and_xyz_files_of_one_image_agree(tmp_path):
    # Source: the band weights: a spectral EXR is integrated with the equal-energy weights of its
    # grid, so writing S and S @ W_E gives the same XYZ (to float32).
    rng = np.random.default_rng(5)
    S = 0.1 + rng.random((3, 4, 41))
    W_E = band_weights(GRID_41, None)
    spectral = write_exr(tmp_path / "s.exr", S, spectral_channel_names(GRID_41.wavelengths_nm))
    summary, _, _ = compare_images(spectral, _xyz(tmp_path, "x.exr", S @ W_E))
    assert summary["relative_error_Y"]["max"] < 1e-6
    assert exr_to_XYZ(spectral)[1]["kind"] == "spectral"


def test_mask_selects_pixels(tmp_path):
    B = np.broadcast_to(WHITE, (2, 4, 3)).copy()
    A = B.copy()
    A[:, 2:] *= 1.5
    mask = np.zeros((2, 4, 3))
    mask[:, :2] = 1.0
    write_png(tmp_path / "m.png", mask)
    a, b = _xyz(tmp_path, "a.exr", A), _xyz(tmp_path, "b.exr", B)
    assert compare_images(a, b)[0]["relative_error_Y"]["max"] == pytest.approx(0.5, rel=1e-6)
    masked = compare_images(a, b, tmp_path / "m.png")[0]
    assert masked["pixels"] == 4
    assert masked["relative_error_Y"]["max"] < 1e-6


def test_compare_files_writes_json_and_difference(tmp_path):
    B = np.broadcast_to(WHITE, (2, 2, 3)).copy()
    a, b = _xyz(tmp_path, "a.exr", 1.1 * B), _xyz(tmp_path, "b.exr", B)
    summary = compare_files(a, b, json=tmp_path / "s.json", diff=tmp_path / "d.exr")
    image, names = read_exr(tmp_path / "d.exr")  # OpenEXR stores channels sorted by name
    assert sorted(names) == ["delta_E00", "delta_uv", "relative_error_Y"]
    np.testing.assert_allclose(image[..., names.index("relative_error_Y")], 0.1, rtol=1e-5)
    assert (tmp_path / "s.json").read_text().startswith("{")
    assert summary["b"] == str(b)


def test_compare_bad_input(tmp_path):
    B = np.broadcast_to(WHITE, (2, 2, 3)).copy()
    b = _xyz(tmp_path, "b.exr", B)
    small = _xyz(tmp_path, "small.exr", B[:1])
    with pytest.raises(SpecrefError, match=r"small.exr: size 2×1 differs from .*b.exr's 2×2"):
        compare_images(small, b)
    odd = write_exr(tmp_path / "odd.exr", np.ones((2, 2, 2)), ["depth", "alpha"])
    with pytest.raises(SpecrefError, match=r"odd\.exr: no X, Y, Z, no R, G, B and no spectral"):
        compare_images(odd, b)
    (tmp_path / "junk.exr").write_bytes(b"not an exr")
    with pytest.raises(SpecrefError, match=r"junk\.exr: cannot read OpenEXR image"):
        compare_images(tmp_path / "junk.exr", b)
    with pytest.raises(SpecrefError, match="compare reads linear images"):
        compare_images(tmp_path / "a.png", b)
    write_png(tmp_path / "m.png", np.ones((3, 3, 3)))
    with pytest.raises(SpecrefError, match=r"m\.png: mask size 3×3 differs"):
        compare_images(b, b, tmp_path / "m.png")

"""Tests of shrm.files: reading maps with band conversion, projecting and prefiltering map files."""

from __future__ import annotations

import numpy as np
import pytest

from reference.colour.spectra import DEFAULT_GRID, GRID_41
from reference.colour.upsampling import RGB_to_spectra_Mallett2019
from reference.errors import SpecrefError
from reference.images.formats import read_exr, spectral_channel_names, write_exr
from shrm.files import prefilter_file, project_file, read_environment

SPECTRAL_NAMES = spectral_channel_names(GRID_41.wavelengths_nm)


def test_read_environment_keeps_or_converts_bands(tmp_path, rng):
    rgb = rng.random((4, 8, 3))
    write_exr(tmp_path / "rgb.exr", rgb)
    image, names = read_environment(tmp_path / "rgb.exr")
    assert names == ["R", "G", "B"]
    np.testing.assert_allclose(image, rgb, rtol=1e-6)  # OpenEXR stores float32
    same, _ = read_environment(tmp_path / "rgb.exr", "rgb")
    np.testing.assert_array_equal(same, image)
    # Source: colour.recovery's Mallett 2019 basis (tests/reference/colour/test_upsampling.py checks
    # it).
    spectral, names = read_environment(tmp_path / "rgb.exr", "spectral")
    assert spectral.shape == (4, 8, DEFAULT_GRID.n_bands)
    assert names == SPECTRAL_NAMES
    np.testing.assert_allclose(spectral, RGB_to_spectra_Mallett2019(image, GRID_41), rtol=1e-12)


def test_read_environment_spectral_to_rgb_is_linear(tmp_path, rng):
    # Property: the 41-band → sRGB conversion is one matrix, so it commutes with scaling and
    # addition; a spectral map stays as it is without --bands.
    a, b = rng.random((4, 8, 41)), rng.random((4, 8, 41))
    for name, image in (("a", a), ("b", b), ("sum", 2.0 * a + b)):
        write_exr(tmp_path / f"{name}.exr", image, channels=SPECTRAL_NAMES)
    kept, names = read_environment(tmp_path / "a.exr")
    assert kept.shape == (4, 8, 41)
    assert names == SPECTRAL_NAMES
    rgb = {n: read_environment(tmp_path / f"{n}.exr", "rgb")[0] for n in ("a", "b", "sum")}
    assert rgb["a"].shape == (4, 8, 3)
    np.testing.assert_allclose(rgb["sum"], 2.0 * rgb["a"] + rgb["b"], rtol=1e-5, atol=1e-6)


def test_project_file_of_a_constant_map(tmp_path):
    # Source: closed form. A constant map v has c_00 = v √(4π) (Y_00 = 1/√(4π)) and no other term.
    write_exr(tmp_path / "c.exr", np.full((16, 32, 3), 0.25))
    info = project_file(tmp_path / "c.exr", 4, tmp_path / "c.npz", window="hanning")
    assert info == {"order": 4, "channels": 3, "out": str(tmp_path / "c.npz")}
    data = np.load(tmp_path / "c.npz")
    assert data["coeffs"].shape == (3, 25)
    np.testing.assert_allclose(data["coeffs"][:, 0], 0.25 * np.sqrt(4 * np.pi), rtol=1e-12)
    np.testing.assert_allclose(data["coeffs"][:, 1:], 0.0, atol=1e-14)
    assert [str(c) for c in data["channels"]] == ["R", "G", "B"]
    assert str(data["window"]) == "hanning"


def test_prefilter_file_lambert_of_a_uniform_sky(tmp_path):
    # Source: closed form. Under a uniform radiance L the irradiance is E = π L in every direction.
    write_exr(tmp_path / "sky.exr", np.full((16, 32, 3), 0.5))
    info = prefilter_file(tmp_path / "sky.exr", "lambert", tmp_path / "cube.exr", size=4)
    assert info["kernel"] == "lambert"
    image, names = read_exr(tmp_path / "cube.exr")
    assert image.shape == (6 * 4, 4, 3)  # faces stacked vertically
    assert names == ["R", "G", "B"]
    np.testing.assert_allclose(image, 0.5 * np.pi, rtol=1e-6)


@pytest.mark.parametrize(
    ("image", "names", "bands", "match"),
    [
        (np.ones((4, 4, 3)), None, None, "2:1"),
        (np.full((4, 8, 3), np.nan), None, None, "radiance must be finite"),
        (-np.ones((4, 8, 3)), None, None, "radiance must be >= 0"),
        (np.ones((4, 8, 3)), None, "xyz", "unknown --bands 'xyz'; allowed: rgb, spectral"),
        (np.ones((4, 8, 4)), ["S0.400nm", "S0.500nm", "S0.600nm", "S0.700nm"], "rgb", "41-band"),
    ],
)
def test_read_environment_bad_input(tmp_path, image, names, bands, match):
    write_exr(tmp_path / "map.exr", image, channels=names)
    with pytest.raises(SpecrefError, match=match):
        read_environment(tmp_path / "map.exr", bands)


def test_project_and_prefilter_say_what_they_do(tmp_path, monkeypatch):
    import io

    monkeypatch.setattr("reference.progress.ANNOUNCE_AFTER", 0.0)  # every stage, however quick

    write_exr(tmp_path / "sky.exr", np.ones((8, 16, 3)))
    stream = io.StringIO()
    project_file(tmp_path / "sky.exr", 2, tmp_path / "sky.npz", progress=stream)
    prefilter_file(tmp_path / "sky.exr", "lambert", tmp_path / "cube.exr", size=4, progress=stream)
    lines = stream.getvalue().splitlines()
    assert [line.split(": ", 1)[1].split(" ...")[0] for line in lines] == [
        "reading",
        "projecting 3 channels to order 2 (ducc0)",
        "writing",
        "reading",
        "prefiltering 3 channels with lambert to 6 faces of 4²",
        "writing",
    ]
    assert lines[0].startswith("sh project sky.exr: reading ... ")

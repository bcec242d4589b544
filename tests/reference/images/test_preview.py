"""Previews of linear images (spectral, XYZ, RGB) against colour-science, and their refusals."""

import colour
import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.images.formats import read_png, spectral_channel_names, write_exr
from reference.images.preview import MIDDLE_GREY, image_preview
from validation.cli import main

WL = np.arange(380.0, 781.0, 10.0)


def _patch_spectra(names=("dark skin", "blue sky", "foliage", "orange")):
    """ColorChecker reflectances on the 41-band grid (colour-science's BabelColor averages)."""
    chart = colour.SDS_COLOURCHECKERS["BabelColor Average"]
    return np.array(
        [chart[n].copy().align(colour.SpectralShape(380, 780, 10)).values for n in names]
    )


def _independent_sRGB(reflectance, exposure_ev):
    """8-bit sRGB of a reflectance under the light E, Y = 1 for white (colour-science)."""
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    sd = colour.SpectralDistribution(dict(zip(WL, reflectance, strict=True)))
    XYZ = colour.sd_to_XYZ(sd, cmfs, colour.SDS_ILLUMINANTS["E"]) / 100.0
    d65 = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]
    rgb = colour.XYZ_to_sRGB(XYZ * 2.0**exposure_ev, d65, None, apply_cctf_encoding=False)
    encoded = colour.cctf_encoding(np.clip(rgb, 0.0, 1.0), "sRGB")
    return np.round(encoded * 255.0)


def test_a_spectral_image_previews_as_colour_science_renders_its_spectra(tmp_path):
    spectra = _patch_spectra()
    image = np.repeat(spectra[None, :, :], 3, axis=0)  # 3 rows × 4 patches × 41 bands
    src = write_exr(tmp_path / "chart.exr", image, spectral_channel_names(WL))
    info = image_preview(src, tmp_path / "chart.png", exposure_ev=0.5)
    assert info["kind"] == "spectral"
    assert info["preview"] == (3, 4)
    png = read_png(tmp_path / "chart.png")
    png = np.round(png * 255.0) if png.dtype.kind == "f" else png.astype(float)
    for k, reflectance in enumerate(spectra):
        expected = _independent_sRGB(reflectance, 0.5)
        assert np.abs(png[1, k, :3] - expected).max() <= 1, (k, png[1, k, :3], expected)


def test_spectral_xyz_and_rgb_layouts_of_one_image_preview_alike(tmp_path):
    from reference.colour.colorimetry import XYZ_to_display_RGB, spectral_channel_weights

    spectra = np.repeat(_patch_spectra()[None], 2, axis=0)
    XYZ = spectra @ spectral_channel_weights(WL)
    paths = {
        "spectral": write_exr(tmp_path / "s.exr", spectra, spectral_channel_names(WL)),
        "xyz": write_exr(tmp_path / "x.exr", XYZ, ["X", "Y", "Z"]),
        "rgb": write_exr(tmp_path / "r.exr", XYZ_to_display_RGB(XYZ), ["R", "G", "B"]),
    }
    shown = {}
    for kind, path in paths.items():
        info = image_preview(path, tmp_path / f"{kind}.png")
        assert info["kind"] == kind
        png = read_png(tmp_path / f"{kind}.png")
        shown[kind] = np.round(png * 255.0) if png.dtype.kind == "f" else png.astype(float)
    assert np.abs(shown["xyz"] - shown["spectral"]).max() <= 1
    assert np.abs(shown["rgb"] - shown["spectral"]).max() <= 1


def test_the_preview_is_a_box_filter_with_the_median_at_middle_grey(tmp_path):
    # A checkerboard of 0 and 2 in every band: each 4 × 4 box averages to 1
    image = np.zeros((16, 64, 41))
    image[(np.add.outer(np.arange(16), np.arange(64)) % 2) == 0] = 2.0
    src = write_exr(tmp_path / "c.exr", image, spectral_channel_names(WL))
    info = image_preview(src, tmp_path / "c.png", width=16)
    assert info["factor"] == 4
    assert info["preview"] == (4, 16)
    # each box has Y = 1 (equal-energy weights sum to 1 in Y): the median box goes to 0.18
    assert info["exposure_ev"] == pytest.approx(np.log2(MIDDLE_GREY / 1.0))
    png = read_png(tmp_path / "c.png")
    assert np.ptp(png[..., :3], axis=(0, 1)).max() == 0  # every box the same grey


def test_bad_input_is_one_line(tmp_path):
    image = np.ones((4, 8, 41))
    image[2, 3, 5] = np.nan
    src = write_exr(tmp_path / "nan.exr", image, spectral_channel_names(WL))
    with pytest.raises(SpecrefError, match=r"nan.exr: rows 0-3 hold NaN or infinite values"):
        image_preview(src, tmp_path / "nan.png")
    assert not (tmp_path / "nan.png").exists()
    other = write_exr(tmp_path / "a.exr", np.ones((2, 2, 1)), ["A"])
    with pytest.raises(SpecrefError, match="no spectral channels"):
        image_preview(other, tmp_path / "a.png")
    for width, exposure in ((0, None), (2.5, None), (16, float("nan")), (16, 1e9)):
        with pytest.raises(SpecrefError, match=r"--width|--exposure"):
            image_preview(other, tmp_path / "a.png", width, exposure)


def test_the_command_writes_a_preview_and_refuses_in_one_line(tmp_path, capsys):
    src = write_exr(tmp_path / "s.exr", np.full((4, 8, 41), 0.3), spectral_channel_names(WL))
    assert main(["env", "preview", str(src), "-o", str(tmp_path / "s.png")]) == 0
    assert "sRGB preview of a 8×4 spectral image" in capsys.readouterr().out
    assert (tmp_path / "s.png").is_file()
    assert main(["env", "preview", str(src), "-o", str(tmp_path / "t.png"), "--width", "0"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "--width" in err


def test_the_command_keeps_its_input_and_refuses_bad_outputs(tmp_path, capsys):
    # the write policy's cases for this command: the input itself, a folder, a device, no parent
    src = write_exr(tmp_path / "s.exr", np.full((4, 8, 41), 0.3), spectral_channel_names(WL))
    before = src.read_bytes()
    (tmp_path / "folder.png").mkdir()
    for out in (src, tmp_path / "folder.png", "/dev/null", tmp_path / "no" / "such" / "x.png"):
        code = main(["env", "preview", str(src), "-o", str(out)])
        err = capsys.readouterr().err.strip()
        if out == tmp_path / "no" / "such" / "x.png":  # the folder is made, as for every output
            assert code == 0
            continue
        assert code == 2, out
        assert len(err.splitlines()) == 1
    assert src.read_bytes() == before
    for bad in ("nan", "-inf", "1e9"):
        argv = ["env", "preview", str(src), "-o", str(tmp_path / "e.png"), f"--exposure={bad}"]
        assert main(argv) == 2
        assert "--exposure" in capsys.readouterr().err
    assert not (tmp_path / "e.png").exists()

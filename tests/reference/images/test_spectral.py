"""Tests of reference/images/spectral.py: streamed spectral EXR and TIFF, and their readers."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reference.errors import SpecrefError
from reference.images.formats import read_exr, spectral_channel_names
from reference.images.spectral import (
    read_environment_file,
    read_spectral_tiff,
    write_spectral_blocks,
)

WL = np.arange(380.0, 781.0, 10.0)


def _blocks(image, rows):
    for row0 in range(0, image.shape[0], rows):
        yield row0, image[row0 : row0 + rows]


@pytest.mark.parametrize("suffix", [".exr", ".tif"])
def test_blocks_round_trip(tmp_path, rng, suffix):
    image = rng.uniform(0, 5, (6, 12, 41)).astype(np.float32)
    path = write_spectral_blocks(tmp_path / f"p{suffix}", 6, 12, WL, _blocks(image, 4))
    back, names = read_environment_file(path)
    assert_allclose(back, image, rtol=0, atol=0)
    assert names == spectral_channel_names(WL)
    assert [p.name for p in tmp_path.iterdir()] == [path.name]


def test_exr_channels_are_the_spectral_layout(tmp_path):
    path = write_spectral_blocks(
        tmp_path / "p.exr", 1, 2, [500.0, 600.0], [(0, np.ones((1, 2, 2), np.float32))]
    )
    assert read_exr(path)[1] == ["S0.500,000000nm", "S0.600,000000nm"]


def test_failed_write_leaves_nothing(tmp_path):
    def broken():
        yield 0, np.ones((1, 4, 41), np.float32)
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError):
        write_spectral_blocks(tmp_path / "p.tif", 2, 4, WL, broken())
    assert list(tmp_path.iterdir()) == []


def test_integer_and_unlabelled_tiffs_are_refused(tmp_path):
    import tifffile

    tifffile.imwrite(tmp_path / "int.tif", np.zeros((4, 8, 3), np.uint8))
    with pytest.raises(SpecrefError, match=r"int.tif: 8-bit integer TIFF, not HDR"):
        read_spectral_tiff(tmp_path / "int.tif")
    tifffile.imwrite(tmp_path / "plain.tif", np.zeros((4, 8, 3), np.float32), photometric="rgb")
    with pytest.raises(SpecrefError, match=r"plain.tif: no wavelengths"):
        read_spectral_tiff(tmp_path / "plain.tif")


def test_unknown_suffix(tmp_path):
    with pytest.raises(SpecrefError, match=r"allowed: .exr, .tif, .tiff"):
        write_spectral_blocks(tmp_path / "p.png", 1, 1, WL, [])


def test_spectralize_file_memory_is_bounded_by_blocks(tmp_path, rng):
    # Our target: peak extra memory <= 2 × the output; the output itself is never held (memory map).
    import tracemalloc

    from reference.colour.upsampling import default_regression
    from reference.images.formats import write_exr
    from reference.images.spectral import spectralize_file

    pano = write_exr(tmp_path / "pano.exr", rng.uniform(0, 2, (64, 128, 3)))
    model = default_regression()
    output_bytes = 64 * 128 * 41 * 4
    spectralize_file(pano, model, tmp_path / "warm.tif")  # imports and caches outside the trace
    tracemalloc.start()
    try:
        spectralize_file(pano, model, tmp_path / "out.tif", rows_per_block=4)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 2 * output_bytes
    assert read_environment_file(tmp_path / "out.tif")[0].shape == (64, 128, 41)


@pytest.mark.parametrize(
    "name", ["venice_sunset_1k.hdr", "studio_small_03_1k.hdr", "StageEnvLatLong.exr"]
)
def test_row_windows_equal_the_whole_read(package_data, name):
    # Source: reference.images.formats.read_hdr / read_exr (imagecodecs, OpenEXR), the whole-file
    # readers. Real files: RLE Radiance scanlines and a tiled, ZIP-compressed half-float EXR with a
    # preview.
    from reference.images.spectral import open_panorama_rows

    path = package_data / "environments" / name
    whole = read_environment_file(path)[0]
    with open_panorama_rows(path) as rows:
        assert rows.streamed
        assert (rows.height, rows.width, len(rows.names)) == whole.shape
        parts = [rows.read(a, min(a + 37, rows.height)) for a in range(0, rows.height, 37)]
    assert np.array_equal(np.concatenate(parts), whole)


def test_flat_radiance_scanlines_and_float_tiff_rows(tmp_path, rng):
    # Flat (uncompressed) RGBE scanlines, and an RGB float TIFF through its memory map.
    import imagecodecs
    import tifffile

    from reference.images.formats import read_hdr
    from reference.images.spectral import open_panorama_rows

    image = rng.uniform(0, 8, (9, 6, 3)).astype(np.float32)  # width < 8: never RLE
    (tmp_path / "p.hdr").write_bytes(imagecodecs.rgbe_encode(image))
    with open_panorama_rows(tmp_path / "p.hdr") as rows:
        parts = [rows.read(a, min(a + 4, 9)) for a in range(0, 9, 4)]
    assert np.array_equal(np.concatenate(parts), read_hdr(tmp_path / "p.hdr"))
    tifffile.imwrite(tmp_path / "p.tif", image, photometric="rgb")
    with open_panorama_rows(tmp_path / "p.tif") as rows:
        assert rows.names == ["R", "G", "B"]
        assert_allclose(rows.read(2, 5), image[2:5], rtol=0, atol=0)


def test_spectralize_reads_the_panorama_by_row_blocks(tmp_path, rng, monkeypatch, row_windows):
    # docs/spectral-environments.md: the input is never read whole; each block reads only its own
    # rows, in order.
    import reference.images.spectral as spectral_images
    from reference.colour.upsampling import default_regression
    from reference.images.formats import write_exr

    pano = write_exr(tmp_path / "pano.exr", rng.uniform(0, 2, (10, 16, 3)))
    calls = row_windows
    monkeypatch.setattr(spectral_images, "read_exr", None)  # a whole read would fail
    info = spectral_images.spectralize_file(pano, default_regression(), tmp_path / "o.exr", 4)
    assert calls == [(0, 4), (4, 8), (8, 10)]
    assert info["streamed"]
    assert info["blocks"] == 3


def test_spectralize_input_memory_is_bounded_by_blocks(tmp_path, rng):
    # With the input streamed as well, peak traced memory over a 256 × 1024 panorama
    # read 8 rows at a time stays below the input in float64 (a whole read, as before, allocates
    # the float32 decode and the float64 image: 1.5 × that), and far below the output (43 MB).
    import tracemalloc

    import imagecodecs

    from reference.colour.upsampling import default_regression
    from reference.images.spectral import spectralize_file

    image = rng.uniform(0, 2, (256, 1024, 3)).astype(np.float32)
    (tmp_path / "pano.hdr").write_bytes(imagecodecs.rgbe_encode(image))
    (tmp_path / "warm.hdr").write_bytes(imagecodecs.rgbe_encode(image[:8]))
    model = default_regression()
    spectralize_file(tmp_path / "warm.hdr", model, tmp_path / "warm.tif", rows_per_block=8)
    tracemalloc.start()
    try:
        spectralize_file(tmp_path / "pano.hdr", model, tmp_path / "out.tif", rows_per_block=8)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < image.size * 8
    assert read_environment_file(tmp_path / "out.tif")[0].shape == (256, 1024, 41)


def test_nan_in_a_late_block_leaves_no_output(tmp_path, rng):
    from reference.colour.upsampling import default_regression
    from reference.images.formats import write_exr
    from reference.images.spectral import spectralize_file

    image = rng.uniform(0, 2, (12, 8, 3))
    image[10, 3, 1] = np.nan
    pano = write_exr(tmp_path / "pano.exr", image)
    with pytest.raises(SpecrefError, match=r"pano.exr: RGB must be finite and >= 0 \(rows 8-11\)"):
        spectralize_file(pano, default_regression(), tmp_path / "o.tif", rows_per_block=4)
    assert not (tmp_path / "o.tif").exists()


def test_spectralize_zarr_to_zarr_equals_in_memory(tmp_path, rng):
    # docs/scale-out.md: a 512×1024 RGB store in, a 41-band store out, streamed by row blocks (7
    # rows, so blocks straddle the output's 128-row chunks); equal, bit for bit, to the blocks
    # spectralized in memory (the same float32 arithmetic, erratum E45).
    from reference.colour.spectral_regression import spectralize_blocks
    from reference.colour.upsampling import default_regression
    from reference.images.spectral import spectralize_file
    from reference.images.zarr_store import open_zarr_image, write_zarr_image

    RGB = rng.gamma(0.7, 0.5, (512, 1024, 3)).astype(np.float32)
    source = write_zarr_image(tmp_path / "rgb.zarr", RGB, ["R", "G", "B"], rows_per_chunk=48)
    model = default_regression()
    info = spectralize_file(source, model, tmp_path / "spectral.zarr", rows_per_block=7)
    assert info["streamed"]
    assert info["blocks"] == -(-512 // 7)
    store = open_zarr_image(tmp_path / "spectral.zarr", wavelengths_nm=model.wavelengths_nm)
    in_memory = np.concatenate(
        [b.copy() for _, b in spectralize_blocks(model, RGB.astype(np.float64), 7)]
    )
    np.testing.assert_array_equal(store.read(), in_memory)
    with pytest.raises(SpecrefError, match=r"spectralize needs an RGB panorama"):
        spectralize_file(tmp_path / "spectral.zarr", model, tmp_path / "again.zarr")

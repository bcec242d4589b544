"""Tests of reference/spectral_images.py: streamed spectral EXR and TIFF, and their readers."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from reference.errors import SpecrefError
from reference.images import read_exr, spectral_channel_names
from reference.spectral_images import (
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
    # Issue 15: peak extra memory <= 2 × the output; the output itself is never held (memory map).
    import tracemalloc

    from reference.images import write_exr
    from reference.spectral_images import spectralize_file
    from reference.upsampling import default_regression

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

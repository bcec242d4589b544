import re

import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.files import atomic_write, write_text_atomic
from reference.images.formats import (
    read_exr,
    read_hdr,
    read_image,
    read_png,
    spectral_channel_names,
    write_exr,
    write_png,
)


def test_atomic_write_leaves_target_untouched_on_failure(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old")

    def interrupted_write():
        with atomic_write(target, "w") as handle:
            handle.write("half")
            raise RuntimeError("interrupted")

    with pytest.raises(RuntimeError, match="interrupted"):
        interrupted_write()
    assert target.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.txt"]  # no temporary left
    write_text_atomic(target, "new")
    assert target.read_text() == "new"


def test_png_round_trip(tmp_path, rng):
    image = rng.integers(0, 256, (5, 7, 3), dtype=np.uint8)
    read = read_png(write_png(tmp_path / "a.png", image))
    np.testing.assert_array_equal(np.round(read * 255).astype(np.uint8), image)


def test_png_keeps_16_bits_and_expands_palettes(tmp_path):
    # Source: imagecodecs' and Pillow's encoders (Pillow's reader truncates 16-bit colour to 8)
    import imagecodecs
    from PIL import Image

    values = np.arange(0, 65535, 2731, dtype=np.uint16)[:24].reshape(2, 4, 3)
    (tmp_path / "a.png").write_bytes(imagecodecs.png_encode(values))
    np.testing.assert_array_equal(read_png(tmp_path / "a.png"), values / 65535.0)
    grey = np.arange(12, dtype=np.uint8).reshape(3, 4) * 20
    Image.fromarray(grey).convert("P").save(tmp_path / "p.png")
    np.testing.assert_array_equal(
        read_png(tmp_path / "p.png"), np.repeat(grey[..., None], 3, -1) / 255
    )


def test_a_png_claiming_too_many_pixels_is_refused_before_decoding(tmp_path):
    import imagecodecs

    data = bytearray(imagecodecs.png_encode(np.zeros((2, 2, 3), np.uint8)))
    data[16:24] = (10**6).to_bytes(4, "big") * 2  # IHDR: 10⁶ × 10⁶ pixels, CRC not redone
    (tmp_path / "big.png").write_bytes(bytes(data))
    with pytest.raises(SpecrefError, match="at most"):
        read_png(tmp_path / "big.png")


@pytest.mark.parametrize("half", [False, True])
def test_exr_round_trip(tmp_path, rng, half):
    image = rng.uniform(0, 100, (6, 4, 3))
    read, names = read_exr(write_exr(tmp_path / "a.exr", image, half=half))
    assert names == ["R", "G", "B"]
    dtype = np.float16 if half else np.float32
    np.testing.assert_array_equal(read, image.astype(dtype).astype(np.float64))


def test_spectral_exr_round_trip_sorted_by_wavelength(tmp_path, rng):
    wl = np.arange(380.0, 781.0, 10.0)
    image = rng.uniform(0, 1, (3, 4, wl.size))
    names = spectral_channel_names(wl)
    # Source: Fichet, Pacanowski & Wilkie (2021): emissive channels S0.<wavelength>nm, decimal
    # comma.
    assert names[0] == "S0.380,000000nm"
    read, read_names = read_exr(write_exr(tmp_path / "s.exr", image, names))
    parsed = [float(re.search(r"(\d+,\d+)nm", n).group(1).replace(",", ".")) for n in read_names]
    np.testing.assert_array_equal(parsed, wl)
    np.testing.assert_array_equal(read, image.astype(np.float32))


def test_read_shared_tiled_half_exr(package_data):
    # Source: reference/data/PROVENANCE.md: 1000x500 half RGB, tiled, mip-mapped.
    image, names = read_exr(package_data / "environments" / "StageEnvLatLong.exr")
    assert image.shape == (500, 1000, 3)
    assert names == ["R", "G", "B"]
    assert np.isfinite(image).all()
    assert np.array_equal(image, image.astype(np.float16).astype(np.float64))


def _rgbe_rows_by_hand(data: bytes, n_rows: int) -> np.ndarray:
    """Decode the first rows of a new-style run-length encoded Radiance file, byte by byte.

    Source: G. Ward, "Real Pixels" (Graphics Gems II) and the Radiance file format: scanline header
    2, 2, width >> 8, width & 255; then each of R, G, B, E as runs (count > 128: repeat the next
    byte count - 128 times; otherwise copy count bytes). A pixel is m · 2^(e - 136), and 0 when e =
    0.
    """
    end = data.index(b"\n\n") + 2
    resolution = data[end : data.index(b"\n", end)].split()
    assert resolution[0] == b"-Y"
    assert resolution[2] == b"+X"
    width = int(resolution[3])
    pos = data.index(b"\n", end) + 1
    rows = []
    for _ in range(n_rows):
        assert data[pos] == 2
        assert data[pos + 1] == 2
        assert (data[pos + 2] << 8) | data[pos + 3] == width
        pos += 4
        channels = []
        for _ in range(4):
            values = []
            while len(values) < width:
                count = data[pos]
                pos += 1
                if count > 128:
                    values += [data[pos]] * (count - 128)
                    pos += 1
                else:
                    values += list(data[pos : pos + count])
                    pos += count
            channels.append(values)
        m = np.array(channels[:3], dtype=np.float64).T
        e = np.array(channels[3], dtype=np.float64)
        rows.append(np.where(e[:, None] == 0, 0.0, m * 2.0 ** (e[:, None] - 136)))
    return np.stack(rows)


def test_hdr_matches_rgbe_definition_by_hand(package_data):
    path = package_data / "environments" / "venice_sunset_1k.hdr"
    image = read_hdr(path)
    assert image.shape == (512, 1024, 3)
    by_hand = _rgbe_rows_by_hand(path.read_bytes(), 3)
    np.testing.assert_array_equal(image[:3], by_hand)
    # Source: reference/data/PROVENANCE.md: the sun peaks at ~6.5e3.
    assert 6.0e3 < image.max() < 7.0e3


@pytest.mark.parametrize("suffix", [".hdr", ".exr", ".png"])
def test_unreadable_images_are_refused(tmp_path, suffix):
    path = tmp_path / f"garbage{suffix}"
    path.write_bytes(b"this is not an image at all")
    with pytest.raises(SpecrefError, match=rf"garbage\{suffix}: cannot read"):
        read_image(path)
    with pytest.raises(SpecrefError, match=r"missing\.exr: file not found"):
        read_image(tmp_path / "missing.exr")


def test_read_image_unknown_type(tmp_path):
    with pytest.raises(SpecrefError, match=r"unsupported image type '\.tif'; allowed: \.exr"):
        read_image(tmp_path / "a.tif")


def test_write_exr_bad_input(tmp_path):
    with pytest.raises(SpecrefError, match="name the 5 channels"):
        write_exr(tmp_path / "a.exr", np.zeros((2, 2, 5)))
    with pytest.raises(SpecrefError, match="2 channel names for 3 channels"):
        write_exr(tmp_path / "a.exr", np.zeros((2, 2, 3)), ["R", "G"])

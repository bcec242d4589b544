"""Zarr panoramas: round trips, refusals, and streamed operations equal to their in-memory twins."""

import numpy as np
import pytest

from reference.errors import SpecrefError
from reference.images.formats import spectral_channel_names
from reference.images.zarr_store import (
    map_zarr_blocks,
    open_zarr_image,
    write_zarr_blocks,
    write_zarr_image,
)

GRID = np.arange(380.0, 790.0, 10.0)
NAMES = spectral_channel_names(GRID)


@pytest.fixture(scope="module")
def panorama(tmp_path_factory):
    # a 512×1024 spectral map with structure at every frequency (seeded)
    rng = np.random.default_rng(18)
    image = rng.gamma(0.5, 1.0, (512, 1024, len(GRID))).astype(np.float32)
    path = tmp_path_factory.mktemp("zarr") / "pano.zarr"
    write_zarr_image(path, image, NAMES, rows_per_chunk=48)
    return path, image


def test_round_trip_is_bit_identical(panorama):
    path, image = panorama
    store = open_zarr_image(path, n_channels=41, wavelengths_nm=GRID)
    assert store.shape == image.shape
    assert store.rows_per_chunk == 48
    np.testing.assert_array_equal(store.read(), image)
    assert np.allclose(store.wavelengths_nm, GRID)
    # row blocks cover the image once, in order
    starts = [start for start, _ in store.row_blocks()]
    assert starts == list(range(0, 512, 48))
    np.testing.assert_array_equal(store.to_dask().compute(), image)


@pytest.mark.parametrize("compression", ["zstd", "blosc-lz4", "none"])
def test_compressions_round_trip(tmp_path, compression):
    image = np.random.default_rng(3).random((8, 16, 3)).astype(np.float32)
    write_zarr_image(tmp_path / "a.zarr", image, ["R", "G", "B"], compression=compression)
    np.testing.assert_array_equal(open_zarr_image(tmp_path / "a.zarr").read(), image)


def test_streamed_colour_management_and_XYZ_equal_in_memory(panorama, tmp_path):
    from reference.colour.colorimetry import band_weights
    from reference.colour.spectra import GRID_41

    path, image = panorama
    illuminant = np.linspace(0.5, 1.5, 41)
    map_zarr_blocks(path, tmp_path / "lit.zarr", lambda b: b * illuminant)
    lit = open_zarr_image(tmp_path / "lit.zarr").read()
    np.testing.assert_array_equal(lit, (image.astype(np.float64) * illuminant).astype(np.float32))
    M = band_weights(GRID_41, None)  # XYZ = R @ W
    map_zarr_blocks(path, tmp_path / "xyz.zarr", lambda b: b @ M, channels=["X", "Y", "Z"])
    xyz = open_zarr_image(tmp_path / "xyz.zarr").read()
    np.testing.assert_array_equal(xyz, (image.astype(np.float64) @ M).astype(np.float32))


@pytest.mark.parametrize("backend", ["numpy", "ducc0"])
def test_streamed_sh_projection_equals_in_memory(panorama, backend):
    from shrm.streamed import project_zarr
    from shrm.transform import project_latlong

    path, image = panorama
    streamed = project_zarr(path, 100, backend=backend)
    whole = project_latlong(image.astype(np.float64), 100, backend=backend)
    scale = np.abs(whole).max(axis=1, keepdims=True)
    assert np.max(np.abs(streamed - whole) / scale) <= 1e-12


@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_streamed_cubemap_is_bit_identical_to_in_memory(panorama, backend):
    from reference.geometry.cubemap import latlong_to_cubemap
    from reference.images.zarr_store import zarr_to_cubemap

    path, image = panorama
    streamed = zarr_to_cubemap(path, 128, backend=backend)
    np.testing.assert_array_equal(
        streamed, latlong_to_cubemap(image.astype(np.float64), 128, backend=backend)
    )


def test_prefetched_blocks_equal_plain_reads(panorama):
    path, image = panorama
    store = open_zarr_image(path)
    ahead = list(store.row_blocks(100))
    plain = list(store.row_blocks(100, prefetch=False))
    assert [s for s, _ in ahead] == [s for s, _ in plain] == list(range(0, 512, 100))
    for (_, a), (_, b) in zip(ahead, plain, strict=True):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(np.concatenate([b for _, b in ahead]), image)


def test_refusals_are_one_line(tmp_path, panorama):
    path, _ = panorama
    with pytest.raises(SpecrefError, match=r"pano.zarr: 41 channels; expected 3"):
        open_zarr_image(path, n_channels=3)
    with pytest.raises(SpecrefError, match=r"wavelengths_nm: the store's grid"):
        open_zarr_image(path, wavelengths_nm=np.arange(400.0, 710.0, 10.0))
    with pytest.raises(SpecrefError, match=r"missing.zarr: Zarr store not found"):
        open_zarr_image(tmp_path / "missing.zarr")
    (tmp_path / "empty.zarr").mkdir()
    with pytest.raises(SpecrefError, match=r"empty.zarr: not a Zarr array"):
        open_zarr_image(tmp_path / "empty.zarr")
    write_zarr_image(tmp_path / "sq.zarr", np.ones((4, 4, 1)), ["Y"])
    with pytest.raises(SpecrefError, match=r"a lat-long map has W = 2H"):
        open_zarr_image(tmp_path / "sq.zarr")
    with pytest.raises(SpecrefError, match=r"unknown compression 'lzma'"):
        write_zarr_image(tmp_path / "c.zarr", np.ones((4, 8, 1)), ["Y"], compression="lzma")


def test_a_failed_write_leaves_the_old_store(tmp_path):
    path = tmp_path / "a.zarr"
    write_zarr_image(path, np.ones((4, 8, 1), dtype=np.float32), ["Y"])

    def failing_blocks():
        yield np.zeros((2, 8, 1))
        raise RuntimeError("killed mid-write")

    with pytest.raises(RuntimeError):
        write_zarr_blocks(path, 4, 8, ["Y"], failing_blocks(), rows_per_chunk=2)
    assert open_zarr_image(path).read().min() == 1.0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.zarr"]
    with pytest.raises(SpecrefError, match=r"2 rows given for a 4-row image"):
        write_zarr_blocks(path, 4, 8, ["Y"], [np.zeros((2, 8, 1))], rows_per_chunk=2)
    assert open_zarr_image(path).read().min() == 1.0


def test_cli_convert_and_project(tmp_path, capsys):
    from reference.images.formats import write_exr
    from validation.cli import main

    rng = np.random.default_rng(5)
    image = rng.random((32, 64, 3)).astype(np.float32)
    write_exr(tmp_path / "m.exr", image)
    out = tmp_path / "m.zarr"
    assert main(["env", "convert", str(tmp_path / "m.exr"), str(out), "--rows", "8"]) == 0
    assert "4 chunks of 8 rows, blosc-lz4" in capsys.readouterr().out
    np.testing.assert_array_equal(open_zarr_image(out).read(), image)
    assert main(["sh", "project", str(out), "--order", "8", "-o", str(tmp_path / "z.npz")]) == 0
    assert (
        main(
            [
                "sh",
                "project",
                str(tmp_path / "m.exr"),
                "--order",
                "8",
                "-o",
                str(tmp_path / "e.npz"),
            ]
        )
        == 0
    )
    z, e = np.load(tmp_path / "z.npz"), np.load(tmp_path / "e.npz")
    assert np.max(np.abs(z["coeffs"] - e["coeffs"])) <= 1e-12 * np.abs(e["coeffs"]).max()
    with pytest.raises(SystemExit) as refused:  # a flag's value refused while parsing
        main(["env", "convert", str(tmp_path / "m.exr"), str(out), "--rows", "0"])
    assert refused.value.code == 2
    assert "argument --rows: must be a whole number in [1, " in capsys.readouterr().err


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_cli_convert_refuses_non_finite_input_in_one_line(tmp_path, capsys, bad):
    from reference.images.formats import write_exr
    from validation.cli import main

    image = np.ones((8, 16, 3), dtype=np.float32)
    image[5, 3, 1] = bad
    write_exr(tmp_path / "bad.exr", image)
    assert main(["env", "convert", str(tmp_path / "bad.exr"), str(tmp_path / "b.zarr")]) == 2
    err = capsys.readouterr().err.strip()
    # the rows that hold it are named (8 rows: one chunk, read a quarter at a time)
    assert err.endswith("bad.exr: radiance must be finite, found NaN or inf (rows 4-5)")
    assert "\n" not in err
    assert "Traceback" not in err
    assert not (tmp_path / "b.zarr").exists()


@pytest.mark.parametrize("suffix", [".exr", ".hdr"])
def test_convert_streams_by_chunks_and_keeps_every_value(tmp_path, suffix, row_windows):
    # OpenEXR scanlines and Radiance rows are read a quarter chunk at a time into one chunk
    # buffer, never the whole image; the store holds the values the whole-image reader gives
    import imagecodecs

    import reference.images.spectral as spectral
    from reference.images.formats import read_image, write_exr

    image = np.random.default_rng(3).random((24, 48, 3)).astype(np.float32) * 50
    path = tmp_path / f"m{suffix}"
    if suffix == ".exr":
        write_exr(path, image)
    else:
        path.write_bytes(imagecodecs.rgbe_encode(image))
    info = spectral.convert_to_zarr(path, tmp_path / "m.zarr", rows_per_chunk=10)  # 10, 10, 4
    assert info["streamed"]
    assert row_windows == [(row, row + 2) for row in range(0, 24, 2)]
    np.testing.assert_array_equal(
        open_zarr_image(tmp_path / "m.zarr").read(), read_image(path).astype(np.float32)
    )


def test_cli_convert_refuses_its_input_as_output(tmp_path, capsys):
    # a store converted onto itself: one line, exit 2, the store as it was
    from validation.cli import main

    image = np.arange(8 * 16 * 3, dtype=np.float32).reshape(8, 16, 3)
    store = write_zarr_image(tmp_path / "m.zarr", image, ["R", "G", "B"], rows_per_chunk=2)
    assert main(["env", "convert", str(store), str(tmp_path / "." / "m.zarr"), "--rows", "4"]) == 2
    err = capsys.readouterr().err.strip()
    assert "m.zarr: is also an input of this command" in err  # the write policy's line
    assert err.endswith("give another output name")
    assert "\n" not in err
    assert open_zarr_image(store).rows_per_chunk == 2
    np.testing.assert_array_equal(open_zarr_image(store).read(), image)

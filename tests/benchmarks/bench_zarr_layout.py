"""The Zarr layout chosen by measurement: read time and size by compression and chunk size.

Group ``scaleout-zarr-read``: reading a whole 512×1024×41 float32 store chunk by chunk (what a
streamed operation does, without the conversion to float64), for each compression of
``reference.images.zarr_store.ZARR_COMPRESSIONS`` and chunks of 32, 128 and 256 rows (5.4, 21.5 and
43 MB), on two maps:

- ``spectral``: ``studio_small_03_1k.hdr`` (Poly Haven, CC0) spectralized by the shipped
  regression (``reference.colour.upsampling.default_regression``): a real panorama's structure;
- ``random``: uniform random bands, which do not compress (the worst case, as in the
  ``scaleout-zarr`` throughput benchmark).

``extra_info`` holds the compression ratio (float32 bytes / stored bytes). The defaults of
``reference.images.zarr_store`` (blosc-lz4, :data:`~reference.images.zarr_store.CHUNK_BYTES`) follow
from these figures (docs/scale-out.md, erratum E48).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

ROWS = (32, 128, 256)
COMPRESSIONS = ("none", "blosc-lz4", "zstd")


@pytest.fixture(scope="module")
def maps(package_data):
    from reference.colour.spectral_regression import spectralize_blocks
    from reference.colour.upsampling import default_regression
    from reference.images.formats import read_hdr

    RGB = read_hdr(package_data / "environments" / "studio_small_03_1k.hdr")
    model = default_regression()
    spectral = np.concatenate([b.copy() for _, b in spectralize_blocks(model, RGB)])
    random = np.random.default_rng(18).random(spectral.shape, dtype=np.float32)
    return {"spectral": spectral, "random": random}, model.wavelengths_nm


@pytest.mark.benchmark(group="scaleout-zarr-read")
@pytest.mark.parametrize("rows", ROWS)
@pytest.mark.parametrize("compression", COMPRESSIONS)
@pytest.mark.parametrize("data", ["spectral", "random"])
def test_read_store(benchmark, maps, tmp_path, data, compression, rows):
    from reference.images.formats import spectral_channel_names
    from reference.images.zarr_store import open_zarr_image, write_zarr_image

    images, wavelengths = maps
    image = images[data]
    path = write_zarr_image(
        tmp_path / "m.zarr",
        image,
        spectral_channel_names(wavelengths),
        rows_per_chunk=rows,
        compression=compression,
    )
    stored = sum(f.stat().st_size for f in Path(path).rglob("*") if f.is_file())
    store = open_zarr_image(path)
    height = image.shape[0]

    def read():
        return [np.asarray(store.array[s : s + rows]) for s in range(0, height, rows)]

    benchmark.extra_info.update(
        {
            "role": "read",
            "data": data,
            "compression": compression,
            "rows_per_chunk": rows,
            "chunk_bytes": rows * image.shape[1] * image.shape[2] * 4,
            "ratio": image.nbytes / stored,
            "float32_bytes": image.nbytes,
        }
    )
    blocks = benchmark.pedantic(read, rounds=5, iterations=1, warmup_rounds=1)
    np.testing.assert_array_equal(np.concatenate(blocks), image)

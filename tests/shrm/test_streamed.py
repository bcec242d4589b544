"""Tests of shrm/streamed.py: row-block SH projection, its refusals, and its progress bar."""

import numpy as np
import pytest

from reference.errors import SpecrefError
from shrm.streamed import project_latlong_blocks, project_zarr
from shrm.transform import project_latlong


@pytest.mark.parametrize("backend", ["numpy", "ducc0"])
def test_blocks_in_any_order_equal_the_whole_map(rng, backend):
    # Fejér-1 quadrature is a sum over rings: the partial projections of the blocks add up.
    image = rng.gamma(0.5, 1.0, (32, 64, 3))
    blocks = [(20, image[20:]), (0, image[:7]), (7, image[7:20])]
    streamed = project_latlong_blocks(blocks, 32, 12, backend=backend)
    whole = project_latlong(image, 12, backend=backend)
    assert np.max(np.abs(streamed - whole)) <= 1e-12 * np.abs(whole).max()


@pytest.mark.parametrize("backend", ["numpy", "ducc0"])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_a_non_finite_pixel_is_refused_with_its_rows(rng, backend, bad):
    # The check is on each block's partial projection; one pixel anywhere must trip it.
    image = rng.random((32, 64, 2))
    image[19, 63, 1] = bad
    blocks = [(0, image[:16]), (16, image[16:])]
    with pytest.raises(SpecrefError, match=r"rows 16–32: radiance must be finite"):
        project_latlong_blocks(blocks, 32, 8, backend=backend)


def test_rows_missing_or_twice_are_refused(rng):
    image = rng.random((16, 32, 1))
    with pytest.raises(SpecrefError, match=r"cover every row exactly once"):
        project_latlong_blocks([(0, image[:8])], 16, 4)
    with pytest.raises(SpecrefError, match=r"cover every row exactly once"):
        project_latlong_blocks([(0, image[:8]), (4, image[4:12]), (8, image[8:])], 16, 4)


def test_progress_bar_counts_every_row(tmp_path, capsys, rng):
    from reference.images.zarr_store import write_zarr_image

    image = rng.random((24, 48, 2)).astype(np.float32)
    path = write_zarr_image(tmp_path / "m.zarr", image, ["R", "G"], rows_per_chunk=5)
    quiet = project_zarr(path, 6, backend="numpy")
    assert capsys.readouterr().err == ""
    shown = project_zarr(path, 6, backend="numpy", progress=True)
    assert "24/24" in capsys.readouterr().err
    np.testing.assert_array_equal(shown, quiet)
    project_zarr(path, 6, backend="numpy", progress=None)  # auto: stderr is not a terminal here
    assert capsys.readouterr().err == ""

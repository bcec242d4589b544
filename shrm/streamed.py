"""SH projection of panoramas too large for memory: partial projections of row blocks, summed.

Eq. (4), Ramamoorthi & Hanrahan 2001 (§5.3, Herbert et al.): ``c_lm = ∫ f Y_lm dω``. With
Fejér-1 quadrature over the rings θ_j, the integral is a sum over rings,

    c_lm = Σ_j w_j √2 λ_lm(θ_j) F_m(θ_j),

so the rings of a block of rows contribute a partial projection of their own, and the partial
projections of consecutive blocks add up to the projection of the whole map. Each block is read,
transformed along φ (rFFT, or ducc0's ``map2leg`` with the block's own ring geometry) and
dropped: memory is one block plus the coefficients, whatever the map's height.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from reference.errors import require
from shrm.sh import check_order, fejer1_weights, latlong_ring_angles
from shrm.transform import _ring_fourier, ducc0_ring_analysis, legendre_analysis

__all__ = ["project_latlong_blocks", "project_zarr"]


def _partial_numpy(block, L, theta, w, method):
    # Eq. (4), Ramamoorthi & Hanrahan 2001: Σ over this block's rings of w_j λ_lm(θ_j) F_m(θ_j)
    with np.errstate(invalid="ignore", over="ignore"):  # NaN/inf: refused after the sum
        F_cos, F_sin = _ring_fourier(block, L)
        return legendre_analysis(L, theta, w, F_cos, F_sin, method)


def _partial_ducc0(block, L, theta, w, method):
    # The same sum with ducc0: map2leg on the block's rings, leg2alm at the block's θ_j.
    return ducc0_ring_analysis(block, L, theta, w)


#: The per-block projection by backend (numba shares the NumPy path: the Legendre sum is BLAS).
_PARTIALS = {"numpy": _partial_numpy, "numba": _partial_numpy, "ducc0": _partial_ducc0}


def project_latlong_blocks(
    blocks: Iterable[tuple[int, np.ndarray]],
    height: int,
    order: int,
    backend: str = "numpy",
    method: str = "auto",
) -> np.ndarray:
    """SH coefficients of a lat-long map given as row blocks, block by block.

    Eq. (4), Ramamoorthi & Hanrahan 2001, by Fejér-1 quadrature (as
    :func:`shrm.transform.project_latlong`, which it equals to rounding).

    Parameters
    ----------
    blocks : iterable of (first_row, ndarray (rows, W, C))
        Row blocks of the map, in any order, covering each row once.
    height : int
        The whole map's height H.
    order : int
        L.
    backend : {"numpy", "numba", "ducc0"}

    Returns
    -------
    ndarray, shape (C, (L+1)²)

    Examples
    --------
    >>> from shrm.transform import project_latlong
    >>> rng = np.random.default_rng(1)
    >>> image = rng.random((16, 32, 2))
    >>> blocks = [(0, image[:5]), (5, image[5:11]), (11, image[11:])]
    >>> streamed = project_latlong_blocks(blocks, 16, 6)
    >>> bool(np.allclose(streamed, project_latlong(image, 6), rtol=0, atol=1e-13))
    True
    """
    require(backend in _PARTIALS, f"streamed projection: backend must be one of {list(_PARTIALS)}")
    L = check_order(order)
    theta_all, w_all = latlong_ring_angles(height), fejer1_weights(height)
    out = None
    seen = np.zeros(height, dtype=int)
    for start, block in blocks:
        block = np.asarray(block, dtype=np.float64)
        if block.ndim == 2:
            block = block[..., None]
        rows = slice(start, start + block.shape[0])
        where = f"row block {start}+{block.shape[0]}"
        require(start >= 0 and rows.stop <= height, f"{where}: outside the {height}-row map")
        require(block.shape[1] // 2 > L, f"order {L} needs a map at least {2 * L + 2} wide")
        seen[rows] += 1
        partial = _PARTIALS[backend](block, L, theta_all[rows], w_all[rows], method)
        # A NaN or inf pixel makes its ring's Fourier coefficients, and so the block's partial
        # projection, non-finite (the weights w_j are positive): checking the (C, (L+1)²)
        # partial refuses the same blocks as checking every pixel, at a fraction of the cost.
        require(np.isfinite(partial).all(), f"rows {start}–{rows.stop}: radiance must be finite")
        out = partial if out is None else out + partial
    require(out is not None and (seen == 1).all(), "row blocks must cover every row exactly once")
    return out


def project_zarr(
    path, order: int, backend: str = "ducc0", rows: int | None = None, progress: bool | None = False
) -> np.ndarray:
    """SH coefficients of a Zarr panorama, streamed by the store's row chunks.

    Returns ``(C, (L+1)²)``; equals :func:`shrm.transform.project_latlong` of the whole map. The
    next chunk is read while this one is projected (``ZarrImage.row_blocks``). ``progress``: a
    progress bar of rows on stderr (tqdm; None shows it only on a terminal).

    Examples
    --------
    >>> import tempfile, os
    >>> from reference.images.zarr_store import write_zarr_image
    >>> with tempfile.TemporaryDirectory() as d:
    ...     path = os.path.join(d, "m.zarr")
    ...     _ = write_zarr_image(path, np.ones((8, 16, 1)), ["Y"], rows_per_chunk=3)
    ...     project_zarr(path, 2, backend="numpy")[0, 0].round(6)
    np.float64(3.544908)
    """
    from reference.images.zarr_store import open_zarr_image

    image = open_zarr_image(path)
    blocks = image.row_blocks(rows)
    if progress is False:
        return project_latlong_blocks(blocks, image.shape[0], order, backend)
    from tqdm import tqdm

    with tqdm(
        total=image.shape[0],
        unit="row",
        desc=f"SH L={order}",
        disable=None if progress is None else False,
    ) as bar:

        def counted():
            for start, block in blocks:
                yield start, block
                bar.update(block.shape[0])

        return project_latlong_blocks(counted(), image.shape[0], order, backend)

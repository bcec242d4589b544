"""Scale-out: a 32-task sweep on a 2-worker LocalCluster against the same sweep serially, and the
streamed SH projection of a Zarr panorama against the in-memory projection, in one run.

Group ``scaleout-sweep`` (target: distributed / serial speed-up >= 1.6 on 2 cores;
``docs/scale-out.md``, "How it scales, and what does not"):

- ``serial``: 32 independent SH projections (seeded 1024×2048×3 maps, order 128, the numba
  path: single-threaded, no cached table, about 0.15 s each with the map's generation), one
  after another, in a process that has already compiled the projection (as the workers have);
- ``local-cluster``: the same tasks through ``reference.tasks.run_tasks`` on a running 2-worker
  ``LocalCluster`` (the cluster's start-up is not timed: it is paid once per sweep session).

Group ``scaleout-zarr`` (throughput of the out-of-core path >= 70 % of the in-memory path):

- ``in-memory``: ``shrm.transform.project_latlong`` of a 1024×2048×41 float32 map in memory,
  L = 100 (ducc0);
- ``zarr-streamed``: ``shrm.streamed.project_zarr`` of the same map from a Zarr store (64-row
  chunks, ``blosc-lz4``: the defaults of ``reference.images.zarr_store`` for this width; random
  data, which does not compress, the worst case for reading), a reader thread reading the next chunk
  while this one is projected, and its peak Python memory (tracemalloc).
- ``zarr-streamed-no-readahead``: the same without the reader thread (each chunk read, then
  projected, in one thread), to show what the overlap buys.

Five rounds each; the report takes the fastest of each.
"""

import numpy as np
import pytest

from reference.tasks import dask_client, run_tasks

N_TASKS = 32


def projection_task(seed: int) -> float:
    # The numba projection: single-threaded and with no cached table, so every task does its
    # full share of work (about 0.15 s) and tasks cannot share anything.
    from shrm.transform import project_latlong

    image = np.random.default_rng(seed).random((1024, 2048, 3))
    return float(np.abs(project_latlong(image, 128, backend="numba")).sum())


@pytest.fixture(scope="module")
def client():
    with dask_client(n_workers=2) as c:
        run_tasks(projection_task, range(4), client=c, progress=False)  # compile in both workers
        yield c


@pytest.fixture(scope="module")
def compiled():
    # Both sides start compiled: the serial process runs the first tasks once, untimed, as the
    # client fixture does on the workers (otherwise the first serial round times numba's loading).
    run_tasks(projection_task, range(2), scheduler="serial", progress=False)


@pytest.mark.benchmark(group="scaleout-sweep")
def test_sweep_serial(benchmark, compiled):
    benchmark.extra_info.update({"role": "serial", "tasks": N_TASKS})
    result = benchmark.pedantic(
        run_tasks,
        args=(projection_task, range(N_TASKS)),
        kwargs={"scheduler": "serial", "progress": False},
        rounds=3,
        iterations=1,
    )
    assert len(result) == N_TASKS


@pytest.mark.benchmark(group="scaleout-sweep")
def test_sweep_local_cluster(benchmark, client):
    benchmark.extra_info.update({"role": "distributed", "tasks": N_TASKS, "workers": 2})
    result = benchmark.pedantic(
        run_tasks,
        args=(projection_task, range(N_TASKS)),
        kwargs={"client": client, "progress": False},
        rounds=3,
        iterations=1,
    )
    assert (
        result
        == run_tasks(projection_task, range(4), scheduler="serial", progress=False) + result[4:]
    )


HEIGHT = 1024


@pytest.fixture(scope="module")
def zarr_map(tmp_path_factory):
    from reference.images.formats import spectral_channel_names
    from reference.images.zarr_store import write_zarr_blocks

    rng = np.random.default_rng(18)
    names = spectral_channel_names(np.arange(380.0, 790.0, 10.0))
    image = rng.random((HEIGHT, 2 * HEIGHT, 41), dtype=np.float32)
    path = tmp_path_factory.mktemp("bench") / "map.zarr"
    blocks = (image[i : i + 64] for i in range(0, HEIGHT, 64))
    write_zarr_blocks(
        path, HEIGHT, 2 * HEIGHT, names, blocks, rows_per_chunk=64, compression="blosc-lz4"
    )
    return path, image


@pytest.mark.benchmark(group="scaleout-zarr")
def test_projection_in_memory(benchmark, zarr_map):
    from shrm.transform import project_latlong

    _, image = zarr_map
    benchmark.extra_info.update({"role": "in-memory", "pixels": image.shape[0] * image.shape[1]})
    benchmark.pedantic(project_latlong, args=(image, 100), kwargs={"backend": "ducc0"}, rounds=5)


@pytest.mark.benchmark(group="scaleout-zarr")
def test_projection_zarr_streamed(benchmark, zarr_map):
    import tracemalloc

    from shrm.streamed import project_zarr

    path, image = zarr_map
    benchmark.extra_info.update(
        {"role": "zarr-streamed", "pixels": image.shape[0] * image.shape[1]}
    )
    benchmark.pedantic(project_zarr, args=(path, 100), kwargs={"backend": "ducc0"}, rounds=5)
    tracemalloc.start()
    project_zarr(path, 100, backend="ducc0")
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    benchmark.extra_info["peak_python_bytes"] = peak
    # a few chunks, never the map: 64 rows × 2048 × 41 float64 is 43 MB; the map is 344 MB
    assert peak < image.nbytes / 2


@pytest.mark.benchmark(group="scaleout-zarr")
def test_projection_zarr_streamed_no_readahead(benchmark, zarr_map):
    from reference.images.zarr_store import open_zarr_image
    from shrm.streamed import project_latlong_blocks

    path, image = zarr_map
    benchmark.extra_info.update(
        {"role": "zarr-streamed-no-readahead", "pixels": image.shape[0] * image.shape[1]}
    )

    def project():
        store = open_zarr_image(path)
        blocks = store.row_blocks(prefetch=False)
        return project_latlong_blocks(blocks, HEIGHT, 100, backend="ducc0")

    benchmark.pedantic(project, rounds=5)

"""Suite-wide pytest set-up: NumPy printing for doctests, shared fixtures, the benchmark switch."""

from __future__ import annotations

import errno
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import colour  # noqa: F401  (imported first: it sets NumPy's legacy print mode, which we undo below)
import matplotlib
import numpy as np
import pytest

# Import the packages (and with them every registry) once, under their package names: pytest's
# importlib mode then finds them in sys.modules instead of executing a module a second time when a
# test run names its file directly, which would register its methods twice.
import impastor  # noqa: F401
import phong_table  # noqa: F401
import reference
import reference.tasks
import shrm  # noqa: F401
import validation.cli
import validation.report.runner  # noqa: F401  (imports every section)

matplotlib.use("Agg")
np.set_printoptions(legacy=False)
# The allocator thresholds every specref command sets (docs/scale-out.md): the suite's processes
# run the same NumPy temporaries, and glibc's default spends seconds on mmap and munmap.
reference.tasks.set_malloc_trim()

ROOT = Path(__file__).resolve().parent

# Benchmarks run only under `make bench` (SPECREF_BENCH=1); the ordinary suite does not collect
# them.
collect_ignore = [] if os.environ.get("SPECREF_BENCH") else ["tests/benchmarks"]
# ``python -m validation.cli`` runs the command on import: never collect it for doctests.
collect_ignore += ["validation/cli/__main__.py", "phong_table/editor/__main__.py"]

# An unreachable scheduler is refused after two seconds here rather than the default ten (the
# tests prove the refusal, not the patience); a value set outside the suite wins.
os.environ.setdefault("SPECREF_DASK_TIMEOUT", "2")


def _share_the_cores() -> None:
    """Each pytest-xdist worker gets its share of the cores for BLAS and OpenMP.

    Two workers whose OpenBLAS each runs one thread per core put four spinning threads on two
    cores: measured here, sixty 902² Cholesky factorizations took 12 s in each of two such
    processes against 1.2 s single-threaded. The limit also reaches the commands the tests start
    (environment variables), unless set outside the suite.
    """
    workers = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1"))
    if workers < 2:
        return
    from threadpoolctl import threadpool_limits

    share = max(1, (os.cpu_count() or 1) // workers)
    for name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(name, str(share))
    threadpool_limits(limits=int(os.environ["OPENBLAS_NUM_THREADS"]))


_share_the_cores()


#: Modules whose tests ask for the same work that a process remembers (``functools`` caches):
#: under ``--dist loadscope`` each group runs on one worker, as one module's tests do, so the
#: work is done once, not once per worker. Measured in one process against two: the equation
#: index (every source and test file parsed: ``validation.report.citations``) 12.5 s of CPU
#: against 23.8 s; the spectral environment fits (``validation.studies.spectral_env.fit_target``)
#: 24.1 s against 36.6 s.
SHARED_WORK = {
    "equation index": (
        "validation/report/citations.py",
        "validation/report/equations.py",
        "tests/validation/report/test_citations.py",
        "tests/validation/report/test_equations.py",
    ),
    "spectral environment fits": (
        "validation/studies/spectral_env.py",
        "tests/validation/studies/test_spectral_env.py",
        "tests/validation/report/sections/test_spectral_env.py",
        "docs/spectral-environments.md",
    ),
}


@pytest.hookimpl(optionalhook=True, tryfirst=True)
def pytest_xdist_make_scheduler(config, log):
    """``--dist loadscope`` with the modules of each :data:`SHARED_WORK` group as one scope."""
    if config.getvalue("dist") != "loadscope":
        return None
    from xdist.scheduler import LoadScopeScheduling

    group_of = {path: group for group, paths in SHARED_WORK.items() for path in paths}

    class SharedWorkScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            group = group_of.get(nodeid.split("::", 1)[0])
            return f"shared work: {group}" if group else super()._split_scope(nodeid)

    return SharedWorkScheduling(config, log)


@pytest.fixture
def rng():
    """The suite's seeded generator; other streams use a local generator with a literal seed."""
    return np.random.default_rng(20261122)


@pytest.fixture(scope="session")
def package_data() -> Path:
    """The data shipped with specref (``reference/data``: environment maps, measured spectra)."""
    from reference.data import data_root

    return data_root()


@pytest.fixture(scope="session")
def dask_local_client():
    """One local Dask cluster for the session: two single-threaded worker processes on 127.0.0.1.

    Starting a cluster costs seconds; every test that only needs *a* cluster shares this one.
    Tests that kill workers or start their own ``dask scheduler`` make their own.
    """
    from reference.tasks import dask_client

    with dask_client("local", n_workers=2) as client:
        yield client


@pytest.fixture
def row_windows(monkeypatch) -> list:
    """The row windows ``(row0, row1)`` that panoramas opened by ``open_panorama_rows`` read.

    Spies on ``reference.images.spectral.open_panorama_rows`` (the streamed commands' reader),
    so a test sees that a file was read a block at a time, never whole.
    """
    import reference.images.spectral as spectral_images

    windows = []
    opened = spectral_images.open_panorama_rows

    def spy(path):
        rows = opened(path)
        read = rows._read
        rows._read = lambda a, b, dtype: windows.append((a, b)) or read(a, b, dtype)
        return rows

    monkeypatch.setattr(spectral_images, "open_panorama_rows", spy)
    return windows


# --- outputs that cannot be written: a read-only and a full file system ----------------------


def _mount_tmpfs(folder: Path, options: str) -> bool:
    """Mount a small tmpfs at ``folder``; False without root (the callers then simulate it)."""
    folder.mkdir()
    if os.geteuid() != 0 or shutil.which("mount") is None:
        return False
    done = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(folder)], capture_output=True
    )
    return done.returncode == 0


def _refuse_in(folder: Path, code: int, monkeypatch) -> None:
    """Without root: every new file in ``folder`` fails with errno ``code``, as the real one does.

    All of specref's writers create their temporary file with ``tempfile.mkstemp`` in the
    destination folder, which is where a read-only or full file system refuses first.
    """
    real = tempfile.mkstemp

    def mkstemp(*args, dir=None, **kwargs):
        if dir is not None and Path(dir).resolve().is_relative_to(folder.resolve()):
            raise OSError(code, os.strerror(code))
        return real(*args, dir=dir, **kwargs)

    monkeypatch.setattr(tempfile, "mkstemp", mkstemp)


@pytest.fixture
def full_folder(tmp_path, monkeypatch):
    """A folder on a 64 KiB file system that is already full (simulated without root)."""
    folder = tmp_path / "full"
    if not _mount_tmpfs(folder, "size=64k"):
        _refuse_in(folder, errno.ENOSPC, monkeypatch)
        yield folder
        return
    filler = folder / "filler"
    with pytest.raises(OSError, match="No space left"):
        filler.write_bytes(b"\0" * (1 << 20))
    yield folder
    subprocess.run(["umount", str(folder)], check=False)


#: The earlier output that :func:`read_only_folder` holds, and its bytes.
EARLIER_OUTPUT = ("earlier.png", b"earlier")


@pytest.fixture
def read_only_folder(tmp_path, monkeypatch):
    """A folder on a read-only file system holding an earlier output (simulated without root).

    The file ``EARLIER_OUTPUT[0]`` holds ``EARLIER_OUTPUT[1]``: a command refused there must
    leave it as it was. As root, a tmpfs written then remounted read-only; else every new file
    there fails with EROFS.
    """
    folder = tmp_path / "ro"
    name, content = EARLIER_OUTPUT
    if not _mount_tmpfs(folder, "size=64k"):
        (folder / name).write_bytes(content)
        _refuse_in(folder, errno.EROFS, monkeypatch)
        yield folder
        return
    (folder / name).write_bytes(content)
    remount = subprocess.run(["mount", "-o", "remount,ro", str(folder)], capture_output=True)
    if remount.returncode != 0:
        _refuse_in(folder, errno.EROFS, monkeypatch)
    yield folder
    subprocess.run(["umount", str(folder)], check=False)


@pytest.fixture(autouse=True)
def _numpy_printing(doctest_namespace):
    """Doctests see ``np`` and modern NumPy printing, whatever a library did to them."""
    doctest_namespace["np"] = np
    np.set_printoptions(legacy=False)


def pytest_collection_modifyitems(config, items):
    """``xslow`` tests run only with SPECREF_XSLOW=1 (the default addopts already deselect them)."""
    if os.environ.get("SPECREF_XSLOW"):
        return
    for item in items:
        if "xslow" in item.keywords:
            item.add_marker(pytest.mark.skip(reason="xslow: set SPECREF_XSLOW=1 to run"))

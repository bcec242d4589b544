"""Dask workers that start ready: ``dask worker tcp://HOST:8786 --preload validation.worker``.

Dask runs a preload module's ``dask_setup(worker)`` once when the worker starts, before it takes a
task. This one imports every specref package, so every registry, shader and method a task can name
is defined before the first task instead of inside it, and numba's kernels are ready to load from
the on-disk cache (``reference.jit``: a kernel this machine compiled before is loaded at its first
call, not compiled again). A worker that cannot import specref fails here, at start-up, with the
import error in its log; the client refuses such a worker, and one whose specref or Python differs
from its own, with one line each (``reference.tasks.usable_workers``).

Examples
--------
>>> class Worker:
...     pass
>>> w = Worker()
>>> dask_setup(w)
>>> sorted(w.specref_identity)
['python', 'specref']
"""

from __future__ import annotations

import importlib

from reference.tasks import dask_teardown  # noqa: F401  (Dask calls it as the worker closes)

#: The packages a task may need: the shared core, each paper's package, the studies.
PACKAGES = ("reference", "phong_table", "shrm", "impastor", "validation.studies")


def dask_setup(worker) -> None:
    """Import specref's packages on a starting worker and record what it runs on the worker."""
    from reference.tasks import WORKER_ARENAS, set_malloc_trim, specref_identity

    # Dask's 64 KiB trim threshold makes every large NumPy temporary an mmap; the tasks' thread
    # shares the main arena, where these thresholds hold
    set_malloc_trim(arenas=WORKER_ARENAS)
    for name in PACKAGES:
        importlib.import_module(name)
    worker.specref_identity = specref_identity()

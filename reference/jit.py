"""The decorator of specref's numba kernels: compiled once per machine, cached on disk.

Every ``_kernels.py`` decorates its kernels with :func:`njit`, which is ``numba.njit(cache=True)``
(never ``fastmath``). numba writes each compiled kernel to a cache folder and later processes load
it instead of compiling again: the first import on a machine pays the compile, every other process,
test worker and Dask worker of that machine does not.

The folder is ``$NUMBA_CACHE_DIR`` when the user sets it (numba's own setting), else ``numba/``
below specref's cache root (:func:`reference.files.default_cache_dir`, ``$SPECREF_CACHE_DIR`` or
``~/.cache/specref``), so an installed package never writes into ``site-packages``.

Why the cache is safe (``tests/reference/test_jit.py`` shows each point):

- numba keys a cached kernel by its source file's modification time and size, its signature and the
  CPU, so an edited kernel file is compiled again and a different machine never loads it;
- numba writes cache files to a temporary name and renames them into place, so processes that
  compile the same kernel at once each find a whole file;
- a kernel calls only kernels of its own file (no ``_kernels.py`` imports another), so the file's
  stamp covers every function a cached kernel inlined.

numba compiles a kernel once per signature, and an array's layout and write flag are part of it: a
read-only array (a cached table, ``np.broadcast_to``) or a strided view where the kernel usually
gets a fresh C-contiguous one compiles the whole kernel again (seconds for the largest). Callers
pass a kernel's input arrays through :func:`kernel_input` (C-contiguous, read-only view, no copy
when the array already is C-contiguous of its dtype), so every caller shares one signature.

What a process with a warm cache still pays at its first render: numba sets up its typing and
lowering registries once per process, when it loads the first cached kernel (tenths of a second,
whatever the number of kernels), and each kernel's cached machine code is loaded at its first call.
``make bench``'s group ``startup-render`` measures the first render of a fresh process against its
second, with the cache cold and warm (the report's Examples section shows the figures).
"""

from __future__ import annotations

import functools
import os
from pathlib import Path

import numba
import numpy as np

from reference.files import default_cache_dir

__all__ = ["kernel_cache_dir", "kernel_input", "njit"]


def kernel_cache_dir() -> Path:
    """The folder where numba caches specref's compiled kernels.

    Examples
    --------
    >>> import os
    >>> os.environ["NUMBA_CACHE_DIR"] = "/tmp/numba-doc-cache"
    >>> str(kernel_cache_dir())
    '/tmp/numba-doc-cache'
    >>> del os.environ["NUMBA_CACHE_DIR"]
    >>> kernel_cache_dir().name
    'numba'
    """
    explicit = os.environ.get("NUMBA_CACHE_DIR")
    return Path(explicit).expanduser() if explicit else default_cache_dir() / "numba"


# numba reads NUMBA_CACHE_DIR once, when it is first imported; setting its config here, before any
# kernel is decorated, sends the cache to specref's folder unless the user chose one.
numba.config.CACHE_DIR = str(kernel_cache_dir())

#: ``numba.njit(cache=True)``: the decorator of every kernel (STYLE.md §6: never ``fastmath``).
njit = functools.partial(numba.njit, cache=True)


def kernel_input(x, dtype=np.float64) -> np.ndarray:
    """``x`` as a kernel reads it: a C-contiguous, read-only view of ``dtype`` (None: its own).

    No copy when ``x`` already is a C-contiguous array of that dtype; the view's write flag is off
    whatever ``x``'s, so writable and read-only inputs share one compiled signature.

    Examples
    --------
    >>> a = np.arange(6.0).reshape(2, 3)
    >>> b = kernel_input(a[:, ::-1])
    >>> b.flags.c_contiguous, b.flags.writeable, np.shares_memory(kernel_input(a), a)
    (True, False, True)
    >>> kernel_input(np.arange(3, dtype=np.float32), None).dtype
    dtype('float32')
    """
    view = np.ascontiguousarray(x, dtype=dtype).view()
    view.flags.writeable = False
    return view

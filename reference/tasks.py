"""Independent jobs on a Dask cluster: local by default, or a remote scheduler.

One way to run a list of independent tasks (a sweep's cells, a study's renders): a
``dask.distributed`` client on a ``LocalCluster`` of worker processes sized to the machine, or on
the scheduler that ``--scheduler ADDRESS`` or the ``SPECREF_SCHEDULER`` environment variable names
(``tcp://host:8786``, as ``dask scheduler`` prints it). ``"serial"`` runs the tasks in this process,
one after another: the baseline every distributed run must reproduce.

Results come back in task order, whatever order the workers finish in, so reductions over them
are order-independent; each task carries its own seed. A worker killed mid-sweep loses only its
running tasks, which the scheduler runs again elsewhere (``retries``), so the results are the same.

specref writes no scheduler of its own: this module only wraps Dask's (``distributed.Client``,
``LocalCluster``, ``as_completed``), with one-line errors and a progress bar.
"""

from __future__ import annotations

import contextlib
import logging
import os
import re
import sys
import weakref
from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass

from reference.errors import SpecrefError, require, require_positive_int

__all__ = [
    "ARENA_SETTING",
    "CHUNKS_PER_WORKER",
    "LOCAL",
    "MAX_LOCAL_WORKERS",
    "MMAP_SETTING",
    "PROFILE_SETTING",
    "QUIET_SETTINGS",
    "SCHEDULER_ENV",
    "SERIAL",
    "STREAMED_MMAP_BYTES",
    "STREAMED_TRIM_BYTES",
    "TIMEOUT_ENV",
    "TRIM_SETTING",
    "WORKER_ARENAS",
    "WORKER_MMAP_BYTES",
    "WORKER_TRIM_BYTES",
    "Shared",
    "add_scheduler_option",
    "chunk_size",
    "connect_timeout",
    "dask_client",
    "dask_teardown",
    "freeze_objects_for_exit",
    "local_workers",
    "run_chunk",
    "run_shared_chunk",
    "run_tasks",
    "scheduler_address",
    "set_malloc_trim",
    "specref_identity",
    "usable_workers",
    "worker_problems",
]

#: The environment variable that names a remote scheduler.
SCHEDULER_ENV = "SPECREF_SCHEDULER"

#: The environment variable that sets how long to wait for a remote scheduler, in seconds.
TIMEOUT_ENV = "SPECREF_DASK_TIMEOUT"

#: The wait for a remote scheduler when ``$SPECREF_DASK_TIMEOUT`` is unset, in seconds.
DEFAULT_TIMEOUT = 10.0

#: The scheduler name that runs tasks in this process, one after another.
SERIAL = "serial"

#: The scheduler name that starts a local cluster (one single-threaded worker process per core).
LOCAL = "local"


def scheduler_address(scheduler: str | None = None, default: str | None = None) -> str | None:
    """The scheduler to use: ``scheduler``, else ``$SPECREF_SCHEDULER``, else ``default``.

    None (and ``"local"``) mean a new local cluster; ``"serial"`` this process. Commands whose
    tasks are short or timed (``specref phong table1``, ``specref impastor table1``) pass
    ``default="serial"``: a local cluster starts in seconds and its workers would share the
    cores that the timings measure.

    Examples
    --------
    >>> scheduler_address("tcp://127.0.0.1:8786")
    'tcp://127.0.0.1:8786'
    >>> scheduler_address("serial")
    'serial'
    >>> scheduler_address("local", default="serial") is None
    True
    >>> scheduler_address("ucx://127.0.0.1:8786")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: --scheduler ucx://127.0.0.1:8786: allowed: tcp://HOST:PORT ...
    """
    address = scheduler or os.environ.get(SCHEDULER_ENV) or default
    if not address or str(address) == LOCAL:
        return None
    address = str(address)
    # Dask's other protocols (tls://, ucx://, inproc://) need settings specref does not pass
    require(
        address == SERIAL or address.startswith(LOCAL + ":") or _TCP_ADDRESS.match(address),
        f"--scheduler {address}: allowed: tcp://HOST:PORT (a running `dask scheduler`), "
        f"host:port, '{LOCAL}', '{LOCAL}:N' or '{SERIAL}'",
    )
    return address


#: A scheduler address specref connects to: ``tcp://host:port`` or ``host:port`` (IPv6 in [ ]).
_TCP_ADDRESS = re.compile(r"^(tcp://)?(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+):[0-9]{1,5}$")


#: The most bytes a scheduler's first message (its handshake, ~60 bytes) may claim.
MAX_HANDSHAKE_BYTES = 1 << 16


def _receive(sock, n: int, deadline: float, address: str) -> bytes:
    import time

    data = b""
    while len(data) < n:
        sock.settimeout(max(deadline - time.monotonic(), 1e-3))
        try:
            chunk = sock.recv(n - len(data))
        except TimeoutError:
            raise SpecrefError(
                f"--scheduler {address}: the peer accepted the connection but sent no Dask "
                "handshake in time; is it a Dask scheduler?"
            ) from None
        require(chunk, f"--scheduler {address}: the peer closed the connection; not a scheduler")
        data += chunk
    return data


def probe_scheduler(address: str, timeout: float) -> dict:
    """Read a scheduler's handshake ourselves, bounded in time and size, before Dask connects.

    Dask's client trusts what the peer sends: a peer that accepts and never answers keeps it
    waiting past its timeout, and a length header of 2⁴⁰ bytes makes it allocate that much. A
    scheduler sends its handshake (a frame of ~60 bytes: compression, Python version, pickle
    protocol) as soon as it accepts; this reads it within ``timeout`` seconds and at most
    :data:`MAX_HANDSHAKE_BYTES`, and refuses anything else in one line.

    Returns
    -------
    dict
        The handshake.

    Raises
    ------
    SpecrefError
        The peer sends nothing in time, closes, claims too many bytes, or sends what is not a
        Dask handshake. OSError (connection refused, unreachable; tried again until the timeout,
        as a scheduler that is starting refuses at first) is left to the caller.

    Examples
    --------
    >>> probe_scheduler("tcp://127.0.0.1:9", 0.5)       # tried again until the timeout
    Traceback (most recent call last):
    ...
    ConnectionRefusedError: [Errno 111] Connection refused
    """
    import socket
    import struct
    import time

    from distributed.protocol.core import loads
    from distributed.protocol.utils import unpack_frames

    deadline = time.monotonic() + timeout
    host, port = address.removeprefix("tcp://").rsplit(":", 1)
    while True:  # as Dask's connect: a scheduler still starting refuses at first
        try:
            sock = socket.create_connection((host.strip("[]"), int(port)), timeout=timeout)
            break
        except OSError:
            if time.monotonic() + 0.2 > deadline:
                raise
            time.sleep(0.2)
    with sock:
        (size,) = struct.unpack("Q", _receive(sock, 8, deadline, address))
        not_dask = f"--scheduler {address}: the peer is not a Dask scheduler"
        require(0 < size <= MAX_HANDSHAKE_BYTES, f"{not_dask} (it announced {size} bytes)")
        try:
            frames, missing = unpack_frames(_receive(sock, size, deadline, address), partial=True)
            require(sum(missing) <= MAX_HANDSHAKE_BYTES, f"{not_dask} (frames too large)")
            rest = [_receive(sock, m, deadline, address) for m in missing]
            handshake = loads(list(frames) + rest, deserialize=False)
        except SpecrefError:
            raise
        except Exception:  # what a stranger's bytes make the decoder raise
            raise SpecrefError(f"{not_dask} (its first message is not a Dask message)") from None
    require(
        isinstance(handshake, dict) and "pickle-protocol" in handshake,
        f"{not_dask} (no handshake)",
    )
    return handshake


#: The most workers ``local:N`` starts on one machine (each is a process of a few hundred MB).
MAX_LOCAL_WORKERS = 256


def local_workers(address: str | None) -> int | None:
    """The worker count of ``local:N`` (a local cluster of N workers); None for other addresses.

    Raises
    ------
    SpecrefError
        ``local:`` followed by anything but a positive integer (one line).

    Examples
    --------
    >>> local_workers("local:3"), local_workers("tcp://127.0.0.1:8786"), local_workers(None)
    (3, None, None)
    >>> local_workers("local:none")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: --scheduler local:none: allowed: local:N, N workers from 1 to 256
    """
    if not address or not str(address).startswith(LOCAL + ":"):
        return None
    count = str(address)[len(LOCAL) + 1 :]
    require(
        count.isdigit() and 1 <= int(count) <= MAX_LOCAL_WORKERS,
        f"--scheduler {address}: allowed: local:N, N workers from 1 to {MAX_LOCAL_WORKERS}",
    )
    return int(count)


def connect_timeout(environ=None) -> float:
    """Seconds to wait for a remote scheduler: ``$SPECREF_DASK_TIMEOUT``, else 10.

    A setting rather than a constant: a scheduler across a slow network needs longer, and a test
    that proves an unreachable address is refused needs no more than a second or two.

    Parameters
    ----------
    environ : mapping, optional
        The environment to read (default ``os.environ``).

    Raises
    ------
    SpecrefError
        The variable is not a positive number of seconds (one line naming it).

    Examples
    --------
    >>> connect_timeout({"SPECREF_DASK_TIMEOUT": "2.5"})
    2.5
    >>> connect_timeout({})
    10.0
    >>> connect_timeout({"SPECREF_DASK_TIMEOUT": "soon"})
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: $SPECREF_DASK_TIMEOUT: 'soon' is not a number of seconds > 0
    """
    text = (os.environ if environ is None else environ).get(TIMEOUT_ENV, "").strip()
    if not text:
        return DEFAULT_TIMEOUT
    try:
        seconds = float(text)
    except ValueError:
        seconds = float("nan")
    require(seconds > 0, f"${TIMEOUT_ENV}: {text!r} is not a number of seconds > 0")
    return seconds


def add_scheduler_option(parser, default: str | None = None) -> None:
    """The ``--scheduler`` option of every command that runs tasks (one help text for all).

    Examples
    --------
    >>> import argparse
    >>> parser = argparse.ArgumentParser()
    >>> add_scheduler_option(parser, default=SERIAL)
    >>> parser.parse_args(["--scheduler", "local"]).scheduler
    'local'
    """
    fallback = (
        "this process, one task after another"
        if default == SERIAL
        else ("a local cluster of one worker process per core")
    )
    import argparse

    def address(value: str) -> str:  # checked when parsed, before any input is read
        try:
            scheduler_address(value)
            local_workers(value)
        except SpecrefError as error:
            raise argparse.ArgumentTypeError(str(error).removeprefix("--scheduler ")) from None
        return value

    parser.add_argument(
        "--scheduler",
        type=address,
        metavar="ADDRESS",
        help="where the tasks run: a running Dask scheduler (tcp://host:8786), 'local' (a local "
        "cluster of one worker process per core), 'local:N' (of N workers) or 'serial'; default "
        f"$SPECREF_SCHEDULER, else {fallback}",
    )


#: A local cluster's scheduler serves its HTTP routes (health, metrics) on a free loopback port:
#: Dask's default 8787 is taken when two commands run at once, and Dask then warns.
LOCAL_SCHEDULER_HTTP = {"dashboard_address": "127.0.0.1:0"}


@contextlib.contextmanager
def dask_client(
    scheduler: str | None = None, n_workers: int | None = None, timeout: float | None = None
):
    """A ``distributed.Client``: on ``scheduler`` if given, else on a new local cluster.

    Parameters
    ----------
    scheduler : str, optional
        Address of a running scheduler (``tcp://host:port``), or ``local:N`` (a local cluster of
        N workers); default ``$SPECREF_SCHEDULER``, else a ``LocalCluster`` of ``n_workers``
        single-threaded processes on 127.0.0.1.
    n_workers : int, optional
        Local workers (default: the machine's cores).
    timeout : float, optional
        Seconds to wait for a remote scheduler; default :func:`connect_timeout`
        (``$SPECREF_DASK_TIMEOUT``, else 10).

    Raises
    ------
    SpecrefError
        No scheduler answers at the address within ``timeout`` (one line, with the address).

    Examples
    --------
    >>> with dask_client("tcp://127.0.0.1:9", timeout=0.5):
    ...     pass
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: --scheduler tcp://127.0.0.1:9: no Dask scheduler answered ...
    """
    from distributed import Client

    address = scheduler_address(scheduler)
    timeout = connect_timeout() if timeout is None else timeout
    require(address != SERIAL, "dask_client: 'serial' runs without a client")
    if local_workers(address):
        address, n_workers = None, local_workers(address)
    if address:
        try:
            probe_scheduler(address, timeout)
            client = Client(address, timeout=timeout)
        except SpecrefError:  # the probe's own line: a peer that is not a scheduler
            raise
        except (OSError, TimeoutError, ValueError) as exc:
            raise SpecrefError(
                f"--scheduler {address}: no Dask scheduler answered within {timeout:g} s "
                f"({type(exc).__name__}); start one with `dask scheduler` or omit --scheduler "
                "for a local cluster"
            ) from None
        try:
            usable_workers(client, address, timeout)
            yield client
        finally:
            _USABLE.pop(client, None)
            client.close()
        return
    with _local_client(n_workers or os.cpu_count() or 1) as client:
        yield client


@contextlib.contextmanager
def _local_client(workers: int):
    # a LocalCluster of single-threaded worker processes on 127.0.0.1, with specref's settings
    import dask
    from distributed import Client, LocalCluster

    with (
        _environ_kept(),
        dask.config.set(
            {
                TRIM_SETTING: WORKER_TRIM_BYTES,
                MMAP_SETTING: WORKER_MMAP_BYTES,
                ARENA_SETTING: WORKER_ARENAS,
                PROFILE_SETTING: False,
                **QUIET_SETTINGS,
            }
        ),
        LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
            scheduler_kwargs=LOCAL_SCHEDULER_HTTP,
            silence_logs=logging.ERROR,
            preload=[__name__],  # dask_teardown: the workers exit without a last collection
        ) as cluster,
        Client(cluster) as client,
    ):
        yield client


def freeze_objects_for_exit() -> None:
    """Let this process exit without the interpreter's last collection over every object.

    When Python exits it runs the cyclic garbage collector over every object still alive; with
    specref's packages and colour-science loaded that took 0.4-0.5 s of every command's and every
    Dask worker's exit (measured from the command's return to the process's end: 0.55 s, and
    0.06 s frozen). ``gc.freeze`` moves the live objects out of the collector's reach, so the
    exit skips them; ``atexit`` handlers, ``weakref.finalize`` callbacks (temporary folders) and
    reference-counted destructors still run. Called once a process's work is done: by the
    ``specref`` command after its command returned, by a worker at its teardown
    (:func:`dask_teardown`).

    Examples
    --------
    >>> import gc
    >>> freeze_objects_for_exit()
    >>> gc.get_freeze_count() > 0
    True
    >>> gc.unfreeze()  # this process goes on: collect its objects again
    """
    import gc

    gc.freeze()


def dask_teardown(worker) -> None:
    """A local cluster's workers preload this module; Dask calls this as a worker closes.

    The worker then exits without the interpreter's last collection
    (:func:`freeze_objects_for_exit`): a two-worker cluster closed in 0.1 s instead of 0.55 s.

    Examples
    --------
    >>> import gc
    >>> dask_teardown(None)
    >>> gc.get_freeze_count() > 0
    True
    >>> gc.unfreeze()
    """
    freeze_objects_for_exit()


@contextlib.contextmanager
def _environ_kept():
    """The client's environment as it was before a local cluster's nannies wrote to it.

    The nannies write the workers' ``pre-spawn-environ`` (the allocator thresholds above, one
    thread per library) and their own bookkeeping (``PYTHONHASHSEED``, the parent's pid) into the
    client's ``os.environ``, where every process the client starts afterwards would inherit them.
    """
    saved = dict(os.environ)
    try:
        yield
    finally:
        for key in set(os.environ) - set(saved):
            del os.environ[key]
        os.environ.update(saved)


def specref_identity() -> dict:
    """What a process runs: specref's version and Python's, to compare a worker with its client.

    Runs on each worker (``Client.run``); a worker that cannot import specref fails to load it.

    Examples
    --------
    >>> sorted(specref_identity())
    ['python', 'specref']
    """
    import importlib.metadata
    import platform

    return {
        "specref": importlib.metadata.version("specref"),
        "python": ".".join(platform.python_version_tuple()[:2]),
    }


def worker_problems(identities: dict, expected: dict) -> dict[str, str]:
    """``worker -> why it cannot run this client's tasks``, from each worker's identity.

    ``identities`` maps worker addresses to :func:`specref_identity` results, or to the exception
    a worker returned instead (it could not import specref).

    Examples
    --------
    >>> me = {"specref": "0.1.0", "python": "3.11"}
    >>> found = {"tcp://a:1": me, "tcp://b:2": {**me, "specref": "0.0.9"},
    ...          "tcp://c:3": ModuleNotFoundError("No module named 'reference'")}
    >>> for worker, why in worker_problems(found, me).items():
    ...     print(worker, why)
    tcp://b:2 specref 0.0.9, the client runs 0.1.0
    tcp://c:3 cannot import specref (ModuleNotFoundError: No module named 'reference')
    """
    problems = {}
    for worker, found in sorted(identities.items()):
        if isinstance(found, BaseException):
            # Dask wraps an error it could not rebuild on the client in a plain Exception whose
            # text is the worker's repr of it
            why = str(found) if type(found) is Exception else f"{type(found).__name__}: {found}"
            problems[worker] = f"cannot import specref ({why})"
            continue
        differ = [
            f"{key} {found.get(key)}, the client runs {value}"
            for key, value in expected.items()
            if found.get(key) != value
        ]
        if differ:
            problems[worker] = "; ".join(differ)
    return problems


def usable_workers(client, address: str, timeout: float | None = None) -> list[str]:
    """The workers of a remote scheduler that run this specref; the others are refused.

    Waits up to ``timeout`` seconds (:func:`connect_timeout`) for a first worker, asks every worker
    for its :func:`specref_identity`, prints one line per refused worker on stderr (its address and
    the difference) and keeps the rest. When a worker was refused, tasks go to the kept ones only
    (:func:`run_tasks`); otherwise to any worker, so workers that join later or restart after a
    crash take tasks too.

    Raises
    ------
    SpecrefError
        No worker joined within ``timeout``, or none can run this specref (one line naming each).

    Examples
    --------
    >>> class Client:  # a stand-in for distributed.Client: two workers, one without specref
    ...     def wait_for_workers(self, n, timeout):
    ...         pass
    ...     def run(self, function, on_error):
    ...         return {"tcp://a:1": function(), "tcp://b:2": ImportError("no specref")}
    >>> usable_workers(Client(), "tcp://s:8786")  # stderr: specref: refused worker tcp://b:2: ...
    ['tcp://a:1']
    """
    timeout = connect_timeout() if timeout is None else timeout
    try:
        client.wait_for_workers(1, timeout=timeout)
    except TimeoutError:
        raise SpecrefError(
            f"--scheduler {address}: no worker joined within {timeout:g} s; start one with "
            f"`dask worker {address} --preload validation.worker`"
        ) from None
    identities = client.run(specref_identity, on_error="return")
    problems = worker_problems(identities, specref_identity())
    good = sorted(set(identities) - set(problems))
    if not good:
        listed = "; ".join(f"{worker}: {problem}" for worker, problem in problems.items())
        raise SpecrefError(f"--scheduler {address}: no usable worker ({listed})")
    for worker, problem in problems.items():
        sys.stderr.write(f"specref: refused worker {worker}: {problem}\n")
    if problems:  # tasks go to the kept workers only (with none refused: to any, as workers come)
        _USABLE[client] = good
    return good


@dataclass(frozen=True)
class Shared:
    """Work that several tasks need, computed once: a dependency of the tasks that use it.

    ``key(task)`` names the shared input a task needs (hashable, picklable); ``build(key)``
    computes it. :func:`run_tasks` then calls ``function(task, build(key(task)))``, building each
    key once: serially, in this process, dropped after its last task; on a cluster, as a Dask task
    that the chunks needing it depend on, so they run where it lives (Dask's data locality) and it
    is rebuilt from its key if its worker dies. Both functions are module-level and deterministic.

    Examples
    --------
    >>> shared = Shared(key=lambda task: task % 2, build=lambda key: 10 * key)
    >>> run_tasks(lambda task, built: task + built, [1, 2, 3], "serial", shared=shared,
    ...           progress=False)
    [11, 2, 13]
    """

    key: Callable[[object], Hashable]
    build: Callable[[Hashable], object]


def _shared_serial(function, tasks, shared: Shared, bar, timer) -> list:
    # each key built at its first task and dropped after its last one (a line each: it is long)
    keys = [shared.key(task) for task in tasks]
    last = {key: i for i, key in enumerate(keys)}
    built, results = {}, []
    for i, (task, key) in enumerate(zip(tasks, keys, strict=True)):
        if key not in built:
            with timer.stage(f"shared work {key!r}"):
                built[key] = shared.build(key)
        results.append(function(task, built[key]))
        if last[key] == i:
            del built[key]
        bar.update(1)
    return results


def _done(result, bar):
    bar.update(1)
    return result


#: Workers :func:`usable_workers` kept, per client, for :func:`run_tasks` (gone with the client).
_USABLE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def run_tasks(
    function: Callable,
    tasks: Sequence,
    scheduler: str | None = None,
    client=None,
    progress: bool = True,
    desc: str = "tasks",
    retries: int = 3,
    default: str | None = None,
    grain: int | None = None,
    shared: Shared | None = None,
) -> list:
    """``[function(task) for task in tasks]``, on a Dask cluster or serially, in task order.

    On a cluster, consecutive tasks go to a worker together, ``grain`` of them per Dask task
    (default :func:`chunk_size`: about :data:`CHUNKS_PER_WORKER` chunks per worker). Small tasks
    then pay the scheduler's per-task overhead once per chunk, and work that consecutive tasks
    share (an exact render that a function remembers, ``functools.lru_cache``) is done once per
    chunk rather than once per task on every worker: callers list their tasks with the shared
    inputs outermost. The results are the same, in the same order. Work that tasks share can
    also be named (``shared``): it is then a task of its own, built once, that they depend on.

    Parameters
    ----------
    function : callable
        A module-level function (workers import it by name), deterministic given its task.
    tasks : sequence
        One argument per call (picklable).
    scheduler : str, optional
        ``"serial"``, a scheduler address, or None: ``$SPECREF_SCHEDULER``, else a local cluster.
    client : distributed.Client, optional
        Use this client (and leave it open) instead of making one.
    progress : bool
        Progress on stderr (never under CI): a bar on a terminal; serially, without one, a line
        with the expected time once the tasks have run a couple of seconds
        (:class:`reference.progress.Progress`) and a line per shared build that runs over a
        second. A cluster's bar shows on a terminal only.
    retries : int
        Times a task is run again after its worker died.
    default : str, optional
        Where the tasks run when neither ``scheduler`` nor ``$SPECREF_SCHEDULER`` says
        (:func:`scheduler_address`).
    grain : int, optional
        Tasks per Dask task on a cluster (default :func:`chunk_size`); 1 sends each alone.
    shared : Shared, optional
        Calls ``function(task, shared.build(shared.key(task)))`` instead, each key built once
        (:class:`Shared`); a chunk then holds tasks of one key only.

    Returns
    -------
    list
        The results, in the order of ``tasks``.

    Examples
    --------
    >>> run_tasks(abs, [-1, 2, -3], scheduler="serial", progress=False)
    [1, 2, 3]
    """
    from reference.progress import ANNOUNCE_AFTER, Progress, StageTimer

    tasks = list(tasks)
    show = progress and not os.environ.get("CI") and sys.stderr.isatty()
    address = scheduler_address(scheduler, default)
    if grain is not None:
        require_positive_int(grain, "grain")
    if client is None and address == SERIAL:
        # a bar on a terminal; else, for work of more than a couple of seconds, lines
        stream = sys.stderr if progress and not os.environ.get("CI") else None
        with Progress(desc, len(tasks), stream, unit="tasks") as bar:
            if shared is not None:
                timer = StageTimer(stream, desc, ANNOUNCE_AFTER)
                return _shared_serial(function, tasks, shared, bar, timer)
            return [_done(function(task), bar) for task in tasks]
    with contextlib.ExitStack() as stack:
        if client is None:
            client = stack.enter_context(dask_client(address or LOCAL))
        return _gather(client, function, tasks, show, desc, retries, grain, shared)


#: glibc's trim threshold for worker processes. Dask's nanny sets ``MALLOC_TRIM_THRESHOLD_`` to
#: 64 KiB, which also switches off glibc's dynamic mmap threshold, so every NumPy temporary above
#: 128 KiB is an mmap and a munmap, which made a large Phong sweep slower on two workers than
#: serially (docs/scale-out.md; the benchmark group ``scaleout-cli`` measures it).
#: Local clusters get it through Dask's setting :data:`TRIM_SETTING`; ``dask worker --preload
#: validation.worker`` sets it in a running worker (:func:`set_malloc_trim`).
WORKER_TRIM_BYTES = 128 << 20
TRIM_SETTING = "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_"
#: glibc's mmap threshold for worker processes: the largest that glibc's own dynamic threshold
#: reaches (32 MiB on 64-bit), so temporaries below it reuse the heap as in a plain process.
WORKER_MMAP_BYTES = 32 << 20
MMAP_SETTING = "distributed.nanny.pre-spawn-environ.MALLOC_MMAP_THRESHOLD_"
#: glibc's malloc arenas for worker processes: one. A worker runs its tasks in a thread, and glibc
#: gives a thread an arena of its own, made of heaps of at most 64 MiB that it shrinks and grows
#: again (returning the pages to the system) as large temporaries come and go: the thresholds
#: above do not hold there. A 768-cell Phong sweep at 512² in a worker spent 3.3-4.7 s in the
#: kernel's page faults against 0.02-0.04 s with the main arena alone (12.6 s of user time either
#: way), which made a worker's cells a fifth slower than the same cells in a plain process.
WORKER_ARENAS = 1
ARENA_SETTING = "distributed.nanny.pre-spawn-environ.MALLOC_ARENA_MAX"


#: Dask's statistical profiler, which samples every worker's task thread every 10 ms: off in
#: local clusters, where it slowed long sweeps (docs/scale-out.md); for workers started by hand,
#: ``DASK_DISTRIBUTED__WORKER__PROFILE__ENABLED=False``.
PROFILE_SETTING = "distributed.worker.profile.enabled"

#: Dask's housekeeping in local clusters, slowed where nothing reads it: the event-loop watchdog
#: (every 20 ms by default, in the client, the scheduler, each nanny and each worker; it only warns
#: of a loop blocked for over 3 s) every 100 ms, and the resource sampling that feeds the
#: dashboard (every 500 ms; local clusters have no dashboard) every 2 s. On an idle two-worker
#: cluster the processes then spend 0.45 s of CPU in 15 s instead of 1.29 s, CPU that a sweep on
#: two cores takes from its workers (docs/scale-out.md; ``DASK_DISTRIBUTED__ADMIN__TICK__INTERVAL``
#: and ``DASK_DISTRIBUTED__ADMIN__SYSTEM_MONITOR__INTERVAL`` do the same for workers started by
#: hand).
QUIET_SETTINGS = {
    "distributed.admin.tick.interval": "100ms",
    "distributed.admin.system-monitor.interval": "2s",
}


#: glibc's thresholds for streamed commands (``env convert``, ``env spectralize``, ...): a block of
#: 8 MiB or more (a chunk's buffers at the default chunk size) is its own mapping, returned to the
#: system when freed, while the reader's smaller windows reuse the heap; set explicitly, so a
#: stream's resident memory stays a few chunks whatever the environment passed on (a parent that
#: started a Dask cluster passes the workers' thresholds to its children; docs/scale-out.md).
STREAMED_TRIM_BYTES, STREAMED_MMAP_BYTES = 128 << 10, 8 << 20


def set_malloc_trim(
    threshold: int = WORKER_TRIM_BYTES, mmap: int = WORKER_MMAP_BYTES, arenas: int | None = None
) -> bool:
    """Set glibc's trim and mmap thresholds in this process (``mallopt``); False without glibc.

    ``arenas``, when given, caps glibc's malloc arenas (:data:`WORKER_ARENAS` in a Dask worker,
    whose tasks run in a thread: threads made after this call share the main arena).

    Examples
    --------
    >>> set_malloc_trim()    # Linux with glibc: the workers' thresholds
    True
    >>> set_malloc_trim(STREAMED_TRIM_BYTES, STREAMED_MMAP_BYTES)   # a streamed command's
    True
    >>> set_malloc_trim()
    True
    """
    import ctypes
    import ctypes.util

    name = ctypes.util.find_library("c")
    try:
        libc = ctypes.CDLL(name) if name else None
        mallopt = libc.mallopt if libc is not None else None
    except (OSError, AttributeError):  # not glibc
        return False
    M_TRIM_THRESHOLD, M_MMAP_THRESHOLD, M_ARENA_MAX = -1, -3, -8
    return bool(
        mallopt
        and mallopt(M_TRIM_THRESHOLD, int(threshold)) == 1
        and mallopt(M_MMAP_THRESHOLD, int(mmap)) == 1
        and (arenas is None or mallopt(M_ARENA_MAX, int(arenas)) == 1)
    )


#: Chunks per worker that :func:`chunk_size` aims at: enough that the workers finish within about
#: a chunk of each other (the last wave leaves the others idle for up to one chunk's time) and a
#: slow or killed worker's share is redone or taken over in small pieces; few enough that each
#: chunk is long against the scheduler's few milliseconds per task (docs/scale-out.md). At 4 a
#: 4,608-cell Phong sweep on two workers ended with one worker idle for 2.6-6 s of its 35 s.
CHUNKS_PER_WORKER = 16


def chunk_size(n_tasks: int, n_workers: int) -> int:
    """Tasks per chunk: ``n_tasks`` over :data:`CHUNKS_PER_WORKER` chunks per worker, at least 1.

    Examples
    --------
    >>> chunk_size(2048, 2), chunk_size(5, 2), chunk_size(0, 4)
    (64, 1, 1)
    """
    return max(1, -(-n_tasks // (CHUNKS_PER_WORKER * max(n_workers, 1))))


def run_chunk(function: Callable, chunk: Sequence) -> list:
    """``[function(task) for task in chunk]``: one Dask task of :func:`run_tasks`.

    Examples
    --------
    >>> run_chunk(abs, [-1, -2])
    [1, 2]
    """
    return [function(task) for task in chunk]


def run_shared_chunk(function: Callable, built, chunk: Sequence) -> list:
    """``[function(task, built) for task in chunk]``: a Dask task with a :class:`Shared` input.

    ``built`` is the result of the shared task it depends on (:func:`run_tasks`).

    Examples
    --------
    >>> run_shared_chunk(pow, 2, [3, 4])
    [9, 16]
    """
    return [function(task, built) for task in chunk]


def _chunks(tasks: list, grain: int, shared: Shared | None) -> list[tuple]:
    # (key or None, task indices) per chunk: consecutive tasks, of one shared key when shared
    if shared is None:
        return [(None, range(i, min(i + grain, len(tasks)))) for i in range(0, len(tasks), grain)]
    groups: dict = {}
    for i, task in enumerate(tasks):
        groups.setdefault(shared.key(task), []).append(i)
    return [
        (key, indices[i : i + grain])
        for key, indices in groups.items()
        for i in range(0, len(indices), grain)
    ]


def _submit(client, function, tasks, chunks, shared, retries, workers) -> list:
    # one future per chunk; with shared work, one build per key that its chunks depend on
    options = {"pure": False, "retries": retries, "workers": workers}
    if shared is None:
        return [
            client.submit(run_chunk, function, [tasks[i] for i in indices], **options)
            for _, indices in chunks
        ]
    built = {}
    for key, _ in chunks:
        if key not in built:
            built[key] = client.submit(shared.build, key, **options)
    return [
        client.submit(
            run_shared_chunk, function, built[key], [tasks[i] for i in indices], **options
        )
        for key, indices in chunks
    ]


def _gather(client, function, tasks, show, desc, retries, grain, shared=None) -> list:
    from distributed import as_completed
    from tqdm import tqdm

    # a remote scheduler's workers that run this specref (usable_workers); None: any worker
    workers = _USABLE.get(client)
    n_workers = len(workers) if workers else max(len(client.scheduler_info()["workers"]), 1)
    grain = chunk_size(len(tasks), n_workers) if grain is None else grain
    chunks = _chunks(tasks, grain, shared)
    futures = _submit(client, function, tasks, chunks, shared, retries, workers)
    sizes = {future.key: len(indices) for future, (_, indices) in zip(futures, chunks, strict=True)}
    with tqdm(total=len(tasks), desc=desc, disable=not show, leave=False) as bar:
        for future in as_completed(futures):
            bar.update(sizes[future.key])
    results = [None] * len(tasks)
    for found, (_, indices) in zip(client.gather(futures), chunks, strict=True):
        for i, result in zip(indices, found, strict=True):
            results[i] = result
    return results

"""Tasks on Dask: identical to a serial run, survive a killed worker, and a real scheduler."""

import os
import shutil
import signal
import socket
import subprocess
import sys
import time

import pytest

from reference.errors import SpecrefError
from reference.tasks import dask_client, run_tasks


def seeded_sum(task):
    # a task that carries its own seed: the same result wherever and whenever it runs
    import numpy as np

    seed, n = task
    return float(np.random.default_rng(seed).standard_normal(n).sum())


def slow_square(task):
    time.sleep(0.4)
    return task * task


def worker_pid(dask_worker=None):
    return os.getpid()


TASKS = [(seed, 1000 + seed) for seed in range(24)]


@pytest.fixture(scope="module")
def client():
    with dask_client(n_workers=2) as c:
        yield c


def test_local_cluster_equals_serial(client):
    serial = run_tasks(seeded_sum, TASKS, scheduler="serial", progress=False)
    distributed = run_tasks(seeded_sum, TASKS, client=client, progress=False)
    assert distributed == serial  # bit-identical, in task order


def test_sweep_survives_a_killed_worker(client):
    futures_done = []
    tasks = list(range(16))
    pids = list(client.run(worker_pid).values())
    assert len(pids) == 2

    def kill_one_later():
        time.sleep(1.0)
        os.kill(pids[0], signal.SIGKILL)
        futures_done.append(True)

    import threading

    killer = threading.Thread(target=kill_one_later)
    killer.start()
    results = run_tasks(slow_square, tasks, client=client, progress=False)
    killer.join()
    assert futures_done == [True]
    assert results == [t * t for t in tasks]
    # the nanny restarted the killed worker
    client.wait_for_workers(2, timeout=60)
    assert pids[0] not in client.run(worker_pid).values()


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_unreachable_scheduler_is_one_line():
    # the client's own timeout (2 s) bounds the wait; the message states it
    address = f"tcp://127.0.0.1:{_free_port()}"
    message = rf"--scheduler {address}: no Dask scheduler answered within 2 s"
    with pytest.raises(SpecrefError, match=message), dask_client(address, timeout=2):
        pass


@pytest.mark.skipif(
    shutil.which("dask") is None
    and not os.path.exists(os.path.join(os.path.dirname(sys.executable), "dask")),
    reason="pip install distributed",
)
def test_real_scheduler_and_workers_on_loopback(tmp_path):
    # As a user would start them: `dask scheduler`, two `dask worker`s; stopped by process id.
    dask = os.path.join(os.path.dirname(sys.executable), "dask")
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    env = {**os.environ, "PYTHONPATH": os.getcwd()}
    logs = open(tmp_path / "dask.log", "wb")  # noqa: SIM115 - closed in finally
    procs = [
        subprocess.Popen(
            [
                dask,
                "scheduler",
                "--host",
                "127.0.0.1",
                "--port",
                str(port),
                "--dashboard-address",
                ":0",
                "--no-show",
            ],
            stdout=logs,
            stderr=logs,
            env=env,
        )
    ]
    try:
        for _ in range(2):
            procs.append(
                subprocess.Popen(
                    [
                        dask,
                        "worker",
                        address,
                        "--nthreads",
                        "1",
                        "--host",
                        "127.0.0.1",
                        "--no-dashboard",
                    ],
                    stdout=logs,
                    stderr=logs,
                    env=env,
                )
            )
        with dask_client(address, timeout=60) as c:
            c.wait_for_workers(2, timeout=120)
            results = run_tasks(seeded_sum, TASKS[:8], client=c, progress=False)
        assert results == run_tasks(seeded_sum, TASKS[:8], scheduler="serial", progress=False)
        # through the environment variable as well
        os.environ["SPECREF_SCHEDULER"] = address
        try:
            assert run_tasks(abs, [-2, 3], progress=False) == [2, 3]
        finally:
            del os.environ["SPECREF_SCHEDULER"]
    finally:
        for proc in reversed(procs):
            os.kill(proc.pid, signal.SIGTERM)
        for proc in procs:
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                os.kill(proc.pid, signal.SIGKILL)
                proc.wait()
        logs.close()

"""Tasks on Dask: identical to a serial run, survive a killed worker, and a real scheduler."""

import contextlib
import os
import shutil
import signal
import socket
import subprocess
import sys
import time

import pytest

from reference.errors import SpecrefError
from reference.tasks import Shared, dask_client, run_tasks


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


@pytest.fixture
def client(dask_local_client):
    # the session's local cluster (conftest.py): two single-threaded workers on 127.0.0.1
    return dask_local_client


def test_local_cluster_equals_serial(client):
    serial = run_tasks(seeded_sum, TASKS, scheduler="serial", progress=False)
    distributed = run_tasks(seeded_sum, TASKS, client=client, progress=False)
    assert distributed == serial  # bit-identical, in task order


def preload_names(dask_worker=None):
    return [preload.name for preload in dask_worker.preloads]


def test_local_workers_exit_without_a_last_collection(client):
    # they preload reference.tasks, whose dask_teardown freezes the objects (a doctest shows it)
    found = client.run(preload_names)
    assert len(found) == 2
    assert all("reference.tasks" in names for names in found.values())


def dask_settings(dask_worker=None):
    import dask

    from reference.tasks import QUIET_SETTINGS

    return {key: dask.config.get(key) for key in QUIET_SETTINGS}


def test_local_workers_keep_their_housekeeping_quiet(client):
    # the event-loop watchdog and the dashboard's sampling, slowed where nothing reads them
    from reference.tasks import QUIET_SETTINGS

    assert list(client.run(dask_settings).values()) == [QUIET_SETTINGS] * 2


def allocator_environment(dask_worker=None):
    keys = ("MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_THRESHOLD_", "MALLOC_ARENA_MAX")
    return [os.environ.get(key) for key in keys]


def test_local_workers_allocate_from_one_arena_with_the_workers_thresholds(client):
    # the tasks' thread shares the main arena, where the thresholds hold (reference.tasks)
    from reference.tasks import WORKER_ARENAS, WORKER_MMAP_BYTES, WORKER_TRIM_BYTES

    expected = [str(WORKER_TRIM_BYTES), str(WORKER_MMAP_BYTES), str(WORKER_ARENAS)]
    assert list(client.run(allocator_environment).values()) == [expected] * 2


#: The figures of ``specref phong table1`` that do not depend on the machine (timings do).
TABLE1_FIGURES = ("scene", "view", "placement", "interpolation", "entries", "segments", "rms")


def test_phong_table1_on_a_cluster_equals_serial(client):
    # docs/scale-out.md, "Sweeps as tasks": Table 1's scenes × views are tasks; the errors do not
    # depend on where they ran
    from validation.studies.phong_table1 import run_table1

    def figures(result):
        return [tuple(row[k] for k in TABLE1_FIGURES) for row in result["rows"]]

    args = (16, 16, 1, ("R1", "R3"), ("far", "near"), False)
    serial = run_table1(*args, scheduler="serial")
    distributed = run_table1(*args, scheduler=client.scheduler.address)
    assert len(serial["rows"]) == 4 * 17  # exact + 16 table rows per scene and view
    assert figures(distributed) == figures(serial)


def test_impastor_table1_on_a_cluster_equals_serial(client):
    # docs/scale-out.md, "Sweeps as tasks": Ferwerda's Table 1 runs one task per light; the same
    # table as serially
    import numpy as np

    from validation.studies.impastor import table1

    serial = table1(lights=("D65", "A"), scheduler="serial")
    distributed = table1(lights=("D65", "A"), scheduler=client.scheduler.address)
    assert [r["label"] for r in distributed["rows"]] == [r["label"] for r in serial["rows"]]
    for light in ("D65", "A"):
        got, want = distributed["lights"][light], serial["lights"][light]
        assert got["out_of_gamut"] == want["out_of_gamut"]
        for key in ("simulation_delta_E00", "screen_delta_E00"):
            # the last bits of NumPy's matrix products differ between processes (measured:
            # <= 3e-13 relative), so not byte for byte
            np.testing.assert_allclose(got[key], want[key], rtol=1e-12, atol=0)


def test_scheduler_names():
    from reference.tasks import SCHEDULER_ENV, scheduler_address

    env = os.environ.pop(SCHEDULER_ENV, None)
    try:
        assert scheduler_address(None, default="serial") == "serial"
        assert scheduler_address("local", default="serial") is None  # a new local cluster
        assert scheduler_address(None) is None
        os.environ[SCHEDULER_ENV] = "tcp://127.0.0.1:8786"
        assert scheduler_address(None, default="serial") == "tcp://127.0.0.1:8786"
        assert scheduler_address("serial") == "serial"
    finally:
        os.environ.pop(SCHEDULER_ENV, None)
        if env is not None:
            os.environ[SCHEDULER_ENV] = env


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
    # the client's own timeout (half a second) bounds the wait; the message states it
    address = f"tcp://127.0.0.1:{_free_port()}"
    message = rf"--scheduler {address}: no Dask scheduler answered within 0.5 s"
    with pytest.raises(SpecrefError, match=message), dask_client(address, timeout=0.5):
        pass


@pytest.mark.skipif(
    shutil.which("dask") is None
    and not os.path.exists(os.path.join(os.path.dirname(sys.executable), "dask")),
    reason="pip install distributed",
)
def test_the_wait_for_a_scheduler_is_a_setting(monkeypatch):
    # $SPECREF_DASK_TIMEOUT, not a constant, bounds the wait; the refusal says how long it waited
    monkeypatch.setenv("SPECREF_DASK_TIMEOUT", "1")
    address = f"tcp://127.0.0.1:{_free_port()}"
    refused = r"no Dask scheduler answered within 1 s"
    with pytest.raises(SpecrefError, match=refused), dask_client(address):
        pass
    monkeypatch.setenv("SPECREF_DASK_TIMEOUT", "-3")
    invalid = r"\$SPECREF_DASK_TIMEOUT: '-3' is not a number"
    with pytest.raises(SpecrefError, match=invalid), dask_client(address):
        pass


@contextlib.contextmanager
def _dask_processes(tmp_path, worker_envs, preload=True):
    """A real `dask scheduler` and one `dask worker` per environment, on 127.0.0.1.

    As a user would start them (with ``--preload validation.worker``); stopped by process id.
    Yields the scheduler's address.
    """
    dask = os.path.join(os.path.dirname(sys.executable), "dask")
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    logs = open(tmp_path / "dask.log", "ab")  # noqa: SIM115 - closed in finally
    scheduler = [dask, "scheduler", "--host", "127.0.0.1", "--port", str(port)]
    scheduler += ["--dashboard-address", ":0", "--no-show"]
    worker = [dask, "worker", address, "--nthreads", "1", "--host", "127.0.0.1", "--no-dashboard"]
    worker += ["--preload", "validation.worker"] if preload else []
    base = {**os.environ, "PYTHONPATH": os.getcwd()}
    procs = [subprocess.Popen(scheduler, stdout=logs, stderr=logs, env=base)]
    try:
        for env in worker_envs:
            procs.append(subprocess.Popen(worker, stdout=logs, stderr=logs, env={**base, **env}))
        yield address
    finally:
        # the workers first, each waited for, then the scheduler: a worker whose scheduler has
        # gone spends seconds retrying it before it stops (8 s here, against 0.6 s)
        for proc in reversed(procs):
            os.kill(proc.pid, signal.SIGTERM)
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                os.kill(proc.pid, signal.SIGKILL)
                proc.wait()
        logs.close()


def test_real_scheduler_and_workers_on_loopback(tmp_path):
    # As a user would start them: `dask scheduler`, two `dask worker`s; stopped by process id.
    with _dask_processes(tmp_path, [{}, {}]) as address:
        with dask_client(address, timeout=60) as c:
            c.wait_for_workers(2, timeout=120)
            results = run_tasks(seeded_sum, TASKS[:8], client=c, progress=False)
            # the preload ran: each worker imported specref and says which it runs
            assert set(c.run(lambda dask_worker: dask_worker.specref_identity["specref"]).values())
        assert results == run_tasks(seeded_sum, TASKS[:8], scheduler="serial", progress=False)
        # through the environment variable as well
        os.environ["SPECREF_SCHEDULER"] = address
        try:
            assert run_tasks(abs, [-2, 3], progress=False) == [2, 3]
        finally:
            del os.environ["SPECREF_SCHEDULER"]


def _without_specref(tmp_path) -> dict:
    # A worker environment where `import reference` fails, as on a machine without specref
    fake = tmp_path / "no-specref" / "reference"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text('raise ImportError("specref is not installed here")\n')
    return {"PYTHONPATH": str(fake.parent)}


def test_a_worker_without_specref_is_refused_in_one_line(tmp_path, capsys):
    # A sweep whose only worker cannot import specref ends within 60 s: one line, exit 2
    from validation.cli import main

    sweep = tmp_path / "s.toml"
    sweep.write_text(
        'kind = "phong"\n[grid]\nmaterials = ["R1"]\nviews = ["near"]\nplacements = ["uniform"]\n'
        'interpolations = ["linear"]\nentries = [25]\nresolution = 8\n'
    )
    from distributed import Client

    with _dask_processes(tmp_path, [_without_specref(tmp_path)], preload=False) as address:
        with Client(address, timeout=60) as c:  # the scheduler is up and the worker joined
            c.wait_for_workers(1, timeout=120)
        start = time.monotonic()
        code = main(["sweep", str(sweep), "-o", str(tmp_path / "out.csv"), "--scheduler", address])
        seconds = time.monotonic() - start
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert seconds < 60
    assert len(err) == 1, err
    assert f"--scheduler {address}: no usable worker (" in err[0]
    assert "cannot import specref (ImportError('specref is not installed here'))" in err[0]
    assert not (tmp_path / "out.csv").exists()


def test_a_mixed_cluster_runs_on_the_workers_that_have_specref(tmp_path, capsys):
    # One worker with specref, one without: the second is refused in one line, the tasks run
    with _dask_processes(tmp_path, [{}, _without_specref(tmp_path)], preload=False) as address:
        from distributed import Client

        with Client(address, timeout=60) as c:  # both workers joined
            c.wait_for_workers(2, timeout=120)
        with dask_client(address, timeout=60) as c:
            results = run_tasks(seeded_sum, TASKS[:6], client=c, progress=False)
    assert results == run_tasks(seeded_sum, TASKS[:6], scheduler="serial", progress=False)
    refused = [line for line in capsys.readouterr().err.splitlines() if "refused worker" in line]
    assert len(refused) >= 1
    assert "cannot import specref" in refused[-1]


def _set_impastor_quick(settings):
    # the ImpastoR section's quick settings in this process (a worker's, through client.run)
    from validation.report.sections import impastor

    impastor.QUICK = settings


def test_report_sections_on_a_cluster_equal_serial(client, tmp_path, monkeypatch):
    # specref report --scheduler: a section's tasks (here the hybrid's held-out cases, on the
    # section's tiny sizes with two paintings) run on the cluster and give the serial figures
    import dataclasses

    import numpy as np

    from validation.report.runner import run_report
    from validation.report.sections import impastor

    tiny, original = impastor.TINY, impastor.QUICK
    two = dataclasses.replace(tiny, held_out={**tiny.held_out, "n_paintings": 2})
    monkeypatch.setattr(impastor, "QUICK", two)

    def held_out(scheduler, folder):
        results = run_report(
            tmp_path / folder,
            effort="quick",
            only=["impastor"],
            progress=False,
            scheduler=scheduler,
        )
        return results["sections"]["impastor"]["held_out_hybrid"], results["meta"]["scheduler"]

    serial, where = held_out("serial", "a")
    # the section runs as a task on a worker: the workers get the same settings
    client.run(_set_impastor_quick, two)
    try:
        distributed, where_distributed = held_out(client.scheduler.address, "b")
    finally:
        client.run(_set_impastor_quick, original)
    assert (where, where_distributed) == ("serial", client.scheduler.address)
    # the section ran as a task on a worker, in a folder of its own: its files came back
    files = sorted(p.relative_to(tmp_path / "a") for p in (tmp_path / "a").rglob("*.png"))
    assert files
    assert files == sorted(p.relative_to(tmp_path / "b") for p in (tmp_path / "b").rglob("*.png"))
    assert distributed["cases"] == serial["cases"]
    assert len(serial["per_case"]) >= 2
    for got, want in zip(distributed["per_case"], serial["per_case"], strict=True):
        np.testing.assert_allclose(got["ratio"], want["ratio"], rtol=1e-12, atol=0)


@pytest.mark.parametrize(
    "command",
    [
        ["impastor", "table1"],
        ["phong", "table1", "--resolution", "8", "--entries", "8", "--repeats", "1"],
        ["report", "--quick", "--only", "spectral-core", "--no-screenshot"],
    ],
    ids=["impastor-table1", "phong-table1", "report"],
)
def test_commands_refuse_an_unreachable_scheduler_in_one_line(
    command, tmp_path, capsys, monkeypatch
):
    # every command with --scheduler: one line naming the address, exit 2, nothing written (the
    # wait is the setting's, shortened here: nothing answers on a free port)
    from validation.cli import main

    monkeypatch.setenv("SPECREF_DASK_TIMEOUT", "0.5")

    address = f"tcp://127.0.0.1:{_free_port()}"
    out = tmp_path / "out"
    extra = ["--out", str(out)] if command[0] == "report" else []
    assert main([*command, *extra, "--scheduler", address]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert address in err
    assert "Traceback" not in err
    assert not (out / "index.html").exists()


@pytest.mark.parametrize("grain", [1, 3, None, 1000])
def test_chunks_of_tasks_give_the_serial_results_in_order(client, grain):
    # consecutive tasks go to a worker together (grain per Dask task; None: chunk_size)
    serial = run_tasks(seeded_sum, TASKS[:10], scheduler="serial", progress=False)
    assert run_tasks(seeded_sum, TASKS[:10], client=client, progress=False, grain=grain) == serial


@pytest.mark.parametrize("grain", [0, -3, 2.5, float("nan")])
def test_a_bad_grain_is_one_line(client, grain):
    with pytest.raises(SpecrefError, match="grain"):
        run_tasks(seeded_sum, TASKS[:4], client=client, progress=False, grain=grain)


def shared_key(task):
    # tasks (folder, seed, n) share the work of their n, in no particular order
    folder, _, n = task
    return (folder, n)


def shared_build(key):
    # the shared work: leaves a file per build, so that a test counts the builds on every worker
    import uuid
    from pathlib import Path

    folder, n = key
    (Path(folder) / f"built-{n}-{uuid.uuid4().hex}").touch()
    return n * 1000


def shared_task(task, built):
    _, seed, n = task
    return seeded_sum((seed, n)) + built


def slow_shared_task(task, built):
    time.sleep(0.3)
    return shared_task(task, built)


def _shared_tasks(folder) -> list:
    return [(str(folder), seed, (100, 200, 300)[seed % 3]) for seed in range(18)]


def _direct(tasks) -> list:
    return [seeded_sum((seed, n)) + n * 1000 for _, seed, n in tasks]


def _builds(folder) -> dict:
    from collections import Counter

    return Counter(path.name.split("-")[1] for path in folder.glob("built-*"))


@pytest.mark.parametrize("grain", [None, 2])
def test_shared_work_is_built_once_per_key_and_gives_the_direct_results(client, tmp_path, grain):
    from reference.tasks import Shared

    tasks = _shared_tasks(tmp_path)
    shared = Shared(shared_key, shared_build)
    serial = run_tasks(shared_task, tasks, scheduler="serial", progress=False, shared=shared)
    assert serial == _direct(tasks)
    assert _builds(tmp_path) == {"100": 1, "200": 1, "300": 1}
    for path in tmp_path.glob("built-*"):
        path.unlink()
    found = run_tasks(shared_task, tasks, client=client, progress=False, shared=shared, grain=grain)
    assert found == serial  # in task order, although the keys interleave
    assert _builds(tmp_path) == {"100": 1, "200": 1, "300": 1}  # a task the chunks depend on


def test_shared_work_survives_a_killed_worker(client, tmp_path):
    # the worker holding a built input dies: Dask builds it again from its key, results unchanged
    from reference.tasks import Shared

    tasks = _shared_tasks(tmp_path)
    pids = list(client.run(worker_pid).values())

    def kill_one_later():
        time.sleep(1.5)
        os.kill(pids[0], signal.SIGKILL)

    import threading

    killer = threading.Thread(target=kill_one_later)
    killer.start()
    shared = Shared(shared_key, shared_build)
    found = run_tasks(
        slow_shared_task, tasks, client=client, progress=False, shared=shared, grain=1
    )
    killer.join()
    assert found == _direct(tasks)
    client.wait_for_workers(2, timeout=60)


def process_id(_task):
    return os.getpid()


def test_local_n_starts_a_cluster_of_n_workers(monkeypatch):
    # and leaves this process's environment as it was: Dask's nannies write the workers'
    # allocator thresholds into it, which every process started later would inherit
    for key in ("MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_THRESHOLD_", "MALLOC_ARENA_MAX"):
        monkeypatch.delenv(key, raising=False)
    before = dict(os.environ)
    pids = run_tasks(process_id, range(6), scheduler="local:1", progress=False, grain=1)
    assert len(set(pids)) == 1
    assert pids[0] != os.getpid()
    assert dict(os.environ) == before
    with pytest.raises(SpecrefError, match=r"^--scheduler local:0: allowed: local:N, N workers"):
        run_tasks(process_id, [1], scheduler="local:0", progress=False)


@pytest.mark.parametrize("count", ["0", "-2", "nan", "2.5", "", "100000"])
def test_a_bad_local_worker_count_is_one_line(tmp_path, capsys, count):
    # specref sweep --scheduler local:N with N not a worker count: one line, exit 2, before any
    # cluster starts, and the earlier output left as it was
    from validation.cli import main

    grid = tmp_path / "s.toml"
    grid.write_text(
        'kind = "phong"\n[grid]\nmaterials = ["R1"]\nviews = ["near"]\nplacements = ["error"]\n'
        'interpolations = ["linear"]\nentries = [8]\nresolution = 4\n'
    )
    out = tmp_path / "out.csv"
    out.write_text("earlier")
    argv = ["sweep", str(grid), "--scheduler", f"local:{count}", "-o", str(out)]
    with pytest.raises(SystemExit) as refused:  # refused while the arguments are parsed
        main(argv)
    assert refused.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert f"--scheduler: local:{count}: allowed: local:N, N workers from 1 to 256" in err
    assert out.read_text() == "earlier"


def test_serial_tasks_say_what_they_do(capsys, monkeypatch):
    """Each shared build has a line (it is the long part); a run under CI or silenced has none."""
    monkeypatch.delenv("CI", raising=False)
    monkeypatch.setattr("reference.progress.ANNOUNCE_AFTER", 0.0)  # every build, however quick
    shared = Shared(key=lambda task: task % 2, build=lambda key: 10 * key)
    found = run_tasks(lambda task, built: task + built, [1, 2, 3], "serial", shared=shared,
                      desc="study")  # fmt: skip
    assert found == [11, 2, 13]
    lines = capsys.readouterr().err.splitlines()
    assert [line.split(" ...")[0] for line in lines] == [
        "study: shared work 1",
        "study: shared work 0",
    ]
    run_tasks(lambda task, built: task, [1], "serial", shared=shared, progress=False)
    monkeypatch.setenv("CI", "true")
    run_tasks(lambda task, built: task, [1], "serial", shared=shared)
    assert capsys.readouterr().err == ""

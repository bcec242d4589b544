import os
import re
import signal
import subprocess
import sys
import textwrap
import time
import warnings
from pathlib import Path

import numpy as np
import pytest

from reference.errors import SpecrefError, SpecrefWarning
from shrm.cache import CACHE_MAGIC, Cache, cache_key, default_cache_dir, hash_inputs
from validation.cli import main

ROOT = Path(__file__).resolve().parents[2]


def _key(n=0):
    return cache_key("test.step", "1", {"n": n})


def _entry(cache, key):
    return cache.path_of(key)


# --- keys ------------------------------------------------------------------------------------


def test_cache_key_changes_with_every_input_and_nothing_else():
    env = np.linspace(0.0, 1.0, 12).reshape(2, 3, 2)
    base = {"env": env, "illuminant": "D65", "brdf": {"name": "ggx", "alpha": 0.2}, "order": 8}
    k = cache_key("shrm.create", "1", base)
    # Same content in new objects, other key order: the same key.
    same = {"order": 8, "brdf": {"alpha": 0.2, "name": "ggx"}, "illuminant": "D65", "env": env + 0}
    assert cache_key("shrm.create", "1", same) == k
    changed = [
        cache_key("shrm.create", "2", base),
        cache_key("sh.project", "1", base),
        cache_key("shrm.create", "1", {**base, "order": 9}),
        cache_key("shrm.create", "1", {**base, "illuminant": "A"}),
        cache_key("shrm.create", "1", {**base, "brdf": {"name": "ggx", "alpha": 0.21}}),
        cache_key("shrm.create", "1", {**base, "env": env.astype(np.float32)}),
        cache_key("shrm.create", "1", {**base, "env": env.reshape(3, 2, 2)}),
    ]
    flipped = env.copy()
    flipped[1, 2, 1] = np.nextafter(flipped[1, 2, 1], 2.0)
    changed.append(cache_key("shrm.create", "1", {**base, "env": flipped}))
    assert len({k, *changed}) == len(changed) + 1


def test_hash_inputs_refuses_objects():
    with pytest.raises(SpecrefError, match=r"cache key: inputs\.f: must be an array"):
        hash_inputs({"f": object()})
    with pytest.raises(SpecrefError, match="arrays must be numeric"):
        hash_inputs({"a": np.array(["x"], dtype=object)})


def test_default_cache_dir_follows_environment(monkeypatch, tmp_path):
    monkeypatch.delenv("SPECREF_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert default_cache_dir() == tmp_path / "xdg" / "specref"
    monkeypatch.delenv("XDG_CACHE_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert default_cache_dir() == tmp_path / "home" / ".cache" / "specref"
    monkeypatch.setenv("SPECREF_CACHE_DIR", str(tmp_path / "mine"))
    assert default_cache_dir() == tmp_path / "mine"
    assert Cache().directory == tmp_path / "mine"


def test_bad_key_and_limit_are_refused(tmp_path, monkeypatch):
    with pytest.raises(SpecrefError, match="cache key: must be 64 lowercase hex digits"):
        Cache(tmp_path).get("../etc/passwd")
    monkeypatch.setenv("SPECREF_CACHE_MAX_BYTES", "lots")
    with pytest.raises(SpecrefError, match="SPECREF_CACHE_MAX_BYTES: must be an integer"):
        Cache(tmp_path)


# --- entries ---------------------------------------------------------------------------------


def test_round_trip_and_hit_counts(tmp_path, rng):
    cache = Cache(tmp_path)
    data = {"coeffs": rng.normal(size=(3, 16)), "order": np.array(3)}
    calls = []

    def compute():
        calls.append(1)
        return data

    first = cache.get_or_compute(_key(), compute)
    second = cache.get_or_compute(_key(), compute)
    assert len(calls) == 1
    assert (cache.hits, cache.misses) == (1, 1)
    np.testing.assert_array_equal(second["coeffs"], data["coeffs"])
    np.testing.assert_array_equal(first["coeffs"], data["coeffs"])
    assert _entry(cache, _key()).read_bytes().startswith(CACHE_MAGIC)
    # A fresh process-level view (a new Cache object) sees the same entry.
    assert Cache(tmp_path).get(_key())["order"] == 3
    assert not list(tmp_path.glob(".*.tmp"))


def test_disabled_cache_always_computes(tmp_path):
    cache = Cache(tmp_path, enabled=False)
    cache.get_or_compute(_key(), lambda: {"x": np.ones(2)})
    assert cache.get(_key()) is None
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize("where", ["payload", "header", "checksum"])
def test_flipped_byte_is_detected_reported_once_deleted_and_rebuilt(tmp_path, where):
    cache = Cache(tmp_path)
    cache.put(_key(), {"x": np.arange(100.0)})
    path = _entry(cache, _key())
    data = bytearray(path.read_bytes())
    checksum = len(CACHE_MAGIC) + 8  # after the format version and the header length
    offset = {"payload": len(data) - 40, "header": len(CACHE_MAGIC) + 45, "checksum": checksum}[
        where
    ]
    data[offset] ^= 0x01
    path.write_bytes(bytes(data))
    with pytest.warns(SpecrefWarning, match="deleted, the result is rebuilt") as record:
        assert cache.get(_key()) is None
    assert len(record) == 1
    assert not path.exists()
    rebuilt = cache.get_or_compute(_key(), lambda: {"x": np.arange(100.0)})
    np.testing.assert_array_equal(rebuilt["x"], np.arange(100.0))
    assert Cache(tmp_path).get(_key()) is not None


def test_truncated_entry_is_detected(tmp_path):
    cache = Cache(tmp_path)
    cache.put(_key(), {"x": np.arange(100.0)})
    path = _entry(cache, _key())
    for size in (len(path.read_bytes()) // 2, len(CACHE_MAGIC) + 3):
        data = path.read_bytes() if path.exists() else None
        if data is None:
            cache.put(_key(), {"x": np.arange(100.0)})
            data = path.read_bytes()
        path.write_bytes(data[:size])
        with pytest.warns(SpecrefWarning, match="truncated|checksum"):
            assert cache.get(_key()) is None
        assert not path.exists()


def test_foreign_files_are_ignored_with_a_warning_and_never_deleted(tmp_path):
    cache = Cache(tmp_path, max_bytes=0)
    notes = tmp_path / "notes.txt"
    notes.write_text("mine")
    squatter = _entry(cache, _key(1))
    squatter.write_bytes(b"not a cache entry at all")
    blocker = _entry(cache, _key(2))
    blocker.mkdir()  # unreadable as a file
    with pytest.warns(SpecrefWarning, match="no specref header"):
        assert cache.get(_key(1)) is None
    with pytest.warns(SpecrefWarning, match="unreadable"):
        assert cache.get(_key(2)) is None
    with pytest.warns(SpecrefWarning, match="is not cached"):
        assert cache.put(_key(1), {"x": np.ones(3)}) is False
    with pytest.warns(SpecrefWarning, match="is not cached"):
        assert cache.put(_key(2), {"x": np.ones(3)}) is False
    assert cache.unusable is None  # one foreign name does not turn the cache off
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SpecrefWarning)
        cache.put(_key(3), {"x": np.ones(3)})  # evicts down to 0 bytes
        info = cache.info()
        assert cache.clear() == 0
    assert sorted(info.foreign) == sorted([notes.name, squatter.name, blocker.name])
    assert info.entries == 0
    assert notes.read_text() == "mine"
    assert squatter.read_bytes() == b"not a cache entry at all"
    assert blocker.is_dir()


def test_lru_eviction_keeps_recently_used_entries(tmp_path):
    cache = Cache(tmp_path)
    for n in range(3):
        cache.put(_key(n), {"x": np.full(1000, float(n))})
    size = _entry(cache, _key(0)).stat().st_size
    # the LRU clock is the modification time: set the three entries' in order, in the past
    epoch = 1_700_000_000
    for n in range(3):
        os.utime(_entry(cache, _key(n)), (epoch + n, epoch + n))
    assert cache.get(_key(0)) is not None  # key 0 becomes the most recently used
    cache.max_bytes = 3 * size + 64  # room for three entries, not four (headers vary by bytes)
    cache.put(_key(3), {"x": np.full(1000, 3.0)})
    present = [n for n in range(4) if _entry(cache, _key(n)).exists()]
    assert present == [0, 2, 3]
    assert cache.info().total_bytes <= cache.max_bytes
    assert cache.clear() == 3
    assert cache.info().entries == 0


# --- processes -------------------------------------------------------------------------------

_WRITER = textwrap.dedent(
    """
    import sys, time, numpy as np
    from pathlib import Path
    from shrm.cache import Cache, cache_key
    folder, marker, mode = sys.argv[1], Path(sys.argv[2]), sys.argv[3]
    key = cache_key("test.step", "1", {"n": 0})
    value = np.arange(200_000.0)

    def hang(path, written, total):
        # the marker appears whole (renamed into place): the test reads it as soon as it exists
        marker.with_suffix(".part").write_text(f"{written} {total}")
        marker.with_suffix(".part").rename(marker)
        time.sleep(60)

    if mode == "hang":
        Cache(folder, write_hook=hang).put(key, {"x": value})
    else:  # race: wait for the start signal, then write the same key several times
        while not marker.exists():
            time.sleep(0.001)
        cache = Cache(folder)
        for _ in range(5):
            cache.put(key, {"x": value})
        assert np.array_equal(Cache(folder).get_or_compute(key, lambda: {"x": value})["x"], value)
    """
)


def _spawn(tmp_path, marker, mode):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.Popen(
        [sys.executable, "-c", _WRITER, str(tmp_path / "cache"), str(marker), mode],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def _wait_for(path, process, timeout=60.0):
    start = time.monotonic()
    while not path.exists():
        assert process.poll() is None, process.communicate()[1]
        assert time.monotonic() - start < timeout, "writer never reached the hook"
        time.sleep(0.01)


@pytest.mark.slow
@pytest.mark.parametrize("previous", [False, True], ids=["empty", "over-an-old-entry"])
def test_sigkill_in_the_middle_of_a_write_then_load_or_rebuild(tmp_path, previous):
    cache = Cache(tmp_path / "cache")
    value = np.arange(200_000.0)
    if previous:
        cache.put(_key(), {"x": value})
    marker = tmp_path / "reached-hook"
    writer = _spawn(tmp_path, marker, "hang")
    _wait_for(marker, writer)
    written, total = map(int, marker.read_text().split())
    assert 0 < written < total  # killed with a half-written temporary file on disk
    assert list((tmp_path / "cache").glob(".*.tmp"))
    writer.send_signal(signal.SIGKILL)
    assert writer.wait(timeout=30) == -signal.SIGKILL
    calls = []

    def rebuild():
        calls.append(1)
        return {"x": value}

    with warnings.catch_warnings():
        warnings.simplefilter("error", SpecrefWarning)  # no corrupt entry may be visible
        got = Cache(tmp_path / "cache").get_or_compute(_key(), rebuild)
    np.testing.assert_array_equal(got["x"], value)
    assert len(calls) == (0 if previous else 1)
    assert Cache(tmp_path / "cache").info().entries == 1


@pytest.mark.slow
def test_concurrent_writers_both_succeed_and_leave_one_valid_entry(tmp_path):
    go = tmp_path / "go"
    writers = [_spawn(tmp_path, go, "race") for _ in range(2)]
    time.sleep(0.5)
    go.write_text("go")
    for writer in writers:
        _out, err = writer.communicate(timeout=120)
        assert writer.returncode == 0, err
    cache = Cache(tmp_path / "cache")
    with warnings.catch_warnings():
        warnings.simplefilter("error", SpecrefWarning)
        got = cache.get(_key())
    np.testing.assert_array_equal(got["x"], np.arange(200_000.0))
    assert cache.info().entries == 1
    assert not list((tmp_path / "cache").glob(".*.tmp"))


# --- CLI -------------------------------------------------------------------------------------


def test_cli_cache_info_and_clear(tmp_path, capsys):
    cache = Cache(tmp_path)
    cache.put(_key(), {"x": np.ones(10)})
    (tmp_path / "README").write_text("foreign")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SpecrefWarning)
        assert main(["cache", "info", "--cache-dir", str(tmp_path)]) == 0
        out = capsys.readouterr().out
        assert f"location: {tmp_path}" in out
        assert "entries: 1" in out
        assert "README" in out
        assert main(["cache", "clear", "--cache-dir", str(tmp_path)]) == 0
        assert Cache(tmp_path).info().entries == 0
    assert "deleted 1 entries" in capsys.readouterr().out
    assert (tmp_path / "README").read_text() == "foreign"


def test_specrefs_other_caches_are_named_not_foreign(tmp_path):
    # The Jakob 2019 tables, the numba kernels and the conformance references share the cache
    # root: named for what they are, never warned about, never deleted; a stranger still is
    (tmp_path / "jakob2019-sRGB-64.coeff").write_bytes(b"\0" * 16)
    (tmp_path / "numba").mkdir()
    (tmp_path / "conformance").mkdir()
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.warns(SpecrefWarning, match="notes.txt: not a specref cache entry") as caught:
        info = Cache(tmp_path).info()
    assert not [w for w in caught if "jakob2019" in str(w.message) or "numba" in str(w.message)]
    assert info.foreign == ["notes.txt"]
    assert set(info.others) == {"jakob2019-sRGB-64.coeff", "numba", "conformance"}
    with pytest.warns(SpecrefWarning, match="notes.txt"):
        Cache(tmp_path).clear()
    assert (tmp_path / "jakob2019-sRGB-64.coeff").exists()
    assert (tmp_path / "numba").is_dir()


def test_the_command_prints_a_warning_as_one_line(tmp_path):
    (tmp_path / "notes.txt").write_text("mine")
    (tmp_path / "jakob2019-sRGB-8.coeff").write_bytes(b"\0")
    done = subprocess.run(
        [sys.executable, "-m", "validation.cli", "cache", "info", "--cache-dir", str(tmp_path)],
        capture_output=True,
        text=True,
        check=True,
    )
    assert done.stderr.splitlines() == [
        f"specref: warning: {tmp_path / 'notes.txt'}: not a specref cache entry (no specref "
        "header); ignored"
    ]
    assert "also here: jakob2019-sRGB-8.coeff: Jakob 2019 coefficient table" in done.stdout


# --- an unusable folder, races with clear, leftovers ----------------------------------------


def _mount_read_only(folder) -> bool:
    """A real read-only file system at ``folder`` (root: a tmpfs mounted ro); False otherwise."""
    import shutil

    folder.mkdir()
    if os.geteuid() != 0 or shutil.which("mount") is None:
        return False
    done = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=64k,ro", "tmpfs", str(folder)], capture_output=True
    )
    return done.returncode == 0


@pytest.fixture
def read_only_cache(tmp_path):
    folder = tmp_path / "ro"
    if _mount_read_only(folder):
        yield folder
        subprocess.run(["umount", str(folder)], check=False)
        return
    folder.chmod(0o555)  # not root: the permission bits refuse the write
    yield folder
    folder.chmod(0o755)


def _full_disk(folder, monkeypatch):
    """ENOSPC at the writer's temporary file, as tests/validation/cli/test_cli_outputs.py does."""
    import errno
    import tempfile

    real = tempfile.mkstemp

    def mkstemp(*args, dir=None, **kwargs):
        if dir is not None and Path(dir).resolve().is_relative_to(folder.resolve()):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real(*args, dir=dir, **kwargs)

    monkeypatch.setattr(tempfile, "mkstemp", mkstemp)


def _unusable(kind, tmp_path, monkeypatch, read_only_cache):
    if kind == "read-only":
        return read_only_cache, "read-only file system|permission denied"
    if kind == "full":
        folder = tmp_path / "full"
        folder.mkdir()
        _full_disk(folder, monkeypatch)
        return folder, "no space left"
    if kind == "file":
        (tmp_path / "file").write_text("not a folder")
        return tmp_path / "file", "a part of the path is a file"
    # a read-only home: the default ~/.cache/specref cannot be created
    monkeypatch.delenv("SPECREF_CACHE_DIR", raising=False)
    monkeypatch.delenv("XDG_CACHE_HOME", raising=False)
    monkeypatch.setenv("HOME", str(read_only_cache))
    return None, "read-only file system|permission denied"


@pytest.mark.parametrize("kind", ["read-only", "full", "file", "read-only home"])
def test_unusable_folder_warns_once_and_runs_without_the_cache(
    kind, tmp_path, monkeypatch, read_only_cache
):
    folder, reason = _unusable(kind, tmp_path, monkeypatch, read_only_cache)
    cache = Cache(folder)
    calls = []

    def compute(n):
        calls.append(n)
        return {"x": np.full(4, float(n))}

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for n in (0, 1, 0):
            got = cache.get_or_compute(_key(n), lambda n=n: compute(n))
            np.testing.assert_array_equal(got["x"], np.full(4, float(n)))
        cache.info()
    messages = [str(w.message) for w in caught if issubclass(w.category, SpecrefWarning)]
    assert len(messages) == 1, messages
    assert "\n" not in messages[0]
    assert "cache folder unusable" in messages[0]
    assert re.search(reason, messages[0]), messages[0]
    assert calls == [0, 1, 0]  # nothing was cached, every result computed


@pytest.mark.slow
def test_shrm_orbit_runs_without_an_unusable_cache(tmp_path, capsys):
    (tmp_path / "file").write_text("not a folder")
    argv = ["shrm", "orbit", "--quick", "--frames", "1", "-o", str(tmp_path / "out")]
    capsys.readouterr()
    assert main([*argv, "--cache-dir", str(tmp_path / "file")]) == 0
    # the command shows the warning once, as one line (docs/bad-input.md)
    lines = capsys.readouterr().err.splitlines()
    assert len([x for x in lines if x.startswith("specref: warning:") and "unusable" in x]) == 1
    assert (tmp_path / "out" / "frame_000.png").is_file()


def test_writer_survives_a_clear_in_the_middle_of_its_write(tmp_path, capsys):
    # Deterministic interleaving: `specref cache clear` runs while the writer's temporary file
    # holds half an entry (before the fix, clear deleted it and the writer's rename crashed).
    value = np.arange(1000.0)
    Cache(tmp_path).put(_key(1), {"x": value})
    cleared = []

    def clear_now(path, written, total):
        assert list(tmp_path.glob(".*.tmp"))
        cleared.append(main(["cache", "clear", "--cache-dir", str(tmp_path)]))

    cache = Cache(tmp_path, write_hook=clear_now)
    assert cache.put(_key(), {"x": value}) is True
    assert cleared == [0]
    assert "deleted 1 entries" in capsys.readouterr().out
    np.testing.assert_array_equal(Cache(tmp_path).get(_key())["x"], value)


def test_writer_whose_temporary_file_vanishes_keeps_its_result(tmp_path):
    # an outside `rm` of the folder's files mid-write: not cached, no crash
    def remove(path, written, total):
        for temp in tmp_path.glob(".*.tmp"):
            temp.unlink()

    cache = Cache(tmp_path, write_hook=remove)
    with pytest.warns(SpecrefWarning, match="temporary file removed"):
        got = cache.get_or_compute(_key(), lambda: {"x": np.ones(8)})
    np.testing.assert_array_equal(got["x"], np.ones(8))
    assert not cache.path_of(_key()).exists()


@pytest.mark.filterwarnings("ignore:.*notes.tmp")
@pytest.mark.parametrize("content", [b"", b"SPECREF", CACHE_MAGIC + b"\x03\x00"])
def test_stale_temporary_files_are_removed_young_ones_kept(tmp_path, content):
    from shrm.cache import STALE_TEMP_SECONDS

    cache = Cache(tmp_path)
    old, young = (tmp_path / f".{_key(n)}.specref.abc{n}.tmp" for n in (0, 1))
    for temp in (old, young):
        temp.write_bytes(content)
    foreign = tmp_path / ".notes.tmp"  # not a name our writers make
    foreign.write_bytes(b"")
    # an mtime older than the stale age, relative to the file's own (not a timing measurement)
    past = young.stat().st_mtime - STALE_TEMP_SECONDS - 60
    for path in (old, foreign):
        os.utime(path, (past, past))
    assert cache.clear() == 0
    assert not old.exists()
    assert young.exists()
    assert foreign.exists()
    # and on opening a cache
    os.utime(young, (past, past))
    Cache(tmp_path)
    assert not young.exists()
    assert foreign.exists()


@pytest.mark.parametrize("size", [0, 3, len(CACHE_MAGIC) - 1])
def test_entry_truncated_inside_the_magic_is_rebuilt(tmp_path, size):
    cache = Cache(tmp_path)
    cache.put(_key(), {"x": np.arange(10.0)})
    path = _entry(cache, _key())
    path.write_bytes(path.read_bytes()[:size])
    assert cache.info().entries == 1  # ours, not foreign
    with pytest.warns(SpecrefWarning, match="truncated"):
        got = cache.get_or_compute(_key(), lambda: {"x": np.arange(10.0)})
    np.testing.assert_array_equal(got["x"], np.arange(10.0))
    np.testing.assert_array_equal(Cache(tmp_path).get(_key())["x"], np.arange(10.0))

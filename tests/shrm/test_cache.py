import os
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
        marker.write_text(f"{written} {total}")
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

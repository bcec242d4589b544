"""A crash-safe, content-addressed persistent cache for maps: SH coefficients, SHRMs, prefilters.

§5.2, Herbert et al.: "A persistent caching scheme, which is tied into this algorithm [...] realizes
map reuse." specref's scheme:

- **Content-addressed.** :func:`cache_key` hashes everything a map depends on: the producing step's
  name and code version, and every input (arrays by dtype, shape and bytes; parameters by
  canonical JSON). A change to any input misses; nothing else does.
- **Entries.** One file ``<key>.specref`` per entry: the magic ``SPECREF-CACHE`` and a newline,
  a format version, the header length, a CRC-32 checksum of everything after it, a JSON
  header (key, metadata, and the name, dtype, shape and offset of each array) and the payload: the
  arrays' raw bytes, 64-byte aligned. A hit maps them without copies (read-only arrays) and no
  pickle is ever involved.
- **Atomic writes.** An entry is written to a temporary file in the cache folder, synced and renamed
  into place (:func:`reference.files.atomic_write`). A writer killed at any point leaves either no
  entry or a whole one. Two processes writing the same key both succeed; the last rename wins and
  leaves one valid entry.
- **Corruption.** A truncated or corrupted entry (bad checksum, short file, bad header) is reported
  once as a :class:`~reference.errors.SpecrefWarning`, deleted and rebuilt. The checksum is CRC-32
  (``zlib.crc32``, as in PNG and gzip): it catches every burst of up to 32 flipped bits and all
  but 2^-32 of other accidents, at about 7 GB/s against SHA-256's 2 GB/s, and a hit must verify
  every byte it maps. It guards against accidents, not against someone who can write to the
  user's own cache folder (the keys themselves are SHA-256 hashes of the inputs).
  An entry cut shorter than the magic itself (a few bytes, or none) is a truncated entry too.
- **Foreign files.** A file in the cache folder that does not start with our magic, or that cannot
  be read, is ignored with a warning and never deleted or overwritten.
- **An unusable folder.** A cache folder that cannot be created, read or written (read-only, a
  full disk, a regular file where the folder should be, a read-only home) is reported once per
  :class:`Cache` as a one-line :class:`~reference.errors.SpecrefWarning`; the cache then passes
  through (every lookup misses, nothing is written) and the caller runs without it.
- **Temporary files.** A writer's temporary file older than :data:`STALE_TEMP_SECONDS` (an hour)
  belongs to a writer that died (a live writer fills and renames its file within the time of
  one write, and rewrites it meanwhile): opening a :class:`Cache`, ``clear`` and eviction remove
  such files, empty ones included. Younger temporary files are left alone, so ``clear`` never
  pulls a file from under a live writer; a writer whose temporary file vanishes anyway (an
  outside ``rm``) keeps its result, uncached.
- **Size limit.** After each write the least-recently-used entries are deleted until the folder's
  entries fit in ``max_bytes``; a hit refreshes the entry's modification time, which is the LRU
  clock.
- **Location.** :func:`reference.files.default_cache_dir`: ``$SPECREF_CACHE_DIR`` if set, else
  ``$XDG_CACHE_HOME/specref``, else ``~/.cache/specref``; the CLI's ``--cache-dir`` overrides both.
  ``specref cache info`` and ``specref cache clear`` inspect and empty it.

References
----------
- F. Herbert, J. Kirkenaer, O. Unter Ecker, "Achieving a Multi-spectral Virtual Reality", 2004.
- XDG Base Directory Specification 0.8 (``XDG_CACHE_HOME``).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import struct
import time
import warnings
import zlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reference.errors import SpecrefError, SpecrefWarning, require
from reference.files import atomic_write, default_cache_dir, output_error

__all__ = [
    "CACHE_MAGIC",
    "DEFAULT_MAX_BYTES",
    "OTHER_SPECREF_CACHES",
    "Cache",
    "CacheInfo",
    "cache_key",
    "default_cache_dir",
    "hash_inputs",
    "other_specref_cache",
]

#: The first bytes of every entry; a file without them is not ours and is never deleted.
CACHE_MAGIC = b"SPECREF-CACHE\n"
#: Entry layout version (bumped when the layout changes; older entries are then rebuilt).
#: 3: CRC-32 instead of SHA-256 as the entry checksum.
FORMAT_VERSION = 3
#: Default size limit of the cache folder, bytes (overridden by ``SPECREF_CACHE_MAX_BYTES``).
DEFAULT_MAX_BYTES = 2 * 1024**3
_SUFFIX = ".specref"
_PREFIX = struct.Struct("<III")  # format version, header length, CRC-32 of the rest
_HEAD = len(CACHE_MAGIC) + _PREFIX.size
#: A leftover temporary file older than this (s) belongs to a writer that died; opening a cache,
#: ``clear`` and eviction remove it (empty or carrying our magic); younger ones are left alone.
STALE_TEMP_SECONDS = 3600.0


def _feed(h, value, where: str) -> None:
    """Feed one input to the hash: arrays by dtype, shape and bytes; the rest by canonical JSON."""
    if isinstance(value, np.ndarray | np.generic):
        array = np.ascontiguousarray(value)
        require(
            array.dtype.kind in "biufc",
            f"cache key: {where}: arrays must be numeric, got dtype {array.dtype}",
        )
        h.update(b"A" + array.dtype.str.encode() + repr(array.shape).encode())
        h.update(array.tobytes())
        return
    if isinstance(value, Mapping):
        h.update(b"{")
        for key in sorted(value, key=str):
            h.update(json.dumps(str(key)).encode() + b":")
            _feed(h, value[key], f"{where}.{key}")
        h.update(b"}")
        return
    if isinstance(value, list | tuple):
        h.update(b"[")
        for i, item in enumerate(value):
            _feed(h, item, f"{where}[{i}]")
        h.update(b"]")
        return
    try:
        text = json.dumps(value, sort_keys=True, separators=(",", ":"), allow_nan=True)
    except TypeError:
        raise SpecrefError(
            f"cache key: {where}: must be an array, a number, a string, a bool, None, a list or "
            f"a dict, got {type(value).__name__}"
        ) from None
    h.update(b"J" + text.encode())


def hash_inputs(inputs: Mapping) -> str:
    """SHA-256 of named inputs: arrays by dtype, shape and bytes; parameters by canonical JSON.

    Parameters
    ----------
    inputs : mapping of str to array, number, str, bool, None, list or dict
        Everything a result depends on. Key order does not matter.

    Returns
    -------
    str
        64 hexadecimal digits.

    Raises
    ------
    SpecrefError
        An input of a type that has no canonical form (an object, a function).

    Examples
    --------
    >>> a = hash_inputs({"order": 10, "env": np.zeros(3)})
    >>> a == hash_inputs({"env": np.zeros(3), "order": 10})
    True
    >>> a == hash_inputs({"order": 10, "env": np.zeros(3, np.float32)})
    False
    """
    h = hashlib.sha256()
    _feed(h, dict(inputs), "inputs")
    return h.hexdigest()


def cache_key(step: str, code_version: str, inputs: Mapping) -> str:
    """The key of a cached result: the step, its code version and every input, hashed.

    Parameters
    ----------
    step : str
        The producing step, e.g. ``"shrm.create"``.
    code_version : str
        The step's code version; bump it when the step's algorithm changes.
    inputs : mapping
        Everything the result depends on (see :func:`hash_inputs`).

    Returns
    -------
    str
        64 hexadecimal digits (SHA-256).

    Examples
    --------
    >>> k = cache_key("sh.project", "1", {"order": 8})
    >>> len(k), k == cache_key("sh.project", "2", {"order": 8})
    (64, False)
    """
    require(
        isinstance(step, str) and step, f"cache key: step must be a non-empty str, got {step!r}"
    )
    return hash_inputs({"step": step, "code_version": str(code_version), "inputs": inputs})


@dataclass(frozen=True)
class CacheInfo:
    """What :meth:`Cache.info` reports.

    Attributes
    ----------
    directory : Path
        The cache folder.
    entries : int
        Number of entries (files that carry our magic).
    total_bytes : int
        Their total size.
    max_bytes : int
        The size limit.
    foreign : list of str
        Names of files in the folder that are not ours (ignored, never deleted).
    others : dict
        specref's other caches in the folder (:data:`OTHER_SPECREF_CACHES`): name -> what it
        is (neither map entries nor foreign; never deleted by ``clear``).
    """

    directory: Path
    entries: int
    total_bytes: int
    max_bytes: int
    foreign: list
    others: dict = field(default_factory=dict)


#: specref's other caches under the same root as the map cache: file or folder name pattern ->
#: what it is. They are neither map entries nor foreign files: never warned about or deleted here.
OTHER_SPECREF_CACHES = {
    "jakob2019-*.coeff": "Jakob 2019 coefficient table (reference.colour.jakob2019)",
    "numba": "compiled kernels (reference.jit)",
    "conformance": "conformance references (validation.conformance)",
}


def other_specref_cache(name: str) -> str:
    """What another specref cache named ``name`` is, or ``""`` (:data:`OTHER_SPECREF_CACHES`).

    Examples
    --------
    >>> other_specref_cache("jakob2019-sRGB-64.coeff"), other_specref_cache("notes.txt")
    ('Jakob 2019 coefficient table (reference.colour.jakob2019)', '')
    """
    import fnmatch

    return next(
        (what for pattern, what in OTHER_SPECREF_CACHES.items() if fnmatch.fnmatch(name, pattern)),
        "",
    )


def _encode_payload(arrays: Mapping[str, np.ndarray]) -> tuple[list, bytes]:
    """The arrays' manifest (name, dtype, shape, offset) and their raw bytes, 64-byte aligned."""
    manifest, chunks, offset = [], [], 0
    for name, value in arrays.items():
        # np.require keeps 0-d arrays 0-d (np.ascontiguousarray would make them 1-d)
        array = np.require(value, requirements="C")
        require(
            array.dtype.kind in "biufc",
            f"cache entry: array {name!r}: must be numeric, got dtype {array.dtype}",
        )
        pad = -offset % 64
        chunks.append(b"\0" * pad)
        offset += pad
        manifest.append([str(name), array.dtype.str, list(array.shape), offset])
        chunks.append(array.tobytes())
        offset += array.nbytes
    return manifest, b"".join(chunks)


class _CorruptError(Exception):
    """An entry that carries our magic but fails a check."""


class _ForeignError(Exception):
    """A file that does not carry our magic (or cannot be read)."""


def _map_file(path: Path):
    """The file's bytes, memory-mapped read-only (no copy; b"" for an empty file).

    Entries are replaced by rename, never rewritten in place, so a mapping stays valid while
    arrays viewing it live.
    """
    import mmap

    with open(path, "rb") as file:
        if os.fstat(file.fileno()).st_size == 0:
            return b""
        return mmap.mmap(file.fileno(), 0, access=mmap.ACCESS_READ)


class Cache:
    """A persistent, content-addressed cache of named arrays, safe against crashes and races.

    Parameters
    ----------
    directory : str or Path, optional
        The cache folder; default :func:`default_cache_dir`. Created on first write.
    max_bytes : int, optional
        Size limit; default ``$SPECREF_CACHE_MAX_BYTES`` or :data:`DEFAULT_MAX_BYTES`.
    enabled : bool
        False turns the cache into a pass-through (every lookup misses, nothing is written).
    write_hook : callable, optional
        ``write_hook(path, bytes_written, total_bytes)``, called once in the middle of
        writing an entry (after the header and half the payload), while the entry's temporary file
        beside ``path`` is incomplete. It exists to test crash safety: a test kills the writing
        process there.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     cache = Cache(folder)
    ...     key = cache_key("demo", "1", {"n": 3})
    ...     first = cache.get_or_compute(key, lambda: {"x": np.arange(3.0)})
    ...     again = cache.get_or_compute(key, lambda: {"x": np.zeros(3)})
    ...     again["x"], cache.hits, cache.misses
    (array([0., 1., 2.]), 1, 1)
    """

    def __init__(
        self,
        directory=None,
        max_bytes: int | None = None,
        enabled: bool = True,
        write_hook: Callable | None = None,
    ):
        self.directory = Path(directory) if directory is not None else default_cache_dir()
        if max_bytes is None:
            env = os.environ.get("SPECREF_CACHE_MAX_BYTES")
            try:
                max_bytes = int(env) if env else DEFAULT_MAX_BYTES
            except ValueError:
                raise SpecrefError(
                    f"SPECREF_CACHE_MAX_BYTES: must be an integer number of bytes, got {env!r}"
                ) from None
        require(
            isinstance(max_bytes, int) and max_bytes >= 0,
            f"cache max_bytes: must be an integer >= 0, got {max_bytes!r}",
        )
        self.max_bytes = max_bytes
        self.enabled = enabled
        self.write_hook = write_hook
        self.hits = 0
        self.misses = 0
        self._warned: set[tuple[str, str]] = set()
        self.unusable: str | None = None
        if self.enabled:
            self._remove_stale_temps()

    # --- paths and warnings --------------------------------------------------------------------

    def path_of(self, key: str) -> Path:
        """The entry file of ``key``."""
        require(
            isinstance(key, str) and len(key) == 64 and all(c in "0123456789abcdef" for c in key),
            f"cache key: must be 64 lowercase hex digits (cache_key), got {key!r:.80}",
        )
        return self.directory / f"{key}{_SUFFIX}"

    def _warn(self, path: Path, reason: str) -> None:
        # Each problem is reported once per file and process.
        if (str(path), reason) in self._warned:
            return
        self._warned.add((str(path), reason))
        warnings.warn(f"{path}: {reason}", SpecrefWarning, stacklevel=3)

    def _give_up(self, reason: str) -> None:
        """The folder cannot be used: warn once, then pass through (no reads, no writes)."""
        if self.unusable is None:
            self.unusable = reason
            warnings.warn(
                f"{self.directory}: cache folder unusable ({reason}); running without the cache",
                SpecrefWarning,
                stacklevel=4,
            )

    # --- reading -------------------------------------------------------------------------------

    @staticmethod
    def _read(path: Path) -> tuple[dict, dict]:
        """Header and arrays of an entry.

        Raises _ForeignError, _CorruptError, FileNotFoundError, NotADirectoryError (the folder).
        """
        try:
            data = _map_file(path)
        except (FileNotFoundError, NotADirectoryError):
            raise
        except OSError as error:
            raise _ForeignError(f"unreadable ({error.strerror or error})") from None
        head = bytes(data[: len(CACHE_MAGIC)])
        if head != CACHE_MAGIC:
            if CACHE_MAGIC.startswith(head):  # cut inside the magic (or empty): ours, truncated
                raise _CorruptError(f"truncated entry ({len(head)} bytes)")
            raise _ForeignError("not a specref cache entry (no specref header)")
        if len(data) < _HEAD:
            raise _CorruptError(f"truncated entry ({len(data)} bytes)")
        version, header_len, checksum = _PREFIX.unpack_from(data, len(CACHE_MAGIC))
        rest = memoryview(data)[_HEAD:]
        if zlib.crc32(rest) != checksum:
            raise _CorruptError("checksum mismatch (corrupted or truncated entry)")
        if version != FORMAT_VERSION:
            raise _CorruptError(f"entry format version {version}, expected {FORMAT_VERSION}")
        try:
            header = json.loads(bytes(rest[:header_len]).decode("utf-8"))
            start = _HEAD + header_len
            if len(data) - start != header["payload_bytes"]:
                raise _CorruptError("payload size does not match the header")
            arrays = {}
            for name, dtype, shape, offset in header["arrays"]:
                dtype = np.dtype(dtype)
                if dtype.kind not in "biufc":
                    raise _CorruptError(f"array {name!r} has dtype {dtype}")
                count = int(np.prod(shape, dtype=np.int64))
                # A read-only view of the file's bytes: no copy.
                array = np.frombuffer(data, dtype, count, start + offset).reshape(shape)
                arrays[name] = array
        except _CorruptError:
            raise
        except Exception as error:  # any decoding failure means a bad entry
            raise _CorruptError(f"undecodable entry ({type(error).__name__})") from None
        return header, arrays

    def get(self, key: str) -> dict | None:
        """The arrays stored under ``key`` (read-only views), or None (a miss).

        A corrupted entry is reported once, deleted and reported as a miss; a foreign or unreadable
        file is reported once and left alone.
        """
        if not self.enabled or self.unusable:
            return None
        path = self.path_of(key)
        try:
            header, arrays = self._read(path)
        except FileNotFoundError:
            return None
        except NotADirectoryError:
            self._give_up("a part of the path is a file, not a folder")
            return None
        except _ForeignError as why:
            self._warn(path, f"{why}; ignored and left in place")
            return None
        except _CorruptError as why:
            self._warn(path, f"{why}; deleted, the result is rebuilt")
            with contextlib.suppress(OSError):  # a read-only folder: rebuilt, not deleted
                path.unlink()
            return None
        if header.get("key") != key:
            self._warn(path, "entry holds another key; deleted, the result is rebuilt")
            with contextlib.suppress(OSError):
                path.unlink()
            return None
        # A hit refreshes the LRU clock.
        with contextlib.suppress(OSError):
            os.utime(path)
        return arrays

    # --- writing -------------------------------------------------------------------------------

    def put(self, key: str, arrays: Mapping[str, np.ndarray], meta: Mapping | None = None) -> bool:
        """Store ``arrays`` under ``key`` atomically; then evict down to the size limit.

        Parameters
        ----------
        key : str
            From :func:`cache_key`.
        arrays : mapping of str to ndarray
            Numeric arrays (no objects: entries are read without pickle).
        meta : mapping, optional
            JSON-serializable description kept in the header (step, shapes, ...).

        Returns
        -------
        bool
            True if stored; False if the cache is disabled or unusable (:meth:`_give_up`: one
            warning, then nothing is written), if a foreign file occupies the entry's name (it is
            never overwritten), or if the temporary file was removed under the writer.
        """
        if not self.enabled or self.unusable:
            return False
        path = self.path_of(key)
        if path.exists():  # a folder of that name is foreign too, not an unusable cache
            try:
                self._read(path)
            except _ForeignError as why:
                self._warn(path, f"{why}; ignored and left in place, the result is not cached")
                return False
            except (_CorruptError, OSError):
                pass
        manifest, payload = _encode_payload(arrays)
        header = json.dumps(
            {
                "key": key,
                "created_ms": int(time.time() * 1000),
                "payload_bytes": len(payload),
                "arrays": manifest,
                "meta": dict(meta or {}),
            },
            sort_keys=True,
            default=str,
        ).encode("utf-8")
        checksum = zlib.crc32(payload, zlib.crc32(header))
        prefix = CACHE_MAGIC + _PREFIX.pack(FORMAT_VERSION, len(header), checksum)
        try:
            with atomic_write(path, "wb") as handle:
                handle.write(prefix + header)
                half = len(payload) // 2
                handle.write(payload[:half])
                if self.write_hook is not None:
                    handle.flush()
                    start = len(prefix) + len(header)
                    self.write_hook(path, start + half, start + len(payload))
                handle.write(payload[half:])
        except FileNotFoundError:
            # the temporary file was removed before the rename (an outside rm of the folder's
            # files): the result stays valid, it is just not cached
            self._warn(path, "temporary file removed while writing; the result is not cached")
            return False
        except (SpecrefError, OSError) as error:
            # a read-only folder or home, a full disk, a file where the folder should be
            # (reference.files.output_error): one warning, then no cache
            self._give_up(_reason(error))
            return False
        self.evict()
        return True

    def get_or_compute(
        self, key: str, compute: Callable[[], Mapping[str, np.ndarray]], meta=None
    ) -> dict:
        """The arrays under ``key``; on a miss, ``compute()`` them, store them and return them.

        Parameters
        ----------
        key : str
            From :func:`cache_key`.
        compute : callable
            ``compute() -> {name: ndarray}``.
        meta : mapping, optional
            Header description, see :meth:`put`.

        Returns
        -------
        dict of str to ndarray
        """
        arrays = self.get(key)
        if arrays is not None:
            self.hits += 1
            return arrays
        self.misses += 1
        arrays = {name: np.asarray(value) for name, value in compute().items()}
        self.put(key, arrays, meta)
        return arrays

    # --- housekeeping --------------------------------------------------------------------------

    def _scan(self) -> tuple[list[tuple[float, int, Path]], list[str], list[Path]]:
        """Our entries (mtime, size, path), foreign file names, and our stale temporary files."""
        ours, foreign, stale = [], [], []
        try:
            paths = sorted(self.directory.iterdir()) if self.directory.is_dir() else []
        except OSError:
            return ours, foreign, stale
        now = time.time()
        for path in paths:
            if other_specref_cache(path.name):  # another cache of specref's: not ours to judge
                continue
            if _is_our_temp(path.name):
                # A writer's temporary file: in progress, or left by a writer that died.
                if _is_stale_temp(path, now):
                    stale.append(path)
                continue
            try:
                if not path.is_file():
                    foreign.append(path.name)
                    continue
                stat = path.stat()
                with path.open("rb") as handle:
                    magic = handle.read(len(CACHE_MAGIC))
            except FileNotFoundError:
                continue  # removed by another process meanwhile
            except OSError:
                foreign.append(path.name)
                self._warn(path, "unreadable; ignored and left in place")
                continue
            # an entry's name and a magic cut short (a truncated entry) count as ours
            truncated = _is_entry_name(path.name) and CACHE_MAGIC.startswith(magic)
            if magic == CACHE_MAGIC or truncated:
                ours.append((stat.st_mtime, stat.st_size, path))
            else:
                foreign.append(path.name)
                self._warn(path, "not a specref cache entry (no specref header); ignored")
        return ours, foreign, stale

    def _remove_stale_temps(self) -> None:
        """Remove temporary files left by writers that died (:data:`STALE_TEMP_SECONDS`)."""
        _, _, stale = self._scan()
        for path in stale:
            with contextlib.suppress(OSError):
                path.unlink()

    def evict(self) -> int:
        """Delete least-recently-used entries until the entries fit in ``max_bytes``.

        Also removes stale temporary files (:data:`STALE_TEMP_SECONDS`).

        Returns
        -------
        int
            Number of entries deleted.
        """
        ours, _, stale = self._scan()
        for path in stale:
            with contextlib.suppress(OSError):
                path.unlink()
        total = sum(size for _, size, _ in ours)
        deleted = 0
        for _, size, path in sorted(ours):
            if total <= self.max_bytes:
                break
            with contextlib.suppress(OSError):
                path.unlink()
                deleted += 1
            total -= size
        return deleted

    def info(self) -> CacheInfo:
        """Entries, their size, the limit and the foreign files of the cache folder."""
        ours, foreign, _ = self._scan()
        try:
            names = sorted(p.name for p in self.directory.iterdir())
        except OSError:
            names = []
        others = {name: other_specref_cache(name) for name in names if other_specref_cache(name)}
        total = sum(size for _, size, _ in ours)
        return CacheInfo(self.directory, len(ours), total, self.max_bytes, foreign, others)

    def clear(self) -> int:
        """Delete every entry and the stale temporary files; foreign files stay.

        Temporary files younger than :data:`STALE_TEMP_SECONDS` may belong to a live writer and
        stay. A folder that refuses the deletion is a one-line :class:`SpecrefError`.

        Returns
        -------
        int
            Number of entries deleted.
        """
        ours, _, stale = self._scan()
        count = 0
        for path in [p for _, _, p in ours] + stale:
            try:
                path.unlink()
            except FileNotFoundError:
                continue
            except OSError as error:
                raise (output_error(path, error) or error) from None
            count += path.suffix == _SUFFIX
        return count


def _reason(error: Exception) -> str:
    """The short reason of a write refusal: the parenthesis of reference.files.output_error."""
    if isinstance(error, OSError):
        translated = output_error("", error)
        if translated is None:
            return error.strerror or str(error)
        error = translated
    text = str(error)
    return text[text.rfind("(") + 1 : text.rfind(")")] if text.endswith(")") else text


def _is_entry_name(name: str) -> bool:
    """Whether ``name`` is an entry's file name, ``<64 hex digits>.specref``."""
    stem = name[: -len(_SUFFIX)]
    return name.endswith(_SUFFIX) and len(stem) == 64 and all(c in "0123456789abcdef" for c in stem)


def _is_stale_temp(path: Path, now: float) -> bool:
    """Whether our temporary file ``path`` was left by a dead writer: old, and empty or ours."""
    try:
        stat = path.stat()
        with path.open("rb") as handle:
            head = handle.read(len(CACHE_MAGIC))
    except OSError:
        return False
    # empty, cut inside the magic, or carrying it: ours (never a foreign file of that name)
    return now - stat.st_mtime > STALE_TEMP_SECONDS and CACHE_MAGIC.startswith(head)


def _is_our_temp(name: str) -> bool:
    """Whether ``name`` is an entry's temporary file (:func:`reference.files.atomic_write`)."""
    return name.startswith(".") and name.endswith(".tmp") and f"{_SUFFIX}." in name

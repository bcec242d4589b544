"""Atomic file writes: every output of specref goes to a temporary file that is renamed into place.

The data go to a temporary file in the destination folder, which is flushed, synced and renamed over
the destination, so an interrupted run never leaves a half-written file. The file system's refusals
(a folder where a file should be, no permission, a full disk) become one-line
:class:`~reference.errors.SpecrefError` messages that name the file (:func:`output_error`).
"""

from __future__ import annotations

import contextlib
import errno
import os
import re
import shutil
import stat
import tempfile
import threading
from pathlib import Path

from reference.errors import SpecrefError, require

__all__ = [
    "MAX_FOLDER_FILES",
    "WRITE_ERRORS",
    "atomic_path",
    "atomic_write",
    "check_output_file",
    "check_output_folder",
    "check_output_store",
    "check_outputs",
    "default_cache_dir",
    "folder_lock",
    "output_error",
    "read_json",
    "remove_stale_temporaries",
    "require_input_file",
    "same_file",
    "temporary_prefix",
    "write_bytes_atomic",
    "write_text_atomic",
]

# The process umask, read once at import: mkstemp creates files 0600, and a finished output should
# get the permissions an ordinary open() would give it.
_UMASK = os.umask(0o022)
os.umask(_UMASK)


def _new_file_permissions(tmp) -> None:
    """Give a temporary file the permissions of a newly created ordinary file (0666 & ~umask)."""
    os.chmod(tmp, 0o666 & ~_UMASK)


#: Errors of the file system that mean "this output cannot be written here", by errno, with what the
#: one-line message says about them.
WRITE_ERRORS = {
    errno.EISDIR: "is a folder; give a file name",
    errno.ENOTDIR: "a part of the path is a file, not a folder",
    errno.EEXIST: "a part of the path is a file, not a folder",
    errno.EACCES: "permission denied",
    errno.EPERM: "permission denied",
    errno.EROFS: "read-only file system",
    errno.ENOSPC: "no space left on the device",
    errno.EDQUOT: "disk quota exceeded",
    errno.EFBIG: "file too large for the file system",
}


def output_error(path, error: OSError) -> SpecrefError | None:
    """The one-line :class:`SpecrefError` for an OSError met while writing ``path``, if it is one.

    Every writer (:func:`atomic_write`, :func:`write_exr`) turns the file system's refusals (a
    folder where a file should be, a file where a folder should be, no permission, a full disk)
    into this message, so no command shows a traceback for them.

    Returns
    -------
    SpecrefError or None
        None when ``error`` is not a refusal to write (the caller re-raises it).

    Examples
    --------
    >>> import errno
    >>> output_error("out/a.exr", OSError(errno.ENOSPC, "No space left on device"))
    SpecrefError('out/a.exr: cannot write (no space left on the device)')
    >>> output_error("a.exr", OSError(errno.EIO, "I/O error")) is None
    True
    """
    reason = WRITE_ERRORS.get(getattr(error, "errno", None))
    if reason is None:
        return None
    return SpecrefError(f"{path}: cannot write ({reason})")


@contextlib.contextmanager
def _write_errors(path):
    """Turn the file system's refusals to write ``path`` into one-line SpecrefErrors."""
    try:
        yield
    except OSError as error:
        translated = output_error(path, error)
        if translated is None:
            raise
        raise translated from None


#: Marks specref's temporary files and folders: ``.<name>.specref-<pid>.<8 random><suffix>``.
_TEMP_MARK = "specref-"
_TEMP_PATTERN = re.compile(r"specref-(\d+)\.[A-Za-z0-9_]{8}")
#: Bytes a temporary name adds to the file's own: ".", ".specref-", a pid of up to 7 digits,
#: ".", 8 random characters and a suffix of up to 6 (".probe").
_TEMP_EXTRA = 1 + len(_TEMP_MARK) + 1 + 7 + 1 + 8 + 6


def temporary_prefix(path) -> str:
    """How a temporary file or folder beside ``path`` starts: ``.<name>.specref-<pid>.``.

    ``tempfile.mkstemp`` and ``mkdtemp`` add 8 random characters and a suffix. The process id
    lets a later write to the same path remove what a killed process left
    (:func:`remove_stale_temporaries`).

    Examples
    --------
    >>> temporary_prefix("out/a.exr") == f".a.exr.specref-{os.getpid()}."
    True
    """
    return f".{Path(path).name}.{_TEMP_MARK}{os.getpid()}."


def _alive(pid: int) -> bool:
    """Whether a process with this id runs (on this machine)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):
        return pid < 2**22  # another user's process (or an id no machine gives out)
    return True


def remove_stale_temporaries(path) -> list[Path]:
    """Remove the temporary files and folders beside ``path`` whose process no longer runs.

    A write renames its temporary file into place or removes it, whatever exception ends it; a
    process killed outright (SIGKILL, a crash, a power cut) cannot, so every write first removes
    the leftovers of earlier writes to the same path: names made by :func:`temporary_prefix`
    whose process id is not running. Files of running processes and anything else stay.

    Returns
    -------
    list of Path
        What was removed.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     dead = Path(d) / ".a.exr.specref-4194303.abcd1234.tmp"   # no such process
    ...     live = Path(d) / (temporary_prefix("a.exr") + "efgh5678.tmp")
    ...     mine = Path(d) / ".a.exr.1.bak"
    ...     for p in (dead, live, mine):
    ...         _ = p.write_text("x")
    ...     [p.name for p in remove_stale_temporaries(Path(d) / "a.exr")], len(os.listdir(d))
    (['.a.exr.specref-4194303.abcd1234.tmp'], 2)
    """
    path = Path(path)
    head, removed = f".{path.name}.", []
    try:
        # names only: every write calls this (a folder of 10,000 files adds a few ms per write)
        names = [n for n in os.listdir(path.parent) if n.startswith(head)]
    except OSError:
        return removed
    for name in names:
        match = _TEMP_PATTERN.match(name, len(head))
        if match is None or _alive(int(match.group(1))):
            continue
        leftover = path.parent / name
        with contextlib.suppress(OSError):
            if leftover.is_dir() and not leftover.is_symlink():
                shutil.rmtree(leftover)
            else:
                os.unlink(leftover)
            removed.append(leftover)
    return removed


def _existing_ancestor(path: Path) -> Path:
    """The nearest folder (or file) on ``path``'s way that exists."""
    parent = path.absolute().parent
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    return parent


def _require_file_target(path: Path) -> None:
    """Refuse a folder, a special file, a path below a file and a name too long for the disk.

    Special files: devices, FIFOs, sockets. Writing is a rename onto ``path``: onto ``/dev/null``
    it would replace the device node.
    """
    require(not path.is_dir(), f"{path}: cannot write ({WRITE_ERRORS[errno.EISDIR]})")
    require(
        not path.exists() or path.is_file(),
        f"{path}: cannot write (a device or special file, not a regular file; give a file name)",
    )
    ancestor = _existing_ancestor(path)
    require(ancestor.is_dir(), f"{path}: cannot write ({WRITE_ERRORS[errno.ENOTDIR]}: {ancestor})")
    try:
        name_max = os.pathconf(ancestor, "PC_NAME_MAX")
    except (AttributeError, OSError, ValueError):  # no pathconf (Windows): the common limit
        name_max = 255
    # the temporary file beside it adds _TEMP_EXTRA bytes to the name (temporary_prefix)
    sizes = [len(part.encode("utf-8", "surrogateescape")) for part in path.parts]
    require(
        max(sizes[:-1], default=0) <= name_max and sizes[-1] + _TEMP_EXTRA <= name_max,
        f"{path}: cannot write (a name in the path is longer than the file system's "
        f"{name_max} bytes, {name_max - _TEMP_EXTRA} for the file's own name)",
    )


def same_file(a, b) -> bool:
    """Whether two paths name the same file: the same inode where both exist, else the same path.

    Hard links, symbolic links and ``..`` count as the same file.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     a = os.path.join(d, "a.exr"); _ = open(a, "w").close()
    ...     os.link(a, os.path.join(d, "b.exr"))
    ...     same_file(a, os.path.join(d, "b.exr")), same_file(a, os.path.join(d, "c.exr"))
    (True, False)
    """
    a, b = Path(a), Path(b)
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.realpath(a) == os.path.realpath(b)


#: Files at the top of a Zarr store (version 2 or 3), the folders specref writes as a whole:
#: a folder with one may be replaced by a new store.
STORE_MARKERS = (".zgroup", ".zarray", "zarr.json")


def check_output_store(path) -> Path:
    """Refuse, before any work, a store path that would lose data or cannot be a store.

    The write policy (docs/bad-input.md): a store replaces only an empty folder or an earlier
    Zarr store, never a folder of other files, a file or a special file.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp()); _ = (d / "holiday.jpg").write_bytes(b"")
    >>> check_output_store(d / "new.zarr").name
    'new.zarr'
    >>> check_output_store(d)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: ...: cannot write a Zarr store: a folder that is not a Zarr ...
    """
    path = Path(path)
    require(
        not path.exists() or path.is_dir(),
        f"{path}: cannot write a Zarr store: a file is in the way",
    )
    if path.is_dir() and any(path.iterdir()):
        require(
            any((path / marker).is_file() for marker in STORE_MARKERS),
            f"{path}: cannot write a Zarr store: a folder that is not a Zarr store is there "
            "(its files would be lost); give another name or remove it",
        )
        foreign = [p.name for p in path.iterdir() if not _store_entry(p)]
        require(
            not foreign,
            f"{path}: cannot write a Zarr store: the earlier store there also holds other files "
            f"({', '.join(sorted(foreign)[:3])}), which would be lost; give another name or "
            "move them",
        )
    return path


#: What the top of a Zarr store holds besides its arrays and groups (folders with a marker).
STORE_FILES = (*STORE_MARKERS, ".zattrs", ".zmetadata")


def _store_entry(entry: Path) -> bool:
    """Whether a top-level entry of a folder belongs to a Zarr store.

    Its metadata, an array or group below it (a folder with a marker), or the chunks of an array
    at its root: Zarr 3's ``c/`` folder, Zarr 2's keys such as ``0.0.0``.
    """
    if entry.is_dir():
        return entry.name == "c" or any((entry / m).is_file() for m in STORE_MARKERS)
    chunk_key = re.fullmatch(r"\d+([./]\d+)*", entry.name) is not None
    return chunk_key or entry.name in STORE_FILES or entry.name.startswith(".")


#: Why a path cannot be looked up at all, by errno, in the words of the refusals.
_LOOKUP_ERRORS = {
    errno.ENAMETOOLONG: "a name in the path is too long for the file system",
    errno.ELOOP: "a loop of symbolic links",
}


def _existing_inputs(inputs) -> list[Path]:
    """The inputs that exist; names the file system cannot look up at all are refused."""
    found = []
    for source in inputs:
        try:
            mode = os.stat(source).st_mode
        except FileNotFoundError:
            continue  # the command says "file not found" in its own words
        except OSError as error:
            reason = _LOOKUP_ERRORS.get(error.errno)
            if reason is None:
                raise
            raise SpecrefError(f"{source}: cannot read ({reason})") from None
        # a device, a FIFO or a socket: /dev/zero never ends, a FIFO waits for a writer
        require(
            stat.S_ISREG(mode) or stat.S_ISDIR(mode),
            f"{source}: cannot read (a device or special file, not a regular file or folder)",
        )
        found.append(source)
    return found


def require_input_file(path) -> Path:
    """``path`` as a regular file to read, or a one-line error that says what it is instead.

    Missing (``file not found``), a folder, a loop of symbolic links, a name too long for the
    file system, or a device, FIFO or socket (``/dev/zero`` never ends, a FIFO waits for a
    writer): each is named as such, where ``is_file()`` called them all "not found".

    Examples
    --------
    >>> require_input_file("/nonexistent.exr")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent.exr: file not found
    >>> require_input_file("/tmp")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /tmp: cannot read (a folder, not a file)
    """
    path = Path(path)
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        raise SpecrefError(f"{path}: file not found") from None
    except OSError as error:
        reason = _LOOKUP_ERRORS.get(error.errno, error.strerror)
        raise SpecrefError(f"{path}: cannot read ({reason})") from None
    require(not stat.S_ISDIR(mode), f"{path}: cannot read (a folder, not a file)")
    require(
        stat.S_ISREG(mode), f"{path}: cannot read (a device or special file, not a regular file)"
    )
    return path


#: Files of an input folder that the write policy looks at (a painting folder, a data folder):
#: enough for any folder a command reads as a whole, few enough to stay instant.
MAX_FOLDER_FILES = 10_000


def _inode(path) -> tuple | None:
    try:
        st = os.stat(path)
    except OSError:
        return None
    return (st.st_dev, st.st_ino)


def _files_in_folders(inputs) -> dict:
    """(device, inode) of the files below the input folders, to the folder each was found in."""
    found: dict = {}
    for folder in (i for i in inputs if i.is_dir()):
        for root, _, files in os.walk(folder):
            for name in files:
                if len(found) >= MAX_FOLDER_FILES:
                    return found
                key = _inode(os.path.join(root, name))
                if key is not None:
                    found.setdefault(key, folder)
    return found


def check_outputs(outputs, inputs=(), stores=()) -> list[Path]:
    """The write policy: refuse, before any work, outputs that cannot or must not be written.

    Every command calls it with all the files it will write (sibling outputs derived from a name
    included) and all the files it reads, before reading or computing anything
    (``validation.cli.main`` does it from the arguments; docs/bad-input.md). An output is
    refused, in one line naming it, when it is

    - a folder, a device, a FIFO or a socket (a rename onto ``/dev/null`` would replace the
      device node; specref never writes to special files: give a regular file name);
    - below a file, or has a name longer than the file system holds;
    - in a folder where a file cannot be written (a read-only or full file system: a small probe
      file is written there and removed);
    - the same file as an input (inodes compared: hard and symbolic links count), or as a file
      below an input folder (a painting folder, a data folder), or as another output of the same
      command.

    An input whose name is too long for the file system, or a loop of symbolic links, is refused
    too (a missing input is left to the command, which says so in its own words).

    An output *store* (a Zarr folder) must not be an input either; whether an existing folder may
    be replaced is its writer's decision (``reference.images.zarr_store``: only a Zarr store).

    Parameters
    ----------
    outputs : iterable of str or Path
        The files to be written (None entries are skipped).
    inputs : iterable of str or Path
        The files to be read (None entries and names that do not exist are skipped).
    stores : iterable of str or Path
        Folders to be written as a whole (Zarr stores).

    Returns
    -------
    list of Path
        The outputs.

    Raises
    ------
    SpecrefError

    Examples
    --------
    >>> import tempfile, os
    >>> d = tempfile.mkdtemp(); a = os.path.join(d, "a.exr"); _ = open(a, "w").close()
    >>> check_outputs([os.path.join(d, "diff.exr")], [a])[0].name
    'diff.exr'
    >>> check_outputs([a], [a, os.path.join(d, "b.exr")])
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: .../a.exr: is also an input of this command (.../a.exr); ...
    >>> check_outputs(["/dev/null"])
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /dev/null: cannot write (a device or special file, ...
    """
    outputs = [Path(o) for o in outputs if o is not None]
    inputs = _existing_inputs(Path(i) for i in inputs if i is not None)
    inside = _files_in_folders(inputs)
    for k, out in enumerate(outputs):
        with _write_errors(out):
            _require_file_target(out)
        _require_not_an_input(out, inputs, inside)
        for other in outputs[:k]:
            require(not same_file(out, other), f"{out}: the command would write it twice ({other})")
        if out.parent.is_dir():  # a read-only or full file system, refused now, not after the work
            with _write_errors(out):
                _write_probe(out)
    for store in (Path(s) for s in stores):
        check_output_store(store)
        _require_not_an_input(store, inputs, {})
        for source in inputs:  # a store replaces its folder: an input inside it would go too
            below = os.path.realpath(source).startswith(os.path.realpath(store) + os.sep)
            require(
                not below,
                f"{store}: the store would replace the folder that holds an input ({source}); "
                "give another output name",
            )
    return outputs


def _require_not_an_input(out: Path, inputs, inside: dict) -> None:
    for source in inputs:
        require(
            not same_file(out, source),
            f"{out}: is also an input of this command ({source}); give another output name",
        )
    folder = inside.get(_inode(out) or _inode(os.path.realpath(out)))
    require(
        folder is None,
        f"{out}: is also an input of this command (a file of the folder {folder}); give "
        "another output name",
    )


@contextlib.contextmanager
def atomic_write(path, mode: str = "wb"):
    """Open a temporary file beside ``path``; on success, sync it and rename it to ``path``.

    On an exception the temporary file is removed and ``path`` is untouched. When the file system
    refuses the write (see :func:`output_error`) the error is a one-line :class:`SpecrefError`.

    Parameters
    ----------
    path : str or Path
        Destination; its folder is created if missing.
    mode : str
        ``"wb"`` or ``"w"``.

    Yields
    ------
    file object
        The temporary file, opened in ``mode``.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = os.path.join(d, "out.txt")
    ...     with atomic_write(p, "w") as f:
    ...         _ = f.write("done")
    ...     open(p).read()
    'done'
    """
    path = Path(path)
    with _write_errors(path):
        _require_file_target(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        remove_stale_temporaries(path)
        tmp = None
        try:
            with _termination_held():  # the file and its name together, or neither
                fd, tmp = tempfile.mkstemp(
                    prefix=temporary_prefix(path), suffix=".tmp", dir=path.parent
                )
            _new_file_permissions(tmp)
            with os.fdopen(fd, mode) as handle:
                yield handle
                handle.flush()
                os.fsync(handle.fileno())
            os.replace(tmp, path)
        except BaseException:
            if tmp is not None:
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(tmp)
            raise


@contextlib.contextmanager
def _termination_held():
    """SIGTERM and SIGHUP wait (in the main thread) until the block has run.

    A termination signal makes the ``specref`` command unwind (``validation.cli.run``); arriving
    between a temporary file's creation and the recording of its name, it would leave the file
    behind. Held here, it is delivered once the name is known, inside the writer's cleanup.
    """
    import signal
    import threading

    masked = (
        hasattr(signal, "pthread_sigmask") and threading.current_thread() is threading.main_thread()
    )
    old = (
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGTERM, signal.SIGHUP})
        if masked
        else None
    )
    try:
        yield
    finally:
        if masked:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)


@contextlib.contextmanager
def atomic_path(path, suffix: str = ""):
    """Yield a temporary file name beside ``path``; on success, sync it and rename it to ``path``.

    For writers that take a file name rather than a file object (OpenEXR, tifffile). As in
    :func:`atomic_write`, an exception removes the temporary file and leaves ``path`` untouched,
    and the file system's refusals become one-line :class:`SpecrefError` (:func:`output_error`).

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     with atomic_path(os.path.join(d, "a.bin")) as tmp:
    ...         _ = open(tmp, "wb").write(b"xy")
    ...     sorted(os.listdir(d))
    ['a.bin']
    """
    path = Path(path)
    with _write_errors(path):
        _require_file_target(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        remove_stale_temporaries(path)
        tmp = None
        try:
            with _termination_held():  # the file and its name together, or neither
                fd, name = tempfile.mkstemp(
                    prefix=temporary_prefix(path), suffix=suffix, dir=path.parent
                )
                tmp = Path(name)
            os.close(fd)
            yield tmp
            with open(tmp, "rb+") as handle:
                os.fsync(handle.fileno())
            _new_file_permissions(tmp)
            os.replace(tmp, path)
        except BaseException:
            if tmp is not None:
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(tmp)
            raise


def read_json(path, kind: str = "JSON"):
    """Read a JSON file; a missing or malformed one is a one-line :class:`SpecrefError`.

    Parameters
    ----------
    path : str or Path
    kind : str
        What the file should be, for the message (``"JSON display file"``).

    Examples
    --------
    >>> read_json("/nonexistent.json", "JSON display file")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /nonexistent.json: file not found
    """
    import json

    path = Path(path)
    require(path.exists(), f"{path}: file not found")
    # /dev/zero or a FIFO would be read for ever
    require(path.is_file(), f"{path}: not a {kind} (not a regular file)")
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise SpecrefError(f"{path}: file not found") from None
    except RecursionError:
        raise SpecrefError(f"{path}: not a {kind} (nested too deeply)") from None
    except (OSError, ValueError) as error:
        raise SpecrefError(f"{path}: not a {kind} ({error})") from None


def check_output_file(path) -> Path:
    """Prove, before any work, that ``path`` can be written; return it.

    Commands whose output comes after a long computation call this first, so an output that
    cannot be written (a folder there, a file in the path, a read-only or full file system) is
    refused in one line at once rather than after the work. A small probe file is written beside
    ``path`` and removed; ``path`` itself is not touched.

    Raises
    ------
    SpecrefError
        One line naming the file and the reason (:func:`output_error`).

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     check_output_file(os.path.join(d, "model.json")).name, os.listdir(d)
    ('model.json', [])
    >>> with tempfile.TemporaryDirectory() as d:
    ...     check_output_file(d)
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: ...: cannot write (is a folder; give a file name)
    >>> check_output_file("/dev/null")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: /dev/null: cannot write (a device or special file, ...
    """
    path = Path(path)
    with _write_errors(path):
        _require_file_target(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        remove_stale_temporaries(path)
        _write_probe(path)
    return path


def _write_probe(path: Path) -> None:
    """Write, sync and remove a small file beside ``path`` (``path`` itself is not touched)."""
    fd, probe = tempfile.mkstemp(prefix=temporary_prefix(path), suffix=".probe", dir=path.parent)
    try:
        os.write(fd, b"specref")
        os.fsync(fd)
    finally:
        os.close(fd)
        os.unlink(probe)


def check_output_folder(folder, marker: str | None = None) -> Path:
    """Create ``folder`` if needed and prove that a file can be written in it; return it.

    Commands that write many files into a folder call this before any work, so an unwritable
    folder (a file of that name, a read-only file system, a full disk) is refused in one line
    before the first frame rather than after it. With ``marker``, the file a command writes into
    every folder it fills (a painting's ``painting.toml``, an export's ``scenes.json``), a folder
    that holds other files but not that one is refused too: its files could be overwritten by the
    command's (an empty folder, or one the command wrote before, is fine).

    Raises
    ------
    SpecrefError
        One line naming the folder and the reason (:func:`output_error`).

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     check_output_folder(os.path.join(d, "frames")).is_dir()
    ...     _ = open(os.path.join(d, "holiday.jpg"), "w").close()
    ...     check_output_folder(d, marker="painting.toml")
    Traceback (most recent call last):
    ...
    reference.errors.SpecrefError: ...: cannot write here: the folder holds other files ...
    """
    folder = Path(folder)
    require(str(folder).strip() != "", "an empty folder name (give a folder)")
    with _write_errors(folder):
        require(not folder.is_file(), f"{folder}: cannot write ({WRITE_ERRORS[errno.ENOTDIR]})")
        if marker is not None and folder.is_dir() and not (folder / marker).exists():
            others = [p.name for p in folder.iterdir() if not p.name.startswith(".")]
            if others:
                raise SpecrefError(
                    f"{folder}: cannot write here: the folder holds other files ({others[0]}, "
                    f"...) and no {marker} of an earlier run, and the command's files could "
                    "replace them; give a new or empty folder"
                )
        folder.mkdir(parents=True, exist_ok=True)
    # a probe of this thread's own: processes and threads filling one folder at once must not
    # remove each other's
    own = f"{os.getpid()}-{threading.get_ident()}"
    probe = write_bytes_atomic(folder / f".specref-write-probe-{own}", b"specref")
    probe.unlink()
    return folder


@contextlib.contextmanager
def folder_lock(folder, item: str = "", wait: bool = True):
    """Hold an exclusive lock on ``folder`` (its ``.lock`` file) while the block runs; yields True.

    Processes that fill one cache folder at once (two commands, the workers of a test run) take
    turns: the second finds what the first wrote instead of writing it again, and no manifest
    update is lost. An advisory ``flock`` (released when the process ends, even killed); where
    the platform has none (Windows), no lock.

    ``item`` names a lock of its own within the folder (``.lock-<item>``), so processes working on
    different items of one folder do not wait for each other. With ``wait=False`` the block runs
    at once and gets False when another process holds the lock (it must then leave the item alone).

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     with folder_lock(d) as held, folder_lock(d, "scene", wait=False) as other:
    ...         held, other, sorted(os.listdir(d))
    (True, True, ['.lock', '.lock-scene'])
    """
    folder = Path(folder)
    require(
        "/" not in item and "\\" not in item and item not in (".", ".."),
        f"folder_lock: {item!r} is not a lock name",
    )
    try:
        import fcntl
    except ImportError:  # no flock: one process at a time is the user's business
        yield True
        return
    with _write_errors(folder):
        folder.mkdir(parents=True, exist_ok=True)
        handle = open(folder / (f".lock-{item}" if item else ".lock"), "a+b")  # noqa: SIM115
    try:
        try:
            fcntl.flock(handle.fileno(), fcntl.LOCK_EX | (0 if wait else fcntl.LOCK_NB))
        except BlockingIOError:
            yield False
            return
        yield True
    finally:
        handle.close()  # releases the lock


def write_bytes_atomic(path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically and return the path.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     write_bytes_atomic(os.path.join(d, "a.bin"), b"xy").stat().st_size
    2
    """
    with atomic_write(path, "wb") as handle:
        handle.write(data)
    return Path(path)


def write_text_atomic(path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically and return the path.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     write_text_atomic(os.path.join(d, "a.txt"), "é").read_text(encoding="utf-8")
    'é'
    """
    return write_bytes_atomic(path, text.encode("utf-8"))


def default_cache_dir() -> Path:
    """The cache folder: ``$SPECREF_CACHE_DIR``, ``$XDG_CACHE_HOME/specref``, ``~/.cache/specref``.

    Returns
    -------
    Path
        The folder (not created here).

    Examples
    --------
    >>> import os
    >>> os.environ["SPECREF_CACHE_DIR"] = "/tmp/specref-doc-cache"
    >>> str(default_cache_dir())
    '/tmp/specref-doc-cache'
    >>> del os.environ["SPECREF_CACHE_DIR"]
    """
    explicit = os.environ.get("SPECREF_CACHE_DIR")
    if explicit:
        return Path(explicit).expanduser()
    xdg = os.environ.get("XDG_CACHE_HOME")
    base = Path(xdg).expanduser() if xdg and Path(xdg).is_absolute() else Path.home() / ".cache"
    return base / "specref"

"""Nothing left behind: the temporary files of atomic writes after a kill (reference.files)."""

import os
import signal
import subprocess
import sys
import time

from reference.files import temporary_prefix, write_bytes_atomic

_SLOW_WRITE = """
import sys, time
from reference.files import atomic_write
with atomic_write(sys.argv[1]) as handle:
    handle.write(b"partial")
    handle.flush()
    print("writing", flush=True)
    time.sleep(60)
"""


def _leftovers(folder, name):
    return sorted(p.name for p in folder.iterdir() if p.name.startswith(f".{name}."))


def test_what_a_killed_write_leaves_the_next_write_removes(tmp_path):
    out = tmp_path / "a.exr"
    child = subprocess.Popen(
        [sys.executable, "-c", _SLOW_WRITE, str(out)], stdout=subprocess.PIPE, text=True
    )
    assert child.stdout.readline().strip() == "writing"
    os.kill(child.pid, signal.SIGKILL)  # no handler runs: the temporary file stays
    child.wait(timeout=30)
    left = _leftovers(tmp_path, "a.exr")
    assert len(left) == 1
    assert f"specref-{child.pid}." in left[0]
    # a write of this process (running) beside it is not touched; the dead one's file is removed
    mine = tmp_path / (temporary_prefix(out) + "abcdefgh.tmp")
    mine.write_bytes(b"in progress")
    write_bytes_atomic(out, b"done")
    assert out.read_bytes() == b"done"
    assert _leftovers(tmp_path, "a.exr") == [mine.name]


def test_a_terminated_command_removes_its_temporary_file(tmp_path):
    # `kill` (SIGTERM) in the middle of writing a 10,000-chip characterization: exit 143, no
    # output and no temporary file
    out = tmp_path / "chips.csv"
    thickness = ",".join(f"{0.1 + 0.01 * i:.2f}" for i in range(200))
    tio2 = ",".join(f"{0.01 * i:.2f}" for i in range(100))
    command = [sys.executable, "-m", "validation.cli", "polymer", "characterize", "-o", str(out)]
    command += ["--thickness", thickness, "--tio2", tio2, "--yes"]
    child = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    end = time.monotonic() + 60
    while not _leftovers(tmp_path, "chips.csv") and child.poll() is None:
        assert time.monotonic() < end, "the command never started writing"
        time.sleep(0.01)
    os.kill(child.pid, signal.SIGTERM)
    assert child.wait(timeout=60) == 128 + signal.SIGTERM
    assert list(tmp_path.iterdir()) == []

"""Progress of long steps: what runs, an estimate of how long, and each stage's time.

Every command that can run longer than a couple of seconds says what it is doing. Library
functions take a ``progress`` stream (None: silent, the default, so tests and doctests print
nothing); the command line passes ``sys.stderr``.

- :class:`Progress` follows a loop of units (rows of an image, cases of a study). On a terminal it
  is a tqdm bar; otherwise, once the work has run for a couple of seconds, it writes a line with
  the expected total time (measured on the units done so far) and a line when it ends. Work that
  ends sooner writes nothing, so logs stay readable.
- :class:`StageTimer` times the named stages of a pipeline and writes a line per stage.
"""

from __future__ import annotations

import contextlib
import threading
import time
from typing import TextIO

__all__ = ["ANNOUNCE_AFTER", "LINE_EVERY", "Progress", "StageTimer", "format_seconds"]

#: Seconds after which a command's stage is announced (``StageTimer(after=...)``): quick stages,
#: and a refusal of bad input in its one line, print nothing else.
ANNOUNCE_AFTER = 1.0
#: Seconds between a long loop's lines off a terminal, after its estimate (:class:`Progress`): the
#: share done and the time left, measured on the work done so far.
LINE_EVERY = 30.0


def format_seconds(seconds: float) -> str:
    """A duration as people read it: ``"0.4 s"``, ``"38 s"``, ``"4 min 10 s"``, ``"1 h 05 min"``.

    Examples
    --------
    >>> [format_seconds(s) for s in (0.42, 38.2, 250, 3900)]
    ['0.4 s', '38 s', '4 min 10 s', '1 h 05 min']
    """
    if seconds < 10:
        return f"{seconds:.1f} s"
    if seconds < 60:
        return f"{seconds:.0f} s"
    minutes, secs = divmod(round(seconds), 60)
    if minutes < 60:
        return f"{minutes} min {secs:02d} s" if secs else f"{minutes} min"
    hours, minutes = divmod(minutes, 60)
    return f"{hours} h {minutes:02d} min"


class Progress:
    """Progress through ``total`` units of work, with the expected total time.

    Parameters
    ----------
    desc : str
        What runs (``"shading 256 rows"``).
    total : int
        Units of work.
    stream : file-like or None
        Where to write (None: nothing). A terminal gets a tqdm bar, anything else lines.
    unit : str
        The unit's name, for the bar.
    estimate_after : float
        Seconds of work after which the expected total is written (line mode).
    line_every : float
        Seconds between the lines that follow the estimate (line mode): the share done and the
        time left.

    Examples
    --------
    >>> import io
    >>> out = io.StringIO()
    >>> with Progress("brute force", 4, out, estimate_after=0.0) as bar:
    ...     for _ in range(4):
    ...         bar.update(1)
    >>> estimate, done = out.getvalue().splitlines()
    >>> estimate.startswith("brute force: 4 rows, about"), done.startswith("brute force: done")
    (True, True)
    """

    def __init__(
        self,
        desc: str,
        total: int,
        stream: TextIO | None = None,
        unit: str = "rows",
        estimate_after: float = 2.0,
        line_every: float = LINE_EVERY,
    ):
        self.desc, self.total, self.stream, self.unit = desc, int(total), stream, unit
        self.estimate_after, self.line_every = estimate_after, line_every
        self.done = 0
        self._estimated = False
        self._last_line = 0.0
        self._bar = None
        self._start = time.perf_counter()

    def __enter__(self) -> Progress:
        self._start = time.perf_counter()
        if self.stream is None:
            return self
        if getattr(self.stream, "isatty", lambda: False)():
            from tqdm import tqdm

            self._bar = tqdm(total=self.total, desc=self.desc, unit=self.unit, file=self.stream)
        return self

    def update(self, n: int = 1) -> None:
        """``n`` more units done."""
        self.done += n
        if self._bar is not None:
            self._bar.update(n)
            return
        if self.stream is None:
            return
        elapsed = time.perf_counter() - self._start
        if self._estimated:
            if self.done < self.total and elapsed - self._last_line >= self.line_every:
                self._last_line = elapsed
                left = elapsed * (self.total - self.done) / max(self.done, 1)
                self._write(
                    f"{100 * self.done / self.total:.0f} % in {format_seconds(elapsed)}, "
                    f"about {format_seconds(left)} left"
                )
            return
        if elapsed >= self.estimate_after:
            self._estimated, self._last_line = True, elapsed
            if self.done >= self.total:  # nothing left to estimate: only the closing line
                return
            expected = elapsed * self.total / max(self.done, 1)
            self._write(
                f"{self.total} {self.unit}, about {format_seconds(expected)} in all "
                f"(measured on the first {self.done})"
            )

    def __exit__(self, kind, value, traceback) -> None:
        if self._bar is not None:
            self._bar.close()
        elif self._estimated and kind is None:
            self._write(f"done in {format_seconds(time.perf_counter() - self._start)}")

    def _write(self, text: str) -> None:
        self.stream.write(f"{self.desc}: {text}\n")
        self.stream.flush()


class StageTimer:
    """Times the named stages of a pipeline; writes one line per stage to ``stream`` if given.

    Examples
    --------
    >>> import io
    >>> out = io.StringIO()
    >>> timer = StageTimer(out, "painting")
    >>> with timer.stage("shadows"):
    ...     pass
    >>> sorted(timer.seconds), out.getvalue().startswith("painting: shadows ...")
    (['shadows'], True)
    >>> quiet = StageTimer(out, "painting", after=5.0)   # announced only after 5 s
    >>> with quiet.stage("quick"):
    ...     pass
    >>> "quick" in out.getvalue(), sorted(quiet.seconds)
    (False, ['quick'])
    >>> with StageTimer(out, "painting", after=0.05).stage("slow"):
    ...     time.sleep(0.5)
    >>> out.getvalue().splitlines()[-1].startswith("painting: slow ... 0.5 s")
    True
    """

    def __init__(self, stream: TextIO | None = None, prefix: str = "", after: float | None = None):
        self.stream, self.prefix, self.after = stream, prefix, after
        self.seconds: dict[str, float] = {}

    @contextlib.contextmanager
    def stage(self, name: str):
        """Time the block as stage ``name``.

        With ``after`` (seconds), a stage is announced only once it has run that long (by a
        timer thread; a kernel that holds the GIL delays it), so quick stages and the one-line
        refusal of bad input stay alone on stderr.
        """
        shown, lock = [False], threading.Lock()

        def announce():
            with lock:
                if shown[0] is None:  # the stage ended first
                    return
                shown[0] = True
                self.stream.write(f"{self.prefix}: {name} ...")
                self.stream.flush()

        timer = None
        if self.stream is not None and (self.after is None or self.after <= 0):
            announce()
        elif self.stream is not None:
            timer = threading.Timer(self.after, announce)
            timer.daemon = True
            timer.start()
        start = time.perf_counter()
        try:
            yield
        finally:
            self.seconds[name] = time.perf_counter() - start
            if timer is not None:
                timer.cancel()
            with lock:
                if shown[0]:
                    self.stream.write(f" {format_seconds(self.seconds[name])}\n")
                    self.stream.flush()
                shown[0] = None

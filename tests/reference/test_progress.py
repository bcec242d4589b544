"""Progress lines off a terminal: the estimate, then the share done and the time left."""

import io

import reference.progress as progress_module
from reference.progress import Progress


class _Clock:
    """A stand-in for the ``time`` module whose perf_counter is set by the test."""

    def __init__(self):
        self.now = 0.0

    def perf_counter(self):
        return self.now


def test_a_long_loop_says_how_far_it_is_and_how_long_is_left(monkeypatch):
    clock = _Clock()
    monkeypatch.setattr(progress_module, "time", clock)
    out = io.StringIO()
    with Progress("shading", 100, out, unit="samples", line_every=30.0) as bar:
        for _ in range(10):  # 10 units every 12 s: 120 s in all
            clock.now += 12.0
            bar.update(10)
    lines = out.getvalue().splitlines()
    assert lines[0] == "shading: 100 samples, about 2 min in all (measured on the first 10)"
    # a line once at least 30 s have passed since the last, until the work is done
    assert lines[1:-1] == [
        "shading: 40 % in 48 s, about 1 min 12 s left",
        "shading: 70 % in 1 min 24 s, about 36 s left",
    ]
    assert lines[-1] == "shading: done in 2 min"


def test_a_short_loop_writes_nothing(monkeypatch):
    clock = _Clock()
    monkeypatch.setattr(progress_module, "time", clock)
    out = io.StringIO()
    with Progress("shading", 10, out) as bar:
        for _ in range(10):
            clock.now += 0.1
            bar.update(1)
    assert out.getvalue() == ""

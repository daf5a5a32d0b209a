"""Progress on stderr for long runs, counted in views (or the stage's own items): a rich bar for
the render and the cross-view stage on a terminal, plain lines in a log (stderr not a terminal:
a CI job, a file, a pipe) and for the rest; nothing when disabled."""
from __future__ import annotations

import sys
import threading
import time

from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn


#: Seconds between plain progress lines in a log, whether or not an item finished meanwhile.
LOG_EVERY_S = 5.0


class ViewProgress:
    """Progress of one stage on stderr: ``label``, done/total, ``unit``/s, time left (nothing when
    disabled). ``advance()`` once per item. On a terminal a rich bar; otherwise (a log) a line
    ``scenegen: <label>: done/total <unit> (elapsed s, rate)`` at the start, every ``every_s`` seconds
    from a timer thread (also while one long item works) and at the end."""

    def __init__(self, enabled: bool, total: int, label: str = "rendering views", unit: str = "views",
                 every_s: float = LOG_EVERY_S):
        self.enabled, self.total, self.label, self.unit = enabled and total > 0, total, label, unit
        self.every_s = every_s
        self._p = None
        self._timer: threading.Thread | None = None
        self._stop = threading.Event()
        self._done = 0
        self._t0 = time.perf_counter()

    def __enter__(self):
        if not self.enabled:
            return self
        console = Console(stderr=True)
        if console.is_terminal:
            self._p = Progress(TextColumn(self.label), BarColumn(), MofNCompleteColumn(),
                               TextColumn("{task.fields[rate]}"), TimeRemainingColumn(), console=console)
            self._p.start()
            self._task = self._p.add_task(self.label, total=self.total, rate="")
        else:
            self._line()
            self._timer = threading.Thread(target=self._beat, name="progress-lines", daemon=True)
            self._timer.start()
        return self

    def _line(self) -> None:
        elapsed = time.perf_counter() - self._t0
        print(f"scenegen: {self.label}: {self._done}/{self.total} {self.unit} ({elapsed:.1f} s, "
              f"{self._done / max(elapsed, 1e-9):.2f} {self.unit}/s)", file=sys.stderr, flush=True)

    def _beat(self) -> None:
        while not self._stop.wait(self.every_s):
            self._line()

    def advance(self, n: int = 1):
        self._done += n
        if self._p is not None:
            rate = self._done / max(time.perf_counter() - self._t0, 1e-9)
            self._p.update(self._task, advance=n, rate=f"{rate:.2f} {self.unit}/s")

    def __exit__(self, *exc):
        if self._p is not None:
            self._p.stop()
        if self._timer is not None:
            self._stop.set()
            self._timer.join()
            self._line()


def line_progress(what: str, unit: str = "views", *, every_s: float = 1.0, enabled: bool = True):
    """``progress(done, total)`` printing ``scenegen: <what>: done/total <unit>`` on stderr at most
    every ``every_s`` seconds and once at the end (None when disabled)."""
    if not enabled:
        return None
    start = last = time.monotonic()

    def progress(done: int, total: int) -> None:
        nonlocal last
        now = time.monotonic()
        if now - last >= every_s or done >= total:
            print(f"scenegen: {what}: {done}/{total} {unit} ({now - start:.1f} s)", file=sys.stderr, flush=True)
            last = now

    return progress

"""Progress on stderr for long runs, counted in views (or the stage's own items): a rich bar for
the render and the cross-view stage, plain lines for the rest (nothing when disabled)."""
from __future__ import annotations

import sys
import time

from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn


class ViewProgress:
    """A rich progress bar on stderr: ``label``, done/total, ``unit``/s, time left (nothing when
    disabled). ``advance()`` once per item."""

    def __init__(self, enabled: bool, total: int, label: str = "rendering views", unit: str = "views"):
        self.enabled, self.total, self.label, self.unit = enabled and total > 0, total, label, unit
        self._p = None
        self._done = 0
        self._t0 = time.perf_counter()

    def __enter__(self):
        if self.enabled:
            self._p = Progress(TextColumn(self.label), BarColumn(), MofNCompleteColumn(),
                               TextColumn("{task.fields[rate]}"), TimeRemainingColumn(),
                               console=Console(stderr=True))
            self._p.start()
            self._task = self._p.add_task(self.label, total=self.total, rate="")
        return self

    def advance(self, n: int = 1):
        self._done += n
        if self._p is not None:
            rate = self._done / max(time.perf_counter() - self._t0, 1e-9)
            self._p.update(self._task, advance=n, rate=f"{rate:.2f} {self.unit}/s")

    def __exit__(self, *exc):
        if self._p is not None:
            self._p.stop()


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

"""Progress on stderr for long runs: a rich bar with frames per second (nothing when disabled)."""
from __future__ import annotations

import time

from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn


class FrameProgress:
    """A rich progress bar with frames/s (nothing when disabled)."""

    def __init__(self, enabled: bool, total: int):
        self.enabled, self.total = enabled, total
        self._p = None
        self._done = 0
        self._t0 = time.perf_counter()

    def __enter__(self):
        if self.enabled:
            self._p = Progress(TextColumn("rendering"), BarColumn(), MofNCompleteColumn(),
                               TextColumn("{task.fields[fps]}"), TimeRemainingColumn())
            self._p.start()
            self._task = self._p.add_task("render", total=self.total, fps="")
        return self

    def advance(self):
        self._done += 1
        if self._p is not None:
            fps = self._done / max(time.perf_counter() - self._t0, 1e-9)
            self._p.update(self._task, advance=1, fps=f"{fps:.2f} frames/s")

    def __exit__(self, *exc):
        if self._p is not None:
            self._p.stop()

"""A view's encoding and writing on a background thread, pipelined with the next frame's render.

:class:`BackgroundWriter` runs :meth:`DatasetWriter.write_view` (truth checks, EXR/PNG encoding,
hashing, atomic fsync'd writes, the journal line) on one thread while the caller renders the next
view. The encoders and the render release the GIL (OpenEXR's compression, OpenCV's PNG, hashlib,
file I/O; Dr.Jit's kernels), so the two overlap for real. One thread, first in first out: the
views are written and recorded in the order they were submitted, by the same code as a serial
write, so the bytes, the manifest and the crash safety (a view is recorded only after all its
files are on disk) are those of a serial run. The queue is bounded (``depth`` views waiting), so
at most ``depth + 1`` frames' arrays are alive besides the one being rendered.
"""
from __future__ import annotations

import queue
import threading

_STOP = object()


class BackgroundWriter:
    """``submit`` views to a :class:`~scenegen.dataset.writer.DatasetWriter` from a worker thread.

    Use as a context manager; leaving it waits for every submitted view (also when the body
    raised). An error of a write is raised by the next :meth:`submit`, by :meth:`drain` or on
    exit; views after a failed one are not written. While it is open, only it may call the
    writer's methods.
    """

    def __init__(self, writer, depth: int = 1):
        if depth < 1:
            raise ValueError(f"depth must be at least 1, got {depth}")
        self.writer = writer
        self._queue: queue.Queue = queue.Queue(maxsize=depth)
        self._error: BaseException | None = None
        self._thread = threading.Thread(target=self._run, name="scenegen-view-writer", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while True:
            item = self._queue.get()
            try:
                if item is _STOP:
                    return
                if self._error is None:  # after a failure: drop the rest, the caller is told
                    view, kwargs = item
                    self.writer.write_view(view, **kwargs)
            except BaseException as e:  # noqa: BLE001 (re-raised in the caller's thread)
                self._error = e
            finally:
                self._queue.task_done()

    def _raise_pending(self) -> None:
        if self._error is not None:
            e, self._error = self._error, None
            raise e

    def submit(self, view: str, **kwargs) -> None:
        """Queue ``writer.write_view(view, **kwargs)``; blocks while ``depth`` views wait."""
        self._raise_pending()
        if not self._thread.is_alive():
            raise RuntimeError("the background writer is closed")
        self._queue.put((view, kwargs))

    def drain(self) -> None:
        """Wait until every submitted view is written and recorded; raise a write's error."""
        self._queue.join()
        self._raise_pending()

    def close(self) -> None:
        """Drain, then stop the thread."""
        try:
            self.drain()
        finally:
            if self._thread.is_alive():
                self._queue.put(_STOP)
                self._thread.join()

    def __enter__(self) -> BackgroundWriter:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.close()
            return
        try:  # the body failed: still finish (and record) what was rendered, then let it propagate
            self.close()
        except Exception:
            pass

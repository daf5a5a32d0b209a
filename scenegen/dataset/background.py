"""A run's views encoded and written on a pool of threads, pipelined with the next frame's render.

:class:`BackgroundWriter` splits :meth:`DatasetWriter.write_view` in two. The work that needs no
writer state (truth checks, EXR/PNG encoding, SHA-256, each file written and fsync'd under a
temporary name: :func:`~scenegen.dataset.view_files.stage_view`) runs on ``workers`` threads, several
views at once; the encoders, hashlib, the file I/O and the render release the GIL, so they overlap
for real. One recorder thread then takes the views **in the order they were submitted** and hands
every finished one at the head of the line to :meth:`DatasetWriter.commit_views`: renamed, each
distinct directory fsync'd once per batch, one fsync'd journal batch. So the journal's order, the
manifest and the bytes are those of a serial run, and the crash safety is too: a view is recorded
only after its files and their directories are durable; files of views not yet recorded are
rewritten with the same bytes by ``--resume`` (temporary ones are removed). At most
``depth + workers`` views' arrays are alive besides the one being rendered.
"""
from __future__ import annotations

import os
import threading
from collections import deque
from concurrent.futures import Future, ThreadPoolExecutor

from scenegen.dataset.files import discard_staged
from scenegen.dataset.view_files import stage_view

#: Views committed with one directory fsync each and one journal fsync, at most.
MAX_BATCH = 64
#: Writer threads at most: each holds a view's arrays while it encodes.
MAX_WORKERS = 8


def machine_cores() -> int:
    """Cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def writer_threads(render_on_cpu: bool = True, cores: int | None = None) -> int:
    """Writer threads for a run: the render's kernels on the CPU hold every core while they run,
    so the writers get half of them; a GPU render leaves them all. At least 2 (one view's fsyncs
    wait while another encodes), at most :data:`MAX_WORKERS`."""
    n = machine_cores() if cores is None else int(cores)
    return max(2, min(MAX_WORKERS, n // 2 if render_on_cpu else n))


class BackgroundWriter:
    """``submit`` views to a :class:`~scenegen.dataset.writer.DatasetWriter` from a pool of threads.

    Use as a context manager; leaving it waits for every submitted view (also when the body
    raised). An error of a write is raised by the next :meth:`submit`, by :meth:`drain` or on
    exit; views after a failed one are not recorded (their files staged are removed). While it is
    open, only it may call the writer's methods. ``workers`` defaults to :func:`writer_threads`.
    """

    def __init__(self, writer, depth: int = 1, workers: int | None = None):
        if depth < 1:
            raise ValueError(f"depth must be at least 1, got {depth}")
        workers = writer_threads() if workers is None else int(workers)
        if workers < 1:
            raise ValueError(f"workers must be at least 1, got {workers}")
        self.writer = writer
        self.workers = workers
        self._limit = depth + workers  # views submitted and not yet recorded, at most
        self._cond = threading.Condition()
        self._line: deque[Future] = deque()  # staging futures in submission order
        self._outstanding = 0  # submitted, neither recorded nor dropped
        self._closing = False
        self._error: BaseException | None = None  # to raise in the caller's thread, once
        self._failed = False  # a view failed: every later one is dropped
        self._pool = ThreadPoolExecutor(workers, thread_name_prefix="scenegen-view-encoder")
        self._thread = threading.Thread(target=self._record_loop, name="scenegen-view-writer", daemon=True)
        self._thread.start()

    def _notify(self, _future=None) -> None:
        with self._cond:
            self._cond.notify_all()

    def _record_loop(self) -> None:
        while True:
            with self._cond:
                self._cond.wait_for(lambda: (self._line and self._line[0].done()) or (self._closing and not self._line))
                if not self._line:
                    return
                batch = []
                while self._line and self._line[0].done() and len(batch) < MAX_BATCH:
                    batch.append(self._line.popleft())
            self._commit(batch)
            with self._cond:
                self._outstanding -= len(batch)
                self._cond.notify_all()

    def _commit(self, batch: list[Future]) -> None:
        """Record the batch's views up to the first failure; from it on every view is dropped
        (its staged files removed), also in later batches."""
        ok = []
        for f in batch:
            e = f.exception()
            if e is None and not self._failed:
                ok.append(f.result())
            elif e is None:
                discard_staged(f.result().staged)
            elif not self._failed:
                self._fail(e)
        try:
            if ok:
                self.writer.commit_views(ok)  # removes the staged files of what it did not record
        except BaseException as e:  # noqa: BLE001 (re-raised in the caller's thread)
            self._fail(e)

    def _fail(self, e: BaseException) -> None:
        with self._cond:
            self._failed = True
            self._error = e

    def _raise_pending(self) -> None:
        with self._cond:
            e, self._error = self._error, None
        if e is not None:
            raise e

    def submit(self, view: str, **kwargs) -> None:
        """Stage ``writer.write_view(view, **kwargs)`` on the pool; blocks while ``depth +
        workers`` views wait to be recorded."""
        self._raise_pending()
        with self._cond:
            if self._closing:
                raise RuntimeError("the background writer is closed")
            self._cond.wait_for(lambda: self._outstanding < self._limit or self._failed)
            if self._error is not None:
                e, self._error = self._error, None
                raise e
            if self._failed:
                raise RuntimeError("the background writer stopped at a failed view (raised before)")
            future = self._pool.submit(stage_view, self.writer.root, view, **kwargs)
            self._line.append(future)
            self._outstanding += 1
        future.add_done_callback(self._notify)

    def drain(self) -> None:
        """Wait until every submitted view is recorded (or dropped); raise a write's error."""
        with self._cond:
            self._cond.wait_for(lambda: self._outstanding == 0)
        self._raise_pending()

    def close(self) -> None:
        """Drain, then stop the threads."""
        try:
            self.drain()
        finally:
            with self._cond:
                self._closing = True
                self._cond.notify_all()
            self._thread.join()
            self._pool.shutdown(wait=True)

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

"""Rendering on Dask distributed workers: tasks of whole frames, a loaded scene kept per worker.

The client (the process owning the :class:`~scenegen.dataset.writer.DatasetWriter`) ships the
spec's source once (a task the others depend on) and submits tasks of one or more whole frames (a rig's members share a frame;
:func:`task_items`), a bounded number in flight (:data:`TASKS_IN_FLIGHT_PER_WORKER`); a worker
builds the scene the first time it sees ``(spec, variant, spp, Mitsuba variant)`` and keeps it
(:data:`_SCENES`, the last :data:`SCENES_KEPT` scenes), renders the task's views, writes their
files with :func:`scenegen.dataset.view_files.write_view_files` and returns the hashes. The client
records each view with :meth:`~scenegen.dataset.writer.DatasetWriter.record_views` as tasks finish
(every task already done at once: one fsync'd batch of journal lines) and keeps nothing after;
the manifest is byte-identical to a serial run's (sorted keys; the views declared in the run's
order by cameras.json), and a run killed at any point resumes like a serial one. A
worker killed mid-write leaves a temporary file; the client removes those once every task is done.

Workers must see the output folder at the same path (one machine, or a shared file system).
A local cluster shares this machine's cores: each worker's Dr.Jit pool gets cores / workers
threads (two processes with a pool of all cores each spent about 20 % more CPU on the same work,
docs/performance.md), and Dask's own periodic work (event-loop ticks, monitors, the workers' stack
sampler) is made rarer (:data:`LOCAL_CLUSTER_CONFIG`).
Mitsuba is imported in a worker only through :func:`scenegen.render.load_scene`, which points
Dr.Jit at a good libLLVM before ``import drjit``.
"""
from __future__ import annotations

import contextlib
import logging
import os
from collections import OrderedDict
from pathlib import Path

from scenegen.dataset.files import remove_stale_temp_files
from scenegen.dataset.view_files import write_view_files
from scenegen.pipeline.view import render_view_data
from scenegen.render import configure_llvm, load_scene
from scenegen.render.threads import render_threads, set_render_threads
from scenegen.spec import resolve_views

__all__ = ["open_client", "render_views_dask", "render_frame_task", "task_items", "shipped_value", "TASKS_IN_FLIGHT_PER_WORKER",
           "TASKS_PER_WORKER", "MAX_VIEWS_PER_TASK", "worker_scene", "worker_stats", "note_stage_items",
           "SCENES_KEPT", "LOCAL_CLUSTER_CONFIG", "DRJIT_THREADS_ENV"]

#: Loaded scenes a worker keeps (least recently used dropped first).
SCENES_KEPT = 2
#: Tasks in flight per worker at most (windowed submission: one waits in each worker's queue
#: while another runs, and the scheduler never holds the whole run).
TASKS_IN_FLIGHT_PER_WORKER = 4
#: About how many tasks per worker a run is cut into (more tasks balance the load; fewer cost
#: less scheduling), and the most views one task renders.
TASKS_PER_WORKER = 8
MAX_VIEWS_PER_TASK = 16
_SCENES: "OrderedDict[tuple, tuple]" = OrderedDict()  # key -> (spec, views, built)
_STATS = {"scene_loads": 0, "views_rendered": 0, "stage_items": 0}
#: Dask settings of a local cluster: its defaults (20 ms event-loop ticks, a 100 ms memory monitor,
#: a 10 ms stack sampler in each worker, for a dashboard we do not start) cost an idle 2-worker
#: cluster 0.17 of a core, 0.025 with these (measured, docs/performance.md).
LOCAL_CLUSTER_CONFIG = {"distributed.admin.tick.interval": "1s", "distributed.admin.system-monitor.interval": "1s",
                        "distributed.worker.memory.monitor-interval": "1s", "distributed.worker.profile.enabled": False}
#: Environment variable a local cluster's workers get: their Dr.Jit thread count.
DRJIT_THREADS_ENV = "SCENEGEN_WORKER_DRJIT_THREADS"


@contextlib.contextmanager
def open_client(*, workers: int | None = None, scheduler: str | None = None):
    """A ``distributed.Client``: on a new LocalCluster of ``workers`` processes (one thread each),
    or connected to ``scheduler`` (e.g. ``tcp://host:8786``). Closed (and the cluster shut down)
    on exit."""
    if (workers is None) == (scheduler is None):
        raise ValueError("give exactly one of --workers N and --scheduler ADDRESS")
    try:
        import dask  # Dask on use: a heavy dependency (~1 s to import) that only --workers/--scheduler need
        from distributed import Client, LocalCluster  # its client and local cluster: the same reason
    except ImportError:  # fail only when the feature is used
        raise ValueError("--workers/--scheduler need Dask distributed: pip install 'dask[distributed]'") from None
    if scheduler is not None:
        try:
            client = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError) as e:
            raise ValueError(f"--scheduler {scheduler}: cannot connect ({e})") from None
        try:
            yield client
        finally:
            client.close()
        return
    if workers < 1:
        raise ValueError(f"--workers must be at least 1, got {workers}")
    configure_llvm()  # spawned workers inherit DRJIT_LIBLLVM_PATH through the environment
    threads = max(1, (os.cpu_count() or 1) // int(workers))  # the workers share this machine's cores
    with dask.config.set(LOCAL_CLUSTER_CONFIG):  # the nannies hand it to (re)started workers
        cluster = LocalCluster(n_workers=int(workers), threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=logging.ERROR,
                               env={DRJIT_THREADS_ENV: str(threads)})
        client = Client(cluster)
    try:
        yield client
    finally:
        client.close()
        cluster.close()


def worker_scene(source, spp: int, variant: str):
    """(spec, views, built) for ``source``, loaded once per worker and kept."""
    key = (source.key, int(spp), variant)
    hit = _SCENES.get(key)
    if hit is not None:
        _SCENES.move_to_end(key)
        return hit
    spec = source.load()
    built = load_scene(spec, variant=variant, spp=spp)  # libLLVM path, then Mitsuba, the variant
    threads = os.environ.get(DRJIT_THREADS_ENV)
    if threads:  # a local cluster's worker: its share of the cores
        set_render_threads(int(threads))
    _SCENES[key] = (spec, resolve_views(spec), built)
    _STATS["scene_loads"] += 1
    while len(_SCENES) > SCENES_KEPT:
        _SCENES.popitem(last=False)
    return _SCENES[key]


def render_frame_task(source, out_dir: str, items, spp: int, seed: int, variant: str):
    """Worker task: render and write the views ``items`` = [(index in the run, view name)];
    returns [(view name, {relative path: sha256})]."""
    spec, views, built = worker_scene(source, spp, variant)
    out = []
    for index, name in items:
        v = views[index]
        if v.name != name:  # the worker's spec is not the client's: never write a wrong view
            raise RuntimeError(f"worker resolved view {index} as {v.name!r}, the client as {name!r}")
        image, linear, truth, extra = render_view_data(spec, built, index, v, spp=spp, seed=seed)
        out.append((name, write_view_files(out_dir, name, image=image, linear_rgb=linear, truth=truth,
                                              extra_files=extra, exr_compression=spec.render.exr_compression)))
        del image, linear, truth, extra  # release the frame's buffers before the next
        _STATS["views_rendered"] += 1
    return out


def note_stage_items(n: int) -> None:
    """Count ``n`` stage items run in this process (:mod:`scenegen.pipeline.stages`)."""
    _STATS["stage_items"] += int(n)


def worker_stats() -> dict:
    """This process's counters: scene_loads, views_rendered, stage_items, pid, render_threads
    (Dr.Jit's; None before a scene is loaded) (run it with ``client.run``)."""
    return {**_STATS, "pid": os.getpid(), "render_threads": render_threads()}


def shipped_value(value):
    """A task's result that its dependents read from the worker holding it (the spec source)."""
    return value


def task_items(pending, n_workers: int) -> list[list[tuple[int, str]]]:
    """``pending`` = [(index, View)] cut into tasks of [(index, view name)]: a frame's views stay
    in one task (a rig's members share a frame), consecutive frames join a task until it holds
    about ``total / (TASKS_PER_WORKER * n_workers)`` views (at most :data:`MAX_VIEWS_PER_TASK`),
    so a small run keeps one frame per task and a large one has few, larger tasks. A view's
    seed comes from its index in the run, not its task: the cut never changes a byte."""
    frames: "OrderedDict[int, list]" = OrderedDict()
    for index, v in pending:
        frames.setdefault(v.frame_index, []).append((index, v.name))
    target = min(MAX_VIEWS_PER_TASK, max(1, len(pending) // (TASKS_PER_WORKER * max(1, n_workers))))
    tasks, current = [], []
    for items in frames.values():
        if current and len(current) + len(items) > target:
            tasks.append(current)
            current = []
        current.extend(items)
    if current:
        tasks.append(current)
    return tasks


def render_views_dask(client, source, writer, pending, *, spp: int, seed: int, variant: str,
                      on_done=None) -> int:
    """Render ``pending`` = [(index, View)] on the client's workers and record each view in
    ``writer`` as its task finishes. Returns the number of views rendered.

    The spec's source goes to the workers once (one task returns it; the others depend on it); at most :data:`TASKS_IN_FLIGHT_PER_WORKER`
    tasks per worker (counted when the run starts) are submitted at a time, the next one as each
    finishes; finished tasks are recorded together (one journal fsync) in the order they arrive
    and released, so the scheduler's tasks and the client's memory stay bounded whatever the
    run's size. The manifest's bytes do not depend on that order (sorted keys, views declared by
    cameras.json), and an interrupted run's journal resumes like a serial one's."""
    from distributed import as_completed  # Dask on use (see open_client): a client exists already

    n_workers = max(1, len(client.scheduler_info().get("workers", {})))
    tasks = iter(task_items(pending, n_workers))
    out_dir = str(Path(writer.root).resolve())
    # once, not pickled into every task: a task that returns it (not scattered data), so that a
    # worker lost with its only copy is recomputed by the scheduler instead of failing the run
    shipped = client.submit(shipped_value, source, pure=False)
    in_flight: set = set()
    done_stream = as_completed()

    def submit_next() -> bool:
        items = next(tasks, None)
        if items is None:
            return False
        fut = client.submit(render_frame_task, shipped, out_dir, items, spp, seed, variant, pure=False)
        in_flight.add(fut)
        done_stream.add(fut)
        return True

    n = 0
    try:
        for _ in range(TASKS_IN_FLIGHT_PER_WORKER * n_workers):
            if not submit_next():
                break
        while in_flight:
            finished = done_stream.next_batch(block=True)
            batch = {}
            for fut in finished:
                batch.update(fut.result())  # a task's error ends the run here (the journal keeps what is recorded)
                in_flight.discard(fut)
                fut.release()
            writer.record_views(batch)
            n += len(batch)
            for _ in batch:
                if on_done is not None:
                    on_done()
            for _ in finished:
                submit_next()
    finally:
        for fut in in_flight:
            fut.cancel()
        done_stream.clear()
        shipped.release()
    # A worker killed mid-write leaves its temporary file (the task reran elsewhere): every task
    # is done now, so nothing writes under out_dir but this process
    remove_stale_temp_files(out_dir)
    return n

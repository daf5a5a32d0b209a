"""The cluster path's bookkeeping (issue 32): tasks of whole frames, a bounded window of tasks in
flight, results recorded as they arrive and nothing kept. The render itself is replaced by a
stand-in task here (the bytes of real renders on workers: tests/scenegen/pipeline/test_scale.py,
test_stage_items_dask.py, test_dask_worker_killed.py)."""
from __future__ import annotations

import logging
import math
import time
from types import SimpleNamespace

import pytest

import scenegen.pipeline.distributed as dd
from scenegen.pipeline.distributed import (MAX_VIEWS_PER_TASK, TASKS_IN_FLIGHT_PER_WORKER, TASKS_PER_WORKER,
                                           render_views_dask, task_items)


def _pending(n_frames: int, per_frame: int = 1):
    return [(f * per_frame + m, SimpleNamespace(frame_index=f, name=f"f{f:05d}_m{m}"))
            for f in range(n_frames) for m in range(per_frame)]


@pytest.mark.parametrize("n_frames,per_frame,workers", [(8, 1, 2), (9, 2, 2), (1000, 1, 2), (10_000, 2, 3),
                                                        (5, 3, 8)])
def test_task_items_keep_frames_whole_cover_the_run_once_and_size_tasks(n_frames, per_frame, workers):
    pending = _pending(n_frames, per_frame)
    tasks = task_items(pending, workers)
    flat = [it for t in tasks for it in t]
    assert flat == [(i, v.name) for i, v in pending]  # every view once, in the run's order
    frame_of = {v.name: v.frame_index for _, v in pending}
    for a, b in zip(tasks, tasks[1:]):  # no frame split across tasks
        assert frame_of[a[-1][1]] != frame_of[b[0][1]]
    target = min(MAX_VIEWS_PER_TASK, max(1, len(pending) // (TASKS_PER_WORKER * workers)))
    assert all(len(t) <= max(target, per_frame) for t in tasks)
    # a task closes only when the next frame would overflow it: at most twice the minimum count
    assert len(tasks) <= 2 * math.ceil(len(pending) / max(target, per_frame)) + 1


def test_small_runs_keep_one_frame_per_task():
    assert [len(t) for t in task_items(_pending(8), 2)] == [1] * 8  # 8 views, 2 workers


class _Writer:
    """Records what render_views_dask hands over, and when."""

    def __init__(self, root):
        self.root = root
        self.recorded: dict[str, dict] = {}
        self.batches = 0

    def record_views(self, views):
        assert not set(views) & set(self.recorded), "a view recorded twice"
        self.recorded.update(views)
        self.batches += 1


def _stand_in_task(source, out_dir, items, spp, seed, variant):
    time.sleep(0.002 * (items[0][0] % 3))  # uneven task times: results arrive out of order
    return [(name, {f"images/{name}.png": f"{index:064x}"}) for index, name in items]


def test_window_bounds_tasks_in_flight_records_out_of_order_and_keeps_nothing(tmp_path, monkeypatch):
    from distributed import Client, Future, LocalCluster

    monkeypatch.setattr(dd, "render_frame_task", _stand_in_task)  # threads: the workers see the patch
    pending = _pending(1200)
    writer = _Writer(tmp_path)
    firsts, max_in_flight = [], [0]  # each submitted task's first view (a task is recorded whole)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None,
                      silence_logs=logging.ERROR) as cluster, Client(cluster) as client:
        submit = client.submit

        def counting_submit(fn, *args, **kwargs):
            if fn is dd.shipped_value:  # the spec's source, shipped once
                return submit(fn, *args, **kwargs)
            source, out_dir, items = args[:3]
            assert isinstance(source, Future)  # the spec shipped once (one task's result), not pickled per task
            firsts.append(items[0][1])
            in_flight = sum(name not in writer.recorded for name in firsts)
            max_in_flight[0] = max(max_in_flight[0], in_flight)
            return submit(fn, *args, **kwargs)

        monkeypatch.setattr(client, "submit", counting_submit)
        n = render_views_dask(client, SimpleNamespace(key="k"), writer, pending, spp=1, seed=0, variant="v")
        time.sleep(0.2)
        left = [k for k in client.futures]  # futures the client still holds
    assert n == 1200
    assert writer.recorded == {v.name: {f"images/{v.name}.png": f"{i:064x}"} for i, v in pending}
    assert len(firsts) == len(task_items(pending, 2))
    assert max_in_flight[0] <= TASKS_IN_FLIGHT_PER_WORKER * 2
    assert writer.batches <= len(firsts)
    assert left == []

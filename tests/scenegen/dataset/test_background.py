"""BackgroundWriter: views written on a thread give the serial writer's bytes; errors surface."""
import sys
import threading
from pathlib import Path

import pytest
import trimesh

from scenegen.dataset import background
from scenegen.dataset.background import BackgroundWriter
from scenegen.dataset.files import TEMP_SUFFIX
from scenegen.dataset.journal import read_journal

sys.path.insert(0, str(Path(__file__).parent))  # the dataset fixtures of test_dataset.py
from test_dataset import SPEC, VIEWS, all_bytes, make_view, new_writer, view_cameras, write_dataset


@pytest.mark.parametrize("workers", [1, 3])
def test_background_writes_the_serial_bytes(tmp_path, workers):
    serial = tmp_path / "serial"
    write_dataset(serial)
    out = tmp_path / "bg"
    w = new_writer(out)
    w.write_cameras(view_cameras(), SPEC)
    w.write_mesh("box", trimesh.creation.box(extents=(1, 2, 3)))
    with BackgroundWriter(w, depth=2, workers=workers) as bg:
        for i, v in enumerate(VIEWS):
            bg.submit(v, **make_view(i))
    assert w.completed_views == tuple(sorted(VIEWS))
    w.close()
    assert all_bytes(out) == all_bytes(serial)


def test_pool_is_bounded_and_records_in_submission_order(tmp_path, monkeypatch):
    """Views staged out of order (the last first) on 3 threads are recorded in the order they
    were submitted, in batches; at most depth + workers views wait."""
    out = tmp_path / "o"
    w = new_writer(out)
    w.write_cameras(view_cameras(), SPEC)
    gates = {v: threading.Event() for v in VIEWS}
    staged = []
    real = background.stage_view

    def gated(root, view, **kw):
        gates[view].wait(10)
        result = real(root, view, **kw)
        staged.append(view)
        return result

    monkeypatch.setattr(background, "stage_view", gated)
    batches = []
    real_commit = w.commit_views
    w.commit_views = lambda views: (batches.append([sv.view for sv in views]), real_commit(views))
    bg = BackgroundWriter(w, depth=1, workers=3)
    for i, v in enumerate(VIEWS[:4]):  # 3 staging, 1 waiting for a thread: the limit
        bg.submit(v, **make_view(i))
    blocked = threading.Thread(target=bg.submit, args=(VIEWS[4],), kwargs=make_view(4))
    blocked.start()
    blocked.join(0.3)
    assert blocked.is_alive()  # a fifth view waits for room
    for v in reversed(VIEWS[:3]):  # the pool's three views finish last first
        gates[v].set()
        while v not in staged:
            blocked.join(0.01)
    while not batches:
        blocked.join(0.01)
    assert batches == [VIEWS[:3]]  # the head finished last: the three committed as one batch
    gates[VIEWS[3]].set()
    gates[VIEWS[4]].set()
    blocked.join(10)
    bg.close()
    assert staged[:3] == list(reversed(VIEWS[:3]))
    assert [v for b in batches for v in b] == VIEWS
    assert [r["view"] for r in read_journal(out).records] == VIEWS  # the journal's order
    assert w.completed_views == tuple(sorted(VIEWS))
    assert not list(out.rglob(f"*{TEMP_SUFFIX}"))


def test_a_failed_write_is_raised_and_later_views_are_not_written(tmp_path):
    w = new_writer(tmp_path / "o")
    w.write_cameras(view_cameras(), SPEC)
    bad = make_view(1)
    bad["linear_rgb"] = bad["linear_rgb"][..., :2]  # wrong shape: write_view raises
    bg = BackgroundWriter(w)
    bg.submit(VIEWS[0], **make_view(0))
    bg.submit(VIEWS[1], **bad)
    with pytest.raises(ValueError, match="linear_rgb"):
        bg.drain()
        bg.submit(VIEWS[2], **make_view(2))
    bg.close()
    assert w.completed_views == (VIEWS[0],)


def test_leaving_on_an_error_still_records_what_was_submitted(tmp_path):
    w = new_writer(tmp_path / "o")
    w.write_cameras(view_cameras(), SPEC)
    with pytest.raises(KeyboardInterrupt):
        with BackgroundWriter(w) as bg:
            bg.submit(VIEWS[0], **make_view(0))
            raise KeyboardInterrupt
    assert w.completed_views == (VIEWS[0],)


def test_writer_threads_follow_the_cores_and_the_renders_share():
    assert background.writer_threads(render_on_cpu=True, cores=2) == 2  # at least 2: fsyncs wait beside encoding
    assert background.writer_threads(render_on_cpu=True, cores=8) == 4  # the CPU render holds the cores
    assert background.writer_threads(render_on_cpu=False, cores=6) == 6  # a GPU render leaves them all
    assert background.writer_threads(render_on_cpu=False, cores=64) == background.MAX_WORKERS

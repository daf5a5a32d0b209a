"""BackgroundWriter: views written on a thread give the serial writer's bytes; errors surface."""
import sys
import threading
from pathlib import Path

import pytest
import trimesh

from scenegen.dataset.background import BackgroundWriter

sys.path.insert(0, str(Path(__file__).parent))  # the dataset fixtures of test_dataset.py
from test_dataset import SPEC, VIEWS, all_bytes, make_view, new_writer, view_cameras, write_dataset


def test_background_writes_the_serial_bytes(tmp_path):
    serial = tmp_path / "serial"
    write_dataset(serial)
    out = tmp_path / "bg"
    w = new_writer(out)
    w.write_cameras(view_cameras(), SPEC)
    w.write_mesh("box", trimesh.creation.box(extents=(1, 2, 3)))
    with BackgroundWriter(w, depth=2) as bg:
        for i, v in enumerate(VIEWS):
            bg.submit(v, **make_view(i))
    assert w.completed_views == tuple(sorted(VIEWS))
    w.close()
    assert all_bytes(out) == all_bytes(serial)


def test_queue_is_bounded_and_order_kept(tmp_path):
    w = new_writer(tmp_path / "o")
    w.write_cameras(view_cameras(), SPEC)
    gate, order = threading.Event(), []
    real = w.write_view

    def slow(view, **kw):
        gate.wait(10)
        order.append(view)
        real(view, **kw)

    w.write_view = slow
    bg = BackgroundWriter(w, depth=1)
    bg.submit(VIEWS[0], **make_view(0))  # taken by the thread, waits at the gate
    bg.submit(VIEWS[1], **make_view(1))  # fills the queue
    blocked = threading.Thread(target=bg.submit, args=(VIEWS[2],), kwargs=make_view(2))
    blocked.start()
    blocked.join(0.3)
    assert blocked.is_alive()  # a third view waits for room: at most depth + 1 in flight
    gate.set()
    blocked.join(10)
    bg.close()
    assert order == VIEWS[:3]


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

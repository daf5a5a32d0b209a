"""Small helpers the command families share: the dataset view a command scores, shape checks."""
from __future__ import annotations

import sys
import time

from recon_eval.errors import InputError


def dataset_view(ds, view, where: str) -> str:
    """``view`` checked against the dataset, or its only view when ``view`` is None (``where``
    says what needs one, for the error)."""
    if view is None:
        if len(ds.views) != 1:
            raise InputError(f"{ds.root}: {where} needs --view VIEW (complete views: {', '.join(ds.views[:8])}"
                             f"{' ...' if len(ds.views) > 8 else ''})")
        return ds.views[0]
    return ds.check_view(view)


def image_size(size, flag: str = "--size") -> tuple[int, int]:
    """(W, H) of a ``--size W H`` option: two positive whole numbers (InputError otherwise)."""
    w, h = (int(v) for v in size)
    if w < 1 or h < 1:
        raise InputError(f"{flag}: expected the image width and height in pixels (two numbers >= 1), got {w} {h}")
    return w, h


def same_shape(est, gt, est_name, gt_name) -> None:
    if est.shape != gt.shape:
        raise InputError(f"{est_name}: shape {est.shape} differs from the truth's {gt.shape} ({gt_name})")


def needs_dataset_for_view(a) -> None:
    """``--view`` only names a view of a dataset truth."""
    if a.view:
        raise InputError(f"--view needs a dataset truth; {a.gt} is not a dataset folder")


#: How stderr_progress behaves in this process (set once by the command line: -q, -v).
PROGRESS = {"enabled": True, "every_s": 2.0}


def configure_progress(*, enabled: bool, every_s: float) -> None:
    """-q turns the progress lines off; -v makes them more frequent."""
    PROGRESS.update(enabled=enabled, every_s=every_s)


def stderr_progress(what: str, *, every_s: float | None = None):
    """``progress(done, total)`` printing ``recon-eval: <what>: done/total`` on stderr at most every
    ``every_s`` seconds (default: the command line's), and the last line when the whole took longer
    than that (short runs print nothing); a no-op under -q."""
    every_s = PROGRESS["every_s"] if every_s is None else every_s
    start = last = time.monotonic()

    def progress(done: int, total: int) -> None:
        nonlocal last
        if not PROGRESS["enabled"]:
            return
        now = time.monotonic()
        if now - last >= every_s or (done >= total and now - start >= every_s):
            print(f"recon-eval: {what}: {done:,}/{total:,} ({100.0 * done / max(total, 1):.0f} %, "
                  f"{now - start:.1f} s)", file=sys.stderr, flush=True)
            last = now

    return progress

"""What the exporters share: opening a dataset, an empty destination, checked destination names,
atomic writes, float text."""
from __future__ import annotations

import os
import shutil
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from scenegen.dataset import Dataset, DatasetError
from scenegen.dataset.files import atomic_write_bytes
from scenegen.dataset.layout import check_name
from scenegen.export.errors import ExportError


def open_dataset(out_dir) -> Dataset:
    p = Path(out_dir)
    if not p.is_dir():
        raise ExportError(f"{p} is not a directory (expected a scenegen dataset folder)")
    try:
        ds = Dataset(p)
    except (DatasetError, ValueError, KeyError, OSError) as e:
        raise ExportError(f"{p} is not a readable scenegen dataset: {e}") from None
    if not ds.views:
        raise ExportError(f"{p} has no complete views to export")
    return ds


def check_dest(dest: Path) -> None:
    if dest.exists() and (not dest.is_dir() or any(dest.iterdir())):
        raise ExportError(f"export destination {dest} exists and is not an empty folder; choose a new one with -o")


@contextmanager
def staged_dest(dest: Path):
    """Yield a fresh sibling folder ``.<name>.partial-<pid>`` to write the export into; renamed to
    ``dest`` when the block ends normally, removed when it raises: a refused or failed export
    leaves nothing behind (an empty ``dest`` that existed before stays as it was)."""
    check_dest(dest)
    created = [p for p in reversed(dest.parents) if not p.exists()]  # outermost first
    dest.parent.mkdir(parents=True, exist_ok=True)
    stage = dest.parent / f".{dest.name}.partial-{os.getpid()}"
    if stage.exists():
        shutil.rmtree(stage)
    stage.mkdir()
    try:
        yield stage
        check_dest(dest)  # nothing appeared there meanwhile
        if dest.exists():
            dest.rmdir()
        stage.rename(dest)
    except BaseException as e:
        if isinstance(e, OSError) and isinstance(e.filename, str) and e.filename.startswith(str(stage)):
            e.filename = str(dest) + e.filename[len(str(stage)):]  # name the file the user asked for
        if stage.exists():
            shutil.rmtree(stage)
        for p in reversed(created):  # the folders made for it, innermost first, if still empty
            if p.is_dir() and not any(p.iterdir()):
                p.rmdir()
        raise


def name(kind: str, value: str) -> str:
    """A name read from the dataset, checked before it becomes part of a destination path."""
    try:
        return check_name(kind, value)
    except ValueError as e:
        raise ExportError(str(e)) from None


def write(dest: Path, rel: str, data: bytes) -> str:
    atomic_write_bytes(dest / rel, data)
    return rel


def crossview_index(ds):
    """The dataset's typed crossview index, or an ExportError naming what the spec must ask for."""
    try:
        return ds.crossview.require_index()
    except DatasetError as e:
        raise ExportError(str(e)) from None


def stereo_frames(ds):
    crossview_index(ds)
    frames = ds.crossview.stereo_frames()
    if not frames:
        raise ExportError(f"{ds.root} has no rectified stereo frames (a stereo rig and crossview.stereo: true)")
    return frames


def fmt(x: float) -> str:
    """Shortest round-trip text of a float (a float64 read back is bit-identical)."""
    return repr(float(x))


def depth_png16(depth_z, valid, units_per_m: float) -> tuple[np.ndarray, int]:
    """(H, W) uint16 ``round(depth_z * units_per_m)`` (1000: millimetres, nerfstudio; 5000: TUM
    RGB-D), 0 where there is no surface or the value does not fit in 16 bits; and the number of
    surface pixels that did not fit (beyond 65535 / units_per_m metres)."""
    with np.errstate(invalid="ignore", over="ignore"):
        q = np.rint(np.where(valid, depth_z, 0.0).astype(np.float64) * units_per_m)
    fits = valid & (q >= 1) & (q <= 65535)
    return np.where(fits, q, 0).astype(np.uint16), int(np.count_nonzero(valid & ~fits))


def each(items, progress=None):
    """The items, calling ``progress(done, total)`` after each (when given)."""
    items = list(items)
    for k, item in enumerate(items):
        yield item
        if progress is not None:
            progress(k + 1, len(items))

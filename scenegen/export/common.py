"""What the exporters share: opening a dataset, an empty destination, checked destination names,
atomic writes, float text."""
from __future__ import annotations

from pathlib import Path

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


def prepare_dest(dest: Path) -> None:
    if dest.exists() and (not dest.is_dir() or any(dest.iterdir())):
        raise ExportError(f"export destination {dest} exists and is not an empty folder; choose a new one with -o")
    dest.mkdir(parents=True, exist_ok=True)


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

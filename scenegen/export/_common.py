"""Helpers shared by the exporters: open a dataset, an empty destination, atomic writes, the
cross-view index."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from scenegen import io as sio


def _error(msg):
    from scenegen.export import ExportError

    return ExportError(msg)


def open_dataset(out_dir):
    from scenegen.dataset import Dataset, DatasetError

    p = Path(out_dir)
    if not p.is_dir():
        raise _error(f"{p} is not a directory (expected a scenegen dataset folder)")
    try:
        ds = Dataset(p)
    except (DatasetError, ValueError, KeyError, OSError) as e:
        raise _error(f"{p} is not a readable scenegen dataset: {e}") from None
    if not ds.views:
        raise _error(f"{p} has no complete views to export")
    return ds


def prepare_dest(dest: Path) -> None:
    if dest.exists() and (not dest.is_dir() or any(dest.iterdir())):
        raise _error(f"export destination {dest} exists and is not an empty folder; choose a new one with -o")
    dest.mkdir(parents=True, exist_ok=True)


def write(dest: Path, rel: str, data: bytes) -> str:
    sio.atomic_write_bytes(dest / rel, data)
    return rel


def crossview_index(ds) -> dict:
    """The dataset's crossview/index.json, or an ExportError naming what the spec must ask for."""
    p = ds.path("crossview/index.json")
    if not p.is_file():
        raise _error(f"{ds.root} has no cross-view truth (crossview/index.json); render the spec with a"
                     " `crossview:` section (docs/scene_spec.md)")
    return sio.read_json(p)


def stereo_frames(ds) -> list[dict]:
    frames = crossview_index(ds)["stereo"]
    if not frames:
        raise _error(f"{ds.root} has no rectified stereo frames (a stereo rig and crossview.stereo: true)")
    return frames


def to_uint8(img) -> np.ndarray:
    a = np.asarray(img)
    return a if a.dtype == np.uint8 else (a.astype(np.float64) / 257.0 + 0.5).astype(np.uint8)


def fmt(x: float) -> str:
    """Shortest round-trip text of a float (a float64 read back is bit-identical)."""
    return repr(float(x))

"""Tanks and Temples crop files (``<scene>.json``): an Open3D ``SelectionPolygonVolume`` as JSON,
``{"class_name": "SelectionPolygonVolume", "bounding_polygon": [[x, y, z], ...],
"orthogonal_axis": "Z", "axis_min": ..., "axis_max": ..., "version_major": 1, ...}``."""
from __future__ import annotations

import json
from pathlib import Path

from recon_eval.errors import InputError
from recon_eval.metrics.tnt import CropVolume
from recon_eval.readers.text import read_text


def read_crop_volume(path) -> CropVolume:
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected a Tanks and Temples crop volume .json)")
    try:
        doc = json.loads(read_text(p, "a crop volume JSON"))
    except json.JSONDecodeError as exc:
        raise InputError(f"{p}:{exc.lineno}: not JSON ({exc.msg})") from None
    except RecursionError:
        raise InputError(f"{p}: not JSON (nested too deeply)") from None
    if not isinstance(doc, dict) or doc.get("class_name", "SelectionPolygonVolume") != "SelectionPolygonVolume":
        raise InputError(f"{p}: class_name: expected SelectionPolygonVolume")
    missing = [k for k in ("bounding_polygon", "orthogonal_axis", "axis_min", "axis_max") if k not in doc]
    if missing:
        raise InputError(f"{p}: missing {', '.join(missing)}")
    try:
        return CropVolume(doc["bounding_polygon"], doc["orthogonal_axis"], doc["axis_min"], doc["axis_max"])
    except (TypeError, ValueError) as exc:
        raise InputError(f"{p}: {exc}") from None

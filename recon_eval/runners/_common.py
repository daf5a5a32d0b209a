"""What every runner shares: the run record, the dataset's boards, JSON output.

A runner is a function ``run(ds, out_dir, options) -> RunOutput``: it runs a third-party
estimator on a scenegen dataset (read through :mod:`recon_eval.readers.scenegen_dataset`, never
through Mitsuba), writes the estimator's raw output in the estimator's own format under
``out_dir`` (OpenCV YAML, PFM, txt/npy, a COLMAP model folder), reads that raw output back and
scores it with recon_eval's metrics. The scoring always goes through the files written, so what is
scored is what a user of the raw output would get.
"""
from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from recon_eval.errors import InputError

#: Version of the run-result JSON (``command: "run"``); bump when a key changes meaning.
RUN_SCHEMA_VERSION = "1.0"


class NotApplicable(InputError):
    """The dataset lacks what the method needs (no board, no stereo rig, no match sets...)."""


@dataclass
class RunOutput:
    """Raw outputs and scores of one method on one dataset.

    ``results``: metric group -> result dataclass or dict (serialised by recon_eval.report);
    ``metrics``: flat headline metrics, name -> float (what gates and the leaderboard read first);
    ``raw_files``: the estimator's own output files, relative to the run folder;
    ``notes``: what the runner did that a reader must know (detections dropped, options)."""

    results: dict = field(default_factory=dict)
    metrics: dict = field(default_factory=dict)
    raw_files: list = field(default_factory=list)
    notes: dict = field(default_factory=dict)


def scene_name(ds) -> str:
    """The scene name recorded in cameras.json (``spec.name``), else the folder name."""
    spec = ds._ds.spec or {}
    return str(spec.get("name") or ds.root.name)


def spec_objects(ds) -> list:
    return list((ds._ds.spec or {}).get("objects", []))


def boards(ds) -> dict:
    """name -> (geometry dict from the spec, board truth dict from scene/targets/<name>.json)."""
    out = {}
    for obj in spec_objects(ds):
        geo = obj.get("geometry", {})
        if geo.get("kind") in ("checkerboard", "charuco", "aruco_grid", "aruco"):
            path = ds.root / "scene" / "targets" / f"{obj['name']}.json"
            if not path.is_file():
                raise InputError(f"{path}: no such file (truth of board {obj['name']!r})")
            out[obj["name"]] = (geo, json.loads(path.read_text()))
    return out


def crossview_index(ds) -> dict | None:
    p = ds.root / "crossview" / "index.json"
    return json.loads(p.read_text()) if p.is_file() else None


def gray(img: np.ndarray) -> np.ndarray:
    """(H, W) uint8 from an RGB/grey uint8/uint16 image."""
    import cv2

    a = np.asarray(img)
    if a.dtype == np.uint16:
        a = (a >> 8).astype(np.uint8)
    return cv2.cvtColor(a, cv2.COLOR_RGB2GRAY) if a.ndim == 3 else a


class Timer:
    def __enter__(self):
        self.t0 = time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.s = time.perf_counter() - self.t0


def finite_or_inf(x) -> float:
    x = float(x)
    return x if np.isfinite(x) else float("inf")


def out_path(out_dir: Path, name: str) -> Path:
    p = Path(out_dir) / name
    p.parent.mkdir(parents=True, exist_ok=True)
    return p

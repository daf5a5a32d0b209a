"""What every runner shares: the run record, the cross-view pairs, output paths.

A runner is a function ``run(ds, out_dir, options) -> RunOutput``: it runs a third-party
estimator on a scenegen dataset (read through :mod:`recon_eval.readers.scenegen_dataset`, never
through Mitsuba), writes the estimator's raw output in the estimator's own format under
``out_dir`` (OpenCV YAML, PFM, txt/npy, a COLMAP model folder), reads that raw output back and
scores it with recon_eval's metrics. The scoring always goes through the files written, so what is
scored is what a user of the raw output would get. Images reach the estimators as
:func:`scenegen.geometry.color.to_grey8` of the stored RGB (16-bit images rounded, ``x / 257``).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

from recon_eval.errors import NotApplicable

#: Version of the run-result JSON (``command: "run"``); bump when a key changes meaning.
RUN_SCHEMA_VERSION = "1.0"


@dataclass
class RunOutput:
    """Raw outputs and scores of one method on one dataset.

    ``results``: metric group -> result dataclass or dict (serialised by recon_eval.report);
    ``metrics``: flat headline metrics, name -> float (what gates and the leaderboard read first);
    ``raw_files``: the estimator's own output files, relative to the run folder;
    ``notes``: what the runner did that a reader must know (detections dropped, options);
    ``warnings``: silent-looking bad output worth a line on stderr (a non-finite F scored inf, a
    disparity of the wrong sign): :func:`recon_eval.runners.run_method` prints each naming the
    method and keeps them in ``inputs.warnings``."""

    results: dict = field(default_factory=dict)
    metrics: dict = field(default_factory=dict)
    raw_files: list = field(default_factory=list)
    notes: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)


def crossview_pairs(ds) -> tuple:
    """(i, j) of the dataset's cross-view pairs; NotApplicable without cross-view truth or pairs."""
    pairs = ds.crossview_pairs()
    if not pairs:
        raise NotApplicable(f"{ds.root}: no cross-view pairs (crossview/index.json: pairs)")
    return pairs


class Timer:
    def __enter__(self):
        self.t0 = time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.s = time.perf_counter() - self.t0


def out_path(out_dir: Path, name: str) -> Path:
    p = Path(out_dir) / name
    p.parent.mkdir(parents=True, exist_ok=True)
    return p

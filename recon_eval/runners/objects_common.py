"""What the object recognition runners share: finding a dataset's BOP export, writing the
estimates as a BOP19 result CSV, scoring that file (docs/metrics.md, "Object pose")."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.errors import NotApplicable
from recon_eval.metrics.objects_bop_eval import bop19_evaluate
from recon_eval.readers.bop import HEADER, BopDataset, read_bop_dataset, read_bop_results
from recon_eval.runners.common import RunOutput, out_path
from scenegen.dataset.files import atomic_write_bytes

#: Where a scenegen dataset keeps its BOP export (``scenegen export --format bop DATASET DEST``).
BOP_EXPORT_FOLDERS = ("bop", "export/bop")
RESULT_CSV = "poses_bop19.csv"


def bop_export(ds) -> BopDataset:
    """The BOP export of scenegen dataset ``ds`` (or ``ds`` itself when it is a BOP folder)."""
    root = Path(ds) if isinstance(ds, (str, Path)) else Path(ds.root)
    for sub in ("", *BOP_EXPORT_FOLDERS):
        d = root / sub if sub else root
        if (d / "test").is_dir() or (d / "scene_gt.json").is_file():
            return read_bop_dataset(d)
    raise NotApplicable(f"{root}: no BOP export (run `scenegen export --format bop {root} {root}/bop` first)")


def back_project(depth_mm: np.ndarray, K: np.ndarray) -> np.ndarray:
    """(N, 3) camera points (mm) of the pixels with depth > 0 (pixel centres at integer u, v)."""
    v, u = np.nonzero(depth_mm > 0)
    z = depth_mm[v, u]
    return np.column_stack([(u - K[0, 2]) / K[0, 0] * z, (v - K[1, 2]) / K[1, 1] * z, z])


def write_bop_csv(path: Path, rows) -> None:
    """rows: (scene_id, im_id, obj_id, score, R (3, 3), t (3,) mm, time_s); written atomically."""
    lines = [HEADER]
    for scene_id, im_id, obj_id, score, R, t, time_s in rows:
        lines.append(f"{scene_id},{im_id},{obj_id},{score:.6f},{' '.join(f'{x:.9f}' for x in np.ravel(R))},"
                     f"{' '.join(f'{x:.6f}' for x in np.ravel(t))},{time_s:.6f}")
    atomic_write_bytes(path, ("\n".join(lines) + "\n").encode("utf-8"))


def score_bop_run(bop: BopDataset, out_dir, rows, notes: dict) -> RunOutput:
    """Write ``rows`` as the run's BOP19 CSV, read it back and score it (what a user of the CSV gets)."""
    path = out_path(Path(out_dir), RESULT_CSV)
    write_bop_csv(path, rows)
    r = bop19_evaluate(read_bop_results(path), bop.targets, bop.gts, bop.views, bop.models)
    metrics = {"bop19_ar": r.ar, "bop19_ar_vsd": r.ar_vsd, "bop19_ar_mssd": r.ar_mssd, "bop19_ar_mspd": r.ar_mspd,
               "add_recall": r.add_recall, "adds_recall": r.adds_recall}
    return RunOutput(results={"bop19": r}, metrics=metrics, raw_files=[RESULT_CSV],
                     notes=dict(notes, targets=bop.targets_source))

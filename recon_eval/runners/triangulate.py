"""OpenCV two-view triangulation: ``cv2.triangulatePoints`` (linear, float64) on every cross-view
pair of the dataset (crossview/index.json), at each pixel noise of SIGMAS_PX.

Exactly the user's path: a triangulation task is written per sigma
(:mod:`recon_eval.tasks.triangulation_task`: ``task_sigma<s>/``, the pairs' P = K [R | t] and noisy
exact truth correspondences, COUNT per pair, seeded), OpenCV triangulates its observations, the
points are written as the answer files (``points_sigma<s>/<pair>.txt``, raw output) and scored from
the files read back, as ``recon-eval triangulation TASK EST_DIR`` would. Headline metrics per sigma:
median error (m) and median error relative to depth over all pairs (at sigma 0 also the largest
relative error: float precision), and the median error per triangulation-angle bin
(``bin_<lo>-<hi>deg``, non-empty bins only).
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable

from recon_eval.errors import InputError, NotApplicable
from recon_eval.runners.common import RunOutput, crossview_pairs
from recon_eval.tasks import triangulation_task as tt

SIGMAS_PX = (0.0, 1.0)
COUNT = 2000
SEED = 0


def _sigma_tag(s: float) -> str:
    return f"sigma{s:g}".replace(".", "p")


def _opencv_answer(task_dir: Path, points_dir: Path, pairs: list, out: RunOutput) -> None:
    """cv2.triangulatePoints on each pair of the task read back, written as the answer files."""
    for tp in pairs:
        tt.write_points(points_dir / f"{tp.name}.txt", tt.reference_points(tp))


def opencv(ds, out_dir, options, *, answer: Callable | None = None) -> RunOutput:
    """OpenCV on the triangulation tasks of every sigma (module docstring). ``answer(task_dir,
    points_dir, pairs, out)`` replaces OpenCV: it writes ``points_dir/<pair>.txt`` for the task in
    ``task_dir`` (an external triangulator, :mod:`recon_eval.runners.external_views`); a missing
    file is scored as failed points."""
    crossview_pairs(ds)  # NotApplicable without cross-view pairs
    out = RunOutput()
    try:
        views, skipped = tt.dataset_pairs(ds)
    except InputError as exc:  # e.g. only zero-baseline pairs
        raise NotApplicable(str(exc)) from None
    for sigma in SIGMAS_PX:
        tag = _sigma_tag(sigma)
        pairs = [tt.build_pair(ds, v1, v2, sigma, COUNT, SEED) for v1, v2 in views]
        tt.write_task(out_dir / f"task_{tag}", pairs, {"dataset": str(ds.root), "sigma_px": sigma, "seed": SEED,
                                                       "count": COUNT})
        _, pairs = tt.read_task(out_dir / f"task_{tag}")  # run on what was written
        (answer or _opencv_answer)(Path(out_dir) / f"task_{tag}", Path(out_dir) / f"points_{tag}", pairs, out)
        out.raw_files += [f"points_{tag}/{tp.name}.txt" for tp in pairs
                          if (Path(out_dir) / f"points_{tag}" / f"{tp.name}.txt").is_file()]
        est, notes = tt.read_estimates(out_dir / f"points_{tag}", pairs)
        res = tt.score_task(pairs, est)
        for name, s in res.items():
            out.results[f"{tag}.{name}"] = s
        pooled = res["all_pairs"]
        out.metrics.update({f"{tag}.median_err_m": pooled.median_m, f"{tag}.median_rel_err": pooled.median_rel,
                            f"{tag}.failure_ratio": pooled.n_failed / max(pooled.n_points, 1)})
        if sigma == 0:  # the float-precision check; with noise the largest error is a far point's noise
            out.metrics[f"{tag}.max_rel_err"] = float(pooled.rel_err.max())
        for b in pooled.bins:
            if b.n:
                out.metrics[f"{tag}.{tt.bin_label(b)}.median_err_m"] = b.median_m
        out.notes[tag] = {"pairs": [tp.name for tp in pairs], "points": int(pooled.n_points), **notes}
    out.notes.update({"count_per_pair": COUNT, "seed": SEED, "sigmas_px": list(SIGMAS_PX),
                      "skipped_zero_baseline_pairs": [f"{i}:{j}" for i, j in skipped]})
    return out

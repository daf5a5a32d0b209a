"""OpenCV optical flow on a dataset's flow pairs (a sequence's frame pairs, moving objects included;
else consecutive frames of each camera stream, both directions; without any, its crossview pairs), scored against the dataset's flow with its
occlusion states (:meth:`recon_eval.readers.scenegen_dataset.DatasetTruth.flow_truth`). Images
reach OpenCV as :func:`scenegen.geometry.color.to_grey8` of the stored RGB.

* ``dis``: ``cv2.DISOpticalFlow_create(DISOPTICAL_FLOW_PRESET_MEDIUM)``, dense; raw output
  ``flow/<i>__<j>.flo``.
* ``farneback``: ``cv2.calcOpticalFlowFarneback(prev, next, None, 0.5, 3, 15, 3, 5, 1.2, 0)`` (the
  parameters of OpenCV's optical-flow tutorial), dense; raw output ``flow/<i>__<j>.flo``.
* ``lk``: ``cv2.goodFeaturesToTrack(maxCorners=500, qualityLevel=0.01, minDistance=7)`` in i at
  pixel centres (no sub-pixel refinement, so the truth flow is read at the pixel),
  ``cv2.calcOpticalFlowPyrLK`` (winSize 21, maxLevel 3) into j; raw output
  ``tracks/<i>__<j>.txt`` (rows ``u_i v_i u_j v_j status``).

Dense results are read back from the .flo files and scored with
:func:`recon_eval.metrics.flow.flow_metrics` (pooled over the pairs); tracks with
:func:`recon_eval.metrics.flow.track_metrics` (pooled).
"""
from __future__ import annotations

import cv2
import numpy as np

from recon_eval.errors import NotApplicable
from recon_eval.metrics.flow import flow_metrics, track_metrics
from recon_eval.readers.flow import read_flow
from recon_eval.runners.common import RunOutput, out_path
from recon_eval.tasks.headlines import flow_headline
from scenegen.dataset.codecs import encode_flo
from scenegen.dataset.files import atomic_write_bytes
from scenegen.geometry.color import to_grey8


def pairs(ds) -> list:
    """The flow pairs a flow method runs on: a sequence's, else both directions of each cross-view pair."""
    pairs = list(ds.flow_pairs())  # a sequence's frame pairs, else the cross-view flow pairs
    if not pairs:
        pairs = [p for i, j in ds.require_crossview_index().pairs for p in ((i, j), (j, i))]
    if not pairs:
        raise NotApplicable(f"{ds.root}: no flow or crossview pairs (crossview/index.json: flow, pairs)")
    return pairs


def _dense(kind: str, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    if kind == "dis":
        return cv2.DISOpticalFlow_create(cv2.DISOPTICAL_FLOW_PRESET_MEDIUM).calc(a, b, None)
    return cv2.calcOpticalFlowFarneback(a, b, None, 0.5, 3, 15, 3, 5, 1.2, 0)


def dense(ds, out_dir, options) -> RunOutput:
    kind = options["algorithm"]
    est, gts, states, raw = [], [], [], []
    for i, j in pairs(ds):
        f = _dense(kind, to_grey8(ds.image(i)), to_grey8(ds.image(j)))
        rel = f"flow/{i}__{j}.flo"
        atomic_write_bytes(out_path(out_dir, rel), encode_flo(f))
        raw.append(rel)
        g, st, _ = ds.flow_truth(i, j)
        est.append(read_flow(out_path(out_dir, rel)))
        gts.append(g)
        states.append(st)
    r = flow_metrics(est, gts, states)
    return RunOutput({"flow": r}, flow_headline(r), raw, {"pairs": len(raw), "opencv_flow": kind})


def lk(ds, out_dir, options) -> RunOutput:
    raw, rows_all, results = [], [], {}
    starts, ends, status, gts, sts = [], [], [], [], []
    for i, j in pairs(ds):
        a, b = to_grey8(ds.image(i)), to_grey8(ds.image(j))
        c = cv2.goodFeaturesToTrack(a, maxCorners=500, qualityLevel=0.01, minDistance=7)
        p0 = np.rint(np.zeros((0, 2)) if c is None else c.reshape(-1, 2)).astype(np.float32)
        if len(p0):
            p1, st, _ = cv2.calcOpticalFlowPyrLK(a, b, p0.reshape(-1, 1, 2), None, winSize=(21, 21), maxLevel=3)
            p1, st = p1.reshape(-1, 2), st.reshape(-1)
        else:
            p1, st = np.zeros((0, 2), np.float32), np.zeros(0, np.uint8)
        rel = f"tracks/{i}__{j}.txt"
        rows = np.c_[p0.astype(np.float64), p1.astype(np.float64), st.astype(np.float64)]
        np.savetxt(out_path(out_dir, rel), rows, fmt="%.17g", header="u_i v_i u_j v_j status")
        raw.append(rel)
        back = np.loadtxt(out_path(out_dir, rel), ndmin=2).reshape(-1, 5)
        g, stt, _ = ds.flow_truth(i, j)
        results[f"{i}__{j}"] = track_metrics(back[:, :2], back[:, 2:4], back[:, 4] > 0, g, stt)
        rows_all.append(back)
    pooled = np.concatenate([r.epe_px for r in results.values()]) if results else np.zeros(0)
    fin = pooled[np.isfinite(pooled)]
    n = len(pooled)
    metrics = {"epe_median_px": float(np.median(fin)) if len(fin) else float("nan"),
               "within_1px": float(np.mean(pooled <= 1.0)) if n else float("nan"),
               "within_3px": float(np.mean(pooled <= 3.0)) if n else float("nan"),
               "lost_frac": float(np.mean(~np.isfinite(pooled))) if n else float("nan"), "n_tracks": n}
    return RunOutput({"tracks": results}, metrics, raw, {"pairs": len(raw)})

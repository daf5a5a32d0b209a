"""TAP-Vid point-tracking metrics (Doersch et al., NeurIPS 2022 Datasets and Benchmarks): occlusion
accuracy (OA), the fraction of visible points within 1, 2, 4, 8, 16 px (< delta^x_avg is their mean)
and the Jaccard at each threshold (AJ is their mean), for one video.

The definitions are the ones of the reference evaluator (``tapnet.evaluation_datasets.
compute_tapvid_metrics``):

* Evaluated frames per query: ``first`` mode, the frames after the query frame; ``strided``
  mode, every frame but the query frame (the query frame is ``round(t)``).
* A point is correct at threshold d when the truth says visible and ``|p - p*|^2 < d^2`` (strict).
* pts_within_d = correct / truth-visible; jaccard_d = true positives / (truth-visible + false
  positives), a true positive being correct and predicted visible, a false positive predicted
  visible where the truth is occluded or the point is not within d.
* OA = mean over evaluated frames of (predicted occluded == truth occluded).

Thresholds are in pixels of the image the metric is computed at. The TAP-Vid benchmark scales
every video to 256 x 256 first, so ``eval_size=(256, 256)`` (the default) scales x by 256 / W and
y by 256 / H before the distances, as its readers do; ``eval_size=None`` scores at the image's own
resolution. Scaling is about the image's top-left corner, so the pixel origin (OpenCV centres here,
TAP-Vid's corner raster) does not change a distance. Benchmark numbers are the plain mean over
videos of these per-video values (the paper prints them x 100).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.arrays import as_float_array
from recon_eval.errors import InputError

#: TAP-Vid's pixel thresholds (at 256 x 256).
TAPVID_THRESHOLDS_PX = (1, 2, 4, 8, 16)
#: The resolution (width, height) at which TAP-Vid's numbers are computed.
TAPVID_EVAL_SIZE = (256, 256)
QUERY_MODES = ("first", "strided")


@dataclass(frozen=True)
class TapVidResult:
    """One video's TAP-Vid metrics (fractions in [0, 1]; NaN where nothing was evaluated)."""

    average_jaccard: float  # AJ: mean of jaccard over the thresholds
    average_pts_within: float  # < delta^x_avg: mean of pts_within over the thresholds
    occlusion_accuracy: float  # OA
    jaccard: dict  # threshold (px) -> Jaccard
    pts_within: dict  # threshold (px) -> fraction of truth-visible points within it
    n_tracks: int
    n_evaluated: int  # (track, frame) pairs evaluated
    n_visible: int  # of them, visible in the truth
    query_mode: str
    eval_size: tuple | None  # (width, height) the distances were computed at; None = the image's own
    thresholds_px: tuple = TAPVID_THRESHOLDS_PX
    operator: str = ">="


def evaluation_mask(query_frames, n_frames: int, query_mode: str) -> np.ndarray:
    """(N, T) bool: the frames each query is scored on (``first``: after its frame; ``strided``:
    all but its frame). ``query_frames`` (N,) frame indices (rounded, as the reference does)."""
    if query_mode not in QUERY_MODES:
        raise InputError(f"query mode: expected one of {', '.join(QUERY_MODES)}, got {query_mode!r}")
    q = np.rint(np.asarray(query_frames, dtype=np.float64)).astype(np.int64).reshape(-1)
    if np.any((q < 0) | (q >= n_frames)):
        raise InputError(f"query frames must lie in [0, {n_frames - 1}], got {int(q.min())}..{int(q.max())}")
    t = np.arange(n_frames)[None, :]
    return t > q[:, None] if query_mode == "first" else t != q[:, None]


def _bool(a, name: str, shape: tuple) -> np.ndarray:
    arr = np.asarray(a)
    if arr.shape != shape:
        raise InputError(f"{name}: expected shape {shape}, got {arr.shape}")
    if arr.dtype != bool and not np.all(np.isin(arr, (0, 1))):
        raise InputError(f"{name}: expected booleans (or 0/1)")
    return arr.astype(bool)


def tapvid_metrics(query_points_tyx, gt_tracks_xy, gt_occluded, pred_tracks_xy, pred_occluded, *,
                   image_size: tuple, query_mode: str = "first",
                   eval_size: tuple | None = TAPVID_EVAL_SIZE,
                   thresholds_px: tuple = TAPVID_THRESHOLDS_PX) -> TapVidResult:
    """TAP-Vid metrics of one video of T frames with N query tracks.

    ``query_points_tyx`` (N, 3) [frame, y, x]; ``gt_tracks_xy``/``pred_tracks_xy`` (N, T, 2) pixels
    [x, y]; ``gt_occluded``/``pred_occluded`` (N, T) bool (True = occluded or out of frame);
    ``image_size`` (width, height) of the frames the tracks are in. A predicted position that is
    not finite counts as not within any threshold."""
    q = as_float_array(query_points_tyx, "query points", (None, 3))
    n = len(q)
    gt = as_float_array(gt_tracks_xy, "truth tracks", (n, None, 2))
    t = gt.shape[1]
    pred = np.asarray(pred_tracks_xy, dtype=np.float64)
    if pred.shape != (n, t, 2):
        raise InputError(f"predicted tracks: expected shape {(n, t, 2)}, got {pred.shape}")
    gt_occ = _bool(gt_occluded, "truth occlusion", (n, t))
    pred_occ = _bool(pred_occluded, "predicted occlusion", (n, t))
    w, h = (float(x) for x in image_size)
    if not (w > 0 and h > 0):
        raise InputError(f"image size: expected positive (width, height), got {image_size}")
    if np.any(~np.isfinite(gt[~gt_occ])):
        raise InputError("truth tracks: a visible truth point is not finite")
    scale = np.array([1.0, 1.0]) if eval_size is None else np.array([eval_size[0] / w, eval_size[1] / h])
    ev = evaluation_mask(q[:, 0], t, query_mode)
    visible, pred_vis = ~gt_occ, ~pred_occ
    d2 = np.sum(np.square((pred - np.where(gt_occ[..., None], 0.0, gt)) * scale), axis=-1)
    d2 = np.where(np.isfinite(d2), d2, np.inf)
    n_ev, n_vis = int(np.sum(ev)), int(np.sum(visible & ev))

    def ratio(a: int, b: int) -> float:
        return a / b if b else float("nan")

    jac, within = {}, {}
    for d in thresholds_px:
        close = d2 < float(d) ** 2
        correct = close & visible & ev
        tp = int(np.sum(correct & pred_vis))
        fp = int(np.sum(pred_vis & (gt_occ | ~close) & ev))
        within[d] = ratio(int(np.sum(correct)), n_vis)
        jac[d] = ratio(tp, n_vis + fp)
    oa = ratio(int(np.sum((pred_occ == gt_occ) & ev)), n_ev)
    return TapVidResult(
        float(np.mean(list(jac.values()))), float(np.mean(list(within.values()))), oa, jac, within,
        n, n_ev, n_vis, query_mode, None if eval_size is None else tuple(eval_size), tuple(thresholds_px),
    )


def mean_over_videos(results: list[TapVidResult]) -> dict:
    """The benchmark's numbers: the plain mean over videos of AJ, < delta^x_avg and OA (NaN videos
    skipped, counted)."""
    out = {}
    for key in ("average_jaccard", "average_pts_within", "occlusion_accuracy"):
        vals = np.array([getattr(r, key) for r in results], dtype=np.float64)
        ok = np.isfinite(vals)
        out[key] = float(np.mean(vals[ok])) if ok.any() else float("nan")
    out["n_videos"] = len(results)
    out["n_videos_without_points"] = int(sum(not np.isfinite(r.average_jaccard) for r in results))
    return out

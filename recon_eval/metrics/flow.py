"""Optical-flow metrics: end-point error (all, non-occluded, occluded pixels), KITTI 2015 Fl
(bg / fg / all, the devkit's "est" rows), MPI-Sintel's speed bins s0-10 / s10-40 / s40+, and
sparse point tracks.

Flows are (H, W, 2) float arrays in pixels, (u right, v down), from the pixel of the first image
to its position in the second; NaN = unknown / missing (readers convert each format's marker).
The truth's occlusion state per pixel is the dataset's (``scenegen.dataset.crossview``: VISIBLE is
non-occluded; OCCLUDED and OUT_OF_FRAME are occluded). Missing estimates are filled by the KITTI
devkit's background interpolation (``io_flow.h`` ``FlowImage::interpolateBackground``: interior
row gaps take the component-wise smaller neighbour, row ends the nearest valid value, then
column ends; what nothing fills stays at the devkit's (0, 0)) and still scored, with the density
reported: a hole is never dropped silently.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from recon_eval.arrays import as_float_array, frozen
from recon_eval.errors import InputError
from recon_eval.metrics.stereo import kitti_interpolate_background
from scenegen.dataset.crossview import VISIBLE

#: MPI-Sintel's speed bins (Butler et al., ECCV 2012): EPE over pixels whose truth speed |f| is
#: below 10, between 10 and 40, above 40 px/frame; bins taken as [0, 10), [10, 40), [40, inf).
SINTEL_BINS = ((0.0, 10.0), (10.0, 40.0), (40.0, np.inf))


def _flow(f, name: str) -> np.ndarray:
    return as_float_array(f, name, (None, None, 2))


def kitti_interpolate_flow(flow) -> np.ndarray:
    """The devkit's ``FlowImage::interpolateBackground`` of an (H, W, 2) flow with NaN = invalid:
    the disparity rule per component (validity shared: a pixel is valid when both components are)
    with the devkit's (0, 0) where nothing fills. Returns a new array."""
    f = np.array(_flow(flow, "flow"), copy=True)
    bad = ~np.all(np.isfinite(f), axis=2)
    f[bad] = np.nan
    out = np.stack([kitti_interpolate_background(f[..., 0]), kitti_interpolate_background(f[..., 1])], axis=2)
    out[~np.all(np.isfinite(out), axis=2)] = 0.0
    return out


def kitti_flow_outliers(flow_ipol, flow_gt, abs_thresh_px: float = 3.0, rel_thresh: float = 0.05) -> np.ndarray:
    """(H, W) bool ``f_err`` of the devkit's ``flowErrorsOutlier`` (evaluate_scene_flow.cpp) in its
    float arithmetic: ``f_dist = sqrt(fu*fu + fv*fv)`` of the float differences, ``f_mag`` the
    truth's (``getFlowMagnitude``), both float32, and the float quotient ``f_dist / f_mag``,
    compared with the double constants 3.0 and 0.05. Ties are common on the KITTI PNG's 1/64 px
    grid, and decided there: 5 / 100 in float is 0.0500000007 > 0.05, an outlier (not in float64)."""
    e, g = np.asarray(flow_ipol, np.float32), np.asarray(flow_gt, np.float32)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        fu, fv = g[..., 0] - e[..., 0], g[..., 1] - e[..., 1]
        f_dist = np.sqrt(fu * fu + fv * fv)
        f_mag = np.sqrt(g[..., 0] * g[..., 0] + g[..., 1] * g[..., 1])
        return (f_dist.astype(np.float64) > abs_thresh_px) & ((f_dist / f_mag).astype(np.float64) > rel_thresh)


@dataclass(frozen=True)
class FlowResult:
    """Flow errors, pooled over the image pairs (pixels counted over all pairs)."""

    epe_all_px: float  # mean |f - f*| over truth pixels
    epe_noc_px: float  # over non-occluded truth pixels (VISIBLE); NaN without occlusion truth or pixels
    epe_occ_px: float  # over occluded / out-of-frame truth pixels
    fl_bg_all_pct: float  # KITTI Fl: % outliers (EPE > 3 px and EPE / |f*| > 5 %), background, all pixels
    fl_fg_all_pct: float
    fl_all_all_pct: float
    fl_bg_noc_pct: float  # ... non-occluded pixels
    fl_fg_noc_pct: float
    fl_all_noc_pct: float
    fl_all_all_est_pct: float  # the devkit's est rows: pixels with an estimate before interpolation
    fl_all_noc_est_pct: float
    s0_10_px: float  # Sintel: EPE over truth pixels with |f*| in [0, 10)
    s10_40_px: float  # [10, 40)
    s40_plus_px: float  # [40, inf)
    density_pct: float  # truth pixels with a valid estimate before interpolation
    n_px: int  # truth pixels
    n_px_noc: int
    n_px_occ: int
    n_pairs: int
    occlusion_truth: bool  # states were given for every pair
    abs_thresh_px: float = 3.0
    rel_thresh: float = 0.05
    aggregation: str = "pooled over pixels of all pairs"
    interpolation: str = "kitti_background"


def flow_metrics(flow_est: Sequence, flow_gt: Sequence, states: Sequence | None = None,
                 fg_masks: Sequence | None = None, *, abs_thresh_px: float = 3.0, rel_thresh: float = 0.05) -> FlowResult:
    """EPE, KITTI Fl and Sintel bins of estimated flows against truth flows (sequences of (H, W, 2)
    arrays, px). ``states``: per pair (H, W) correspondence states (VISIBLE = non-occluded) or
    None for a pair without occlusion truth; ``fg_masks``: per pair (H, W) bool foreground (KITTI's
    object map; default background). KITTI's Fl is the devkit's ``flowErrorsOutlier``
    (evaluate_scene_flow.cpp): ``f_err > 3 && f_err / |f*| > 0.05`` on the interpolated estimate,
    in the devkit's float arithmetic (:func:`kitti_flow_outliers`), counts pooled over pairs; EPE
    (float64) is computed on the same interpolated estimate."""
    n = len(flow_est)
    if n == 0 or len(flow_gt) != n:
        raise InputError(f"flow: need as many truth flows as estimates (>0), got {n} and {len(flow_gt)}")
    acc = {k: 0.0 for k in ("e_all", "e_noc", "e_occ")}
    cnt = {k: 0 for k in ("all", "noc", "occ", "est", "noc_est")}
    out = {k: 0 for k in ("bg_all", "fg_all", "bg_noc", "fg_noc", "all_est", "noc_est")}
    tot = dict(out)
    bins = [[0.0, 0] for _ in SINTEL_BINS]
    have_states = states is not None and all(s is not None for s in states)
    for k in range(n):
        e, g = _flow(flow_est[k], f"estimated flow #{k}"), _flow(flow_gt[k], f"truth flow #{k}")
        if e.shape != g.shape:
            raise InputError(f"flow #{k}: estimate {e.shape} and truth {g.shape} differ in shape")
        valid_gt = np.all(np.isfinite(g), axis=2)
        est_valid = np.all(np.isfinite(e), axis=2)
        ei = kitti_interpolate_flow(e)
        err = np.linalg.norm(ei - np.where(valid_gt[..., None], g, 0.0), axis=2)
        mag = np.linalg.norm(np.where(valid_gt[..., None], g, 0.0), axis=2)
        outlier = kitti_flow_outliers(ei, np.where(valid_gt[..., None], g, 0.0), abs_thresh_px, rel_thresh)
        st = None if states is None or states[k] is None else np.asarray(states[k])
        if st is not None and st.shape != g.shape[:2]:
            raise InputError(f"states #{k}: expected shape {g.shape[:2]}, got {st.shape}")
        noc = valid_gt & (st == VISIBLE) if st is not None else np.zeros_like(valid_gt)
        occ = valid_gt & ~noc if st is not None else np.zeros_like(valid_gt)
        fg = np.zeros_like(valid_gt) if fg_masks is None else np.asarray(fg_masks[k], bool)
        acc["e_all"] += float(err[valid_gt].sum())
        acc["e_noc"] += float(err[noc].sum())
        acc["e_occ"] += float(err[occ].sum())
        cnt["all"] += int(valid_gt.sum())
        cnt["noc"] += int(noc.sum())
        cnt["occ"] += int(occ.sum())
        cnt["est"] += int((valid_gt & est_valid).sum())
        for name, region in (("all", valid_gt), ("noc", noc)):
            for side, m in (("bg", ~fg), ("fg", fg)):
                out[f"{side}_{name}"] += int((outlier & region & m).sum())
                tot[f"{side}_{name}"] += int((region & m).sum())
            out[f"{name}_est"] += int((outlier & region & est_valid).sum())
            tot[f"{name}_est"] += int((region & est_valid).sum())
        for b, (lo, hi) in enumerate(SINTEL_BINS):
            sel = valid_gt & (mag >= lo) & (mag < hi)
            bins[b][0] += float(err[sel].sum())
            bins[b][1] += int(sel.sum())

    def mean(s, c):
        return s / c if c else float("nan")

    def pct(a, b):
        return 100.0 * a / b if b else float("nan")

    noc_nan = not have_states
    return FlowResult(
        mean(acc["e_all"], cnt["all"]), float("nan") if noc_nan else mean(acc["e_noc"], cnt["noc"]),
        float("nan") if noc_nan else mean(acc["e_occ"], cnt["occ"]),
        pct(out["bg_all"], tot["bg_all"]), pct(out["fg_all"], tot["fg_all"]),
        pct(out["bg_all"] + out["fg_all"], tot["bg_all"] + tot["fg_all"]),
        float("nan") if noc_nan else pct(out["bg_noc"], tot["bg_noc"]),
        float("nan") if noc_nan else pct(out["fg_noc"], tot["fg_noc"]),
        float("nan") if noc_nan else pct(out["bg_noc"] + out["fg_noc"], tot["bg_noc"] + tot["fg_noc"]),
        pct(out["all_est"], tot["all_est"]), float("nan") if noc_nan else pct(out["noc_est"], tot["noc_est"]),
        *(mean(s, c) for s, c in bins), pct(cnt["est"], cnt["all"]), cnt["all"], cnt["noc"], cnt["occ"], n,
        have_states, abs_thresh_px, rel_thresh,
    )


@dataclass(frozen=True)
class TrackResult:
    """Sparse point tracks (e.g. pyramidal Lucas-Kanade) against the truth flow at their start."""

    epe_px: np.ndarray  # (N,) |x_j - (x_i + f*(x_i))| per track, inf where the tracker lost it
    epe_mean_px: float  # over tracked points with truth
    epe_median_px: float
    within_1px: float  # fraction of the points with truth whose track ends within 1 px (failures count)
    within_3px: float
    within_5px: float
    n_points: int  # points with truth
    n_lost: int  # points with truth that the tracker lost (status 0 or non-finite)
    n_no_truth: int  # points whose start has no truth flow (ignored, counted)
    n_occluded: int  # points with truth whose start pixel is occluded / out of frame in the second image
    operator: str = "<="


def track_metrics(points_i, points_j_est, status, flow_gt, states=None) -> TrackResult:
    """Tracks from integer pixel centres ``points_i`` (N, 2) OpenCV px of image i to
    ``points_j_est`` (N, 2) in image j; ``status`` (N,) truthy where the tracker kept the point.
    Truth: ``points_i + flow_gt[v, u]``; points without truth flow are ignored (counted), lost
    ones are failures (inf). ``states``: (H, W) correspondence states, for the occluded count."""
    pi = as_float_array(points_i, "track start points", (None, 2))
    pj = as_float_array(points_j_est, "track end points", (len(pi), 2))
    ok = np.asarray(status).reshape(-1).astype(bool)
    if ok.shape != (len(pi),):
        raise InputError(f"track status: expected shape ({len(pi)},), got {ok.shape}")
    g = _flow(flow_gt, "truth flow")
    u, v = np.rint(pi[:, 0]).astype(np.int64), np.rint(pi[:, 1]).astype(np.int64)
    if np.any(np.abs(pi - np.stack([u, v], 1)) > 0) or np.any((u < 0) | (v < 0) | (u >= g.shape[1]) | (v >= g.shape[0])):
        raise InputError("track start points must be pixel centres (integers) inside the image")
    truth = g[v, u]
    has = np.all(np.isfinite(truth), axis=1)
    e = np.linalg.norm(pj - (pi + np.where(has[:, None], truth, 0.0)), axis=1)
    e = np.where(ok & np.isfinite(e), e, np.inf)[has]
    fin = e[np.isfinite(e)]
    n_occ = 0 if states is None else int(np.sum(np.asarray(states)[v, u][has] != VISIBLE))
    nan = float("nan")
    n = len(e)
    return TrackResult(
        frozen(e), float(np.mean(fin)) if len(fin) else nan, float(np.median(fin)) if len(fin) else nan,
        float(np.mean(e <= 1.0)) if n else nan, float(np.mean(e <= 3.0)) if n else nan,
        float(np.mean(e <= 5.0)) if n else nan, n, int(np.sum(~np.isfinite(e))), int(np.sum(~has)), n_occ,
    )

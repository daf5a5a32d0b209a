"""Depth metrics against transcriptions of the reference code (none of it installs from PyPI):

* monodepth2 (nianticlabs/monodepth2, ``evaluate_depth.py``): ``compute_errors`` and the
  evaluation loop's mask, Garg crop, median scaling and MIN_DEPTH / MAX_DEPTH clamp;
* KITTI depth devkit (``devkit/cpp/evaluate_depth.cpp``, ``depthError``): scale-invariant log
  error (errors[6]) and inverse RMSE (errors[3]); the leaderboard shows them x100 and in 1/km;
* BTS (cleinc/bts, ``bts_eval.py``): ``compute_errors`` log10, the Eigen crop;
* MiDaS (isl-org/MiDaS, and DPT's evaluation): ``compute_scale_and_shift`` and ``BadPixelMetric``.
"""
from __future__ import annotations

import numpy as np
import pytest

from recon_eval.metrics.depth import eigen_depth_metrics

MIN_DEPTH, MAX_DEPTH = 1e-3, 80.0


def _images(n=3, seed=0):
    """KITTI-like truth (sparse, 2..90 m) and predictions off by a scale with 5 % far outliers."""
    rng = np.random.default_rng(seed)
    gts, preds = [], []
    for _ in range(n):
        g = rng.uniform(2.0, 90.0, (60, 200))
        g[rng.random(g.shape) < 0.6] = 0.0  # no lidar return
        p = 0.37 * g * rng.lognormal(0.0, 0.15, g.shape) + rng.uniform(0.5, 3.0, g.shape)
        p[rng.random(g.shape) < 0.05] = 150.0 * 0.37
        gts.append(g)
        preds.append(p)
    return preds, gts


def _monodepth2(pred_depth, gt_depth, crop: bool):
    """monodepth2 evaluate_depth.py, the loop body after 'gt_height, gt_width = gt_depth.shape[:2]'
    (median scaling on, disable_median_scaling off), and compute_errors; averaged with mean(0)."""
    errors = []
    for pred, gt in zip(pred_depth, gt_depth):
        gt_height, gt_width = gt.shape[:2]
        mask = np.logical_and(gt > MIN_DEPTH, gt < MAX_DEPTH)
        if crop:
            c = np.array([0.40810811 * gt_height, 0.99189189 * gt_height,
                          0.03594771 * gt_width, 0.96405229 * gt_width]).astype(np.int32)
            crop_mask = np.zeros(mask.shape)
            crop_mask[c[0]:c[1], c[2]:c[3]] = 1
            mask = np.logical_and(mask, crop_mask)
        p, g = pred[mask], gt[mask]
        ratio = np.median(g) / np.median(p)
        p = p * ratio
        p[p < MIN_DEPTH] = MIN_DEPTH
        p[p > MAX_DEPTH] = MAX_DEPTH
        thresh = np.maximum((g / p), (p / g))
        a1, a2, a3 = (thresh < 1.25).mean(), (thresh < 1.25 ** 2).mean(), (thresh < 1.25 ** 3).mean()
        rmse = np.sqrt(((g - p) ** 2).mean())
        rmse_log = np.sqrt(((np.log(g) - np.log(p)) ** 2).mean())
        abs_rel = np.mean(np.abs(g - p) / g)
        sq_rel = np.mean(((g - p) ** 2) / g)
        errors.append((abs_rel, sq_rel, rmse, rmse_log, a1, a2, a3))
    return np.array(errors).mean(0)


@pytest.mark.parametrize("crop", [False, True])
def test_eigen_metrics_equal_monodepth2(crop, agreement):
    preds, gts = _images()
    ref = _monodepth2(preds, gts, crop)
    r = eigen_depth_metrics(preds, gts, alignment="median", min_depth_m=MIN_DEPTH, max_depth_m=MAX_DEPTH,
                            crop="garg" if crop else None)
    ours = np.array([r.abs_rel, r.sq_rel_m, r.rmse_m, r.rmse_log, r.a1, r.a2, r.a3])
    d = float(np.max(np.abs(ours - ref) / np.maximum(np.abs(ref), 1e-300)))
    assert d < 1e-12
    # without the clamp the 150 m outliers dominate abs_rel (the 0.646 vs 0.255 kind of gap)
    unclamped = eigen_depth_metrics(preds, gts, alignment="median", min_depth_m=MIN_DEPTH, max_depth_m=MAX_DEPTH,
                                    clamp=False, crop="garg" if crop else None)
    assert unclamped.abs_rel > 1.2 * r.abs_rel
    agreement(f"depth.eigen{'.garg' if crop else ''}",
              f"abs_rel, sq_rel, rmse, rmse_log, a1..a3 (relative), median scaling, clamp [1e-3, 80]"
              f"{', Garg crop' if crop else ''}", "monodepth2 `evaluate_depth.py` (transcribed)", "nianticlabs master",
              "3 sparse 200x60 maps, 5 % predictions at 150 m", d)


def _kitti_devkit(D_gt, D_ipol):
    """KITTI depth devkit evaluate_depth.cpp depthError, errors[3] (inverse rmse) and errors[6]
    (scale invariant log) for one image; valid truth = depth > 0."""
    num_pixels, logSum, e3, e5 = 0, 0.0, 0.0, 0.0
    valid = D_gt > 0
    g, p = D_gt[valid], D_ipol[valid]
    d_err_inv = np.abs(1.0 / g - 1.0 / p)
    e3 = np.sum(d_err_inv * d_err_inv)
    d_err_log = np.abs(np.log(g) - np.log(p))
    e5 = np.sum(d_err_log * d_err_log)
    logSum = np.sum(np.log(g) - np.log(p))
    num_pixels = len(g)
    inv_rmse = np.sqrt(e3 / num_pixels)
    normalizedSquaredLog = e5 / num_pixels
    silog = np.sqrt(normalizedSquaredLog - (logSum * logSum / (num_pixels * num_pixels)))
    return silog, inv_rmse


def _bts_log10(pred, gt):
    """BTS bts_eval.py compute_errors: log10 = np.mean(np.abs(np.log10(gt) - np.log10(pred)))."""
    return np.mean(np.abs(np.log10(gt) - np.log10(pred)))


def test_silog_irmse_equal_kitti_devkit_and_log10_bts(agreement):
    preds, gts = _images(seed=1)
    dense = [np.clip(p, 1.0, 80.0) for p in preds]  # the devkit scores a dense (interpolated) prediction
    r = eigen_depth_metrics(dense, gts)
    ref = np.array([_kitti_devkit(g, p) for p, g in zip(dense, gts)]).mean(0)  # statMean over images
    ref_log10 = np.mean([_bts_log10(p[g > 0], g[g > 0]) for p, g in zip(dense, gts)])
    d = max(abs(r.silog_x100 / 100 - ref[0]) / ref[0], abs(r.irmse_per_km / 1000 - ref[1]) / ref[1],
            abs(r.log10 - ref_log10) / ref_log10)
    assert d < 1e-12
    agreement("depth.silog_irmse_log10", "SILog, iRMSE (KITTI depth devkit), log10 (BTS), relative",
              "KITTI depth devkit `depthError`; BTS `compute_errors` (transcribed)", "devkit 2017; cleinc master",
              "3 sparse 200x60 maps", d)


def test_eigen_crop_equals_bts(agreement):
    """BTS bts_eval.py: eval_mask[int(0.3324324 * gt_height):int(0.91351351 * gt_height),
    int(0.0359477 * gt_width):int(0.96405229 * gt_width)] = 1 (KITTI eigen_crop)."""
    preds, gts = _images(seed=2)
    vals = []
    for p, g in zip(preds, gts):
        h, w = g.shape
        m = np.zeros(g.shape, bool)
        m[int(0.3324324 * h):int(0.91351351 * h), int(0.0359477 * w):int(0.96405229 * w)] = True
        m &= (g > MIN_DEPTH) & (g < MAX_DEPTH)
        pp = np.clip(p, MIN_DEPTH, MAX_DEPTH)[m]
        vals.append(np.mean(np.abs(g[m] - pp) / g[m]))
    r = eigen_depth_metrics(preds, gts, min_depth_m=MIN_DEPTH, max_depth_m=MAX_DEPTH, crop="eigen")
    d = abs(r.abs_rel - np.mean(vals)) / np.mean(vals)
    assert d < 1e-12
    agreement("depth.eigen_crop", "abs_rel in the Eigen crop (relative)", "BTS `bts_eval.py` (transcribed)",
              "cleinc master", "3 sparse 200x60 maps", d)


def _midas(prediction, target, mask, depth_cap):
    """MiDaS compute_scale_and_shift + BadPixelMetric.__call__ (threshold 1.25), one image, numpy."""
    target_disparity = np.zeros_like(target)
    target_disparity[mask] = 1.0 / target[mask]
    a_00 = np.sum(mask * prediction * prediction)
    a_01 = np.sum(mask * prediction)
    a_11 = np.sum(mask)
    b_0 = np.sum(mask * prediction * target_disparity)
    b_1 = np.sum(mask * target_disparity)
    det = a_00 * a_11 - a_01 * a_01
    scale = (a_11 * b_0 - a_01 * b_1) / det
    shift = (-a_01 * b_0 + a_00 * b_1) / det
    prediction_aligned = scale * prediction + shift
    disparity_cap = 1.0 / depth_cap
    prediction_aligned[prediction_aligned < disparity_cap] = disparity_cap
    prediciton_depth = 1.0 / prediction_aligned
    err = np.maximum(prediciton_depth[mask] / target[mask], target[mask] / prediciton_depth[mask])
    return scale, shift, 100.0 * np.mean(err > 1.25)


def test_inverse_depth_scale_shift_equals_midas(agreement):
    rng = np.random.default_rng(4)
    g = rng.uniform(0.5, 9.0, (48, 64))
    g[rng.random(g.shape) < 0.2] = 0.0
    mask = g > 0
    inv = np.where(mask, 1.0 / np.where(mask, g, 1.0), 0.3)
    pred = 3.0 * inv + 0.8 + rng.normal(0.0, 0.05, g.shape)  # relative inverse depth, MiDaS-like
    s, b, bad = _midas(pred, g, mask, depth_cap=10.0)
    r = eigen_depth_metrics([pred], [g], alignment="scale_shift_inverse", max_depth_m=10.0, pred_is_inverse=True)
    d = max(abs(r.per_image_scale[0] - s) / abs(s), abs(r.per_image_shift_inv_m[0] - b) / abs(b),
            abs(100.0 * (1.0 - r.a1) - bad) / 100.0)
    assert d < 1e-12
    agreement("depth.midas", "scale, shift in inverse depth and delta > 1.25 % (relative)",
              "MiDaS `compute_scale_and_shift`, `BadPixelMetric` (transcribed)", "isl-org master",
              "one 64x48 map, depth cap 10 m", d)

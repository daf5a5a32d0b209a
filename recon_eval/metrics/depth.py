"""Depth-map metrics: Eigen et al. (NIPS 2014) as monodepth2 computes them, the KITTI depth
benchmark's SILog and iRMSE, log10; declared alignment (median, least-squares scale and shift in
depth, or in inverse depth as MiDaS / DPT), the Garg and Eigen crops; averaged per image.

Definitions: shared/notes/metrics.md, "Depth maps". Depths are (H, W) float arrays in metres
(z-depth). Truth pixels that are not finite or <= 0 (or outside (min_depth_m, max_depth_m), or
outside the crop) are unknown and skipped. After alignment the predictions are clamped to
[min_depth_m, max_depth_m] (monodepth2 ``evaluate_depth.py``: ``pred_depth[pred_depth < MIN_DEPTH]
= MIN_DEPTH``, likewise for MAX_DEPTH; ``clamp=False`` keeps them as they are). Predictions that are
then not finite or <= 0 are missing: excluded from the error terms and counted in ``coverage``
(never dropped silently).
"""
from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
from typing import Sequence

import numpy as np

from recon_eval.arrays import as_float_array, frozen
from recon_eval.errors import InputError


class DepthAlignment(str, Enum):
    NONE = "none"
    MEDIAN = "median"  # per image: p *= median(g) / median(p)
    SCALE_SHIFT = "scale_shift"  # per image: least squares min sum (s p + b - g)^2, in depth space
    # per image, MiDaS / DPT: least squares min sum (s q + b - 1/g)^2 with q the prediction in
    # inverse depth; depth = 1 / max(s q + b, 1 / max_depth)
    SCALE_SHIFT_INVERSE = "scale_shift_inverse"


#: Evaluation crops as fractions of (height, width): rows [top, bottom), columns [left, right),
#: each bound ``int(fraction * size)``. ``garg``: Garg et al. (ECCV 2016), the crop monodepth2
#: applies on the Eigen split (``evaluate_depth.py``: 0.40810811 .. 0.99189189 of the height,
#: 0.03594771 .. 0.96405229 of the width); ``eigen``: Eigen et al.'s KITTI crop as BTS implements
#: it (``bts_eval.py``: 0.3324324 .. 0.91351351, 0.0359477 .. 0.96405229).
CROPS = {"garg": (0.40810811, 0.99189189, 0.03594771, 0.96405229),
         "eigen": (0.3324324, 0.91351351, 0.0359477, 0.96405229)}


def crop_mask(shape, crop: str | None) -> np.ndarray:
    """(H, W) bool: the pixels inside the named crop (all pixels for None)."""
    H, W = shape
    m = np.zeros((H, W), bool)
    if crop is None:
        m[:] = True
        return m
    if crop not in CROPS:
        raise InputError(f"depth crop must be one of {', '.join(CROPS)} or none, got {crop!r}")
    t, b, l, r = CROPS[crop]
    m[int(t * H):int(b * H), int(l * W):int(r * W)] = True
    return m


@dataclass(frozen=True)
class DepthResult:
    """Eigen metrics, each the mean over images of the per-image value (per-image arrays kept)."""

    abs_rel: float  # mean |g - p| / g
    sq_rel_m: float  # mean (g - p)^2 / g  (metres)
    rmse_m: float  # sqrt(mean (g - p)^2)
    rmse_log: float  # sqrt(mean (ln g - ln p)^2)
    a1: float  # fraction with max(g/p, p/g) < 1.25
    a2: float  # ... < 1.25^2
    a3: float  # ... < 1.25^3
    coverage: float  # mean over images of (valid predictions / truth pixels)
    per_image_abs_rel: np.ndarray  # (n_images,), NaN for an image with no valid pixel
    per_image_rmse_m: np.ndarray
    per_image_scale: np.ndarray  # scale applied to each prediction (1 for none)
    per_image_shift_m: np.ndarray  # shift applied in depth (0 unless scale_shift)
    n_images: int
    n_images_failed: int  # images with no valid pixel: excluded from the means, counted here
    alignment: str
    aggregation: str = "mean of per-image values"
    operator: str = "<"
    silog_x100: float = float("nan")  # KITTI depth: 100 sqrt(mean d^2 - (mean d)^2), d = ln g - ln p
    irmse_per_km: float = float("nan")  # KITTI depth: sqrt(mean (1/g - 1/p)^2), 1/km
    log10: float = float("nan")  # mean |log10 g - log10 p|
    per_image_shift_inv_m: np.ndarray | None = None  # shift in inverse depth (1/m; scale_shift_inverse)
    clamp: bool = True  # predictions clamped to [min_depth_m, max_depth_m] after alignment (monodepth2)
    crop: str | None = None
    min_depth_m: float = 0.0
    max_depth_m: float = float("inf")


def _midas_scale_shift(q: np.ndarray, target: np.ndarray) -> tuple[float, float]:
    """MiDaS ``compute_scale_and_shift`` (isl-org/MiDaS, and DPT's evaluation): the 2x2 normal
    equations of min sum (s q + b - target)^2; (0, 0) when the determinant is not > 0."""
    a00, a01, a11 = np.sum(q * q), np.sum(q), float(len(q))
    b0, b1 = np.sum(q * target), np.sum(target)
    det = a00 * a11 - a01 * a01
    if not det > 0:
        return 0.0, 0.0
    return float((a11 * b0 - a01 * b1) / det), float((-a01 * b0 + a00 * b1) / det)


def _aligned(p: np.ndarray, g: np.ndarray, vg: np.ndarray, alignment: DepthAlignment, max_depth_m: float,
             pred_is_inverse: bool):
    """(aligned depth (H, W), scale, depth shift, inverse-depth shift), or None if nothing to fit."""
    if alignment == DepthAlignment.SCALE_SHIFT_INVERSE:
        with np.errstate(divide="ignore", invalid="ignore"):
            q = p if pred_is_inverse else np.where(p > 0, 1.0 / p, np.nan)
        vq = vg & np.isfinite(q)
        if vq.sum() == 0:
            return None
        s, b = _midas_scale_shift(q[vq], 1.0 / g[vq])
        a = s * q + b
        cap = 1.0 / max_depth_m  # MiDaS: prediction_aligned[prediction_aligned < disparity_cap] = cap
        a = np.where(a < cap, cap, a)
        with np.errstate(divide="ignore"):
            return 1.0 / a, s, 0.0, b
    if pred_is_inverse:
        raise InputError("an inverse-depth prediction needs alignment scale_shift_inverse")
    vp = vg & np.isfinite(p) & (p > 0)
    if vp.sum() == 0:
        return None
    if alignment == DepthAlignment.NONE:
        return p, 1.0, 0.0, 0.0
    if alignment == DepthAlignment.MEDIAN:
        s = float(np.median(g[vp]) / np.median(p[vp]))
        return s * p, s, 0.0, 0.0
    A = np.stack([p[vp], np.ones(int(vp.sum()))], axis=1)
    (s, b), *_ = np.linalg.lstsq(A, g[vp], rcond=None)
    return s * p + b, float(s), float(b), 0.0


def eigen_depth_metrics(
    depth_pred: Sequence,
    depth_gt: Sequence,
    *,
    alignment: DepthAlignment = DepthAlignment.NONE,
    min_depth_m: float = 0.0,
    max_depth_m: float = np.inf,
    clamp: bool = True,
    crop: str | None = None,
    pred_is_inverse: bool = False,
) -> DepthResult:
    """Eigen et al. depth metrics as monodepth2 ``compute_errors`` (abs_rel, sq_rel, rmse,
    rmse_log (natural log), a1..a3 with strict ``<``), BTS's log10, the KITTI depth devkit's
    scale-invariant log error (``evaluate_depth.cpp`` ``depthError``: errors[6], x100 as the
    leaderboard) and inverse RMSE (errors[3], in 1/km), per image then averaged over images.

    Truth used where ``min_depth_m < g < max_depth_m`` (both strict, monodepth2's ``gt > MIN_DEPTH
    & gt < MAX_DEPTH``) inside ``crop`` (:data:`CROPS`). Per-image alignment as declared; then the
    predictions are clamped to [min_depth_m, max_depth_m] unless ``clamp=False``.
    ``pred_is_inverse``: the prediction is inverse depth up to scale and shift (a MiDaS / DPT
    output), for ``scale_shift_inverse``. depth_pred, depth_gt: sequences of (H, W) arrays, metres."""
    alignment = DepthAlignment(alignment)
    n = len(depth_pred)
    if n == 0 or len(depth_gt) != n:
        raise InputError(f"depth: need as many truth maps as predictions (>0), got {n} and {len(depth_gt)}")
    keys = ("abs_rel", "sq_rel", "rmse", "rmse_log", "a1", "a2", "a3", "silog", "irmse", "log10", "coverage",
            "scale", "shift", "shift_inv")
    per = {k: np.full(n, np.nan) for k in keys}
    for k in range(n):
        p = as_float_array(depth_pred[k], f"predicted depth #{k}", (None, None))
        g = as_float_array(depth_gt[k], f"GT depth #{k}", (None, None))
        if p.shape != g.shape:
            raise InputError(f"depth #{k}: prediction {p.shape} and truth {g.shape} differ in shape")
        with np.errstate(invalid="ignore"):
            vg = np.isfinite(g) & (g > min_depth_m) & (g < max_depth_m) & (g > 0) & crop_mask(g.shape, crop)
        fit = _aligned(p, g, vg, alignment, max_depth_m, pred_is_inverse) if vg.any() else None
        if fit is None:
            per["coverage"][k] = 0.0
            continue
        pa, per["scale"][k], per["shift"][k], per["shift_inv"][k] = fit
        if clamp:
            with np.errstate(invalid="ignore"):
                pa = np.where(pa < min_depth_m, min_depth_m, np.where(pa > max_depth_m, max_depth_m, pa))
        with np.errstate(invalid="ignore"):
            ok = vg & np.isfinite(pa) & (pa > 0)
        per["coverage"][k] = ok.sum() / vg.sum()
        if ok.sum() == 0:
            continue
        gg, pp = g[ok], pa[ok]
        thresh = np.maximum(gg / pp, pp / gg)
        d = np.log(gg) - np.log(pp)
        per["abs_rel"][k] = np.mean(np.abs(gg - pp) / gg)
        per["sq_rel"][k] = np.mean((gg - pp) ** 2 / gg)
        per["rmse"][k] = np.sqrt(np.mean((gg - pp) ** 2))
        per["rmse_log"][k] = np.sqrt(np.mean(d**2))
        per["silog"][k] = 100.0 * np.sqrt(max(np.mean(d**2) - np.mean(d) ** 2, 0.0))
        per["irmse"][k] = 1000.0 * np.sqrt(np.mean((1.0 / gg - 1.0 / pp) ** 2))
        per["log10"][k] = np.mean(np.abs(np.log10(gg) - np.log10(pp)))
        for i, name in enumerate(("a1", "a2", "a3"), start=1):
            per[name][k] = np.mean(thresh < 1.25**i)
    failed = np.isnan(per["abs_rel"])

    def m(key):
        v = per[key][~failed]
        return float(np.mean(v)) if len(v) else float("nan")

    inverse = alignment == DepthAlignment.SCALE_SHIFT_INVERSE
    return DepthResult(
        m("abs_rel"), m("sq_rel"), m("rmse"), m("rmse_log"), m("a1"), m("a2"), m("a3"),
        float(np.mean(per["coverage"])), frozen(per["abs_rel"]), frozen(per["rmse"]),
        frozen(per["scale"]), frozen(per["shift"]), n, int(failed.sum()), alignment.value,
        silog_x100=m("silog"), irmse_per_km=m("irmse"), log10=m("log10"),
        per_image_shift_inv_m=frozen(per["shift_inv"]) if inverse else None, clamp=bool(clamp), crop=crop,
        min_depth_m=float(min_depth_m), max_depth_m=float(max_depth_m),
    )

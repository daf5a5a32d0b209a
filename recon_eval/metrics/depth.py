"""Depth-map metrics of Eigen et al. (NIPS 2014), with declared alignment, averaged per image.

Definitions: shared/notes/metrics.md, "Depth maps". Depths are (H, W) float arrays in metres
(z-depth). Truth pixels that are not finite or <= 0 (or outside (min_depth_m, max_depth_m)) are
unknown and skipped. Predictions that are not finite or <= 0 after alignment are missing: they are
excluded from the error terms and counted in ``coverage`` (never dropped silently).
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
    per_image_shift_m: np.ndarray  # shift applied (0 unless scale_shift)
    n_images: int
    n_images_failed: int  # images with no valid pixel: excluded from the means, counted here
    alignment: str
    aggregation: str = "mean of per-image values"
    operator: str = "<"


def _align(p: np.ndarray, g: np.ndarray, alignment: DepthAlignment) -> tuple[float, float]:
    if alignment == DepthAlignment.NONE:
        return 1.0, 0.0
    if alignment == DepthAlignment.MEDIAN:
        return float(np.median(g) / np.median(p)), 0.0
    A = np.stack([p, np.ones_like(p)], axis=1)
    (s, b), *_ = np.linalg.lstsq(A, g, rcond=None)
    return float(s), float(b)


def eigen_depth_metrics(
    depth_pred: Sequence,
    depth_gt: Sequence,
    *,
    alignment: DepthAlignment = DepthAlignment.NONE,
    min_depth_m: float = 0.0,
    max_depth_m: float = np.inf,
) -> DepthResult:
    """Eigen et al. depth metrics (abs_rel, sq_rel, rmse, rmse_log (natural log), a1..a3 with
    strict ``<``), computed per image then averaged over images. Per-image alignment as declared.
    Truth used where ``min_depth_m < g < max_depth_m`` (both strict, as monodepth2's
    ``gt > MIN_DEPTH & gt < MAX_DEPTH``).
    depth_pred, depth_gt: sequences of (H, W) arrays, metres."""
    alignment = DepthAlignment(alignment)
    n = len(depth_pred)
    if n == 0 or len(depth_gt) != n:
        raise InputError(f"depth: need as many truth maps as predictions (>0), got {n} and {len(depth_gt)}")
    keys = ("abs_rel", "sq_rel", "rmse", "rmse_log", "a1", "a2", "a3", "coverage", "scale", "shift")
    per = {k: np.full(n, np.nan) for k in keys}
    for k in range(n):
        p = as_float_array(depth_pred[k], f"predicted depth #{k}", (None, None))
        g = as_float_array(depth_gt[k], f"GT depth #{k}", (None, None))
        if p.shape != g.shape:
            raise InputError(f"depth #{k}: prediction {p.shape} and truth {g.shape} differ in shape")
        vg = np.isfinite(g) & (g > min_depth_m) & (g < max_depth_m) & (g > 0)
        vp = vg & np.isfinite(p) & (p > 0)
        if vp.sum() == 0:
            per["coverage"][k] = 0.0
            continue
        s, b = _align(p[vp], g[vp], alignment)
        pa = s * p + b
        ok = vg & np.isfinite(pa) & (pa > 0)
        per["scale"][k], per["shift"][k] = s, b
        per["coverage"][k] = ok.sum() / vg.sum()
        if ok.sum() == 0:
            continue
        gg, pp = g[ok], pa[ok]
        thresh = np.maximum(gg / pp, pp / gg)
        per["abs_rel"][k] = np.mean(np.abs(gg - pp) / gg)
        per["sq_rel"][k] = np.mean((gg - pp) ** 2 / gg)
        per["rmse"][k] = np.sqrt(np.mean((gg - pp) ** 2))
        per["rmse_log"][k] = np.sqrt(np.mean((np.log(gg) - np.log(pp)) ** 2))
        for i, name in enumerate(("a1", "a2", "a3"), start=1):
            per[name][k] = np.mean(thresh < 1.25**i)
    failed = np.isnan(per["abs_rel"])

    def m(key):
        v = per[key][~failed]
        return float(np.mean(v)) if len(v) else float("nan")

    return DepthResult(
        m("abs_rel"), m("sq_rel"), m("rmse"), m("rmse_log"), m("a1"), m("a2"), m("a3"),
        float(np.mean(per["coverage"])), frozen(per["abs_rel"]), frozen(per["rmse"]),
        frozen(per["scale"]), frozen(per["shift"]), n, int(failed.sum()), alignment.value,
    )

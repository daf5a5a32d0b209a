"""Stereo disparity metrics: KITTI 2015 D1, Middlebury v3, ETH3D two-view.

Definitions: shared/notes/metrics.md, "Stereo disparity". Disparities are (H, W) float arrays in
pixels. Invalid / missing values are NaN (readers convert each format's marker: KITTI PNG 0,
Middlebury/ETH3D PFM inf). Truth pixels that are not finite or <= 0 are unknown and skipped.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from recon_eval.arrays import as_float_array
from recon_eval.errors import InputError


def _pair(est, gt, k: int, what: str = "disparity") -> tuple[np.ndarray, np.ndarray]:
    e = as_float_array(est, f"estimated {what} #{k}", (None, None))
    g = as_float_array(gt, f"GT {what} #{k}", (None, None))
    if e.shape != g.shape:
        raise InputError(f"{what} #{k}: estimate {e.shape} and truth {g.shape} differ in shape")
    return e, g


def kitti_interpolate_background(disp) -> np.ndarray:
    """KITTI devkit ``DisparityImage::interpolateBackground`` (devkit_stereo_flow, io_disp.h):
    fill invalid (NaN) pixels so that every pixel is scored.

    Per row, an interior gap (valid neighbours on both sides) takes the smaller (background) of its
    two neighbours; leading/trailing gaps copy the nearest valid value of the row. Then per column,
    still-invalid pixels at the top/bottom copy the nearest valid value of the column. An image
    with no valid pixel stays all NaN; so do wholly invalid interior rows (the column pass only
    extrapolates to the top and bottom): the devkit leaves them at -1 and :func:`kitti_d1` scores
    them as -1 too. Returns a new (H, W) array.
    """
    d = np.array(disp, dtype=np.float64, copy=True)
    H, W = d.shape
    for v in range(H):
        row = d[v]
        valid = np.isfinite(row)
        if not valid.any():
            continue
        idx = np.flatnonzero(valid)
        # index of the previous / next valid pixel for every column
        prev = np.maximum.accumulate(np.where(valid, np.arange(W), -1))
        nxt = np.minimum.accumulate(np.where(valid, np.arange(W), W)[::-1])[::-1]
        inv = ~valid
        interior = inv & (prev >= 0) & (nxt < W)
        row[interior] = np.minimum(row[prev[interior]], row[nxt[interior]])
        row[inv & (prev < 0)] = row[idx[0]]
        row[inv & (nxt >= W)] = row[idx[-1]]
    for u in range(W):
        col = d[:, u]
        valid = np.isfinite(col)
        if not valid.any() or valid.all():
            continue
        idx = np.flatnonzero(valid)
        col[: idx[0]] = col[idx[0]]
        col[idx[-1] + 1 :] = col[idx[-1]]
    return d


@dataclass(frozen=True)
class KittiD1Result:
    """KITTI 2015 D1 outlier percentages, pooled over all images (sum of bad / sum of valid)."""

    d1_bg_noc_pct: float  # background (obj_map == 0), non-occluded truth
    d1_fg_noc_pct: float  # foreground (obj_map > 0), non-occluded truth
    d1_all_noc_pct: float
    d1_bg_occ_pct: float  # "all" pixels: the occ truth (includes occluded)
    d1_fg_occ_pct: float
    d1_all_occ_pct: float
    density_pct: float  # valid estimates / pixels with truth (occ truth), before interpolation
    n_px_noc: int
    n_px_occ: int
    n_images: int
    abs_thresh_px: float = 3.0
    rel_thresh: float = 0.05
    operator: str = "err > abs AND err/|gt| > rel"
    aggregation: str = "pooled over images"
    interpolation: str = "kitti_background"
    # the devkit's "est" rows: the same outliers over the pixels with a valid estimate (before
    # interpolation) only; NaN where there is none
    d1_bg_noc_est_pct: float = float("nan")
    d1_fg_noc_est_pct: float = float("nan")
    d1_all_noc_est_pct: float = float("nan")
    d1_bg_occ_est_pct: float = float("nan")
    d1_fg_occ_est_pct: float = float("nan")
    d1_all_occ_est_pct: float = float("nan")


def kitti_d1(
    disp_est: Sequence,
    disp_gt_occ: Sequence,
    disp_gt_noc: Sequence | None = None,
    obj_map: Sequence | None = None,
    *,
    abs_thresh_px: float = 3.0,
    rel_thresh: float = 0.05,
) -> KittiD1Result:
    """KITTI 2015 D1 (Menze & Geiger, CVPR 2015; devkit ``disp_err`` in io_disp.h): a pixel is an
    outlier if ``|d - d*| > 3 px AND |d - d*| / |d*| > 5 %``, in the devkit's float arithmetic
    (:func:`kitti_disparity_outliers`). Missing estimates (NaN or negative:
    the devkit's ``isValid`` is ``d >= 0``) are filled by :func:`kitti_interpolate_background` and
    still scored; pixels nothing fills (an image or an interior row without any estimate) keep the
    devkit's invalid value -1 and are scored with it. Density is reported, and the devkit's "est"
    rows (the pixels with an estimate before interpolation). Errors are pooled: sum of outliers
    over all images / sum of valid truth pixels (devkit ``disparityErrorsOutlier``,
    evaluate_stereo.cpp). Percent; NaN where no pixel.

    disp_est, disp_gt_occ: sequences of (H, W) arrays (pixels, NaN = invalid); disp_gt_noc: the
    non-occluded truth (default: the occ truth); obj_map: foreground masks (> 0 = foreground,
    default: all background).
    """
    n = len(disp_est)
    if n == 0 or len(disp_gt_occ) != n:
        raise InputError(f"kitti_d1: need as many truth maps as estimates (>0), got {n} and {len(disp_gt_occ)}")
    regions = [f"{r}_{w}{e}" for r in ("bg", "fg") for w in ("noc", "occ") for e in ("", "_est")]
    bad = {k: 0 for k in regions}
    tot = dict(bad)
    n_valid_est = n_gt_px = 0
    for k in range(n):
        e, g_occ = _pair(disp_est[k], disp_gt_occ[k], k)
        g_noc = g_occ if disp_gt_noc is None else _pair(disp_est[k], disp_gt_noc[k], k)[1]
        fg = np.zeros(e.shape, bool) if obj_map is None else np.asarray(obj_map[k]) > 0
        if fg.shape != e.shape:
            raise InputError(f"obj_map #{k}: expected shape {e.shape}, got {fg.shape}")
        with np.errstate(invalid="ignore"):
            est_valid = np.isfinite(e) & (e >= 0)
        e = np.where(est_valid, e, np.nan)
        valid_occ = np.isfinite(g_occ) & (g_occ > 0)
        n_gt_px += int(valid_occ.sum())
        n_valid_est += int((valid_occ & est_valid).sum())
        ei = kitti_interpolate_background(e)
        ei[~np.isfinite(ei)] = -1.0  # the devkit's invalid value, left where nothing interpolates
        for name, g in (("noc", g_noc), ("occ", g_occ)):
            valid = np.isfinite(g) & (g > 0)
            out = kitti_disparity_outliers(ei, g, abs_thresh_px, rel_thresh)
            for region, mask in (("bg", ~fg), ("fg", fg)):
                for suffix, sel in (("", valid & mask), ("_est", valid & mask & est_valid)):
                    bad[f"{region}_{name}{suffix}"] += int((out & sel).sum())
                    tot[f"{region}_{name}{suffix}"] += int(sel.sum())

    def pct(b, t):
        return 100.0 * b / t if t else float("nan")

    def d1(name):  # (bg, fg, all) of one row
        b, f = f"bg_{name}", f"fg_{name}"
        return pct(bad[b], tot[b]), pct(bad[f], tot[f]), pct(bad[b] + bad[f], tot[b] + tot[f])

    noc, occ, noc_est, occ_est = d1("noc"), d1("occ"), d1("noc_est"), d1("occ_est")
    return KittiD1Result(
        *noc, *occ, pct(n_valid_est, n_gt_px), tot["bg_noc"] + tot["fg_noc"], tot["bg_occ"] + tot["fg_occ"], n,
        abs_thresh_px, rel_thresh, d1_bg_noc_est_pct=noc_est[0], d1_fg_noc_est_pct=noc_est[1],
        d1_all_noc_est_pct=noc_est[2], d1_bg_occ_est_pct=occ_est[0], d1_fg_occ_est_pct=occ_est[1],
        d1_all_occ_est_pct=occ_est[2],
    )


def kitti_disparity_outliers(disp_ipol, disp_gt, abs_thresh_px: float = 3.0, rel_thresh: float = 0.05) -> np.ndarray:
    """(H, W) bool ``d_err`` of the devkit's ``disparityErrorsOutlier`` (evaluate_scene_flow.cpp)
    in its arithmetic: the disparities are floats, ``fabs`` is the float overload, so ``|d* - d|``
    and ``|d* - d| / |d*|`` are float32 values, compared with the double constants 3.0 and 0.05.
    The float quotient matters at exact ties, which the KITTI PNG's 1/256 px grid makes common:
    5 / 100 in float is 0.0500000007 > 0.05, an outlier (in float64 it is not)."""
    g = np.asarray(disp_gt, np.float32)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        err = np.abs(g - np.asarray(disp_ipol, np.float32))  # float32
        return (err.astype(np.float64) > abs_thresh_px) & ((err / np.abs(g)).astype(np.float64) > rel_thresh)


@dataclass(frozen=True)
class TwoViewResult:
    """Middlebury v3 / ETH3D two-view disparity metrics for one image pair (or pooled pixels)."""

    bad_0_5_pct: float  # % of pixels with err > 0.5 px (denominator: see `denominator`)
    bad_1_0_pct: float
    bad_2_0_pct: float
    bad_4_0_pct: float
    invalid_pct: float  # % of truth pixels without a valid estimate
    totbad_2_0_pct: float  # bad_2_0 + invalid (Middlebury totbad at 2 px)
    avgerr_px: float  # mean |d - d*| over valid estimates
    rms_px: float  # sqrt(mean (d - d*)^2) over valid estimates
    a50_px: float  # error quantiles: sorted valid errors at index floor(N q)
    a90_px: float
    a95_px: float
    a99_px: float
    coverage_pct: float  # % of truth pixels with a valid estimate = 100 - invalid_pct
    n_px: int  # truth pixels scored (inside the mask)
    benchmark: str  # 'middlebury_v3' or 'eth3d_two_view'
    denominator: str  # 'truth pixels' (Middlebury) or 'covered pixels' (ETH3D)
    operator: str = ">"  # bad when err > threshold
    ndisp: float | None = None  # Middlebury: estimates clipped to [0, ndisp] (calib.txt); None = not clipped
    round_disp: bool = False  # Middlebury evaldisp's rounddisp: estimates rounded to integers


def two_view_metrics(est_list, gt_list, masks, *, benchmark: str, ndisp: float | None = None,
                     round_disp: bool = False) -> TwoViewResult:
    """Middlebury v3 (``benchmark="middlebury_v3"``) or ETH3D (``"eth3d_two_view"``) metrics of
    (H, W) estimates and truths (pixels), pooled over the pairs (the benchmarks count per pixel);
    ``masks``: per-pair (H, W) bool restrictions, or None. See :func:`middlebury`."""
    if (ndisp is not None or round_disp) and benchmark != "middlebury_v3":
        raise InputError("ndisp and round_disp are Middlebury evaldisp options")
    errs, n_gt, n_cov = [], 0, 0
    for k, (e_in, g_in) in enumerate(zip(est_list, gt_list)):
        e, g = _pair(e_in, g_in, k)
        valid_gt = np.isfinite(g) & (g >= 0) if benchmark == "eth3d_two_view" else np.isfinite(g)
        if masks is not None:
            m = np.asarray(masks[k], bool)
            if m.shape != g.shape:
                raise InputError(f"mask #{k}: expected shape {g.shape}, got {m.shape}")
            valid_gt &= m
        valid_est = np.isfinite(e)
        if ndisp is not None:  # evaldisp: d = max(0, min(maxd, d)) for valid estimates
            e = np.where(valid_est, np.clip(e, 0.0, ndisp), e)
        if round_disp:
            e = np.where(valid_est, np.round(e), e)
        if benchmark == "eth3d_two_view":  # ETH3D: |d| > image width is treated as missing
            valid_est &= np.abs(np.where(valid_est, e, 0.0)) <= g.shape[1]
        cov = valid_gt & valid_est
        n_gt += int(valid_gt.sum())
        n_cov += int(cov.sum())
        errs.append(np.abs(e[cov] - g[cov]))
    err = np.concatenate(errs) if errs else np.zeros(0)
    denom = n_gt if benchmark == "middlebury_v3" else n_cov

    def pct(count, d):
        return 100.0 * count / d if d else float("nan")

    bad = [pct(int(np.sum(err > t)), denom) for t in (0.5, 1.0, 2.0, 4.0)]
    invalid = pct(n_gt - n_cov, n_gt)
    if len(err):
        s = np.sort(err)
        q = [float(s[min(int(np.floor(len(s) * f)), len(s) - 1)]) for f in (0.5, 0.9, 0.95, 0.99)]
        avg, rms = float(np.mean(err)), float(np.sqrt(np.mean(err**2)))
    else:
        q, avg, rms = [float("nan")] * 4, float("nan"), float("nan")
    totbad = pct(int(np.sum(err > 2.0)) + (n_gt - n_cov), n_gt)
    return TwoViewResult(*bad, invalid, totbad, avg, rms, *q, pct(n_cov, n_gt), n_gt, benchmark,
                         "truth pixels" if benchmark == "middlebury_v3" else "covered pixels",
                         ndisp=None if ndisp is None else float(ndisp), round_disp=bool(round_disp))


def middlebury(disp_est, disp_gt, nonocc_mask=None, *, ndisp: float | None = None,
               round_disp: bool = False) -> TwoViewResult:
    """Middlebury v3 (Scharstein et al., GCPR 2014; MiddEval3 ``evaldisp.cpp``): truth = inf is
    unknown and skipped; valid (finite) estimates are clipped to [0, ndisp] (``d = max(0, min(maxd,
    d))``, ndisp from the dataset's calib.txt; None = no clipping) and rounded if ``round_disp``;
    bad-x = % of truth pixels whose valid estimate has err > x; invalid = % of truth pixels with no
    valid estimate; totbad = bad + invalid; avgerr (``serr / (n - invalid)``), rms and the
    quantiles over valid estimates. ``nonocc_mask`` (H, W) bool restricts to non-occluded pixels
    (evaldisp evaluates where mask0nocc.png is 255). One pair of (H, W) arrays, pixels."""
    return two_view_metrics([disp_est], [disp_gt], None if nonocc_mask is None else [nonocc_mask],
                            benchmark="middlebury_v3", ndisp=ndisp, round_disp=round_disp)


def eth3d_two_view(disp_est, disp_gt, mask=None) -> TwoViewResult:
    """ETH3D two-view (Schoeps et al., CVPR 2017): estimates that are non-finite or have
    |d| > image width are missing and excluded; bad_0_5/1_0/2_0/4_0 (strict ``>``), avgerr, rms and
    a50/a90/a95/a99 (sorted errors at floor(N q)) over covered pixels; coverage is the penalty.
    One pair of (H, W) arrays, pixels; ``mask`` (H, W) bool (e.g. non-occluded)."""
    return two_view_metrics([disp_est], [disp_gt], None if mask is None else [mask], benchmark="eth3d_two_view")

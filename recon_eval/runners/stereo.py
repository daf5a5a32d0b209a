"""OpenCV stereo matching on the rectified pairs of the cross-view truth
(``crossview/stereo/<left view>/left.png, right.png``, docs/crossview.md), read through the dataset
reader and converted to grey by :func:`scenegen.geometry.color.to_grey8` (OpenCV's RGB -> grey).

Raw output: ``disparity/<left view>.pfm`` (float32, left image, px; +inf where the matcher gave
no disparity). Scores against ``disp_left.pfm`` (all pixels with truth) restricted to the
non-occluded mask ``disp_left_noc.png``: Middlebury v3 bad-0.5/1/2/4 % (strict >), invalid %,
avgerr, rms (recon_eval.metrics.stereo.middlebury), pooled over all frames, plus the median signed
error (estimate - truth, px) over covered non-occluded pixels: the matcher's disparity bias.

Matcher settings are fixed from the image width only (never from the truth): numDisparities =
the smallest multiple of 16 >= width / 4. StereoBM: block size 15 (``2 * BLOCK + 5``; BM needs an
odd size >= 5), uniqueness 10, texture threshold 5. StereoSGBM (3-way): block size 5 (``BLOCK``)
and the smoothness penalties OpenCV documents for ``cv2.StereoSGBM_create``,
P1 = 8 x channels x block^2 and P2 = 32 x channels x block^2, for the channels actually passed:
grey images, 1 channel, so P1 = 200 and P2 = 800 (OpenCV's stereo_match sample uses 3 channels'
600 / 2400 for its colour input; on these grey pairs that over-smooths: bad-2.0 on
stereo_tabletop 8.18 % with 600 / 2400, 7.56 % with 200 / 800).
"""
from __future__ import annotations

import cv2
import numpy as np

from recon_eval.errors import InputError, NotApplicable
from recon_eval.metrics.stereo import two_view_metrics
from recon_eval.readers.pfm import read_pfm
from recon_eval.runners.common import RunOutput, out_path
from recon_eval.tasks.disparity_sign import reversed_sign_hint
from scenegen.dataset.codecs import write_pfm
from scenegen.geometry.color import to_grey8

#: SGBM block size; StereoBM uses 2 * BLOCK + 5 = 15.
BLOCK = 5


def sgbm_matcher(width: int, channels: int):
    """StereoSGBM (module docstring's settings) for images ``width`` pixels wide, and its
    numDisparities (also the active IR runner's, :mod:`recon_eval.runners.active_stereo`)."""
    return _matcher("sgbm", width, channels)


def _matcher(kind: str, width: int, channels: int):
    """The matcher for images ``width`` pixels wide with ``channels`` channels, and its
    numDisparities."""
    nd = 16 * int(np.ceil(width / 4 / 16))
    if kind == "bm":
        m = cv2.StereoBM_create(numDisparities=nd, blockSize=2 * BLOCK + 5)  # BM needs an odd size >= 5
        m.setUniquenessRatio(10)
        m.setTextureThreshold(5)
        return m, nd
    return cv2.StereoSGBM_create(minDisparity=0, numDisparities=nd, blockSize=BLOCK, P1=8 * channels * BLOCK**2,
                                 P2=32 * channels * BLOCK**2, disp12MaxDiff=1, uniquenessRatio=10,
                                 speckleWindowSize=100, speckleRange=2, mode=cv2.STEREO_SGBM_MODE_SGBM_3WAY), nd


def _opencv(kind: str):
    """``compute(ds, left, path, out)``: the OpenCV matcher ``kind`` on the frame of ``left``, its
    disparity written as PFM to ``path``."""
    def compute(ds, left, path, out) -> None:
        L, R = (to_grey8(im) for im in ds.stereo_images(left))
        m, nd = _matcher(kind, L.shape[1], 1 if L.ndim == 2 else L.shape[2])  # grey: 1 channel
        raw = m.compute(L, R).astype(np.float64) / 16.0  # fixed point, 4 fractional bits
        write_pfm(path, np.where(raw >= 0, raw, np.nan))  # invalid = minDisparity - 1 (/16) -> missing
        out.notes[f"{left}.num_disparities"] = nd
    return compute


def run(ds, out_dir, options, *, compute=None) -> RunOutput:
    """OpenCV's matcher ``options["matcher"]`` on every rectified frame, scored (module docstring).
    ``compute(ds, left, path, out)`` replaces it (an external estimator writing the PFM at ``path``,
    :mod:`recon_eval.runners.external`); a missing or unreadable PFM is scored as no disparity."""
    lefts = ds.stereo_left_views()
    if not lefts:
        raise NotApplicable(f"{ds.root}: no rectified stereo pairs (crossview/index.json: stereo)")
    compute = compute or _opencv(options["matcher"])
    out = RunOutput()
    ests, gts, masks, signed = [], [], [], []
    for left in lefts:
        path = out_path(out_dir, f"disparity/{left}.pfm")
        compute(ds, left, path, out)
        gt = ds.stereo_disparity(left)
        if path.is_file():
            out.raw_files.append(f"disparity/{left}.pfm")
            est = read_pfm(path)  # score what was written
        else:
            est = np.full_like(gt, np.nan)
        if est.shape != gt.shape:
            raise InputError(f"{path}: disparity shape {est.shape} differs from the truth's {gt.shape}")
        noc = ds.stereo_noc_mask(left)
        ests.append(est)
        gts.append(gt)
        masks.append(noc)
        if hint := reversed_sign_hint(est, gt, noc):
            out.warnings.append(f"{left} (non-occluded): {hint}")
        ok = noc & np.isfinite(gt) & np.isfinite(est)
        signed.append((est - gt)[ok])
    # pooled over frames (Middlebury counts per pixel)
    noc_res = two_view_metrics(ests, gts, masks, benchmark="middlebury_v3")
    all_res = two_view_metrics(ests, gts, [np.isfinite(g) for g in gts], benchmark="middlebury_v3")
    s = np.concatenate(signed)
    out.results["middlebury_noc"] = noc_res
    out.results["middlebury_all"] = all_res
    med = float(np.median(s)) if len(s) else float("inf")
    out.results["bias"] = {"median_signed_err_px": med, "mean_signed_err_px": float(np.mean(s)) if len(s) else float("inf"),
                           "n_px": int(len(s)), "definition": "estimate - truth over covered non-occluded pixels"}
    out.metrics.update({"bad_2_0_noc_pct": noc_res.bad_2_0_pct, "bad_1_0_noc_pct": noc_res.bad_1_0_pct,
                        "invalid_noc_pct": noc_res.invalid_pct, "avgerr_noc_px": noc_res.avgerr_px,
                        "median_signed_err_px": med, "abs_median_signed_err_px": abs(med),
                        "bad_2_0_all_pct": all_res.bad_2_0_pct})
    return out

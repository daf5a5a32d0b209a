"""OpenCV stereo matching on the rectified pairs of the cross-view truth
(``crossview/stereo/<left view>/left.png, right.png``, docs/crossview.md).

Raw output: ``disparity/<left view>.pfm`` (float32, left image, px; +inf where the matcher gave
no disparity). Scores against ``disp_left.pfm`` (all pixels with truth) restricted to the
non-occluded mask ``disp_left_noc.png``: Middlebury v3 bad-0.5/1/2/4 % (strict >), invalid %,
avgerr, rms (recon_eval.stereo.middlebury), pooled over all frames, plus the median signed error
(estimate - truth, px) over covered non-occluded pixels: the matcher's disparity bias.

Matcher settings are fixed from the image width only (never from the truth): numDisparities =
the smallest multiple of 16 >= width / 4, block size 5 (SGBM: P1 = 8 * 3 * 5^2,
P2 = 32 * 3 * 5^2, the values OpenCV's stereo_match sample uses).
"""
from __future__ import annotations

import numpy as np

from recon_eval.runners._common import NotApplicable, RunOutput, crossview_index, gray, out_path

BLOCK = 5


def write_pfm(path, disp: np.ndarray) -> None:
    """(H, W) float -> PFM ``Pf``, little-endian, rows bottom to top; NaN stored as +inf."""
    d = np.where(np.isfinite(disp), disp, np.inf).astype("<f4")
    h, w = d.shape
    with open(path, "wb") as f:
        f.write(f"Pf\n{w} {h}\n-1.0\n".encode("ascii"))
        f.write(np.ascontiguousarray(d[::-1]).tobytes())


def _matcher(kind: str, width: int):
    import cv2

    nd = 16 * int(np.ceil(width / 4 / 16))
    if kind == "bm":
        m = cv2.StereoBM_create(numDisparities=nd, blockSize=2 * BLOCK + 5)  # BM needs an odd size >= 5
        m.setUniquenessRatio(10)
        m.setTextureThreshold(5)
        return m, nd
    return cv2.StereoSGBM_create(minDisparity=0, numDisparities=nd, blockSize=BLOCK, P1=8 * 3 * BLOCK**2,
                                 P2=32 * 3 * BLOCK**2, disp12MaxDiff=1, uniquenessRatio=10,
                                 speckleWindowSize=100, speckleRange=2, mode=cv2.STEREO_SGBM_MODE_SGBM_3WAY), nd


def run(ds, out_dir, options) -> RunOutput:
    import cv2

    from recon_eval.readers.kitti_png import read_kitti_disparity
    from recon_eval.readers.pfm import read_pfm

    idx = crossview_index(ds)
    if not idx or not idx.get("stereo"):
        raise NotApplicable(f"{ds.root}: no rectified stereo pairs (crossview/index.json: stereo)")
    kind = options["matcher"]
    out = RunOutput()
    ests, gts, masks, signed = [], [], [], []
    for entry in idx["stereo"]:
        base = ds.root / entry["dir"]
        L = cv2.imread(str(base / "left.png"), cv2.IMREAD_UNCHANGED)
        R = cv2.imread(str(base / "right.png"), cv2.IMREAD_UNCHANGED)
        if L is None or R is None:
            raise NotApplicable(f"{base}: left.png / right.png missing")
        L, R = gray(L[..., ::-1] if L.ndim == 3 else L), gray(R[..., ::-1] if R.ndim == 3 else R)
        m, nd = _matcher(kind, L.shape[1])
        raw = m.compute(L, R).astype(np.float64) / 16.0  # fixed point, 4 fractional bits
        est = np.where(raw >= 0, raw, np.nan)  # invalid = minDisparity - 1 (/16) -> missing
        path = out_path(out_dir, f"disparity/{entry['left_view']}.pfm")
        write_pfm(path, est)
        out.raw_files.append(f"disparity/{entry['left_view']}.pfm")
        est = read_pfm(path)  # score what was written
        gt = read_pfm(base / "disp_left.pfm")
        noc = np.isfinite(read_kitti_disparity(base / "disp_left_noc.png"))
        ests.append(est)
        gts.append(gt)
        masks.append(noc)
        ok = noc & np.isfinite(gt) & np.isfinite(est)
        signed.append((est - gt)[ok])
        out.notes[f"{entry['left_view']}.num_disparities"] = nd
    from recon_eval.stereo import _two_view  # pooled over frames (Middlebury counts per pixel)

    noc_res = _two_view(ests, gts, masks, benchmark="middlebury_v3")
    all_res = _two_view(ests, gts, [np.isfinite(g) for g in gts], benchmark="middlebury_v3")
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

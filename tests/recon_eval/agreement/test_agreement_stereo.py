"""Stereo metrics against transcriptions of the benchmarks' C++ (neither installs from PyPI):

* KITTI 2015 devkit (devkit_scene_flow, ``io_disp.h`` ``DisparityImage::interpolateBackground``,
  ``evaluate_scene_flow.cpp`` ``disparityErrorsOutlier``), loops transcribed line by line, in the
  devkit's float arithmetic (``fabs`` of a float difference is the float overload);
* Middlebury MiddEval3 SDK ``evaldisp.cpp`` ``evaldisp`` (clip to [0, maxdisp], rounddisp, mask
  value 255), transcribed.
"""
from __future__ import annotations

import json

import numpy as np
import pytest

from recon_eval.cli import main
from recon_eval.metrics.stereo import kitti_d1, middlebury
from scenegen.dataset.codecs import encode_png, write_pfm

ABS_THRESH, REL_THRESH = 3.0, 0.05


def _devkit_interpolate(D):
    """io_disp.h interpolateBackground on a float image with -1 = invalid (isValid: d >= 0)."""
    D = D.copy()
    height_, width_ = D.shape
    valid = lambda u, v: D[v, u] >= 0  # noqa: E731
    for v in range(height_):
        count = 0
        for u in range(width_):
            if valid(u, v):
                if count >= 1:
                    u1, u2 = u - count, u - 1
                    if u1 > 0 and u2 < width_ - 1:
                        d_ipol = min(D[v, u1 - 1], D[v, u2 + 1])
                        for u_curr in range(u1, u2 + 1):
                            D[v, u_curr] = d_ipol
                count = 0
            else:
                count += 1
        for u in range(width_):
            if valid(u, v):
                for u2 in range(u):
                    D[v, u2] = D[v, u]
                break
        for u in range(width_ - 1, -1, -1):
            if valid(u, v):
                for u2 in range(u + 1, width_):
                    D[v, u2] = D[v, u]
                break
    for u in range(width_):
        for v in range(height_):
            if valid(u, v):
                for v2 in range(v):
                    D[v2, u] = D[v, u]
                break
        for v in range(height_ - 1, -1, -1):
            if valid(u, v):
                for v2 in range(v + 1, height_):
                    D[v2, u] = D[v, u]
                break
    return D


def _devkit_errors(D_gt, D_orig, O_map):
    """evaluate_scene_flow.cpp disparityErrorsOutlier: (errors, pixels) of bg, bg_result, fg,
    fg_result, all, all_result; D_gt valid where >= 0."""
    D_gt, D_orig = np.asarray(D_gt, np.float32), np.asarray(D_orig, np.float32)  # DisparityImage holds floats
    D_ipol = _devkit_interpolate(D_orig)
    c = {k: [0, 0] for k in ("bg", "bg_r", "fg", "fg_r", "all", "all_r")}
    H, W = D_gt.shape
    for u in range(W):
        for v in range(H):
            if D_gt[v, u] >= 0:
                d_gt, d_est = D_gt[v, u], D_ipol[v, u]  # float
                diff = abs(d_gt - d_est)  # fabs(float): the float overload
                assert diff.dtype == np.float32
                d_err = float(diff) > ABS_THRESH and float(diff / abs(d_gt)) > REL_THRESH  # float quotient vs 0.05
                region = "bg" if O_map[v, u] == 0 else "fg"
                for key, use in ((region, True), (region + "_r", D_orig[v, u] >= 0), ("all", True),
                                 ("all_r", D_orig[v, u] >= 0)):
                    if use:
                        c[key][0] += d_err
                        c[key][1] += 1
    return c


def _kitti_input(seed=0):
    rng = np.random.default_rng(seed)
    H, W = 24, 40
    gt = rng.uniform(1.0, 60.0, (H, W))
    gt[rng.random((H, W)) < 0.3] = -1.0  # no truth
    gt[:, :4] = rng.uniform(0.2, 1.9, (H, 4))  # small disparities: d = -1 is within 3 px of them
    est = gt + rng.normal(0.0, 2.0, (H, W))
    est[rng.random((H, W)) < 0.3] = -1.0  # holes
    est[7] = -1.0  # wholly invalid interior rows: the devkit leaves them at -1
    est[15:17] = -1.0
    est[:, 0] = -1.0
    obj = (rng.random((H, W)) < 0.25).astype(int)
    return gt, est, obj


def test_d1_equals_kitti_devkit(agreement):
    gt, est, obj = _kitti_input()
    c = _devkit_errors(gt, est, obj)
    r = kitti_d1([np.where(est >= 0, est, np.nan)], [np.where(gt >= 0, gt, np.nan)], None, [obj])
    pct = lambda k: 100.0 * c[k][0] / c[k][1]  # noqa: E731
    ours = [r.d1_bg_occ_pct, r.d1_fg_occ_pct, r.d1_all_occ_pct, r.d1_bg_occ_est_pct, r.d1_fg_occ_est_pct,
            r.d1_all_occ_est_pct]
    ref = [pct("bg"), pct("fg"), pct("all"), pct("bg_r"), pct("fg_r"), pct("all_r")]
    d = float(np.max(np.abs(np.array(ours) - ref)))
    assert d == 0
    agreement("kitti.d1", "D1 bg/fg/all and the est rows (%), wholly invalid interior rows",
              "KITTI 2015 devkit `interpolateBackground`, `disparityErrorsOutlier` (transcribed)", "devkit_scene_flow (2015)",
              "40x24, 30 % holes, 3 empty interior rows", d)


def _evaldisp(disp, gtdisp, mask, badthresh, maxdisp, rounddisp):
    """MiddEval3 evaldisp.cpp evaldisp() at scale 1: (badpercent, invalidpercent, totalbadpercent, avgErr)."""
    n = bad = invalid = 0
    serr = 0.0
    H, W = gtdisp.shape
    for y in range(H):
        for x in range(W):
            gt = gtdisp[y, x]
            if gt == np.inf:
                continue
            d = disp[y, x]
            valid = d != np.inf
            if valid:
                d = max(0, min(maxdisp, d))
            if valid and rounddisp:
                d = round(d)
            err = abs(d - gt)
            if mask is not None and mask[y, x] != 255:
                continue
            n += 1
            if valid:
                serr += err
                if err > badthresh:
                    bad += 1
            else:
                invalid += 1
    return 100.0 * bad / n, 100.0 * invalid / n, 100.0 * (bad + invalid) / n, serr / (n - invalid)


def test_d1_at_exact_five_percent_ties_equals_kitti_devkit(agreement):
    """Disparities on the KITTI PNG's 1/256 px grid, a third of the pixels off by exactly 5 % (> 3 px)."""
    rng = np.random.default_rng(3)
    k = rng.integers(16, 200, (24, 32))
    gt = 20.0 * k / 4  # 20 k / 4 px: on the 1/256 grid
    est = gt + rng.integers(-300, 300, gt.shape) / 256
    tie = rng.random(gt.shape) < 1 / 3
    est[tie] = 21.0 * k[tie] / 4  # error k / 4 px = 5 % of the truth, above 3 px for k >= 16
    c = _devkit_errors(gt, est, np.zeros(gt.shape, int))
    d = abs(kitti_d1([est], [gt]).d1_all_occ_pct - 100.0 * c["all"][0] / c["all"][1])
    assert c["all"][0] >= tie.sum() > 200 and d == 0
    agreement("kitti.d1.ties", "D1 all (%) with exact 5 % ties (the devkit's float quotient)",
              "KITTI 2015 devkit `disparityErrorsOutlier` (transcribed, float)", "devkit_scene_flow (2015)",
              f"32x24 on the 1/256 px grid, {int(tie.sum())} ties", d)


def _middlebury_input(seed=1):
    rng = np.random.default_rng(seed)
    H, W = 30, 44
    gt = rng.uniform(5.0, 60.0, (H, W))
    gt[rng.random((H, W)) < 0.1] = np.inf
    est = gt + rng.normal(0.0, 1.5, (H, W))
    est[rng.random((H, W)) < 0.1] = np.inf
    est[rng.random((H, W)) < 0.05] = -20.0  # clipped to 0
    est[rng.random((H, W)) < 0.05] = 500.0  # clipped to ndisp
    mask = np.where(rng.random((H, W)) < 0.8, 255, 128).astype(np.uint8)
    mask[np.isinf(gt)] = 0
    return gt, est, mask


@pytest.mark.parametrize("rounddisp", [0, 1])
def test_middlebury_equals_evaldisp(rounddisp, agreement):
    gt, est, mask = _middlebury_input()
    ndisp = 64.0
    e = np.where(np.isinf(est), np.nan, est)
    g = np.where(np.isinf(gt), np.nan, gt)
    d = 0.0
    for m in (None, mask):
        for th in (0.5, 1.0, 2.0, 4.0):
            ref = _evaldisp(est, gt, m, th, ndisp, rounddisp)
            r = middlebury(e, g, None if m is None else m == 255, ndisp=ndisp, round_disp=bool(rounddisp))
            badk = {0.5: r.bad_0_5_pct, 1.0: r.bad_1_0_pct, 2.0: r.bad_2_0_pct, 4.0: r.bad_4_0_pct}[th]
            ours = [badk, r.invalid_pct, badk + r.invalid_pct, r.avgerr_px]
            d = max(d, float(np.max(np.abs(np.array(ours) - ref))))
    assert d < 1e-12
    agreement(f"middlebury.evaldisp{'.round' if rounddisp else ''}",
              f"bad 0.5/1/2/4, invalid, totbad (%), avgerr (px), all and nonocc mask{', rounddisp' if rounddisp else ''}",
              "MiddEval3 `evaldisp.cpp` (transcribed)", "MiddEval3 SDK (avgErr of 10/2014)", "44x30, 10 % holes, 10 % out of [0, ndisp]", d)


def test_cli_reads_the_exports_mask_and_calib(tmp_path, agreement):
    """Our Middlebury export's files: disp0.pfm, mask0nocc.png (255/128/0) and calib.txt (ndisp)."""
    gt, est, mask = _middlebury_input(2)
    folder = tmp_path / "frame"
    folder.mkdir()
    write_pfm(folder / "disp0.pfm", gt.astype(np.float32))
    (folder / "mask0nocc.png").write_bytes(encode_png(mask))
    (folder / "calib.txt").write_text("cam0=[100 0 22; 0 100 15; 0 0 1]\ndoffs=0\nbaseline=100\nwidth=44\n"
                                      "height=30\nndisp=64\nisint=0\n")
    write_pfm(tmp_path / "est.pfm", est.astype(np.float32))
    out = tmp_path / "r.json"
    assert main(["disparity", str(tmp_path / "est.pfm"), str(folder / "disp0.pfm"), "--benchmark", "middlebury",
                 "--gt-noc", str(folder / "mask0nocc.png"), "--json", str(out), "--quiet"]) == 0
    doc = json.loads(out.read_text())
    r = doc["results"]["middlebury"]
    ref = _evaldisp(est.astype(np.float32).astype(float), gt.astype(np.float32).astype(float), mask, 2.0, 64.0, 0)
    d = max(abs(r["bad_2_0_pct"] - ref[0]), abs(r["invalid_pct"] - ref[1]), abs(r["avgerr_px"] - ref[3]))
    assert d < 1e-9 and doc["inputs"]["ndisp"] == 64.0
    agreement("middlebury.cli_export_files", "bad 2.0, invalid (%), avgerr (px) from the export's mask0nocc.png "
              "and calib.txt", "MiddEval3 `evaldisp.cpp` (transcribed)", "MiddEval3 SDK (avgErr of 10/2014)", "44x30 PFM files", d)

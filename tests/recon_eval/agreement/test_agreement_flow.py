"""Optical-flow metrics against transcriptions of the reference code:

* KITTI 2015 devkit (devkit_scene_flow): ``io_flow.h`` ``FlowImage::interpolateBackground``,
  ``readFlowField`` / ``writeFlowField`` and ``evaluate_scene_flow.cpp`` ``flowErrorsOutlier``
  (in its float arithmetic: exact 5 % ties on the PNG's 1/64 px grid are outliers there);
* MPI-Sintel: EPE = mean over pixels of sqrt(du^2 + dv^2) (Butler et al. 2012, the
  ``flow_code`` error measure), the speed bins s0-10 / s10-40 / s40+;
* Middlebury ``.flo`` (flow-code readme: "PIEH", width, height, (u, v) float32 row-major).
"""
from __future__ import annotations

import numpy as np

from recon_eval.metrics.flow import flow_metrics
from recon_eval.readers.flow import decode_kitti_flow, encode_kitti_flow, read_flow
from scenegen.dataset.codecs import encode_png
from scenegen.dataset.crossview import OCCLUDED, VISIBLE

ABS_THRESH, REL_THRESH = 3.0, 0.05


def _devkit_interpolate(fu, fv, valid):
    """io_flow.h interpolateBackground on (u, v, valid) planes (invalid flow stored as 0)."""
    fu, fv, valid = fu.copy(), fv.copy(), valid.copy()
    height_, width_ = valid.shape
    for v in range(height_):
        count = 0
        for u in range(width_):
            if valid[v, u]:
                if count >= 1:
                    u1, u2 = u - count, u - 1
                    if u1 > 0 and u2 < width_ - 1:
                        fu_ipol = min(fu[v, u1 - 1], fu[v, u2 + 1])
                        fv_ipol = min(fv[v, u1 - 1], fv[v, u2 + 1])
                        for u_curr in range(u1, u2 + 1):
                            fu[v, u_curr], fv[v, u_curr], valid[v, u_curr] = fu_ipol, fv_ipol, True
                count = 0
            else:
                count += 1
        for u in range(width_):
            if valid[v, u]:
                for u2 in range(u):
                    fu[v, u2], fv[v, u2], valid[v, u2] = fu[v, u], fv[v, u], True
                break
        for u in range(width_ - 1, -1, -1):
            if valid[v, u]:
                for u2 in range(u + 1, width_):
                    fu[v, u2], fv[v, u2], valid[v, u2] = fu[v, u], fv[v, u], True
                break
    for u in range(width_):
        for v in range(height_):
            if valid[v, u]:
                for v2 in range(v):
                    fu[v2, u], fv[v2, u], valid[v2, u] = fu[v, u], fv[v, u], True
                break
        for v in range(height_ - 1, -1, -1):
            if valid[v, u]:
                for v2 in range(v + 1, height_):
                    fu[v2, u], fv[v2, u], valid[v2, u] = fu[v, u], fv[v, u], True
                break
    return fu, fv


def _flow_errors_outlier(gu, gv, gvalid, eu, ev, evalid, obj):
    """evaluate_scene_flow.cpp flowErrorsOutlier: (errors, pixels) of bg, fg, all and all_result.
    FlowImage holds floats: every value and operation below is float32 (numpy scalars), and the
    comparisons are with the double constants ABS_THRESH and REL_THRESH (Python floats, the
    float32 value widened first: numpy would narrow a Python float to float32 instead)."""
    gu, gv, eu, ev = (np.asarray(a, np.float32) for a in (gu, gv, eu, ev))
    iu, iv = _devkit_interpolate(eu, ev, evalid)
    c = {k: [0, 0] for k in ("bg", "fg", "all", "all_r")}
    H, W = gvalid.shape
    for u in range(W):
        for v in range(H):
            fu, fv = gu[v, u] - iu[v, u], gv[v, u] - iv[v, u]  # float fu = F_gt.getFlowU - F_ipol.getFlowU
            f_dist = np.sqrt(fu * fu + fv * fv)  # float f_dist = sqrt(fu*fu+fv*fv)
            f_mag = np.sqrt(gu[v, u] * gu[v, u] + gv[v, u] * gv[v, u])  # getFlowMagnitude
            assert f_dist.dtype == f_mag.dtype == np.float32
            with np.errstate(divide="ignore", invalid="ignore"):
                f_err = float(f_dist) > ABS_THRESH and float(f_dist / f_mag) > REL_THRESH
            if gvalid[v, u]:
                key = "bg" if obj[v, u] == 0 else "fg"
                c[key][0] += f_err
                c[key][1] += 1
                c["all"][0] += f_err
                c["all"][1] += 1
                if evalid[v, u]:
                    c["all_r"][0] += f_err
                    c["all_r"][1] += 1
    return c


def _input(seed=0):
    rng = np.random.default_rng(seed)
    H, W = 20, 32
    g = rng.normal(0, 15, (H, W, 2))
    g[:, :3] = rng.normal(0, 1.0, (H, 3, 2))  # small flows: an unfilled (0, 0) estimate is close
    gvalid = rng.random((H, W)) > 0.2
    e = g + rng.normal(0, 2.5, (H, W, 2))
    evalid = rng.random((H, W)) > 0.25
    evalid[6] = False  # a wholly invalid interior row: the devkit leaves it at (0, 0)
    evalid[:, 0] = False
    obj = (rng.random((H, W)) < 0.3).astype(int)
    return g, gvalid, e, evalid, obj


def test_fl_equals_kitti_devkit(agreement):
    g, gvalid, e, evalid, obj = _input()
    c = _flow_errors_outlier(g[..., 0], g[..., 1], gvalid, np.where(evalid, e[..., 0], 0.0),
                             np.where(evalid, e[..., 1], 0.0), evalid, obj)
    r = flow_metrics([np.where(evalid[..., None], e, np.nan)], [np.where(gvalid[..., None], g, np.nan)],
                     None, [obj > 0])
    pct = lambda k: 100.0 * c[k][0] / c[k][1]  # noqa: E731
    d = float(np.max(np.abs(np.array([r.fl_bg_all_pct, r.fl_fg_all_pct, r.fl_all_all_pct, r.fl_all_all_est_pct])
                            - [pct("bg"), pct("fg"), pct("all"), pct("all_r")])))
    assert d == 0
    agreement("kitti.fl", "Fl bg/fg/all and the est row (%), a wholly invalid interior row",
              "KITTI 2015 devkit `interpolateBackground`, `flowErrorsOutlier` (transcribed)", "devkit_scene_flow (2015)",
              "32x20, 25 % holes", d)


def _ties(seed=0):
    """Flows on the KITTI PNG's 1/64 px grid where a third of the pixels err by exactly 5 % of
    the truth's magnitude, above 3 px: truth (20 k, 0) / 64, estimate (21 k, 0) / 64, or the error
    (3 k, 4 k) / 64 on a truth of magnitude 100 k / 64."""
    rng = np.random.default_rng(seed)
    H, W = 24, 32
    k = rng.integers(200, 1500, (H, W)).astype(float)
    g = np.stack([20 * k, np.zeros((H, W))], axis=2) / 64
    e = g + rng.integers(-400, 400, (H, W, 2)) / 64  # off the tie: mostly within 5 %, some outliers
    tie = rng.random((H, W)) < 1 / 3
    e[tie] = np.stack([21 * k, np.zeros((H, W))], axis=2)[tie] / 64
    diag = tie & (rng.random((H, W)) < 0.5)
    g[diag] = np.stack([60 * k, 80 * k], axis=2)[diag] / 64
    e[diag] = g[diag] + np.stack([3 * k, 4 * k], axis=2)[diag] / 64
    return g, e, tie


def test_fl_at_exact_five_percent_ties_equals_kitti_devkit(agreement):
    g, e, tie = _ties()
    ones, obj = np.ones(tie.shape, bool), np.zeros(tie.shape, int)
    c = _flow_errors_outlier(g[..., 0], g[..., 1], ones, e[..., 0], e[..., 1], ones, obj)
    r = flow_metrics([e], [g])
    assert c["all"][0] >= tie.sum() > 200  # every tie an outlier in the devkit
    d = abs(r.fl_all_all_pct - 100.0 * c["all"][0] / c["all"][1])
    assert d == 0
    agreement("kitti.fl.ties", "Fl all (%) with exact 5 % ties (the devkit's float quotient)",
              "KITTI 2015 devkit `flowErrorsOutlier` (transcribed, float)", "devkit_scene_flow (2015)",
              f"32x24 on the 1/64 px grid, {int(tie.sum())} ties", d)


def test_epe_and_sintel_bins_equal_the_definition(agreement):
    rng = np.random.default_rng(1)
    g = rng.normal(0, 25, (40, 60, 2))
    e = g + rng.normal(0, 1.0, g.shape)
    st = np.where(rng.random((40, 60)) < 0.8, VISIBLE, OCCLUDED).astype(np.uint8)
    r = flow_metrics([e], [g], [st])
    epe = np.sqrt(np.sum((e - g) ** 2, axis=2))
    speed = np.sqrt(np.sum(g ** 2, axis=2))
    ref = [epe.mean(), epe[st == VISIBLE].mean(), epe[st != VISIBLE].mean(), epe[speed < 10].mean(),
           epe[(speed >= 10) & (speed < 40)].mean(), epe[speed >= 40].mean()]
    ours = [r.epe_all_px, r.epe_noc_px, r.epe_occ_px, r.s0_10_px, r.s10_40_px, r.s40_plus_px]
    d = float(np.max(np.abs(np.array(ours) - ref)))
    assert d < 1e-12
    agreement("flow.epe_sintel", "EPE all / noc / occ, s0-10 / s10-40 / s40+ (px)",
              "MPI-Sintel EPE and speed bins (definition)", "Butler et al. 2012", "60x40 dense flow", d)


def _kitti_read(img_rgb16):
    """io_flow.h readFlowField: u = (red - 32768) / 64, v = (green - 32768) / 64, valid = blue > 0."""
    red, green, blue = (img_rgb16[..., k].astype(np.float32) for k in range(3))
    u = np.where(blue > 0, (red - 32768.0) / 64.0, 0)
    v = np.where(blue > 0, (green - 32768.0) / 64.0, 0)
    return u, v, blue > 0


def _kitti_write(u, v, valid):
    """io_flow.h writeFlowField: (uint16)max(min(f*64 + 32768, 65535), 0), blue = 1 if valid."""
    out = np.zeros(u.shape + (3,), np.uint16)
    for k, f in enumerate((u, v)):
        out[..., k] = np.where(valid, np.maximum(np.minimum(f.astype(np.float32) * 64.0 + 32768.0, 65535.0), 0.0), 0)
    out[..., 2] = valid
    return out


def test_kitti_flow_png_and_flo_equal_the_formats(tmp_path, agreement):
    rng = np.random.default_rng(2)
    f = rng.normal(0, 40, (16, 24, 2))
    f[0, 0] = [600.0, -600.0]  # beyond the PNG's range: clamped as the devkit does
    valid = rng.random((16, 24)) > 0.1
    png = encode_kitti_flow(np.where(valid[..., None], f, np.nan))
    ref = _kitti_write(f[..., 0], f[..., 1], valid)
    n_bad = int(np.sum(png != ref))
    (tmp_path / "f.png").write_bytes(encode_png(png))
    back = read_flow(tmp_path / "f.png")
    u, v, val = _kitti_read(ref)
    d = max(float(np.nanmax(np.abs(back[..., 0] - np.where(val, u, np.nan)))),
            float(np.nanmax(np.abs(back[..., 1] - np.where(val, v, np.nan)))))
    assert n_bad == 0 and d == 0 and np.array_equal(np.isfinite(back[..., 0]), val)
    # .flo as the Middlebury readme lays it out
    raw = b"PIEH" + np.array([24, 16], "<i4").tobytes() + f.astype("<f4").tobytes()
    (tmp_path / "f.flo").write_bytes(raw)
    d = max(d, float(np.max(np.abs(read_flow(tmp_path / "f.flo") - f.astype(np.float32)))))
    assert d == 0
    assert np.array_equal(decode_kitti_flow(png)[valid], ((png[valid, :2].astype(float) - 32768) / 64))
    agreement("flow.files", "KITTI flow PNG write / read and .flo read (px)",
              "KITTI devkit `writeFlowField` / `readFlowField`; Middlebury flow-code readme (transcribed)",
              "devkit_scene_flow (2015)", "24x16 flow", d)

"""``recon-eval disparity`` and ``recon-eval depth``: per-pixel maps against a truth map or a
dataset's truth (docs/metrics.md, "Stereo disparity", "Depth maps"). Map formats:
:func:`recon_eval.readers.registry.read_map`."""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from recon_eval.cli.common import dataset_view, needs_dataset_for_view, same_shape, stderr_progress
from recon_eval.cli.scored import scored
from recon_eval.errors import InputError, NotApplicable
from recon_eval.metrics.depth import CROPS, DepthAlignment, eigen_depth_metrics
from recon_eval.metrics.stereo import eth3d_two_view, kitti_d1, middlebury
from recon_eval.readers.kitti_png import read_kitti_obj_map
from recon_eval.readers.middlebury import CALIB, is_middlebury_mask, middlebury_ndisp, read_middlebury_mask
from recon_eval.readers.registry import find_view_map, read_map
from recon_eval.readers.scenegen_dataset import is_dataset, read_dataset
from recon_eval.report import plots
from recon_eval.report.html import Figure
from recon_eval.tasks.disparity_sign import reversed_sign_hint
from recon_eval.tasks.headlines import depth_headline


# --- disparity --------------------------------------------------------------------------------
def disparity_arguments(p) -> None:
    p.add_argument("est", help="estimated disparity (.png KITTI uint16, .pfm, .npy, .exr)")
    p.add_argument("gt", help="truth disparity (occ / all pixels), or a dataset folder with --view")
    p.add_argument("--view", help="dataset truth: the left view of a rectified stereo pair")
    p.add_argument("--right-view", help="dataset truth: its right view (default: the other member of the rig)")
    p.add_argument("--truth", choices=DISPARITY_TRUTHS, default="auto",
                   help="dataset truth: view = the views' own disparity (needs a rectified rig: equal pinhole "
                        "cameras side by side), rectified = the rectified stereo frame of the cross-view truth "
                        "(crossview/stereo/VIEW/disp_left.pfm, with its non-occlusion mask), auto (default) = view "
                        "when the rig is rectified, else rectified")
    p.add_argument("--gt-noc", help="non-occluded truth (KITTI) or non-occlusion mask source (.png/.pfm/.npy/.exr; "
                                    "a Middlebury mask0nocc.png: 255 = evaluated)")
    p.add_argument("--obj-map", help="KITTI foreground map PNG")
    p.add_argument("--benchmark", choices=["kitti", "middlebury", "eth3d"], default="kitti",
                   help="whose metrics: KITTI D1, Middlebury v3 bad-x/avgerr, ETH3D two-view (default kitti)")
    p.add_argument("--ndisp", type=float, help="Middlebury: clip estimates to [0, NDISP] as evaldisp does (default: "
                                               "ndisp of the calib.txt beside the truth file; for a dataset truth "
                                               "the export's max(16, 16 ceil(max d / 16)))")
    p.add_argument("--calib", help="Middlebury calib.txt giving ndisp (default: calib.txt beside the truth)")
    p.add_argument("--round-disp", action="store_true", help="Middlebury evaldisp's rounddisp: round the estimates")


def score_disparity(a):
    est = read_map(a.est, "disparity")
    gt_kind, noc_mask = "file", None
    if is_dataset(a.gt):
        ds = read_dataset(a.gt)
        view = dataset_view(ds, a.view, "a disparity truth")
        gt, noc_mask, gt_kind = dataset_disparity(ds, view, a.right_view, a.truth)
    else:
        needs_dataset_for_view(a)
        gt = read_map(a.gt, "disparity")
    same_shape(est, gt, a.est, a.gt)
    if hint := reversed_sign_hint(est, gt):  # ~100 % bad with no other clue
        print(f"recon-eval: warning: {a.method or a.est}: {hint}", file=sys.stderr)
    mask = None
    if a.gt_noc and a.benchmark != "kitti" and is_middlebury_mask(a.gt_noc):
        mask, noc = read_middlebury_mask(a.gt_noc), None
    elif a.gt_noc:
        noc = read_map(a.gt_noc, "disparity")
    else:  # the rectified frame's own non-occlusion mask (None for a view truth)
        noc = None if noc_mask is None else np.where(noc_mask, gt, np.nan)
    inputs = {"est": a.est, "gt": a.gt, "gt_kind": gt_kind, "gt_noc": a.gt_noc, "obj_map": a.obj_map,
              "benchmark": a.benchmark}
    if noc_mask is not None and not a.gt_noc:
        inputs["gt_noc"] = "the rectified frame's non-occlusion mask (disp_left_noc.png)"
    if a.benchmark == "kitti":
        obj = [read_kitti_obj_map(a.obj_map)] if a.obj_map else None
        res = {"kitti_d1": kitti_d1([est], [gt], None if noc is None else [noc], obj)}
    elif a.benchmark == "middlebury":
        mask = mask if noc is None else np.isfinite(noc)
        ndisp, source = _middlebury_ndisp(a, gt, gt_kind != "file")
        inputs.update(ndisp=ndisp, ndisp_source=source)
        res = {"middlebury": middlebury(est, gt, mask, ndisp=ndisp, round_disp=a.round_disp)}
    else:
        mask = mask if noc is None else np.isfinite(noc)
        res = {"eth3d": eth3d_two_view(est, gt, mask)}

    def figures():
        e = np.abs(est - gt)
        e = e[np.isfinite(gt)]
        return [
            Figure("Disparity error", plots.map_error_figure(est, gt, title="disparity", unit="px", error_clip=6.0),
                   "error colour scale capped at 6 px (twice KITTI's 3 px)"),
            Figure("Cumulative disparity error",
                   plots.cumulative_figure({"|d - d*| over truth pixels": e}, xlabel="disparity error (px)",
                                           title="cumulative error (missing estimates count as failures)",
                                           thresholds=(0.5, 1.0, 2.0, 3.0, 4.0), xmax=8.0)),
        ]

    return inputs, res, figures


#: Which dataset disparity truth ``disparity --truth`` scores against.
DISPARITY_TRUTHS = ("auto", "view", "rectified")


def dataset_disparity(ds, view: str, right: str | None, which: str):
    """(truth disparity (H, W) px, non-occlusion mask (H, W) bool or None, what it is) of a dataset
    view: the views' own truth (``which`` "view": a rectified rig), the rectified stereo frame of
    the cross-view truth ("rectified"), or the first of the two that exists ("auto")."""
    why = "--truth rectified"
    if which in ("auto", "view"):
        try:
            return ds.disparity(view, right), None, f"scenegen-dataset view {view}: fx * baseline / depth_z"
        except InputError as exc:
            if which == "view":
                raise
            why = str(exc)
    if right is not None:
        raise InputError(f"--right-view: a rectified stereo frame has its own right image; drop --right-view "
                         f"(the views' own truth failed: {why})")
    try:
        gt = ds.stereo_disparity(view)
    except NotApplicable as exc:
        if which == "rectified":
            raise InputError(str(exc)) from None
        raise InputError(f"{ds.root}: no disparity truth for view {view!r}: {why}; and no rectified stereo frame "
                         f"({exc})") from None
    return gt, ds.stereo_noc_mask(view), f"scenegen-dataset rectified stereo frame crossview/stereo/{view}"


def _middlebury_ndisp(a, gt, dataset_truth: bool):
    """(ndisp, where it came from) for Middlebury's clipping of the estimates."""
    if a.ndisp is not None:
        return a.ndisp, "--ndisp"
    if a.calib:
        return middlebury_ndisp(a.calib), a.calib
    if dataset_truth:  # what scenegen's Middlebury export writes into calib.txt for this truth
        fin = gt[np.isfinite(gt)]
        vmax = float(fin.max()) if fin.size else 0.0
        return float(max(16, 16 * math.ceil(vmax / 16))), "dataset truth: max(16, 16 ceil(max d / 16)) as the export"
    calib = Path(a.gt).parent / CALIB
    if calib.is_file():
        return middlebury_ndisp(calib), str(calib)
    return None, f"none: no {CALIB} beside the truth, estimates not clipped (evaldisp clips to ndisp; pass --calib)"


# --- depth ------------------------------------------------------------------------------------
def depth_arguments(p) -> None:
    p.add_argument("est", help="predicted z-depth (.npy, .pfm, .exr), metres; with a dataset truth also a folder "
                               "of <view>.npy|.pfm|.exr (a view without a file is a failed image)")
    p.add_argument("gt", help="truth depth (.npy, .pfm, .exr), metres, or a dataset folder (truth/<view>.exr depth_z)")
    p.add_argument("--view", action="append", help="dataset truth: view(s) to score (default: all; a single "
                                                   "estimate file needs exactly one)")
    p.add_argument("--alignment", choices=[a.value for a in DepthAlignment], default="none",
                   help="scale_shift_inverse: least squares in inverse depth, as MiDaS / DPT")
    p.add_argument("--min-depth", type=float, default=0.0, help="truth used where min < g < max (monodepth2: 1e-3)")
    p.add_argument("--max-depth", type=float, default=float("inf"), help="(monodepth2 on KITTI: 80)")
    p.add_argument("--no-clamp", action="store_true",
                   help="do not clamp the aligned predictions to [min-depth, max-depth] (monodepth2 does)")
    p.add_argument("--crop", choices=sorted(CROPS), help="evaluation crop: garg (monodepth2's) or eigen (BTS's)")
    p.add_argument("--pred-inverse", action="store_true",
                   help="the prediction is inverse depth up to scale and shift (MiDaS / DPT output); "
                        "needs --alignment scale_shift_inverse")


def _dataset_depths(a, ds):
    """(estimates, truths, views without an estimate, view names) against a dataset truth."""
    if Path(a.est).is_dir():
        views = a.view or list(ds.views)
        for v in views:
            ds.check_view(v)
        est_list, missing = [], []
        gt_list = [ds.depth(v) for v in views]
        progress = stderr_progress("depth maps (views)")
        for k, (v, g) in enumerate(zip(views, gt_list)):
            progress(k + 1, len(views))
            f = find_view_map(a.est, v)
            if f is None:
                missing.append(v)
                est_list.append(np.full_like(g, np.nan))
            else:
                est_list.append(read_map(str(f), "depth"))
                same_shape(est_list[-1], g, f, f"{a.gt} view {v}")
        return est_list, gt_list, missing, list(views)
    if a.view and len(a.view) > 1:
        raise InputError(f"{a.est}: one estimate file scores one view; pass a folder of <view> files for several")
    v = dataset_view(ds, a.view[0] if a.view else None, "a single depth estimate")
    est_list, gt_list = [read_map(a.est, "depth")], [ds.depth(v)]
    same_shape(est_list[0], gt_list[0], a.est, f"{a.gt} view {v}")
    return est_list, gt_list, [], [v]


def score_depth(a):
    names = None
    if is_dataset(a.gt):
        est_list, gt_list, missing, names = _dataset_depths(a, read_dataset(a.gt))
        gt_kind = "scenegen-dataset truth/<view>.exr depth_z"
    else:
        needs_dataset_for_view(a)
        est_list, gt_list, missing, gt_kind = [read_map(a.est, "depth")], [read_map(a.gt, "depth")], [], "file"
        same_shape(est_list[0], gt_list[0], a.est, a.gt)
    res = {"eigen": eigen_depth_metrics(est_list, gt_list, alignment=a.alignment,
                                        min_depth_m=a.min_depth, max_depth_m=a.max_depth, clamp=not a.no_clamp,
                                        crop=a.crop, pred_is_inverse=a.pred_inverse)}
    inputs = {"est": a.est, "gt": a.gt, "gt_kind": gt_kind, "views": names, "views_without_estimate": missing,
              "alignment": a.alignment, "clamp": not a.no_clamp, "crop": a.crop, "pred_inverse": a.pred_inverse}

    def figures():
        r = res["eigen"]
        figs, rel = [], {}
        for k, (e, g) in enumerate(zip(est_list, gt_list)):
            with np.errstate(invalid="ignore", divide="ignore"):
                if r.per_image_shift_inv_m is not None:  # aligned in inverse depth
                    q = e if a.pred_inverse else 1.0 / e
                    e_al = 1.0 / np.maximum(r.per_image_scale[k] * q + r.per_image_shift_inv_m[k], 1.0 / a.max_depth)
                else:
                    e_al = r.per_image_scale[k] * e + r.per_image_shift_m[k]
                if r.clamp:
                    e_al = np.clip(e_al, a.min_depth, a.max_depth)
            label = names[k] if names else Path(a.est).name
            if k < 8:
                figs.append(Figure(f"Depth error: {label}",
                                   plots.map_error_figure(e_al, g, title=f"{label} (alignment {a.alignment})", unit="m")))
            with np.errstate(invalid="ignore", divide="ignore"):
                ok = np.isfinite(g) & (g > a.min_depth) & (g < a.max_depth)
                rel[label] = np.where(np.isfinite(e_al[ok]) & (e_al[ok] > 0), np.abs(e_al[ok] - g[ok]) / g[ok], np.inf)
        if len(rel) > 6:
            rel = {"all images": np.concatenate(list(rel.values()))}
        figs.append(Figure("Cumulative relative depth error",
                           plots.cumulative_figure(rel, xlabel="|p - g| / g", title="cumulative abs_rel per pixel",
                                                   thresholds=(0.25,), xmax=0.5),
                           "missing predictions count as failures; 0.25 = a1's ratio bound"))
        return figs

    return inputs, res, figures


COMMANDS = {"disparity": scored(disparity_arguments, score_disparity),
            "depth": scored(depth_arguments, score_depth, lambda a, res: depth_headline(res["eigen"], a.alignment))}

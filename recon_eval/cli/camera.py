"""``recon-eval calibration`` and ``recon-eval pnp``: a camera's intrinsics, and one view's pose,
against a dataset's truth camera or truth files (docs/metrics.md, "Calibration and PnP")."""
from __future__ import annotations

import numpy as np

from recon_eval.cli.common import dataset_view, needs_dataset_for_view
from recon_eval.cli.scored import no_figures, scored
from recon_eval.errors import InputError
from recon_eval.metrics.calibration import (intrinsics_errors, mrcal_projection_diff, projection_difference,
                                            reprojection_rms)
from recon_eval.metrics.pnp import pnp_errors
from recon_eval.readers.npy import read_npy
from recon_eval.readers.opencv_calib import read_opencv_calibration
from recon_eval.readers.pose_file import read_pose
from recon_eval.readers.scenegen_dataset import is_dataset, read_dataset
from recon_eval.report import plots
from recon_eval.report.html import Figure
from recon_eval.tasks.headlines import calibration_headline


# --- calibration ------------------------------------------------------------------------------
def calibration_arguments(p) -> None:
    p.add_argument("est", help="estimated calibration, OpenCV YAML/JSON (camera_matrix/K, distortion_coefficients/D)")
    p.add_argument("gt", help="truth: a dataset folder (camera of --view) or an OpenCV YAML/JSON calibration")
    p.add_argument("--view", help="dataset truth: the view whose camera is the truth")
    p.add_argument("--camera", help="dataset truth: the spec camera that was calibrated (its first view gives the "
                                    "truth and the held-out points); default: the dataset's only camera")
    p.add_argument("--est-model", choices=["opencv", "fisheye"], help="override the estimate's distortion model")
    p.add_argument("--grid", type=int, nargs=2, metavar=("NX", "NY"),
                   help="projection-difference grid (default 60 x 40; mrcal_projection_diff: mrcal's 60 x "
                        "round(60 H / W))")
    p.add_argument("--focus-radius", type=float, default=-1.0,
                   help="mrcal_projection_diff: focus region radius in px (default min(W, H) / 6, as mrcal)")
    p.add_argument("--points", type=int, default=5000, help="dataset truth: held-out truth points for reprojection")


def score_calibration(a):
    est = read_opencv_calibration(a.est, model=a.est_model)
    inputs = {"est": a.est, "gt": a.gt, "est_model": est.model}
    held_out = None
    if is_dataset(a.gt):
        ds = read_dataset(a.gt)
        view = calibration_view(ds, a.view, a.camera)
        gt, pose = ds.camera(view)
        uv, X = ds.points_at_pixels(view, max_points=a.points)
        held_out = (pose, X, uv)
        inputs.update(view=view, camera=ds.view_info(view).get("camera_name"), gt_kind="scenegen-dataset camera",
                      held_out_points=len(X))
    else:
        needs_dataset_for_view(a)
        if a.camera:
            raise InputError(f"--camera needs a dataset truth; {a.gt} is not a dataset folder")
        gt = read_opencv_calibration(a.gt)
        inputs["gt_kind"] = "OpenCV calibration file"
    inputs["gt_model"] = gt.model
    if (gt.width, gt.height) != (est.width, est.height):
        raise InputError(f"{a.est}: image_width/image_height {est.width}x{est.height} differ from the truth's "
                         f"{gt.width}x{gt.height} ({a.gt})")
    nx, ny = a.grid or (60, 40)
    res = {"intrinsics": intrinsics_errors(est.K, gt.K),
           "projection_diff": projection_difference(gt, est, grid_nx=nx, grid_ny=ny),
           "projection_diff_rotation_fitted": projection_difference(gt, est, grid_nx=nx, grid_ny=ny, fit_rotation=True),
           "mrcal_projection_diff": mrcal_projection_diff(gt, est, gridn_width=a.grid[0] if a.grid else 60,
                                                          gridn_height=a.grid[1] if a.grid else None,
                                                          focus_radius=a.focus_radius)}
    if held_out is not None:
        pose, X, uv = held_out
        res["reprojection_held_out"] = reprojection_rms(est, pose.R, pose.t, X, uv)

    def figures():
        figs = []
        for key, what in (("projection_diff", "intrinsics only"), ("projection_diff_rotation_fitted", "rotation fitted")):
            r = res[key]
            figs.append(Figure(f"Projection difference ({what})",
                               plots.field_figure(r.diff_px, r.grid_u_px, r.grid_v_px, unit="px",
                                                  title=f"|project_est(unproject_gt(x)) - x|, {what}"),
                               f"mrcal-style; mean {r.mean_px:.4g} px, max {r.max_px:.4g} px"))
        return figs

    return inputs, res, figures


def calibration_view(ds, view: str | None, camera: str | None) -> str:
    """The view whose camera is the calibration truth: ``view``, else the first view of spec camera
    ``camera``, else the first view when every view has the same camera; InputError otherwise."""
    if view is not None:
        if camera is not None and ds.view_info(view).get("camera_name") != camera:
            raise InputError(f"--view {view} was taken with camera {ds.view_info(view).get('camera_name')!r}, "
                             f"not --camera {camera!r}")
        return ds.check_view(view)
    names = list(dict.fromkeys(ds.view_info(v).get("camera_name") for v in ds.views))
    if camera is not None:
        views = ds.views_of_camera(camera)
        if not views:
            raise InputError(f"{ds.root}: no view of camera {camera!r} (cameras: {', '.join(map(str, names))})")
        return views[0]
    first = ds.camera(ds.views[0])[0]
    if any(ds.camera(v)[0] != first for v in ds.views[1:]):
        raise InputError(f"{ds.root}: the views have different cameras ({', '.join(map(str, names))}): pass --camera "
                         f"NAME (or --view VIEW) for the one that was calibrated")
    return ds.views[0]


# --- PnP --------------------------------------------------------------------------------------
def pnp_arguments(p) -> None:
    p.add_argument("est", help="estimated pose (.json {R, t} / 3x4 / 4x4, .npy, .txt)")
    p.add_argument("gt", help="truth: a dataset folder (pose of --view) or a pose file")
    p.add_argument("--view", help="dataset truth: the view (required when the dataset has several)")
    p.add_argument("--est-convention", choices=["cam_from_world", "world_from_cam"], default="cam_from_world",
                   help="what a bare matrix in EST holds (default: OpenCV solvePnP's cam_from_world)")
    p.add_argument("--gt-convention", choices=["cam_from_world", "world_from_cam"], default="cam_from_world",
                   help="how a truth pose file's R, t are meant (default cam_from_world: x_cam = R x_world + t)")
    p.add_argument("--points", type=int, default=5000, help="dataset truth: held-out truth points for reprojection")
    p.add_argument("--points-world", help="non-dataset truth: (N, 3) .npy world points for reprojection")
    p.add_argument("--pixels", help="non-dataset truth: (N, 2) .npy pixels observing them")
    p.add_argument("--calib", help="non-dataset truth: camera for reprojection (OpenCV YAML/JSON)")


def score_pnp(a):
    R_est, t_est = read_pose(a.est, a.est_convention)
    inputs = {"est": a.est, "gt": a.gt, "est_convention": a.est_convention}
    cam = X = uv = None
    if is_dataset(a.gt):
        ds = read_dataset(a.gt)
        view = dataset_view(ds, a.view, "a PnP truth")
        cam, pose = ds.camera(view)
        R_gt, t_gt = pose.R, pose.t
        uv, X = ds.points_at_pixels(view, max_points=a.points)
        inputs.update(view=view, gt_kind="scenegen-dataset cameras.json", held_out_points=len(X))
    else:
        needs_dataset_for_view(a)
        R_gt, t_gt = read_pose(a.gt, a.gt_convention)
        if not (np.all(np.isfinite(R_gt)) and np.all(np.isfinite(t_gt))):
            raise InputError(f"{a.gt}: the truth pose has non-finite values")
        inputs.update(gt_kind="pose file", gt_convention=a.gt_convention)
        if a.points_world or a.pixels or a.calib:
            if not (a.points_world and a.pixels and a.calib):
                raise InputError("reprojection needs all of --points-world, --pixels and --calib")
            X, uv, cam = read_npy(a.points_world, (None, 3)), read_npy(a.pixels, (None, 2)), read_opencv_calibration(a.calib)
            if len(X) != len(uv):
                raise InputError(f"{a.points_world} ({len(X)} points) and {a.pixels} ({len(uv)} pixels) differ in length")
    return inputs, {"pnp": pnp_errors(R_est, t_est, R_gt, t_gt, cam=cam, points_world=X, pixels=uv)}, no_figures


def calibration_metrics(a, res) -> dict:
    """``metrics`` of ``calibration --json``: the names a calibration run gives the same numbers."""
    return calibration_headline(res["intrinsics"], res["projection_diff"], res.get("reprojection_held_out"))


COMMANDS = {"calibration": scored(calibration_arguments, score_calibration, calibration_metrics),
            "pnp": scored(pnp_arguments, score_pnp)}

"""Headline metric names shared by a task's runs and its scoring command (docs/ci.md, "Metric
paths"): one name per number, so one gate file gates a method run with ``recon-eval run`` (built-in
or ``--command``) and the same estimate scored by hand with the command's ``--json``. The F's are
in :mod:`recon_eval.tasks.fmatrix_pair` (:func:`~recon_eval.tasks.fmatrix_pair.headline`)."""
from __future__ import annotations

import numpy as np

#: Optical flow (:class:`recon_eval.metrics.flow.FlowResult` field -> headline name).
FLOW = {"epe_all_px": "epe_all_px", "epe_noc_px": "epe_noc_px", "epe_occ_px": "epe_occ_px",
        "fl_all_all_pct": "fl_all_all_pct", "s0_10_px": "s0_10_px"}
#: Depth maps (:class:`recon_eval.metrics.depth.DepthResult` field -> headline name); the
#: alignment's name in front (``median.abs_rel``) unless it is ``none``.
DEPTH = {"abs_rel": "abs_rel", "sq_rel_m": "sq_rel_m", "rmse_m": "rmse_m", "a1": "a1", "coverage": "coverage"}


def flow_headline(r) -> dict:
    """The headline of a :class:`~recon_eval.metrics.flow.FlowResult`."""
    return {name: getattr(r, field) for field, name in FLOW.items()}


def depth_headline(r, alignment: str) -> dict:
    """The headline of a :class:`~recon_eval.metrics.depth.DepthResult` under ``alignment``."""
    pre = "" if alignment == "none" else f"{alignment}."
    return {pre + name: getattr(r, field) for field, name in DEPTH.items()}


def calibration_headline(intrinsics, projection_diff, held_out=None, prefix: str = "") -> dict:
    """The headline of an estimated calibration: its intrinsics errors
    (:class:`~recon_eval.metrics.calibration.IntrinsicsErrors`), projection difference and
    held-out reprojection RMS (None: not measured), ``prefix`` (a camera's name) in front."""
    m = {"fx_rel_err": intrinsics.fx_rel_err, "fy_rel_err": intrinsics.fy_rel_err,
         "cx_abs_err_px": intrinsics.cx_abs_err_px, "cy_abs_err_px": intrinsics.cy_abs_err_px,
         "proj_diff_rms_px": projection_diff.rms_px, "proj_diff_max_px": projection_diff.max_px}
    if held_out is not None:
        m["held_out_reproj_rms_px"] = held_out.rms_px
    return {prefix + k: v for k, v in m.items()}


def poses_headline(ape, alignment: str) -> dict:
    """The headline of camera poses against the truth (an :class:`~recon_eval.metrics.poses.ApeResult`):
    as the SfM runs name them after their Sim(3) alignment (registration ratio, max and median
    rotation error; unregistered cameras inf), ``<alignment>.`` in front for another alignment."""
    rot = [float(x) for x in ape.rot_err_deg]
    pre = "" if alignment == "sim3" else f"{alignment}."
    return {pre + "registration_ratio": ape.registration_ratio,
            pre + "max_rot_err_deg": max(rot) if rot else float("inf"),
            pre + "median_rot_err_deg": float(np.median(rot)) if rot else float("inf")}


def trajectory_headline(ape, rpe, alignment: str) -> dict:
    """The headline of a camera trajectory: :func:`poses_headline`, then evo's APE and RPE
    translation RMSE (finite entries; unregistered cameras count in the ratio and the max)."""
    pre = "" if alignment == "sim3" else f"{alignment}."
    return {**poses_headline(ape, alignment), pre + "ape_trans_rmse_m": ape.trans_stats_m.rmse,
            pre + "rpe_trans_rmse_m": rpe.trans_stats_m.rmse}


def tracks_headline(res: dict) -> dict:
    """The headline of point tracks (TAP-Vid's mean over the streams, ``score_streams``' result)."""
    mean = res["mean_over_streams"]
    return {k: mean[k] for k in ("average_jaccard", "average_pts_within", "occlusion_accuracy")}


def normals_headline(r, group: str) -> dict:
    """The headline of a normal map's errors over ``group`` (all, or an object's name; a
    :class:`~recon_eval.metrics.normals.NormalResult`): DiLiGenT's mean and median angular error
    and the share within 10 degrees, ``<group>.`` in front (photometric stereo runs, ``recon-eval
    normals``)."""
    return {f"{group}.mean_ae_deg": r.mean_ae_deg, f"{group}.median_ae_deg": r.median_ae_deg,
            f"{group}.within_10deg": r.within_10deg}


#: Tanks and Temples threshold of the cloud headline, metres (``recon-eval cloud``'s default --tau).
CLOUD_TAU_M = 0.01


def cloud_headline(res: dict) -> dict:
    """The headline of a point cloud or mesh against the truth (``recon-eval cloud``'s result
    groups at its defaults): Tanks and Temples at 1 cm and the Chamfer-L1 distance. (The SfM runs'
    ``cloud_precision_at_1cm`` is another measure: their sparse points against the mesh's vertices,
    without downsampling.)"""
    tt, ch = res[f"tanks_and_temples@{CLOUD_TAU_M:g}m"], res["chamfer"]
    return {"tnt_precision_at_1cm": tt.precision, "tnt_recall_at_1cm": tt.recall, "tnt_fscore_at_1cm": tt.fscore,
            "chamfer_l1_m": ch.chamfer_l1_m}

"""What the odometry runners (:mod:`.stereo_vo`, :mod:`.inertial`) share: the rectified stereo
frames of a sequence in time order with their truth, the IMU stream, and the scoring of an
estimated trajectory through the TUM files written.

Raw output: ``trajectory.txt`` (TUM: ``timestamp tx ty tz qx qy qz qw``, world_from_cam of the
left rectified camera, the frame's ``time_s``) and, beside it, ``groundtruth.txt`` (the truth in
the same form), so that ``recon-eval poses trajectory.txt groundtruth.txt --alignment se3
--kitti-lengths ...`` gives the same figures. Scored (docs/metrics.md, "Visual odometry"): evo's
APE and RPE (consecutive frames) after an SE(3) alignment (a metric stereo or inertial estimate:
no scale), and the KITTI odometry devkit's t_err (%) / r_err (deg / 100 m) over segments of
:data:`ODOMETRY_LENGTH_FRACTIONS` of the truth's path length (KITTI's 100 .. 800 m are longer than
these sequences; the lengths used are in the result), rounded to 0.1 m.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.errors import NotApplicable
from recon_eval.metrics.association import associate_evo
from recon_eval.metrics.kitti_odometry import kitti_odometry
from recon_eval.metrics.poses import ape, rpe
from recon_eval.readers.tum import read_tum
from recon_eval.runners.common import out_path
from recon_eval.tasks.stamped_trajectory import associated_poses
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.rotation import quat_wxyz_from_matrix

#: KITTI segment lengths as fractions of the truth's path (rpg_trajectory_evaluation's 10 .. 50 %).
ODOMETRY_LENGTH_FRACTIONS = (0.1, 0.2, 0.3, 0.4, 0.5)
#: TUM association of the written trajectory with the truth, seconds (evo --t_max_diff).
MAX_TIME_DIFF_S = 0.01


@dataclass(frozen=True)
class FrameSequence:
    """The rectified stereo frames of one rig in time order: ``frames`` (StereoFrame),
    ``times_s`` (N,), ``world_from_cam`` (N Rigid3, the left rectified camera's truth)."""

    frames: tuple
    times_s: np.ndarray
    world_from_cam: tuple


def stereo_sequence(ds) -> FrameSequence:
    """The dataset's rectified stereo frames sorted by time (NotApplicable with fewer than 3, or
    without a clock)."""
    frames = ds.crossview.stereo_frames() if ds.crossview.index is not None else ()
    if len(frames) < 3:
        raise NotApplicable(f"{ds.root}: {len(frames)} rectified stereo frames; odometry needs a sequence of 3 or more")
    infos = [ds.view_info(f.left_view) for f in frames]
    if any("time_s" not in i for i in infos):
        raise NotApplicable(f"{ds.root}: the stereo frames have no clock (time_s); odometry needs a sequence")
    order = np.argsort([i["time_s"] for i in infos], kind="stable")
    frames = tuple(frames[k] for k in order)
    return FrameSequence(frames, np.array([infos[k]["time_s"] for k in order], float),
                         tuple(ds.read(lambda f: f.cam_from_world("left").inverse(), f) for f in frames))


def imu_stream(ds):
    """The dataset's first IMU stream, or None."""
    names = ds.streams.of_kind("imu")
    return ds.streams[names[0]] if names else None


def tum_text(times_s, world_from_cam) -> str:
    """TUM lines (``%.6f`` stamps, quaternion scalar last)."""
    rows = []
    for t, T in zip(times_s, world_from_cam):
        w, x, y, z = quat_wxyz_from_matrix(T.R)
        rows.append(f"{t:.6f} " + " ".join(repr(float(v)) for v in (*T.t, x, y, z, w)) + "\n")
    return "".join(rows)


def path_length_m(world_from_cam) -> float:
    c = np.stack([T.t for T in world_from_cam])
    return float(np.sum(np.linalg.norm(np.diff(c, axis=0), axis=1)))


def score_trajectory(out, out_dir, seq: FrameSequence, estimate: list) -> None:
    """Write ``trajectory.txt`` and ``groundtruth.txt`` (module docstring), read them back and
    score them into ``out``: results ``ape``, ``rpe``, ``kitti_odometry``; metrics
    ``ape_trans_rmse_m``, ``ape_rot_rmse_deg``, ``rpe_trans_rmse_m``, ``kitti_t_err_pct``,
    ``kitti_r_err_deg_per_100m``, ``final_drift_pct`` (end-point error over the path)."""
    est_path, gt_path = out_path(out_dir, "trajectory.txt"), out_path(out_dir, "groundtruth.txt")
    est_path.write_text(tum_text(seq.times_s, estimate))
    gt_path.write_text(tum_text(seq.times_s, seq.world_from_cam))
    out.raw_files += ["trajectory.txt", "groundtruth.txt"]
    est, gt = read_tum(est_path), read_tum(gt_path)
    e, g = associated_poses(est, gt, associate_evo(gt.timestamps_s, est.timestamps_s, MAX_TIME_DIFF_S, 0.0))
    length = path_length_m(seq.world_from_cam)
    lengths = tuple(sorted({round(f * length, 1) for f in ODOMETRY_LENGTH_FRACTIONS} - {0.0}))
    a, r = ape(e, g, alignment="origin"), rpe(e, g, alignment="origin")
    k = kitti_odometry(e, g, lengths_m=lengths)
    end = Rigid3(est.poses.R_cam_from_world[-1], est.poses.t_cam_from_world[-1]).inverse().t
    drift = float(np.linalg.norm(end - seq.world_from_cam[-1].t))
    out.results.update({"ape": a, "rpe": r, "kitti_odometry": k})
    out.notes.update({"path_length_m": length, "kitti_lengths_m": list(lengths), "alignment": "origin",
                      "frames": len(seq.frames)})
    out.metrics.update({"ape_trans_rmse_m": a.trans_stats_m.rmse, "ape_rot_rmse_deg": a.rot_stats_deg.rmse,
                        "rpe_trans_rmse_m": r.trans_stats_m.rmse, "kitti_t_err_pct": k.t_err_pct,
                        "kitti_r_err_deg_per_100m": k.r_err_deg_per_100m,
                        "final_drift_pct": 100.0 * drift / length})

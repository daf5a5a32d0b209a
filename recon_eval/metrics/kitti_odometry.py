"""KITTI odometry benchmark errors (Geiger et al., CVPR 2012; devkit_odometry
``cpp/evaluate_odometry.cpp``): translation error (%) and rotation error (deg / 100 m) averaged
over all sub-sequences of 100, 200, ..., 800 m starting every 10 frames.

For each first frame f (0, 10, 20, ...) and length L, the last frame l is the first frame whose
travelled truth distance from f exceeds L (``lastFrameFromSegmentLength``: ``dist[l] > dist[f] +
L``, the distances from the truth's camera centres, ``trajectoryDistances``); with world_from_cam
poses P (estimate) and Q (truth), ``E = (P_f^-1 P_l)^-1 (Q_f^-1 Q_l)``; the segment's errors are
``|t(E)| / L`` and ``angle(R(E)) / L``; the benchmark's numbers are their means over all segments
(``saveStats``), x100 for % and in deg per 100 m. No alignment, as the devkit (optional here).
A segment with an unregistered camera at either end is a failure: counted, not scored.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.errors import InputError
from recon_eval.metrics.align import Sim3
from recon_eval.metrics.poses import Poses, match_poses, pose_alignment
from scenegen.geometry.rotation import rotation_angle_rad

KITTI_LENGTHS_M = (100.0, 200.0, 300.0, 400.0, 500.0, 600.0, 700.0, 800.0)
KITTI_STEP_FRAMES = 10


@dataclass(frozen=True)
class KittiOdometryResult:
    """KITTI odometry t_err / r_err (devkit ``saveStats``) and the per-length means (its plots)."""

    t_err_pct: float  # mean over segments of |t(E)| / L, x100; NaN without a segment
    r_err_deg_per_100m: float  # mean over segments of angle(R(E)) / L, in deg per 100 m
    lengths_m: tuple
    per_length_t_err_pct: tuple  # mean per length; NaN with fewer than 3 segments (the devkit's rule)
    per_length_r_err_deg_per_100m: tuple
    n_segments: int
    n_failed_segments: int  # segments with an unregistered camera at an end
    step_frames: int
    alignment: str
    tgt_from_src: Sim3
    benchmark: str = "kitti_odometry"


def kitti_odometry(est: Poses, gt: Poses, *, lengths_m=KITTI_LENGTHS_M, step_frames: int = KITTI_STEP_FRAMES,
                   alignment: str = "none") -> KittiOdometryResult:
    """The KITTI odometry devkit's errors of ``est`` against ``gt`` (frames in truth order, matched
    by name; see the module docstring). ``alignment``: one of
    :data:`recon_eval.metrics.poses.POSE_ALIGNMENTS` (the devkit uses none)."""
    lengths = tuple(float(x) for x in lengths_m)
    if not lengths or not all(x > 0 for x in lengths) or step_frames < 1:
        raise InputError("kitti_odometry: lengths must be > 0 metres and step_frames >= 1")
    m = match_poses(est, gt)
    T = pose_alignment(m, gt, alignment)
    N = len(gt.names)
    Qw = np.tile(np.eye(4), (N, 1, 1))
    Qw[:, :3, :3] = np.swapaxes(gt.R_cam_from_world, 1, 2)
    Qw[:, :3, 3] = gt.centers_world
    Pw = np.full((N, 4, 4), np.nan)
    reg = m.registered
    if np.any(reg):
        R, t = T.cam_from_tgt(m.R_est[reg], m.t_est[reg])
        Pw[reg] = np.eye(4)
        Pw[reg, :3, :3] = np.swapaxes(R, 1, 2)
        Pw[reg, :3, 3] = -np.einsum("nji,nj->ni", R, t)
    dist = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(Qw[:, :3, 3], axis=0), axis=1))]
    seg_len, seg_t, seg_r, failed = [], [], [], 0
    for f in range(0, N, step_frames):
        for L in lengths:
            after = np.flatnonzero(dist[f:] > dist[f] + L)
            if len(after) == 0:
                continue
            last = f + int(after[0])
            if not (reg[f] and reg[last]):
                failed += 1
                continue
            dg = np.linalg.inv(Qw[f]) @ Qw[last]
            dr = np.linalg.inv(Pw[f]) @ Pw[last]
            E = np.linalg.inv(dr) @ dg
            seg_len.append(L)
            seg_t.append(np.linalg.norm(E[:3, 3]) / L)
            seg_r.append(float(rotation_angle_rad(E[:3, :3])) / L)
    seg_len, seg_t, seg_r = np.array(seg_len), np.array(seg_t), np.array(seg_r)
    deg100 = 100.0 * 180.0 / np.pi

    def per_length(v, scale):
        out = []
        for L in lengths:
            sel = np.abs(seg_len - L) < 1.0
            out.append(float(np.mean(v[sel]) * scale) if sel.sum() > 2.5 else float("nan"))
        return tuple(out)

    nan = float("nan")
    return KittiOdometryResult(
        float(np.mean(seg_t) * 100.0) if len(seg_t) else nan, float(np.mean(seg_r) * deg100) if len(seg_r) else nan,
        lengths, per_length(seg_t, 100.0), per_length(seg_r, deg100), len(seg_t), failed, int(step_frames),
        str(alignment.value if hasattr(alignment, "value") else alignment), T,
    )

"""KITTI odometry t_err / r_err against the devkit's ``evaluate_odometry.cpp`` (devkit_odometry,
``trajectoryDistances``, ``lastFrameFromSegmentLength``, ``rotationError``, ``translationError``,
``calcSequenceErrors`` with lengths 100..800 and step 10, ``saveStats``), transcribed; it does not
install from a registry (evo never added it)."""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from recon_eval.metrics.kitti_odometry import kitti_odometry
from recon_eval.metrics.poses import Poses

LENGTHS = [100, 200, 300, 400, 500, 600, 700, 800]


def _devkit(poses_gt, poses_result):
    dist = [0.0]
    for i in range(1, len(poses_gt)):
        d = poses_gt[i - 1][:3, 3] - poses_gt[i][:3, 3]
        dist.append(dist[i - 1] + np.sqrt(np.sum(d * d)))
    err = []
    for first_frame in range(0, len(poses_gt), 10):
        for length in LENGTHS:
            last_frame = next((i for i in range(first_frame, len(dist)) if dist[i] > dist[first_frame] + length), -1)
            if last_frame == -1:
                continue
            pose_delta_gt = np.linalg.inv(poses_gt[first_frame]) @ poses_gt[last_frame]
            pose_delta_result = np.linalg.inv(poses_result[first_frame]) @ poses_result[last_frame]
            pose_error = np.linalg.inv(pose_delta_result) @ pose_delta_gt
            a, b, c = pose_error[0, 0], pose_error[1, 1], pose_error[2, 2]
            d = 0.5 * (a + b + c - 1.0)
            r_err = np.arccos(max(min(d, 1.0), -1.0))
            t_err = np.sqrt(np.sum(pose_error[:3, 3] ** 2))
            err.append((r_err / length, t_err / length))
    err = np.array(err)
    return err[:, 1].mean(), err[:, 0].mean(), len(err)


def _drive(n=1400, seed=0):
    rng = np.random.default_rng(seed)
    yaw = np.cumsum(rng.normal(0, 0.01, n))
    step = np.stack([np.sin(yaw), 0.01 * rng.normal(size=n), np.cos(yaw)], 1) * 1.1  # ~1.1 m per frame
    c = np.cumsum(step, axis=0)
    Q = np.tile(np.eye(4), (n, 1, 1))
    Q[:, :3, :3] = Rotation.from_euler("y", yaw[:, None]).as_matrix()
    Q[:, :3, 3] = c
    # the estimate: odometry with a small drift in every increment
    P = [np.eye(4)]
    for k in range(1, n):
        inc = np.linalg.inv(Q[k - 1]) @ Q[k]
        noise = np.eye(4)
        noise[:3, :3] = Rotation.from_rotvec(rng.normal(0, 2e-4, 3)).as_matrix()
        noise[:3, 3] = rng.normal(0, 0.01, 3) + [0, 0, 0.004]
        P.append(P[-1] @ inc @ noise)
    return Q, np.array(P)


def _poses(T, names):
    R = np.swapaxes(T[:, :3, :3], 1, 2)
    return Poses(names, R, -np.einsum("nij,nj->ni", R, T[:, :3, 3]))


def test_t_err_r_err_equal_the_devkit(agreement):
    Q, P = _drive()
    names = tuple(f"{k:06d}" for k in range(len(Q)))
    t_ref, r_ref, n_ref = _devkit(list(Q), list(P))
    r = kitti_odometry(_poses(P, names), _poses(Q, names))
    assert r.n_segments == n_ref > 100
    d = max(abs(r.t_err_pct - 100 * t_ref) / (100 * t_ref),
            abs(r.r_err_deg_per_100m - np.degrees(r_ref) * 100) / (np.degrees(r_ref) * 100))
    assert d < 1e-9
    agreement("kitti.odometry", "t_err (%), r_err (deg/100 m), relative",
              "KITTI odometry devkit `evaluate_odometry.cpp` (transcribed)", "devkit_odometry (2012)",
              "1400 frames, 1.5 km drive, drifting odometry", d)

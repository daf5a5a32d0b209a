"""Inertial dead reckoning: the IMU-only baseline of the odometry runners (``imu-dead-reckoning``)
and the gyroscope's rotation between two frames (the stereo odometry's outlier check,
:mod:`.stereo_vo`).

:func:`integrate_imu` is classical RK4 on the state (q_wxyz, v, p) of
``q' = q (x) (0, w) / 2``, ``v' = R(q) f + g``, ``p' = v`` (``f`` the specific force in the IMU
frame, ``g`` :data:`scenegen.geometry.conventions.GRAVITY_WORLD_MPS2`), one step of ``2 dt`` per
sample pair: the inputs at a step's start, middle and end are the samples k, k + 1, k + 2, so no
sample is interpolated; the state is known at every other sample. Its error on the noise-free
readings of a 10 s hand-held spline at 200 Hz is below 1 mm (tests/recon_eval/runners/
test_runners_inertial.py); a real IMU's noise and bias make the drift the baseline measures.

The baseline (:func:`dead_reckoning`) starts from the true state of the IMU at its first sample
(position, velocity, orientation from the stream's truth fields), integrates the MEASURED
readings, and reports the left rectified camera's pose at each stereo frame: ``world_from_imu @
imu_from_cam``, the extrinsic ``imu_from_cam`` taken from the truth at the first frame (a
calibrated rig).
"""
from __future__ import annotations

import numpy as np

from recon_eval.errors import NotApplicable
from recon_eval.runners.common import RunOutput
from recon_eval.runners.odometry_common import FrameSequence, imu_stream, score_trajectory, stereo_sequence
from scenegen.geometry.conventions import GRAVITY_WORLD_MPS2
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.rotation import matrix_from_quat_wxyz, matrix_from_rotvec


def _quat_mul(p, q):
    w1, x1, y1, z1 = p
    w2, x2, y2, z2 = q
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def integrate_imu(q0_wxyz, v0_mps, p0_m, gyro_rad_s, accel_mps2, dt_s: float):
    """RK4 dead reckoning (module docstring) of N samples (N, 3) every ``dt_s`` seconds from the
    state at sample 0. Returns ``(index (M,), R (M, 3, 3) world_from_imu, p (M, 3) m)`` at the
    samples 0, 2, 4, ... (M = (N - 1) // 2 + 1)."""
    def deriv(q, v, w, f):
        return 0.5 * _quat_mul(q, np.r_[0.0, w]), matrix_from_quat_wxyz(q) @ f + GRAVITY_WORLD_MPS2, v

    q, v, p, h = np.asarray(q0_wxyz, float), np.asarray(v0_mps, float), np.asarray(p0_m, float), 2 * dt_s
    Rs, ps = [matrix_from_quat_wxyz(q)], [p]
    for k in range(0, len(gyro_rad_s) - 2, 2):
        k1 = deriv(q, v, gyro_rad_s[k], accel_mps2[k])
        k2 = deriv(q + h / 2 * k1[0], v + h / 2 * k1[1], gyro_rad_s[k + 1], accel_mps2[k + 1])
        k3 = deriv(q + h / 2 * k2[0], v + h / 2 * k2[1], gyro_rad_s[k + 1], accel_mps2[k + 1])
        k4 = deriv(q + h * k3[0], v + h * k3[1], gyro_rad_s[k + 2], accel_mps2[k + 2])
        p = p + h / 6 * (k1[2] + 2 * k2[2] + 2 * k3[2] + k4[2])
        v = v + h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        q = q + h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        q = q / np.linalg.norm(q)
        Rs.append(matrix_from_quat_wxyz(q))
        ps.append(p)
    return np.arange(0, 2 * len(ps), 2), np.stack(Rs), np.stack(ps)


def gyro_rotation(stamps_s, gyro_rad_s, t0_s: float, t1_s: float) -> np.ndarray:
    """(3, 3) ``imu(t0)_from_imu(t1)``: the gyroscope readings between t0 and t1 chained as
    exp(w dt) over the sample intervals (each interval's rate the mean of its two ends), the
    intervals clipped to [t0, t1]."""
    R = np.eye(3)
    s = np.asarray(stamps_s, float)
    for k in range(len(s) - 1):
        a, b = max(s[k], t0_s), min(s[k + 1], t1_s)
        if b > a:
            R = R @ matrix_from_rotvec(0.5 * (gyro_rad_s[k] + gyro_rad_s[k + 1]) * (b - a))
    return R


def dead_reckoning(seq: FrameSequence, imu) -> list:
    """world_from_cam (Rigid3) of the left rectified camera at each frame of ``seq`` from the IMU
    stream ``imu`` (module docstring); the frame's state is the integrated state at the even
    sample nearest to its time."""
    stamps = imu.field("stamp_s")
    if len(stamps) < 3:
        raise NotApplicable("the IMU stream has fewer than 3 samples")
    dt = float(np.median(np.diff(stamps)))
    q0 = imu.field("quat_wxyz")[0]
    idx, R, p = integrate_imu(q0, imu.field("velocity_mps")[0], imu.field("position_m")[0],
                              imu.field("gyro_rad_s"), imu.field("accel_mps2"), dt)
    k0 = int(np.argmin(np.abs(stamps[idx] - seq.times_s[0])))
    # the extrinsic from the truth at the first frame: the IMU's true pose there, the camera's
    world_from_imu_f0 = Rigid3(matrix_from_quat_wxyz(imu.field("quat_wxyz")[idx[k0]]), imu.field("position_m")[idx[k0]])
    imu_from_cam = world_from_imu_f0.inverse() @ seq.world_from_cam[0]
    out = []
    for t in seq.times_s:
        j = int(np.argmin(np.abs(stamps[idx] - t)))
        out.append(Rigid3(R[j], p[j]) @ imu_from_cam)
    return out


def run(ds, out_dir, options) -> RunOutput:
    """``imu-dead-reckoning``: the IMU-only baseline (module docstring), scored as the stereo
    odometry (:func:`.odometry_common.score_trajectory`)."""
    seq = stereo_sequence(ds)
    imu = imu_stream(ds)
    if imu is None:
        raise NotApplicable(f"{ds.root}: no IMU stream (an 'imu' member in a rig)")
    out = RunOutput()
    score_trajectory(out, out_dir, seq, dead_reckoning(seq, imu))
    return out

"""The course's stereo odometry pipeline (``stereo-vo-pnp``), OpenCV throughout, on the dataset's
rectified pairs (``crossview/stereo/<left view>/``: rectification is given, both sides one ideal
pinhole with baseline B):

1. corners: ``cv2.goodFeaturesToTrack`` on the previous left image (:data:`MAX_CORNERS`, quality
   0.01, :data:`MIN_DISTANCE_PX` apart);
2. spatial matching along rows: pyramidal Lucas-Kanade (``cv2.calcOpticalFlowPyrLK``) from the
   left image to the right one, kept where the match stays on its row (|dv| <= :data:`ROW_TOL_PX`)
   and the disparity ``d = u_l - u_r`` lies in [:data:`MIN_DISPARITY_PX`, width / 2];
3. stereo triangulation in the previous left camera: ``Z = f B / d``, ``X = (u - cx) Z / f``,
   ``Y = (v - cy) Z / f``;
4. temporal matching: the same LK from the previous left image to the current one, kept where the
   backward track returns within :data:`FB_TOL_PX`;
5. motion against the previous frame: ``cv2.solvePnPRansac`` (EPnP minimal sets, reprojection
   threshold :data:`RANSAC_PX`, 0.999 confidence, OpenCV's RNG seeded per frame) then
   ``cv2.solvePnPRefineLM`` on the inliers: ``cam_k_from_cam_k-1``; chained from the truth pose of
   the first frame (world_from_cam_k = world_from_cam_k-1 @ cam_k-1_from_cam_k);
6. outlier detection against the odometry (the mapping robot's check), with what the dataset has:
   the IMU's gyroscope (a step whose rotation differs from the gyroscope's rotation between the two
   frame times by more than :data:`GYRO_GATE_DEG`) and the wheel odometry (a step whose length
   differs from the distance the integrated wheel odometry travelled between the two frame times by
   more than :data:`WHEEL_GATE_M` plus :data:`WHEEL_GATE_FRACTION` of it); such a step, or one with
   fewer than :data:`MIN_INLIERS` PnP inliers, is rejected and replaced by the gyroscope's rotation
   (else the previous step's) and the previous accepted step's translation (constant velocity),
   scaled to the wheels' distance where there are wheels. The camera-IMU extrinsic rotation is
   taken from the truth at the first frame (a calibrated rig).

Scored as :func:`.odometry_common.score_trajectory` (SE(3) APE / RPE, KITTI t_err / r_err).
"""
from __future__ import annotations

import cv2
import numpy as np

from recon_eval.runners.common import RunOutput
from recon_eval.runners.inertial import gyro_rotation
from recon_eval.runners.odometry_common import imu_stream, score_trajectory, stereo_sequence
from scenegen.geometry.color import to_grey8
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.rotation import matrix_from_quat_wxyz, matrix_from_rotvec, rotation_angle_rad

MAX_CORNERS = 600
MIN_DISTANCE_PX = 4
ROW_TOL_PX = 1.0
MIN_DISPARITY_PX = 0.5
FB_TOL_PX = 0.5
RANSAC_PX = 0.5
MIN_INLIERS = 12
GYRO_GATE_DEG = 1.0
WHEEL_GATE_M = 0.05
WHEEL_GATE_FRACTION = 0.1
LK = dict(winSize=(11, 11), maxLevel=3, criteria=(cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 40, 0.01))


def stereo_points(left, right, f: float, cx: float, cy: float, baseline_m: float):
    """Steps 1-3: ``(uv (N, 2) px in the left image, xyz (N, 3) m in the left camera)``."""
    corners = cv2.goodFeaturesToTrack(left, MAX_CORNERS, 0.01, MIN_DISTANCE_PX)
    if corners is None:
        return np.zeros((0, 2), np.float32), np.zeros((0, 3))
    uv = corners.reshape(-1, 2).astype(np.float32)
    uv_r, st, _ = cv2.calcOpticalFlowPyrLK(left, right, uv, None, **LK)
    d = uv[:, 0] - uv_r[:, 0]
    ok = (st.ravel() == 1) & (np.abs(uv_r[:, 1] - uv[:, 1]) <= ROW_TOL_PX) & (d >= MIN_DISPARITY_PX) & \
         (d <= left.shape[1] / 2)
    uv, d = uv[ok], d[ok].astype(np.float64)
    z = f * baseline_m / d
    xyz = np.column_stack([(uv[:, 0] - cx) * z / f, (uv[:, 1] - cy) * z / f, z])
    return uv, xyz


def track(prev, cur, uv):
    """Step 4: (kept (N,) bool, uv in ``cur`` (N, 2)) with the forward-backward check."""
    if len(uv) == 0:
        return np.zeros(0, bool), uv
    fwd, st1, _ = cv2.calcOpticalFlowPyrLK(prev, cur, uv, None, **LK)
    back, st2, _ = cv2.calcOpticalFlowPyrLK(cur, prev, fwd, None, **LK)
    ok = (st1.ravel() == 1) & (st2.ravel() == 1) & (np.linalg.norm(back - uv, axis=1) <= FB_TOL_PX)
    return ok, fwd


def pnp_step(xyz, uv, K, seed: int):
    """Step 5: (cam_k_from_cam_k-1 as Rigid3 or None, number of inliers)."""
    if len(xyz) < 6:
        return None, 0
    cv2.setRNGSeed(seed)
    ok, rvec, tvec, inl = cv2.solvePnPRansac(xyz, uv.astype(np.float64), K, None, iterationsCount=300,
                                             reprojectionError=RANSAC_PX, confidence=0.999, flags=cv2.SOLVEPNP_EPNP)
    if not ok or inl is None or len(inl) < 6:
        return None, 0 if inl is None else len(inl)
    i = inl.ravel()
    rvec, tvec = cv2.solvePnPRefineLM(xyz[i], uv[i].astype(np.float64), K, None, rvec, tvec)
    return Rigid3(matrix_from_rotvec(rvec.ravel()), tvec.ravel()), len(i)


def _cam_rotations_from_gyro(ds, seq):
    """``rot(k) -> (3, 3) cam_k-1_from_cam_k`` from the gyroscope, or None without an IMU."""
    imu = imu_stream(ds)
    if imu is None:
        return None
    stamps, gyro = imu.field("stamp_s"), imu.field("gyro_rad_s")
    k0 = int(np.argmin(np.abs(stamps - seq.times_s[0])))
    R_imu_from_cam = matrix_from_quat_wxyz(imu.field("quat_wxyz")[k0]).T @ seq.world_from_cam[0].R
    return lambda k: R_imu_from_cam.T @ gyro_rotation(stamps, gyro, seq.times_s[k - 1], seq.times_s[k]) @ R_imu_from_cam


def _wheel_distances(ds, seq):
    """``dist(k) -> m`` travelled by the integrated wheel odometry from frame k - 1 to frame k (its
    planar path length, interpolated in time), or None without a wheel odometry stream."""
    names = ds.streams.of_kind("wheel_odometry")
    if not names:
        return None
    s = ds.streams[names[0]]
    stamps, xy = s.field("stamp_s"), s.field("odom_pose")[:, :2]
    travelled = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(xy, axis=0), axis=1))]
    return lambda k: float(np.interp(seq.times_s[k], stamps, travelled) - np.interp(seq.times_s[k - 1], stamps, travelled))


def _fallback(R_gyro, last_step, wheel_m):
    """The replacement of a rejected step (module docstring, step 6), or None with nothing to go on."""
    if R_gyro is None and last_step is None:
        return None
    t = last_step.t if last_step is not None else np.zeros(3)
    if wheel_m is not None and np.linalg.norm(t) > 0:
        t = t / np.linalg.norm(t) * wheel_m
    return Rigid3(R_gyro if R_gyro is not None else last_step.R, t)


def run(ds, out_dir, options) -> RunOutput:
    """``stereo-vo-pnp`` (module docstring)."""
    seq = stereo_sequence(ds)
    cam = seq.frames[0].camera
    K = np.asarray(cam.K, float)
    f, cx, cy, B = float(K[0, 0]), float(K[0, 2]), float(K[1, 2]), float(seq.frames[0].baseline_m)
    gyro, wheels = _cam_rotations_from_gyro(ds, seq), _wheel_distances(ds, seq)
    images = [tuple(to_grey8(ds.read(fr.image, s)) for s in ("left", "right")) for fr in seq.frames]
    est, last_step, rejected, inliers = [seq.world_from_cam[0]], None, [], []
    for k in range(1, len(seq.frames)):
        (L0, R0), (L1, _) = images[k - 1], images[k]
        uv0, xyz = stereo_points(L0, R0, f, cx, cy, B)
        kept, uv1 = track(L0, L1, uv0)
        step, n = pnp_step(xyz[kept], uv1[kept], K, seed=k)
        inliers.append(n)
        prev_from_cur = step.inverse() if step is not None else None
        R_gyro = gyro(k) if gyro is not None else None
        wheel_m = wheels(k) if wheels is not None else None
        bad = prev_from_cur is None or n < MIN_INLIERS or (
            R_gyro is not None and np.degrees(rotation_angle_rad(prev_from_cur.R.T @ R_gyro)) > GYRO_GATE_DEG) or (
            wheel_m is not None and abs(np.linalg.norm(prev_from_cur.t) - wheel_m) > WHEEL_GATE_M + WHEEL_GATE_FRACTION * wheel_m)
        if bad:
            rejected.append(k)
            fallback = _fallback(R_gyro, last_step, wheel_m)
            prev_from_cur = fallback if fallback is not None else Rigid3.identity()  # nothing to go on: hold
        else:
            last_step = prev_from_cur
        est.append(est[-1] @ prev_from_cur)
    out = RunOutput()
    out.notes.update({"rejected_steps": rejected, "gyro_check": gyro is not None, "wheel_check": wheels is not None,
                      "median_pnp_inliers": float(np.median(inliers))})
    score_trajectory(out, out_dir, seq, est)
    out.metrics["rejected_step_fraction"] = len(rejected) / (len(seq.frames) - 1)
    return out

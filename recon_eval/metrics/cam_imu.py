"""Camera-IMU calibration against the truth: the extrinsic ``cam_from_imu`` and the time offset
of each camera, as Kalibr reports them (``T_cam_imu``, ``timeshift_cam_imu``: ``t_imu = t_cam +
shift``).

Errors: rotation angle of ``R_est^T R_gt`` (deg); translation error of the camera's centre in the
IMU frame, ``|t(imu_from_cam_est) - t(imu_from_cam_gt)|`` (m: the lever arm a VIO system
integrates; ``t(cam_from_imu)`` mixes in the rotation error); the time offset's signed error
``shift_est - shift_gt`` (s) and its magnitude.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.arrays import as_float_array
from recon_eval.errors import InputError
from scenegen.geometry.rotation import rotation_error_rad


@dataclass(frozen=True)
class CamImuError:
    camera: str
    rot_err_deg: float
    trans_err_m: float  # camera centre in the IMU frame
    time_offset_err_s: float  # signed: estimated shift - true shift
    abs_time_offset_err_s: float


def cam_imu_error(camera: str, cam_from_imu_est, shift_est_s: float, cam_from_imu_gt, shift_gt_s: float) -> CamImuError:
    """The errors of one camera's calibration (module docstring); transforms (4, 4)."""
    Te = as_float_array(cam_from_imu_est, "cam_from_imu estimate", (4, 4))
    Tg = as_float_array(cam_from_imu_gt, "cam_from_imu truth", (4, 4))
    if not (np.isfinite(shift_est_s) and np.isfinite(shift_gt_s)):
        raise InputError(f"{camera}: time offsets must be finite")
    c_est = -Te[:3, :3].T @ Te[:3, 3]  # t(imu_from_cam) = the camera centre in the IMU frame
    c_gt = -Tg[:3, :3].T @ Tg[:3, 3]
    dt = float(shift_est_s) - float(shift_gt_s)
    return CamImuError(camera, float(np.degrees(rotation_error_rad(Te[:3, :3], Tg[:3, :3]))),
                       float(np.linalg.norm(c_est - c_gt)), dt, abs(dt))

"""VIO systems' settings files with the true calibration of an EuRoC export's rig
(:mod:`scenegen.export.euroc`), both OpenCV FileStorage YAML (``%YAML:1.0``), as those systems
read them with ``cv::FileStorage``:

* ``orbslam3.yaml``: ORB-SLAM3's settings (``File.version: "1.0"``): ``Camera.type: "PinHole"``,
  ``Camera1.fx .. p2`` (and ``Camera2`` for a stereo rig), ``Camera.width/height/fps/RGB``,
  ``Stereo.T_c1_c2`` (cam1-from-cam2: the right camera to the left), ``Stereo.ThDepth``,
  ``IMU.T_b_c1`` (body = IMU from cam1), ``IMU.NoiseGyro/NoiseAcc/GyroWalk/AccWalk`` (Kalibr's
  continuous-time values, the unit ORB-SLAM3's EuRoC settings use), ``IMU.Frequency``, and the ORB
  extractor and viewer values of its ``Examples/Stereo-Inertial/EuRoC.yaml``. ORB-SLAM3 has no
  camera-IMU time offset: with one other than 0 the summary says so. A stereo rig whose cameras
  differ in size (ORB-SLAM3 takes one ``Camera.width``) gets no file, and the reason;
* ``openvins/kalibr_imucam_chain.yaml``, ``openvins/kalibr_imu_chain.yaml`` and
  ``openvins/estimator_config.yaml`` as OpenVINS's ``config/euroc_mav`` folder holds them:
  per camera ``T_imu_cam`` (IMU-from-camera), ``cam_overlaps``, ``camera_model: pinhole``,
  ``distortion_model: radtan``, ``distortion_coeffs``, ``intrinsics``, ``resolution``,
  ``rostopic``, ``timeshift_cam_imu`` (``t_imu = t_cam + shift``, OpenVINS's ``calib_camimu_dt``);
  ``imu0`` with ``T_i_b``, the four noise values, ``model: "kalibr"`` with identity ``Tw``,
  ``R_IMUtoGYRO``, ``Ta``, ``R_IMUtoACC`` and zero ``Tg`` (an ideal IMU: no scale, misalignment or
  g-sensitivity), ``update_rate``; the estimator file names them and states the camera count,
  stereo use and standard gravity; calibration of extrinsics, intrinsics and time offset off
  (the values are the truth).
"""
from __future__ import annotations

import numpy as np

from scenegen.export.common import fmt
from scenegen.export.euroc_calib import radtan_parameters
from scenegen.geometry.conventions import GRAVITY_WORLD_MPS2

HEADER = "%YAML:1.0\n"
#: ORB-SLAM3's Examples/Stereo-Inertial/EuRoC.yaml values that are not calibration.
ORB_EXTRACTOR = (("nFeatures", "1200"), ("scaleFactor", "1.2"), ("nLevels", "8"), ("iniThFAST", "20"),
                 ("minThFAST", "7"))
VIEWER = (("KeyFrameSize", "0.05"), ("KeyFrameLineWidth", "1.0"), ("GraphLineWidth", "0.9"), ("PointSize", "2.0"),
          ("CameraSize", "0.08"), ("CameraLineWidth", "3.0"), ("ViewpointX", "0.0"), ("ViewpointY", "-0.7"),
          ("ViewpointZ", "-3.5"), ("ViewpointF", "500.0"))


def _opencv_matrix(name: str, T) -> str:
    data = ", ".join(fmt(x) for x in np.asarray(T, float).ravel())
    return f"{name}: !!opencv-matrix\n   rows: 4\n   cols: 4\n   dt: f\n   data: [{data}]\n"


def _rows(T, indent: str = "    ") -> str:
    return "".join(f"{indent}- [{', '.join(fmt(x) for x in row)}]\n" for row in np.asarray(T, float))


def orbslam3_yaml(rig, root: str) -> tuple[bytes | None, str]:
    """(the file, a note for the summary) of ORB-SLAM3's settings (module docstring)."""
    cams = rig.cameras[:2]
    if len({(c.camera.width, c.camera.height) for c in cams}) > 1:
        return None, "none: the stereo cameras differ in size; ORB-SLAM3 takes one Camera.width/height"
    out = [HEADER, 'File.version: "1.0"\n', 'Camera.type: "PinHole"\n']
    for k, cam in enumerate(cams, start=1):
        (fx, fy, cx, cy), (k1, k2, p1, p2) = radtan_parameters(cam.camera, f"{root}: camera of rig member "
                                                                            f"{cam.member!r}")
        out += [f"Camera{k}.{n}: {fmt(v)}\n" for n, v in (("fx", fx), ("fy", fy), ("cx", cx), ("cy", cy), ("k1", k1),
                                                           ("k2", k2), ("p1", p1), ("p2", p2))]
    fps = 1e9 / float(np.median(np.diff(cams[0].stamps_ns))) if len(cams[0].stamps_ns) > 1 else 0.0
    out += [f"Camera.width: {cams[0].camera.width}\n", f"Camera.height: {cams[0].camera.height}\n",
            f"Camera.fps: {fmt(fps)}\n", "Camera.RGB: 1\n"]
    if len(cams) == 2:
        out += ["Stereo.ThDepth: 60.0\n",
                _opencv_matrix("Stereo.T_c1_c2", (cams[0].imu_from_cam.inverse() @ cams[1].imu_from_cam).matrix)]
    imu = rig.imu
    out += [_opencv_matrix("IMU.T_b_c1", cams[0].imu_from_cam.matrix),
            f"IMU.NoiseGyro: {fmt(imu.get('gyroscope_noise_density', 0.0))}\n",
            f"IMU.NoiseAcc: {fmt(imu.get('accelerometer_noise_density', 0.0))}\n",
            f"IMU.GyroWalk: {fmt(imu.get('gyroscope_random_walk', 0.0))}\n",
            f"IMU.AccWalk: {fmt(imu.get('accelerometer_random_walk', 0.0))}\n",
            f"IMU.Frequency: {fmt(imu['rate_hz'])}\n"]
    out += [f"ORBextractor.{k}: {v}\n" for k, v in ORB_EXTRACTOR] + [f"Viewer.{k}: {v}\n" for k, v in VIEWER]
    mode = "stereo-inertial" if len(cams) == 2 else "monocular-inertial"
    note = mode if rig.time_offset_s == 0 else f"{mode}; its camera-IMU time offset {rig.time_offset_s} s is not " \
                                               "modelled by ORB-SLAM3"
    return "".join(out).encode(), note


def openvins_files(rig, root: str) -> dict[str, bytes]:
    """OpenVINS's three settings files (module docstring), by relative path."""
    cams = []
    for k, cam in enumerate(rig.cameras):
        intr, dist = radtan_parameters(cam.camera, f"{root}: camera of rig member {cam.member!r}")
        others = [j for j in range(len(rig.cameras)) if j != k]
        cams.append(f"cam{k}:\n  T_imu_cam: # IMU from camera: R_CtoI, p_CinI\n" + _rows(cam.imu_from_cam.matrix) +
                    f"  cam_overlaps: [{', '.join(map(str, others))}]\n  camera_model: pinhole\n"
                    f"  distortion_coeffs: [{', '.join(fmt(x) for x in dist)}]\n  distortion_model: radtan\n"
                    f"  intrinsics: [{', '.join(fmt(x) for x in intr)}] # fu, fv, cu, cv\n"
                    f"  resolution: [{cam.camera.width}, {cam.camera.height}]\n  rostopic: /cam{k}/image_raw\n"
                    f"  timeshift_cam_imu: {fmt(0.0 - rig.time_offset_s)}\n")
    eye, zero = _rows(np.eye(3)), _rows(np.zeros((3, 3)))
    noise = "".join(f"  {k}: {fmt(rig.imu.get(k, 0.0))}\n" for k in (
        "accelerometer_noise_density", "accelerometer_random_walk", "gyroscope_noise_density", "gyroscope_random_walk"))
    imu = (HEADER + "\nimu0:\n  T_i_b:\n" + _rows(np.eye(4)) + noise + "  rostopic: /imu0\n  time_offset: 0.0\n"
           f"  update_rate: {fmt(rig.imu['rate_hz'])}\n  model: \"kalibr\"\n"
           f"  Tw:\n{eye}  R_IMUtoGYRO:\n{eye}  Ta:\n{eye}  R_IMUtoACC:\n{eye}  Tg:\n{zero}")
    n = len(rig.cameras)
    estimator = (HEADER + "\n# scenegen truth: the calibration in the kalibr_*.yaml files is exact\n"
                 f"use_stereo: {'true' if n > 1 else 'false'}\nmax_cameras: {n}\n"
                 "calib_cam_extrinsics: false\ncalib_cam_intrinsics: false\ncalib_cam_timeoffset: false\n"
                 f"gravity_mag: {fmt(-GRAVITY_WORLD_MPS2[2])}\n"
                 'relative_config_imu: "kalibr_imu_chain.yaml"\nrelative_config_imucam: "kalibr_imucam_chain.yaml"\n')
    return {"openvins/kalibr_imucam_chain.yaml": (HEADER + "\n" + "".join(cams)).encode(),
            "openvins/kalibr_imu_chain.yaml": imu.encode(), "openvins/estimator_config.yaml": estimator.encode()}

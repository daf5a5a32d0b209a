"""The calibration files of an EuRoC MAV export (:mod:`scenegen.export.euroc`):

* ``mav0/camN/sensor.yaml`` and ``mav0/imu0/sensor.yaml`` as the EuRoC MAV dataset writes them
  (ASL dataset format): ``sensor_type``, ``T_BS`` (``cols: 4, rows: 4, data:`` the 4x4
  body-from-sensor transform, row-major; body = the IMU), ``rate_hz``; a camera's ``resolution``
  ``[width, height]``, ``camera_model: pinhole``, ``intrinsics [fu, fv, cu, cv]``,
  ``distortion_model: radial-tangential``, ``distortion_coefficients [k1, k2, p1, p2]``; the IMU's
  four continuous-time noise values (Kalibr's model, the values the IMU was simulated with).
* ``camchain.yaml`` and ``imu.yaml`` in Kalibr's formats (Kalibr wiki, "YAML formats"): per
  camera ``camera_model: pinhole``, ``intrinsics``, ``distortion_model: radtan``,
  ``distortion_coeffs``, ``resolution``, ``rostopic``, ``T_cam_imu`` (cam-from-IMU, the inverse of
  T_BS), ``timeshift_cam_imu`` (``t_imu = t_cam + shift``: the IMU stamps a sample taken at the
  true time t with ``t - time_offset_s``, so the shift is ``-time_offset_s``) and, from cam1 on,
  ``T_cn_cnm1`` (camN-from-camN-1); ``imu0:`` with ``T_i_b`` (identity: the body is the IMU), the
  four noise values, ``rostopic``, ``update_rate``.

Pixels: OpenCV's convention (the top-left pixel's centre is (0, 0)), Kalibr's and EuRoC's too. A
camera these formats cannot hold (a fisheye model, a skew, k3 or OpenCV's rational and thin-prism
terms) is refused: its images are distorted by terms radial-tangential has not.
"""
from __future__ import annotations

import numpy as np

from scenegen.export.common import fmt
from scenegen.export.errors import ExportError
from scenegen.geometry.camera.models import camera_model


def radtan_parameters(camera, where: str) -> tuple[list[float], list[float]]:
    """([fu, fv, cu, cv], [k1, k2, p1, p2]) of a camera, or an ExportError naming what EuRoC's
    pinhole + radial-tangential cannot express."""
    if camera_model(camera.model).opencv_fisheye:
        raise ExportError(f"{where}: the {camera.model} camera model; EuRoC and Kalibr's radtan hold a pinhole with "
                          "k1 k2 p1 p2")
    if camera.skew != 0.0:
        raise ExportError(f"{where}: skew {camera.skew:g} px; EuRoC's pinhole intrinsics [fu, fv, cu, cv] have none")
    K, dist = camera.to_opencv()
    d = np.zeros(max(4, len(dist)))
    d[:len(dist)] = dist
    if np.any(d[4:] != 0):
        raise ExportError(f"{where}: distortion beyond k1 k2 p1 p2 (OpenCV coefficients {[float(x) for x in d]}); "
                          "EuRoC's radial-tangential model holds k1 k2 p1 p2 only")
    return [K[0, 0], K[1, 1], K[0, 2], K[1, 2]], [float(x) for x in d[:4]]


def _list(values) -> str:
    return "[" + ", ".join(fmt(v) for v in values) + "]"


def _matrix_rows(T, indent: str) -> str:
    return "".join(f"{indent}- {_list(row)}\n" for row in np.asarray(T))


def _t_bs(T) -> str:
    return f"T_BS:\n  cols: 4\n  rows: 4\n  data: {_list(np.asarray(T).ravel())}\n"


def _rate_hz(stamps_ns) -> float:
    dt = np.diff(np.asarray(stamps_ns, np.int64)) / 1e9
    return float(1.0 / np.median(dt)) if len(dt) else 0.0


def camera_sensor_yaml(index: int, cam, where: str) -> bytes:
    """``mav0/cam<index>/sensor.yaml``; rate_hz = 1 / the median frame interval (0: one frame)."""
    intr, dist = radtan_parameters(cam.camera, where)
    return ("# General sensor definitions.\nsensor_type: camera\n"
            f"comment: scenegen rig member {cam.member!r}, OpenCV pixels (top-left pixel centre (0, 0))\n\n"
            "# Sensor extrinsics wrt. the body-frame.\n" + _t_bs(cam.imu_from_cam.matrix) +
            "\n# Camera specific definitions.\n"
            f"rate_hz: {fmt(_rate_hz(cam.stamps_ns))}\n"
            f"resolution: [{cam.camera.width}, {cam.camera.height}]\n"
            "camera_model: pinhole\n"
            f"intrinsics: {_list(intr)} #fu, fv, cu, cv\n"
            "distortion_model: radial-tangential\n"
            f"distortion_coefficients: {_list(dist)} #k1, k2, p1, p2\n").encode()


_NOISE = (("gyroscope_noise_density", "rad / s / sqrt(Hz)"), ("gyroscope_random_walk", "rad / s^2 / sqrt(Hz)"),
          ("accelerometer_noise_density", "m / s^2 / sqrt(Hz)"), ("accelerometer_random_walk", "m / s^3 / sqrt(Hz)"))


def imu_sensor_yaml(rig) -> bytes:
    """``mav0/imu0/sensor.yaml``: T_BS identity (the IMU is the body), rate and noise values."""
    noise = "".join(f"{k}: {fmt(rig.imu.get(k, 0.0))} # [ {unit} ]\n" for k, unit in _NOISE)
    return ("# General sensor definitions.\nsensor_type: imu\n"
            f"comment: scenegen IMU {rig.stream.sensor!r}, stream {rig.stream.name!r}\n\n"
            "# Sensor extrinsics wrt. the body-frame.\n" + _t_bs(np.eye(4)) +
            f"rate_hz: {fmt(rig.imu['rate_hz'])}\n\n"
            "# inertial sensor noise model parameters (static)\n" + noise).encode()


def camchain_yaml(rig, root: str) -> bytes:
    """Kalibr's ``camchain.yaml`` (imu-camchain form: with T_cam_imu and timeshift_cam_imu)."""
    out = []
    for k, cam in enumerate(rig.cameras):
        intr, dist = radtan_parameters(cam.camera, f"{root}: camera of rig member {cam.member!r}")
        cam_from_imu = cam.imu_from_cam.inverse()
        out.append(f"cam{k}:\n  camera_model: pinhole\n  intrinsics: {_list(intr)}\n  distortion_model: radtan\n"
                   f"  distortion_coeffs: {_list(dist)}\n  resolution: [{cam.camera.width}, {cam.camera.height}]\n"
                   f"  rostopic: /cam{k}/image_raw\n  T_cam_imu:\n" + _matrix_rows(cam_from_imu.matrix, "  "))
        if k:
            prev_from_imu = rig.cameras[k - 1].imu_from_cam.inverse()
            out.append("  T_cn_cnm1:\n" + _matrix_rows((cam_from_imu @ prev_from_imu.inverse()).matrix, "  "))
        out.append(f"  timeshift_cam_imu: {fmt(0.0 - rig.time_offset_s)}\n")
    return "".join(out).encode()


def kalibr_imu_yaml(rig) -> bytes:
    """Kalibr's ``imu.yaml`` (imu0 block as Kalibr's calibrators write it)."""
    noise = "".join(f"  {k}: {fmt(rig.imu.get(k, 0.0))}\n" for k, _ in sorted(_NOISE, key=lambda n: n[0]))
    return ("imu0:\n  T_i_b:\n" + _matrix_rows(np.eye(4), "  ") + noise +
            f"  rostopic: /imu0\n  update_rate: {fmt(rig.imu['rate_hz'])}\n").encode()

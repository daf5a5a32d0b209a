"""EuRoC MAV (ASL dataset format) with Kalibr calibration files, from a rig of cameras and an IMU
(docs/crossview.md, "Exports"; the rig: :mod:`scenegen.export.euroc_rig`).

Timestamps are integer nanoseconds of the scene clock (its ``t = 0`` is the epoch; rounded to the
nearest ns). The body frame ``B`` (EuRoC's ``S`` of the ground truth) is the IMU; ``R`` is the
world (Z-up, OpenCV camera axes for the cameras).

* ``mav0/camN/data/<timestamp>.png`` (the rendered 8-bit image, as rendered: EuRoC's own are
  grey) and ``mav0/camN/data.csv`` (``#timestamp [ns],filename``), one folder per camera member
  of the rig in member order (cam0, cam1 for a stereo pair); ``sensor.yaml`` beside
  (:mod:`scenegen.export.euroc_calib`).
* ``mav0/imu0/data.csv``: ``#timestamp [ns],w_RS_S_x [rad s^-1],...,a_RS_S_z [m s^-2]``, the
  measured gyroscope and accelerometer values at the IMU's own stamps (``stamp_s``: the true time
  minus the member's ``time_offset_s``); ``sensor.yaml`` beside.
* ``mav0/state_groundtruth_estimate0/data.csv``: at each IMU sample's true time, ``p_RS_R``
  (the IMU origin in the world), ``q_RS`` (world_from_imu, w first), ``v_RS_R`` (world frame) and
  the biases in the measurements ``b_w_RS_S``, ``b_a_RS_S`` (IMU frame).
* ``camchain.yaml`` and ``imu.yaml``: Kalibr's files for the same rig.
* ``orbslam3.yaml`` and ``openvins/``: ORB-SLAM3's and OpenVINS's settings with the same true
  calibration (:mod:`scenegen.export.vio_settings`).
"""
from __future__ import annotations

from scenegen.dataset.codecs import encode_png
from scenegen.export.common import fmt, write
from scenegen.export.errors import ExportError
from scenegen.export.euroc_calib import camchain_yaml, camera_sensor_yaml, imu_sensor_yaml, kalibr_imu_yaml
from scenegen.export.euroc_rig import ns, vio_rig
from scenegen.export.vio_settings import openvins_files, orbslam3_yaml
from scenegen.geometry.color import to_uint8

IMU_HEAD = ("#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
            "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]")
GROUNDTRUTH_HEAD = ("#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
                    "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], "
                    "b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], "
                    "b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]")


def _csv(head: str, stamps, *columns) -> bytes:
    rows = (",".join([str(int(s)), *(fmt(x) for c in columns for x in c[k])]) for k, s in enumerate(stamps))
    return (head + "\n" + "".join(r + "\n" for r in rows)).encode()


def _stamps(times_s, what: str, root) -> list[int]:
    stamps = ns(times_s)
    if len(stamps) and stamps[0] < 0:
        raise ExportError(f"{root}: {what} starts at a negative time; EuRoC timestamps are unsigned nanoseconds")
    return stamps.tolist()


def export(ds, dest, progress=None) -> dict:
    rig = vio_rig(ds)
    root = str(ds.root)
    s = rig.stream
    files = 0
    calib = {f"mav0/cam{k}/sensor.yaml": camera_sensor_yaml(k, cam, f"{root}: camera of rig member {cam.member!r}")
             for k, cam in enumerate(rig.cameras)}  # refused before any image is written
    calib.update({"mav0/imu0/sensor.yaml": imu_sensor_yaml(rig), "camchain.yaml": camchain_yaml(rig, root),
                  "imu.yaml": kalibr_imu_yaml(rig)})
    orbslam3, orbslam3_note = orbslam3_yaml(rig, root)
    if orbslam3 is not None:
        calib["orbslam3.yaml"] = orbslam3
    calib.update(openvins_files(rig, root))
    imu_stamps = _stamps(s.field("stamp_s"), f"the IMU stream {s.name!r}", root)
    true_stamps = _stamps(s.time_s, f"the IMU stream {s.name!r}", root)
    total, done = sum(len(c.views) for c in rig.cameras), 0
    for k, cam in enumerate(rig.cameras):
        rows = []
        for stamp, v in zip(cam.stamps_ns, cam.views):
            write(dest, f"mav0/cam{k}/data/{stamp}.png", encode_png(to_uint8(ds.image(v))))
            rows.append(f"{stamp},{stamp}.png\n")
            done += 1
            if progress is not None:
                progress(done, total)
        write(dest, f"mav0/cam{k}/data.csv", ("#timestamp [ns],filename\n" + "".join(rows)).encode())
        files += len(rows) + 1
    write(dest, "mav0/imu0/data.csv", _csv(IMU_HEAD, imu_stamps, s.field("gyro_rad_s"), s.field("accel_mps2")))
    write(dest, "mav0/state_groundtruth_estimate0/data.csv",
          _csv(GROUNDTRUTH_HEAD, true_stamps, s.field("position_m"), s.field("quat_wxyz"), s.field("velocity_mps"),
               s.field("gyro_bias_rad_s"), s.field("accel_bias_mps2")))
    for rel, data in calib.items():
        write(dest, rel, data)
    return {"files": files + 2 + len(calib), "rig": rig.rig, "imu_stream": s.name, "imu_samples": s.samples,
            "cameras": {f"cam{k}": c.member for k, c in enumerate(rig.cameras)},
            "frames": len(rig.cameras[0].views), "timeshift_cam_imu_s": 0.0 - rig.time_offset_s,
            "orbslam3": orbslam3_note}

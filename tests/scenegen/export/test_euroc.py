"""The EuRoC MAV export (scenegen.export.euroc) read back by a reader written here from the
formats' documentation (EuRoC's ASL dataset format: csv + sensor.yaml; Kalibr's wiki, "YAML
formats"), with csv, PyYAML and SciPy's rotations, not our code: a two-camera rig with a
distorting camera and an IMU, 32x24, three frames; and the refusals. evo reads the trajectories we
write (TUM export, KITTI poses, EuRoC ground truth) and gives recon-eval's APE."""
from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest
import yaml
from evo.core import metrics, sync
from evo.core.trajectory import PosePath3D, PoseTrajectory3D
from evo.tools import file_interface
from scipy.spatial.transform import Rotation

from recon_eval.cli import main as recon_eval
from recon_eval.readers.kitti_odometry import write_kitti_poses
from recon_eval.readers.registry import read_poses
from scenegen.cli import main
from scenegen.dataset import Dataset
from scenegen.export.errors import ExportError
from scenegen.export.euroc_calib import radtan_parameters
from scenegen.geometry.camera import Camera
from scenegen.pipeline.run import render_spec

sys.path.insert(0, str(Path(__file__).parents[1] / "spec"))
from test_imu_spec import VIO  # noqa: E402

#: VIO with a distorting camera (k1 k2 p1 p2), a second camera 0.1 m to the right and the IMU's
#: clock in step with the rig's (so a ground-truth row lies at every frame's time).
STEREO_VIO = (VIO.replace("cam: {size: [32, 24], fx: 30}",
                          "cam: {size: [32, 24], fx: 30, fy: 31, cx: 15.2, cy: 11.7, model: opencv, "
                          "dist: [-0.05, 0.01, 0.001, -0.002]}")
              .replace("      - {camera: cam, name: left}\n",
                       "      - {camera: cam, name: left}\n"
                       "      - {camera: cam, name: right, rig_from_cam: {translation: [0.1, 0, 0], "
                       "rotation_deg: [0, 2, 0]}}\n")
              .replace(", time_offset_s: 0.005}", "}"))


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    root = tmp_path_factory.mktemp("euroc")
    spec = root / "vio.yaml"
    spec.write_text(STEREO_VIO)
    render_spec(spec, root / "out", progress=False)
    assert main(["export", str(root / "out"), "--format", "euroc", "-o", str(root / "euroc")]) == 0
    return root / "out", root / "euroc"


def read_csv(path: Path) -> tuple[list[str], list[list[str]]]:
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


def matrix(rows) -> np.ndarray:
    return np.asarray(rows, dtype=np.float64).reshape(4, 4)


def pose(R, t) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, t
    return T


@pytest.mark.render
def test_the_euroc_export_reads_back_as_the_dataset(exported):
    out, dest = exported
    cams = json.loads((out / "cameras.json").read_text())
    stream = Dataset(out).streams["seq_imu"]
    mav = dest / "mav0"
    assert sorted(p.name for p in mav.iterdir()) == ["cam0", "cam1", "imu0", "state_groundtruth_estimate0"]
    # the ground truth: body (= IMU) pose in the world per timestamp
    head, rows = read_csv(mav / "state_groundtruth_estimate0" / "data.csv")
    assert head[0] == "#timestamp" and head[1].strip() == "p_RS_R_x [m]" and head[4].strip() == "q_RS_w []"
    assert len(head) == 17 and head[16].strip() == "b_a_RS_S_z [m s^-2]"
    world_from_body = {int(r[0]): pose(Rotation.from_quat([float(x) for x in r[5:8]] + [float(r[4])]).as_matrix(),
                                       [float(x) for x in r[1:4]]) for r in rows}
    assert len(rows) == stream.samples == 41
    chain = yaml.safe_load((dest / "camchain.yaml").read_text())
    worst = 0.0
    for k, member in enumerate(("left", "right")):
        views = [v for v in cams["view_order"] if cams["views"][v]["rig_member"] == member]
        head, rows = read_csv(mav / f"cam{k}" / "data.csv")
        assert head == ["#timestamp [ns]", "filename"]
        stamps = [int(r[0]) for r in rows]
        assert stamps == [round(cams["views"][v]["time_s"] * 1e9) for v in views] == [0, 100_000_000, 200_000_000]
        assert [r[1] for r in rows] == [f"{s}.png" for s in stamps]
        assert all((mav / f"cam{k}" / "data" / r[1]).is_file() for r in rows)
        assert len(list((mav / f"cam{k}" / "data").iterdir())) == len(views)
        sensor = yaml.safe_load((mav / f"cam{k}" / "sensor.yaml").read_text())
        T_BS = matrix(sensor["T_BS"]["data"])
        assert sensor["sensor_type"] == "camera" and sensor["T_BS"]["rows"] == sensor["T_BS"]["cols"] == 4
        assert sensor["rate_hz"] == 10.0 and sensor["resolution"] == [32, 24]
        cam = cams["views"][views[0]]["camera"]
        assert sensor["camera_model"] == "pinhole" and sensor["distortion_model"] == "radial-tangential"
        assert sensor["intrinsics"] == [cam["fx"], cam["fy"], cam["cx"], cam["cy"]] == [30.0, 31.0, 15.2, 11.7]
        assert sensor["distortion_coefficients"] == cam["dist"][:4] == [-0.05, 0.01, 0.001, -0.002]
        assert not any(cam["dist"][4:])
        # T_BS composed with the ground-truth body pose is the camera's pose at each frame
        for s, v in zip(stamps, views):
            c = cams["views"][v]["cam_from_world"]
            world_from_cam = np.linalg.inv(pose(c["R"], c["t"]))
            err = float(np.abs(world_from_body[s] @ T_BS - world_from_cam).max())
            assert err < 1e-9, (member, v)
            worst = max(worst, err)
        # Kalibr: T_cam_imu is the inverse of T_BS; the same intrinsics
        kc = chain[f"cam{k}"]
        assert np.abs(matrix(kc["T_cam_imu"]) @ T_BS - np.eye(4)).max() < 1e-12
        assert kc["intrinsics"] == sensor["intrinsics"] and kc["distortion_coeffs"] == sensor["distortion_coefficients"]
        assert (kc["camera_model"], kc["distortion_model"], kc["resolution"]) == ("pinhole", "radtan", [32, 24])
        assert str(kc["timeshift_cam_imu"]) == "0.0" and kc["rostopic"] == f"/cam{k}/image_raw"
    print(f"ground truth @ T_BS vs world_from_cam over 6 views: max {worst:.1e}")
    # cam1's T_cn_cnm1 takes cam0 coordinates to cam1's: the rig's 0.1 m baseline
    c1_from_c0 = matrix(chain["cam1"]["T_cn_cnm1"])
    assert np.abs(c1_from_c0 - matrix(chain["cam1"]["T_cam_imu"]) @ np.linalg.inv(matrix(chain["cam0"]["T_cam_imu"]))
                  ).max() < 1e-12
    assert abs(np.linalg.norm(c1_from_c0[:3, 3]) - 0.1) < 1e-12 and "T_cn_cnm1" not in chain["cam0"]
    # the IMU rows are the stream's measured values at its stamps
    head, rows = read_csv(mav / "imu0" / "data.csv")
    assert head == ["#timestamp [ns]", "w_RS_S_x [rad s^-1]", "w_RS_S_y [rad s^-1]", "w_RS_S_z [rad s^-1]",
                    "a_RS_S_x [m s^-2]", "a_RS_S_y [m s^-2]", "a_RS_S_z [m s^-2]"]
    values = np.array([[float(x) for x in r[1:]] for r in rows])
    assert [int(r[0]) for r in rows] == [round(t * 1e9) for t in stream.field("stamp_s")]
    assert np.array_equal(values[:, :3], stream.field("gyro_rad_s"))
    assert np.array_equal(values[:, 3:], stream.field("accel_mps2"))
    imu = cams["spec"]["sensors"]["imu"]["imu0"]
    noise = ("gyroscope_noise_density", "gyroscope_random_walk", "accelerometer_noise_density",
             "accelerometer_random_walk")
    sensor = yaml.safe_load((mav / "imu0" / "sensor.yaml").read_text())
    assert sensor["sensor_type"] == "imu" and np.array_equal(matrix(sensor["T_BS"]["data"]), np.eye(4))
    assert sensor["rate_hz"] == 200.0 and all(sensor[k] == imu[k] for k in noise)
    kimu = yaml.safe_load((dest / "imu.yaml").read_text())["imu0"]
    assert np.array_equal(matrix(kimu["T_i_b"]), np.eye(4)) and all(kimu[k] == imu[k] for k in noise)
    assert kimu["update_rate"] == 200.0 and kimu["rostopic"] == "/imu0"


@pytest.mark.render
def test_a_dataset_without_an_imu_is_refused_with_exit_2(crossview_render, tmp_path, capsys):
    dest = tmp_path / "euroc"
    assert main(["export", str(crossview_render[1]), "--format", "euroc", "-o", str(dest)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no IMU stream" in err[0] and "Traceback" not in err[0]
    assert not dest.exists() and not list(tmp_path.iterdir())


@pytest.mark.parametrize("camera, what", [
    (Camera("fisheye", 32, 24, 30, 30, 15.5, 11.5, dist=(0.01, 0, 0, 0)), "fisheye camera model"),
    (Camera("opencv", 32, 24, 30, 30, 15.5, 11.5, skew=0.5, dist=(0, 0, 0, 0)), "skew 0.5 px"),
    (Camera("opencv", 32, 24, 30, 30, 15.5, 11.5, dist=(0.01, 0, 0, 0, 0.001)), "beyond k1 k2 p1 p2"),
])
def test_a_camera_radial_tangential_cannot_hold_is_refused(camera, what):
    with pytest.raises(ExportError, match=what):
        radtan_parameters(camera, "cam")
    fu, _ = radtan_parameters(Camera("opencv", 32, 24, 30, 31, 15.5, 11.5, dist=(0.01, 0.002, 0, 0, 0)), "cam")
    assert fu == [30.0, 31.0, 15.5, 11.5]


@pytest.mark.render
def test_one_camera_and_an_imu_clock_behind_the_rig(tmp_path):
    """VIO as it is: one camera, the IMU stamping a sample taken at true time t with t - 0.005 s.
    Kalibr's t_imu = t_cam + timeshift_cam_imu: the reading in the ground-truth row stamped T
    (the camera's clock) is the IMU row stamped T + shift."""
    spec = tmp_path / "vio.yaml"
    spec.write_text(VIO)
    render_spec(spec, tmp_path / "out", progress=False)
    assert main(["export", str(tmp_path / "out"), "--format", "euroc", "-o", str(tmp_path / "e")]) == 0
    mav = tmp_path / "e" / "mav0"
    assert sorted(p.name for p in mav.iterdir()) == ["cam0", "imu0", "state_groundtruth_estimate0"]
    chain = yaml.safe_load((tmp_path / "e" / "camchain.yaml").read_text())
    assert list(chain) == ["cam0"] and chain["cam0"]["timeshift_cam_imu"] == -0.005
    shift_ns = round(chain["cam0"]["timeshift_cam_imu"] * 1e9)
    imu = [int(r[0]) for r in read_csv(mav / "imu0" / "data.csv")[1]]
    truth = [int(r[0]) for r in read_csv(mav / "state_groundtruth_estimate0" / "data.csv")[1]]
    assert len(imu) == len(truth) == 41 and [t + shift_ns for t in truth] == imu
    assert imu[0] == 0 and truth[0] == 5_000_000


def _evo_ape_rmse(ref, est, *, align: bool, max_diff=0.01):
    if max_diff is not None:
        ref, est = sync.associate_trajectories(ref, est, max_diff=max_diff)
    if align:
        est.align(ref)
    ape = metrics.APE(metrics.PoseRelation.translation_part)
    ape.process_data((ref, est))
    return ape.get_statistic(metrics.StatisticsType.rmse), ref.num_poses


def _noisy(traj, seed, every=1):
    rng = np.random.default_rng(seed)
    ids = list(range(0, traj.num_poses, every))
    p = traj.positions_xyz[ids] + rng.normal(0, 0.01, (len(ids), 3))
    q = traj.orientations_quat_wxyz[ids]
    if isinstance(traj, PoseTrajectory3D):
        return PoseTrajectory3D(positions_xyz=p, orientations_quat_wxyz=q, timestamps=traj.timestamps[ids])
    return PosePath3D(positions_xyz=p, orientations_quat_wxyz=q)


@pytest.mark.render
def test_evo_reads_our_tum_kitti_and_euroc_trajectories_and_gives_recon_evals_ape(exported, tmp_path):
    """evo's readers on the TUM export, a KITTI file recon_eval writes and the EuRoC ground truth:
    the stamps are the views' times (TUM: time_s, not frame indices), the positions the truth,
    and evo's APE of an estimate (written by evo) equals ``recon-eval poses``'s."""
    out, dest = exported
    cams = json.loads((out / "cameras.json").read_text())
    left = [v for v in cams["view_order"] if cams["views"][v]["rig_member"] == "left"]
    centres = np.array([-np.array(cams["views"][v]["cam_from_world"]["R"]).T @ cams["views"][v]["cam_from_world"]["t"]
                        for v in left])
    assert main(["export", str(out), "--format", "tum", "-o", str(tmp_path / "tum")]) == 0
    tum = file_interface.read_tum_trajectory_file(str(tmp_path / "tum" / "r_left.txt"))
    assert tum.timestamps.tolist() == [cams["views"][v]["time_s"] for v in left] == [0.0, 0.1, 0.2]
    assert np.abs(tum.positions_xyz - centres).max() < 1e-12
    _, poses = read_poses(out, camera="cam")
    left_poses = type(poses)(tuple(left), poses.R_cam_from_world[[poses.names.index(v) for v in left]],
                             poses.t_cam_from_world[[poses.names.index(v) for v in left]])
    write_kitti_poses(tmp_path / "gt_kitti.txt", left_poses)
    kitti = file_interface.read_kitti_poses_file(str(tmp_path / "gt_kitti.txt"))
    assert np.abs(kitti.positions_xyz - centres).max() < 1e-12
    euroc = file_interface.read_euroc_csv_trajectory(str(dest / "mav0" / "state_groundtruth_estimate0" / "data.csv"))
    assert euroc.num_poses == 41 and euroc.timestamps[-1] == pytest.approx(0.2)

    worst = 0.0
    cases = [("tum", tum, file_interface.write_tum_trajectory_file, tmp_path / "tum" / "r_left.txt", False, 1),
             ("kitti", kitti, file_interface.write_kitti_poses_file, tmp_path / "gt_kitti.txt", False, 1),
             ("euroc", euroc, file_interface.write_tum_trajectory_file,
              dest / "mav0" / "state_groundtruth_estimate0" / "data.csv", True, 4)]
    for k, (what, ref, write_est, gt_file, align, every) in enumerate(cases):
        est = _noisy(ref, k, every)
        est_file = tmp_path / f"est_{what}.txt"
        write_est(str(est_file), est)
        rmse, n = _evo_ape_rmse(ref, est, align=align, max_diff=None if what == "kitti" else 0.01)
        report = tmp_path / f"{what}.json"
        assert recon_eval(["poses", str(est_file), str(gt_file), "--alignment", "se3" if align else "none",
                           "--json", str(report), "--quiet"]) == 0
        ape = json.loads(report.read_text())["results"]["ape"]
        assert ape["n_registered"] == n and (what != "euroc" or n == 11)
        worst = max(worst, abs(ape["trans_stats_m"]["rmse"] - rmse))
    assert worst < 1e-12
    print(f"evo vs recon-eval APE rmse on TUM / KITTI / EuRoC files: max difference {worst:.1e} m")


def _fs_matrix(node) -> np.ndarray:
    """A FileStorage node: an ``!!opencv-matrix`` or a sequence of rows."""
    if node.isSeq():
        return np.array([[node.at(i).at(j).real() for j in range(node.at(i).size())] for i in range(node.size())])
    return node.mat().astype(np.float64)


@pytest.mark.render
def test_orbslam3_and_openvins_settings_load_in_opencv_with_the_true_calibration(exported):
    """ORB-SLAM3 and OpenVINS read their settings with cv::FileStorage: so do we here (cv2), and
    compare every calibration value with EuRoC's sensor.yaml files (read with PyYAML)."""
    _, dest = exported
    sensors = [yaml.safe_load((dest / "mav0" / f"cam{k}" / "sensor.yaml").read_text()) for k in (0, 1)]
    imu = yaml.safe_load((dest / "mav0" / "imu0" / "sensor.yaml").read_text())
    T_BS = [matrix(s["T_BS"]["data"]) for s in sensors]
    fs = cv2.FileStorage(str(dest / "orbslam3.yaml"), cv2.FILE_STORAGE_READ)
    assert fs.isOpened() and fs.getNode("File.version").string() == "1.0"
    assert fs.getNode("Camera.type").string() == "PinHole"
    for k, s in enumerate(sensors, start=1):
        got = [fs.getNode(f"Camera{k}.{n}").real() for n in ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2")]
        assert got == s["intrinsics"] + s["distortion_coefficients"]
    assert (fs.getNode("Camera.width").real(), fs.getNode("Camera.height").real()) == (32, 24)
    assert fs.getNode("Camera.fps").real() == 10.0
    # dt: f, as ORB-SLAM3's own files: float32 of the truth
    assert np.abs(_fs_matrix(fs.getNode("IMU.T_b_c1")) - T_BS[0]).max() < 1e-7
    assert np.abs(_fs_matrix(fs.getNode("Stereo.T_c1_c2")) - np.linalg.inv(T_BS[0]) @ T_BS[1]).max() < 1e-7
    assert fs.getNode("IMU.NoiseGyro").real() == imu["gyroscope_noise_density"] == 0.001
    assert fs.getNode("IMU.AccWalk").real() == imu["accelerometer_random_walk"]
    assert fs.getNode("IMU.Frequency").real() == 200.0
    ov = cv2.FileStorage(str(dest / "openvins" / "kalibr_imucam_chain.yaml"), cv2.FILE_STORAGE_READ)
    for k, s in enumerate(sensors):
        cam = ov.getNode(f"cam{k}")
        assert np.array_equal(_fs_matrix(cam.getNode("T_imu_cam")), T_BS[k])
        assert [cam.getNode("intrinsics").at(i).real() for i in range(4)] == s["intrinsics"]
        assert [cam.getNode("distortion_coeffs").at(i).real() for i in range(4)] == s["distortion_coefficients"]
        assert cam.getNode("distortion_model").string() == "radtan" and cam.getNode("timeshift_cam_imu").real() == 0
        assert cam.getNode("cam_overlaps").at(0).real() == 1 - k
    imu_chain = cv2.FileStorage(str(dest / "openvins" / "kalibr_imu_chain.yaml"), cv2.FILE_STORAGE_READ)
    oi = imu_chain.getNode("imu0")  # the FileStorage must outlive its nodes
    assert oi.getNode("gyroscope_noise_density").real() == 0.001 and oi.getNode("update_rate").real() == 200.0
    assert oi.getNode("model").string() == "kalibr" and np.array_equal(_fs_matrix(oi.getNode("Tg")), np.zeros((3, 3)))
    est = cv2.FileStorage(str(dest / "openvins" / "estimator_config.yaml"), cv2.FILE_STORAGE_READ)
    assert est.getNode("max_cameras").real() == 2 and est.getNode("gravity_mag").real() == 9.80665
    assert est.getNode("relative_config_imucam").string() == "kalibr_imucam_chain.yaml"

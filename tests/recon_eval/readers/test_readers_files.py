"""Readers: NeRF transforms.json, KITTI odometry, EXR maps, OpenCV calibration, single pose files.
Each format is written, read back and checked value by value."""
import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from recon_eval.errors import InputError
from recon_eval.metrics.poses import Poses


@pytest.fixture
def ring_poses(ring_of_cameras):
    """``ring_poses(n=5)``: n ring cameras as Poses named img<k>."""
    def make(n=5):
        R, t = ring_of_cameras(n)
        return Poses(tuple(f"img{k}" for k in range(n)), R, t)
    return make


class TestNerf:
    def test_round_trip_through_opengl(self, tmp_path, plane_scene, ring_poses):
        from recon_eval.readers.nerf import read_nerf_transforms, write_nerf_transforms

        P = ring_poses()
        write_nerf_transforms(tmp_path / "transforms.json", P, plane_scene.DISTORTED)
        n = read_nerf_transforms(tmp_path / "transforms.json")
        assert n.poses.names == P.names and n.file_paths[0] == "images/img0.png"
        np.testing.assert_allclose(n.poses.R_cam_from_world, P.R_cam_from_world, atol=1e-14)
        np.testing.assert_allclose(n.poses.t_cam_from_world, P.t_cam_from_world, atol=1e-14)
        assert n.cameras["img0"] == plane_scene.DISTORTED  # cx, cy through NeRF's pixel + 0.5 and back

    def test_known_opengl_matrix(self, tmp_path):
        from recon_eval.readers.nerf import read_nerf_transforms

        # An OpenGL camera at (1, 2, 3) with identity camera-to-world rotation looks down world -z;
        # in OpenCV axes that is cam_from_world R = diag(1, -1, -1).
        T = np.eye(4)
        T[:3, 3] = [1, 2, 3]
        doc = {"camera_angle_x": 2 * np.arctan(0.5), "w": 100, "h": 80,
               "frames": [{"file_path": "./train/r_0", "transform_matrix": T.tolist()}]}
        (tmp_path / "t.json").write_text(json.dumps(doc))
        n = read_nerf_transforms(tmp_path / "t.json")
        assert n.poses.names == ("r_0",)
        np.testing.assert_allclose(n.poses.R_cam_from_world[0], np.diag([1.0, -1, -1]))
        np.testing.assert_allclose(n.poses.centers_world[0], [1, 2, 3])
        cam = n.cameras["r_0"]
        assert cam.fx == pytest.approx(100.0) and cam.fy == pytest.approx(100.0)
        assert (cam.cx, cam.cy) == (49.5, 39.5)  # w/2 in NeRF pixels = (w-1)/2 in OpenCV pixels

    def test_bad_frames(self, tmp_path):
        from recon_eval.readers.nerf import read_nerf_transforms

        (tmp_path / "a.json").write_text(json.dumps({"frames": [{"file_path": "x"}]}))
        with pytest.raises(InputError, match=r"a.json: frames\[0\]: expected keys"):
            read_nerf_transforms(tmp_path / "a.json")
        T = (2 * np.eye(4)).tolist()
        (tmp_path / "b.json").write_text(json.dumps({"frames": [{"file_path": "x", "transform_matrix": T}]}))
        with pytest.raises(InputError, match=r"b.json: frames\[0\].transform_matrix"):
            read_nerf_transforms(tmp_path / "b.json")


class TestKittiOdometry:
    def test_round_trip_both_conventions(self, tmp_path, ring_poses):
        from recon_eval.readers.kitti_odometry import read_kitti_poses, write_kitti_poses

        P = ring_poses(4)
        for conv in ("world_from_cam", "cam_from_world"):
            write_kitti_poses(tmp_path / f"{conv}.txt", P, conv)
            Q = read_kitti_poses(tmp_path / f"{conv}.txt", conv)
            assert Q.names == ("000000", "000001", "000002", "000003")
            np.testing.assert_allclose(Q.R_cam_from_world, P.R_cam_from_world, atol=1e-15)
            np.testing.assert_allclose(Q.t_cam_from_world, P.t_cam_from_world, atol=1e-14)

    def test_world_from_cam_line(self, tmp_path):
        from recon_eval.readers.kitti_odometry import read_kitti_poses

        # KITTI: camera 1 m forward (+z) of the first frame: world_from_cam t = (0, 0, 1)
        (tmp_path / "p.txt").write_text("1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 1\n")
        Q = read_kitti_poses(tmp_path / "p.txt")
        np.testing.assert_array_equal(Q.t_cam_from_world[1], [0, 0, -1])
        np.testing.assert_array_equal(Q.centers_world[1], [0, 0, 1])

    def test_malformed(self, tmp_path):
        from recon_eval.readers.kitti_odometry import read_kitti_poses

        (tmp_path / "p.txt").write_text("1 0 0 0 0 1 0 0 0 0 1\n")
        with pytest.raises(InputError, match=r"p.txt:1: expected 12 numbers"):
            read_kitti_poses(tmp_path / "p.txt")
        (tmp_path / "q.txt").write_text("2 0 0 0 0 1 0 0 0 0 1 0\n")
        with pytest.raises(InputError, match="not a rotation"):
            read_kitti_poses(tmp_path / "q.txt")


class TestExr:
    def test_round_trip_missing_is_nan(self, tmp_path):
        from recon_eval.readers.exr import read_exr_map, write_exr_map

        a = np.arange(12, dtype=np.float32).reshape(3, 4).astype(np.float64) + 0.25
        a[2, 1] = np.nan
        write_exr_map(tmp_path / "d.exr", a)
        np.testing.assert_array_equal(read_exr_map(tmp_path / "d.exr"), a)

    def test_channel_choice(self, tmp_path):
        from scenegen.dataset.codecs import write_exr

        from recon_eval.readers.exr import read_exr_map

        one = np.ones((2, 3), np.float32)
        write_exr(tmp_path / "t.exr", {"depth_z": one * 2, "range": one * 3, "P_world.X": one})
        assert np.all(read_exr_map(tmp_path / "t.exr") == 2)  # depth_z preferred
        assert np.all(read_exr_map(tmp_path / "t.exr", "range") == 3)
        write_exr(tmp_path / "u.exr", {"a": one, "b": one})
        with pytest.raises(InputError, match=r"u.exr: cannot tell which channel.*\['a', 'b'\]"):
            read_exr_map(tmp_path / "u.exr")
        with pytest.raises(InputError, match="no channel 'c'"):
            read_exr_map(tmp_path / "u.exr", "c")
        (tmp_path / "bad.exr").write_bytes(b"not an exr")
        with pytest.raises(InputError, match="bad.exr: not a readable EXR"):
            read_exr_map(tmp_path / "bad.exr")

    def test_dataset_truth_file_reads_as_depth(self, plane_dataset, plane_scene):
        from recon_eval.readers.exr import read_exr_map

        d = read_exr_map(plane_dataset[0] / "truth" / "left_000.exr")
        assert np.allclose(d, plane_scene.HEIGHT_M)


class TestOpencvCalibration:
    @pytest.mark.parametrize("ext", [".yaml", ".json"])
    @pytest.mark.parametrize("cam", ["pinhole", "distorted", "fisheye"])
    def test_round_trip(self, tmp_path, ext, cam, plane_scene):
        from scenegen.geometry.camera import Camera

        from recon_eval.readers.opencv_calib import read_opencv_calibration, write_opencv_calibration

        cam = {"pinhole": plane_scene.PINHOLE, "distorted": plane_scene.DISTORTED,
               "fisheye": Camera("fisheye", 64, 48, 30.0, 31.0, 32.0, 23.0, 0.0, (0.05, -0.01, 0.002, 0.0))}[cam]
        write_opencv_calibration(tmp_path / f"c{ext}", cam)
        assert read_opencv_calibration(tmp_path / f"c{ext}") == cam

    def test_ros_camera_info_and_plain_json(self, tmp_path):
        from recon_eval.readers.opencv_calib import read_opencv_calibration

        (tmp_path / "ros.yaml").write_text(
            "image_width: 640\nimage_height: 480\ncamera_matrix:\n  rows: 3\n  cols: 3\n"
            "  data: [500, 0, 319.5, 0, 501, 239.5, 0, 0, 1]\ndistortion_model: plumb_bob\n"
            "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [-0.1, 0.01, 0, 0, 0]\n")
        c = read_opencv_calibration(tmp_path / "ros.yaml")
        assert (c.model, c.fx, c.fy, c.cx, c.cy, c.dist[:2]) == ("opencv", 500, 501, 319.5, 239.5, (-0.1, 0.01))
        (tmp_path / "k.json").write_text(json.dumps({"K": [[50, 0, 9.5], [0, 50, 7.5], [0, 0, 1]], "D": [0, 0, 0, 0],
                                                     "image_size": [20, 16]}))
        c = read_opencv_calibration(tmp_path / "k.json")
        assert (c.model, c.width, c.height) == ("pinhole", 20, 16)

    def test_errors_name_file_and_field(self, tmp_path):
        from recon_eval.readers.opencv_calib import read_opencv_calibration

        (tmp_path / "a.yaml").write_text("%YAML:1.0\n---\nfoo: 1\n")
        with pytest.raises(InputError, match="a.yaml: no camera matrix.*camera_matrix"):
            read_opencv_calibration(tmp_path / "a.yaml")
        (tmp_path / "b.yaml").write_text("%YAML:1.0\n---\nK: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n")
        with pytest.raises(InputError, match="b.yaml: no image size.*image_width"):
            read_opencv_calibration(tmp_path / "b.yaml")
        (tmp_path / "c.yaml").write_text("%YAML:1.0\n---\nK: [1, 2\n")
        with pytest.raises(InputError, match="c.yaml: not a readable OpenCV"):
            read_opencv_calibration(tmp_path / "c.yaml")
        (tmp_path / "d.json").write_text('{"K": [1, 0, 0], "image_size": [4, 4]}')
        with pytest.raises(InputError, match="d.json: K: expected 9 numbers"):
            read_opencv_calibration(tmp_path / "d.json")


class TestPoseFile:
    def test_formats_and_conventions(self, tmp_path):
        from recon_eval.readers.pose_file import read_pose

        R = Rotation.from_rotvec([0.1, -0.2, 0.3]).as_matrix()
        t = np.array([0.5, -1.0, 2.0])
        (tmp_path / "p.json").write_text(json.dumps({"R": R.tolist(), "t": t.tolist()}))
        (tmp_path / "w.json").write_text(json.dumps({"world_from_cam": {"R": R.T.tolist(), "t": (-R.T @ t).tolist()}}))
        np.savetxt(tmp_path / "p.txt", np.c_[R, t])
        np.save(tmp_path / "p.npy", np.r_[np.c_[R, t], [[0, 0, 0, 1]]])
        for f in ("p.json", "w.json", "p.txt", "p.npy"):
            Re, te = read_pose(tmp_path / f)
            np.testing.assert_allclose(Re, R, atol=1e-15)
            np.testing.assert_allclose(te, t, atol=1e-15)
        Re, te = read_pose(tmp_path / "w.json".replace("w", "p"), "world_from_cam")
        np.testing.assert_allclose(-Re.T @ te, t, atol=1e-15)  # the centre is the stored t
        (tmp_path / "bad.txt").write_text("1 2 3\n")
        with pytest.raises(InputError, match="bad.txt: expected a 3x4 or 4x4"):
            read_pose(tmp_path / "bad.txt")

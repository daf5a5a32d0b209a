"""The readers registry: which reader a path gets (suffix, folder contents, numbers per line), and
the errors for paths no reader accepts."""
import json

import numpy as np
import pytest

from recon_eval.errors import InputError
from recon_eval.metrics.poses import Poses
from recon_eval.readers.exr import write_exr_map
from recon_eval.readers.kitti_odometry import write_kitti_poses
from recon_eval.readers.kitti_png import write_kitti_disparity
from recon_eval.readers.nerf import write_nerf_transforms
from recon_eval.readers.registry import (MAP_SUFFIXES, POSE_FORMATS, find_view_map, read_image, read_map,
                                         read_poses, sniff_trajectory)
from scenegen.dataset.codecs import write_pfm, write_png


class TestMaps:
    def test_each_suffix_reads_its_format(self, tmp_path):
        d = np.array([[1.5, 2.0], [np.nan, 4.25]])
        write_kitti_disparity(tmp_path / "d.png", d)
        write_pfm(tmp_path / "d.pfm", d)
        np.save(tmp_path / "d.npy", d)
        write_exr_map(tmp_path / "d.exr", d, "disparity")
        assert MAP_SUFFIXES == (".png", ".pfm", ".npy", ".exr")
        for s in MAP_SUFFIXES:
            np.testing.assert_array_equal(read_map(tmp_path / f"d{s}", "disparity"), d)  # NaN = missing in each

    def test_exr_channel_follows_the_kind(self, tmp_path):
        from scenegen.dataset.codecs import write_exr

        one = np.ones((2, 2), np.float32)
        write_exr(tmp_path / "m.exr", {"depth_z": one, "disparity": 2 * one})
        assert np.all(read_map(tmp_path / "m.exr", "depth") == 1)
        assert np.all(read_map(tmp_path / "m.exr", "disparity") == 2)

    def test_unknown_suffix_and_folder(self, tmp_path):
        (tmp_path / "d.tif").write_bytes(b"")
        with pytest.raises(InputError, match=r"d.tif: unknown image format '.tif'"):
            read_map(tmp_path / "d.tif")
        (tmp_path / "f").mkdir()
        with pytest.raises(InputError, match="is a folder"):
            read_map(tmp_path / "f")

    def test_view_maps_in_a_folder(self, tmp_path):
        np.save(tmp_path / "a.npy", np.zeros((2, 2)))
        write_pfm(tmp_path / "a.pfm", np.zeros((2, 2)))
        write_pfm(tmp_path / "b.pfm", np.zeros((2, 2)))
        assert find_view_map(tmp_path, "a") == tmp_path / "a.npy"  # .npy first
        assert find_view_map(tmp_path, "b") == tmp_path / "b.pfm"
        assert find_view_map(tmp_path, "c") is None


def test_images(tmp_path):
    rgb = np.arange(24, dtype=np.uint8).reshape(2, 4, 3)
    write_png(tmp_path / "i.png", rgb)
    np.testing.assert_array_equal(read_image(tmp_path / "i.png"), rgb)  # RGB, as stored
    (tmp_path / "bad.png").write_bytes(b"not a png")
    for p in (tmp_path / "bad.png", tmp_path / "absent.png"):
        with pytest.raises(InputError, match="cannot read as an image"):
            read_image(p)


class TestPoses:
    def test_every_source_is_sniffed(self, plane_dataset, tmp_path, write_colmap, ring_of_cameras):
        from scipy.spatial.transform import Rotation

        root, _ = plane_dataset
        assert read_poses(root)[0] == "dataset"
        qs = Rotation.random(2, random_state=0).as_quat(scalar_first=True)
        write_colmap(tmp_path / "colmap", qs, np.zeros((2, 3)))
        assert read_poses(tmp_path / "colmap")[0] == "colmap"
        R, t = ring_of_cameras(3)
        P = Poses(("a", "b", "c"), R, t)
        write_nerf_transforms(tmp_path / "transforms.json", P)
        kind, got = read_poses(tmp_path / "transforms.json")
        assert kind == "nerf" and got.names == ("a", "b", "c")
        write_kitti_poses(tmp_path / "k.txt", P)
        kind, got = read_poses(tmp_path / "k.txt")
        assert kind == "kitti" and len(got.names) == 3
        (tmp_path / "tum.txt").write_text("# comment\n1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n")
        kind, traj = read_poses(tmp_path / "tum.txt")
        assert kind == "tum" and list(traj.timestamps_s) == [1.0, 2.0]
        (tmp_path / "data.csv").write_text("#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], "
                                           "q_RS_x [], q_RS_y [], q_RS_z []\n1000000000,0,0,0,1,0,0,0\n"
                                           "1500000000,1,0,0,1,0,0,0\n")
        kind, traj = read_poses(tmp_path / "data.csv")  # EuRoC ground truth: stamped, as TUM
        assert kind == "tum" and list(traj.timestamps_s) == [1.0, 1.5]
        assert [f.kind for f in POSE_FORMATS] == ["dataset", "colmap", "colmap", "nerf", "tum", "tum", "kitti"]

    def test_dataset_camera_subset(self, plane_dataset):
        kind, P = read_poses(plane_dataset[0], camera="left")
        assert kind == "dataset" and P.names == ("left_000",)
        with pytest.raises(InputError, match="no complete view of camera 'nope'"):
            read_poses(plane_dataset[0], camera="nope")

    def test_kitti_convention_is_passed_on(self, tmp_path, ring_of_cameras):
        R, t = ring_of_cameras(2)
        write_kitti_poses(tmp_path / "k.txt", Poses(("0", "1"), R, t), convention="cam_from_world")
        _, P = read_poses(tmp_path / "k.txt", kitti_convention="cam_from_world")
        np.testing.assert_allclose(P.R_cam_from_world, R, atol=1e-15)

    def test_errors(self, tmp_path):
        (tmp_path / "folder").mkdir()
        with pytest.raises(InputError, match="neither a dataset .* nor a COLMAP model"):
            read_poses(tmp_path / "folder")
        with pytest.raises(InputError, match="no such file or folder"):
            read_poses(tmp_path / "absent.txt")
        (tmp_path / "five.txt").write_text("1 2 3 4 5\n")
        with pytest.raises(InputError, match=r"five.txt:1: expected 8 \(TUM\) or 12"):
            read_poses(tmp_path / "five.txt")
        (tmp_path / "empty.txt").write_text("# nothing\n")
        with pytest.raises(InputError, match="empty trajectory"):
            sniff_trajectory(tmp_path / "empty.txt")
        (tmp_path / "bad.json").write_text(json.dumps({"frames": "no"}))
        with pytest.raises(InputError, match="bad.json: frames"):
            read_poses(tmp_path / "bad.json")

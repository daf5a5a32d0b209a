import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from recon_eval.errors import InputError
from recon_eval.readers.colmap_text import read_colmap_text
from recon_eval.readers.kitti_png import read_kitti_disparity, write_kitti_disparity
from recon_eval.readers.matrix import read_matrix3
from recon_eval.readers.npy import read_npy
from recon_eval.readers.pfm import read_pfm
from scenegen.dataset.codecs import write_pfm
from recon_eval.readers.ply import read_geometry, write_point_cloud_ply
from recon_eval.readers.tum import associate, read_tum



class TestPfm:
    def test_round_trip_with_missing(self, tmp_path):
        a = np.arange(12, dtype=np.float32).reshape(3, 4).astype(np.float64) + 0.5
        a[1, 2] = np.nan
        write_pfm(tmp_path / "d.pfm", a)
        b = read_pfm(tmp_path / "d.pfm")
        np.testing.assert_array_equal(b, a)  # NaN positions equal too; row order top first

    def test_big_endian_and_inf(self, tmp_path):
        data = np.array([[1.0, np.inf], [3.0, 4.0]], dtype=">f4")
        (tmp_path / "b.pfm").write_bytes(b"Pf\n2 2\n1.0\n" + data[::-1].tobytes())
        np.testing.assert_array_equal(read_pfm(tmp_path / "b.pfm"), [[1.0, np.nan], [3.0, 4.0]])
        assert np.isinf(read_pfm(tmp_path / "b.pfm", keep_inf=True)[0, 1])

    def test_malformed(self, tmp_path):
        (tmp_path / "x.pfm").write_bytes(b"P6\n2 2\n255\n")
        with pytest.raises(InputError, match="x.pfm"):
            read_pfm(tmp_path / "x.pfm")
        (tmp_path / "t.pfm").write_bytes(b"Pf\n2 2\n-1\n\x00\x00")
        with pytest.raises(InputError, match="truncated"):
            read_pfm(tmp_path / "t.pfm")


class TestKittiPng:
    def test_round_trip(self, tmp_path):
        d = np.array([[1.5, 0.0, 100.25], [np.nan, 255.99609375, 3.0]])
        write_kitti_disparity(tmp_path / "d.png", d)
        out = read_kitti_disparity(tmp_path / "d.png")
        expected = d.copy()
        expected[0, 1] = np.nan  # 0 = invalid in KITTI
        np.testing.assert_array_equal(out, expected)

    def test_eight_bit_png_is_rejected(self, tmp_path):
        import cv2

        cv2.imwrite(str(tmp_path / "e.png"), np.zeros((2, 2), np.uint8))
        with pytest.raises(InputError, match="uint16"):
            read_kitti_disparity(tmp_path / "e.png")


class TestNpyAndMatrix:
    def test_shape_check(self, tmp_path):
        np.save(tmp_path / "a.npy", np.zeros((5, 3)))
        assert read_npy(tmp_path / "a.npy", (None, 3)).shape == (5, 3)
        with pytest.raises(InputError, match=r"a.npy: expected an array of shape \(N, 4\), got \(5, 3\)"):
            read_npy(tmp_path / "a.npy", (None, 4))

    def test_missing_file_named(self, tmp_path):
        with pytest.raises(InputError, match="nope.npy: no such file"):
            read_npy(tmp_path / "nope.npy")

    def test_matrix_formats(self, tmp_path):
        M = np.arange(9.0).reshape(3, 3)
        (tmp_path / "m.txt").write_text("# F\n0 1 2\n3 4 5\n6 7 8\n")
        (tmp_path / "m.json").write_text(json.dumps({"F": M.tolist()}))
        np.save(tmp_path / "m.npy", M)
        for name in ("m.txt", "m.json", "m.npy"):
            np.testing.assert_array_equal(read_matrix3(tmp_path / name, key="F"), M)
        (tmp_path / "bad.txt").write_text("1 2 3")
        with pytest.raises(InputError, match="9 numbers"):
            read_matrix3(tmp_path / "bad.txt")


class TestPly:
    def test_point_cloud_round_trip(self, tmp_path):
        p = np.random.default_rng(0).normal(size=(50, 3))
        write_point_cloud_ply(tmp_path / "c.ply", p)
        g = read_geometry(tmp_path / "c.ply")
        np.testing.assert_array_equal(g.vertices, p)
        assert g.faces is None

    def test_mesh(self, tmp_path):
        import trimesh

        trimesh.creation.box().export(tmp_path / "box.ply")
        g = read_geometry(tmp_path / "box.ply")
        assert g.faces.shape == (12, 3) and g.vertices.shape == (8, 3)

    def test_garbage(self, tmp_path):
        (tmp_path / "g.ply").write_text("not a ply")
        with pytest.raises(InputError, match="g.ply"):
            read_geometry(tmp_path / "g.ply")


class TestColmapText:
    def test_against_pycolmap(self, tmp_path, write_colmap):
        import pycolmap

        rng = np.random.default_rng(0)
        qs = Rotation.random(3, random_state=1).as_quat(scalar_first=True)
        ts = rng.normal(size=(3, 3))
        write_colmap(tmp_path / "m", qs, ts)
        model = read_colmap_text(tmp_path / "m")
        rec = pycolmap.Reconstruction(str(tmp_path / "m"))
        for im in rec.images.values():
            cw = im.cam_from_world() if callable(im.cam_from_world) else im.cam_from_world
            k = model.poses.names.index(im.name)
            np.testing.assert_allclose(model.poses.R_cam_from_world[k], cw.matrix()[:, :3], atol=1e-12)
            np.testing.assert_allclose(model.poses.t_cam_from_world[k], cw.matrix()[:, 3], atol=1e-12)
        np.testing.assert_array_equal(model.points_world, [[0.1, 0.2, 3.0]])
        cam = model.cameras[1]
        assert cam.params_opencv_px == (500.0, 505.0, 319.5, 239.5)  # COLMAP 0.5 pixel-centre shift

    def test_bad_quaternions_name_the_file(self, tmp_path, write_colmap):
        """Quaternions go through scenegen.geometry.rotation (normalised, scipy); a zero or non-finite
        one is bad input naming images.txt, never NaN rotations."""
        write_colmap(tmp_path / "nan", [[np.nan, 0, 0, 1]], [[0.0, 0, 0]])
        with pytest.raises(InputError, match=r"nan/images.txt: a zero or non-finite quaternion"):
            read_colmap_text(tmp_path / "nan")
        write_colmap(tmp_path / "zero", [[0.0, 0, 0, 0]], [[0.0, 0, 0]])
        with pytest.raises(InputError, match=r"zero/images.txt: a zero or non-finite quaternion"):
            read_colmap_text(tmp_path / "zero")
        write_colmap(tmp_path / "scaled", [[2.0, 0, 0, 0]], [[0.0, 0, 0]])  # normalised first
        np.testing.assert_array_equal(read_colmap_text(tmp_path / "scaled").poses.R_cam_from_world[0], np.eye(3))

    def test_missing_images_file(self, tmp_path):
        (tmp_path / "m").mkdir()
        (tmp_path / "m" / "cameras.txt").write_text("")
        with pytest.raises(InputError, match="missing images.txt"):
            read_colmap_text(tmp_path / "m")


class TestTum:
    def test_read_converts_to_cam_from_world(self, tmp_path, numbers_text):
        c = np.array([1.0, 2.0, 3.0])
        q_xyzw = Rotation.from_rotvec([0.1, 0.2, 0.3]).as_quat()
        (tmp_path / "gt.txt").write_text("# ts tx ty tz qx qy qz qw\n" + f"1.0 {numbers_text(c)} {numbers_text(q_xyzw)}\n")
        tr = read_tum(tmp_path / "gt.txt")
        R_wc = Rotation.from_quat(q_xyzw).as_matrix()
        np.testing.assert_allclose(tr.poses.R_cam_from_world[0], R_wc.T, atol=1e-15)
        np.testing.assert_allclose(tr.poses.centers_world[0], c, atol=1e-14)

    def test_associate(self, tmp_path):
        (tmp_path / "gt.txt").write_text("1.000 0 0 0 0 0 0 1\n2.000 1 0 0 0 0 0 1\n3.000 2 0 0 0 0 0 1\n")
        (tmp_path / "est.txt").write_text("1.004 0 0 0 0 0 0 1\n2.5 1 0 0 0 0 0 1\n3.001 2 0 0 0 0 0 1\n")
        est = associate(read_tum(tmp_path / "est.txt"), read_tum(tmp_path / "gt.txt"), max_diff_s=0.01)
        assert est.names == ("1.000000", "3.000000")

    def test_bad_line(self, tmp_path):
        (tmp_path / "x.txt").write_text("1 2 3\n")
        with pytest.raises(InputError, match=r"x.txt:1: expected 8 numbers"):
            read_tum(tmp_path / "x.txt")


class TestColmapBinary:
    def test_bad_quaternion_names_the_file(self, tmp_path):
        import struct

        from recon_eval.readers.colmap_binary import read_colmap_binary

        d = tmp_path / "bin"
        d.mkdir()
        # one PINHOLE camera (model id 1, 4 params), one image with the quaternion (0, 0, 0, 0)
        (d / "cameras.bin").write_bytes(struct.pack("<QiiQQ4d", 1, 1, 1, 64, 48, 50.0, 50.0, 32.0, 24.0))
        (d / "images.bin").write_bytes(struct.pack("<QI4d3dI", 1, 1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1)
                                       + b"a.png\0" + struct.pack("<Q", 0))
        with pytest.raises(InputError, match=r"images.bin: quaternion must be 4 finite numbers, not all zero"):
            read_colmap_binary(d)

    def test_same_model_as_text(self, tmp_path, write_colmap):
        import pycolmap

        from recon_eval.readers.colmap_binary import read_colmap_binary

        qs = Rotation.random(3, random_state=2).as_quat(scalar_first=True)
        ts = np.random.default_rng(1).normal(size=(3, 3))
        write_colmap(tmp_path / "txt", qs, ts)
        (tmp_path / "bin").mkdir()
        pycolmap.Reconstruction(str(tmp_path / "txt")).write_binary(str(tmp_path / "bin"))
        a, b = read_colmap_binary(tmp_path / "bin"), read_colmap_text(tmp_path / "txt")
        order = [a.poses.names.index(n) for n in b.poses.names]
        np.testing.assert_allclose(a.poses.R_cam_from_world[order], b.poses.R_cam_from_world, atol=1e-15)
        np.testing.assert_allclose(a.poses.t_cam_from_world[order], b.poses.t_cam_from_world, atol=0)
        np.testing.assert_array_equal(a.points_world, b.points_world)
        assert a.cameras == b.cameras

    def test_truncated(self, tmp_path):
        from recon_eval.readers.colmap_binary import read_colmap_binary

        (tmp_path / "cameras.bin").write_bytes(b"\x01\x00\x00\x00\x00\x00\x00\x00\x01")
        (tmp_path / "images.bin").write_bytes(b"")
        with pytest.raises(InputError, match="truncated"):
            read_colmap_binary(tmp_path)

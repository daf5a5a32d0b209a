"""The CLI with our dataset folder as the truth, the calibration and pnp subcommands, the new pose
formats, and clean exit-2 errors."""
import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from recon_eval.cli import main
from recon_eval.metrics.poses import Poses



def run(argv, capsys):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def doc(path):
    return json.loads(path.read_text())


def dataset_poses(root):
    from recon_eval.readers.scenegen_dataset import read_dataset

    return read_dataset(root).poses


def rotate_one(P: Poses, name: str, angle_deg: float) -> Poses:
    """P with camera ``name`` rotated about its own optical axis by angle_deg (centre unchanged)."""
    R, t = P.R_cam_from_world.copy(), P.t_cam_from_world.copy()
    k = P.names.index(name)
    dR = Rotation.from_rotvec([0, 0, np.radians(angle_deg)]).as_matrix()
    c = -R[k].T @ t[k]
    R[k] = dR @ R[k]
    t[k] = -R[k] @ c
    return Poses(P.names, R, t)


class TestPosesAgainstDataset:
    def test_nerf_with_a_planted_rotation_error(self, plane_dataset, tmp_path, capsys):
        from recon_eval.readers.nerf import write_nerf_transforms

        root, _ = plane_dataset
        write_nerf_transforms(tmp_path / "transforms.json", rotate_one(dataset_poses(root), "free_000", 2.0))
        code, _, err = run(["poses", tmp_path / "transforms.json", root, "--alignment", "none",
                            "--json", tmp_path / "p.json", "--quiet"], capsys)
        assert code == 0, err
        r = doc(tmp_path / "p.json")
        assert r["inputs"]["format"] == "nerf" and r["inputs"]["gt_format"] == "dataset"
        np.testing.assert_allclose(r["results"]["ape"]["rot_err_deg"], [0, 0, 2.0], atol=1e-9)
        assert r["results"]["ape"]["trans_stats_m"]["max"] < 1e-12

    def test_colmap_model_matched_by_view_name(self, plane_dataset, tmp_path, capsys, numbers_text):
        from scenegen.geometry.rotation import quat_wxyz_from_matrix

        root, _ = plane_dataset
        P = dataset_poses(root)
        d = tmp_path / "sparse"
        d.mkdir()
        (d / "cameras.txt").write_text("1 plane_scene.PINHOLE 40 30 40 40 20 15\n")
        lines = []
        for k, n in enumerate(P.names[:2], start=1):  # free_000 not registered
            q = quat_wxyz_from_matrix(P.R_cam_from_world[k - 1])
            lines += [f"{k} {numbers_text(q)} {numbers_text(P.t_cam_from_world[k - 1])} 1 images/{n}.png", ""]  # matched by stem
        (d / "images.txt").write_text("\n".join(lines) + "\n")
        code, _, err = run(["poses", d, root, "--alignment", "none", "--json", tmp_path / "p.json", "--quiet"], capsys)
        assert code == 0, err
        ape = doc(tmp_path / "p.json")["results"]["ape"]
        assert ape["registration_ratio"] == pytest.approx(2 / 3) and ape["trans_err_m"][2] == "inf"

    def test_kitti_trajectory_of_one_camera(self, plane_dataset, tmp_path, capsys):
        from recon_eval.readers.kitti_odometry import write_kitti_poses

        root, _ = plane_dataset
        P = dataset_poses(root)
        write_kitti_poses(tmp_path / "k.txt", Poses(("a",), P.R_cam_from_world[:1], P.t_cam_from_world[:1]))
        code, _, err = run(["poses", tmp_path / "k.txt", root, "--camera", "left", "--alignment", "none",
                            "--json", tmp_path / "p.json", "--quiet"], capsys)
        assert code == 0, err
        r = doc(tmp_path / "p.json")
        assert r["results"]["ape"]["names"] == ["left_000"] and r["results"]["ape"]["trans_err_m"][0] < 1e-12
        assert r["inputs"]["kitti_convention"] == "world_from_cam"

    def test_tum_against_a_dataset_is_a_clear_error(self, plane_dataset, tmp_path, capsys):
        (tmp_path / "t.txt").write_text("0.0 0 0 0 0 0 0 1\n")
        code, _, err = run(["poses", tmp_path / "t.txt", plane_dataset[0]], capsys)
        assert code == 2 and "t.txt: a TUM trajectory is matched by timestamps" in err and "Traceback" not in err


class TestMapsAgainstDataset:
    def test_disparity(self, plane_dataset, tmp_path, capsys, plane_scene):
        from scenegen.dataset.codecs import write_pfm

        root, _ = plane_dataset
        d = np.full((30, 40), plane_scene.PINHOLE.fx * plane_scene.BASELINE_M / plane_scene.HEIGHT_M)
        d[0, :10] += 5.0  # 10 bad pixels of 1200
        write_pfm(tmp_path / "d.pfm", d)
        code, _, err = run(["disparity", tmp_path / "d.pfm", root, "--view", "left_000", "--benchmark", "middlebury",
                            "--json", tmp_path / "r.json", "--quiet"], capsys)
        assert code == 0, err
        assert doc(tmp_path / "r.json")["results"]["middlebury"]["bad_2_0_pct"] == pytest.approx(100 * 10 / 1200)
        code, _, err = run(["disparity", tmp_path / "d.pfm", root], capsys)
        assert code == 2 and "needs --view VIEW" in err

    def test_depth_folder_with_a_missing_view(self, plane_dataset, tmp_path, capsys):
        from recon_eval.readers.exr import write_exr_map
        from recon_eval.readers.scenegen_dataset import read_dataset

        root, _ = plane_dataset
        ds = read_dataset(root)
        (tmp_path / "est").mkdir()
        np.save(tmp_path / "est" / "left_000.npy", ds.depth("left_000") * 1.1)
        write_exr_map(tmp_path / "est" / "free_000.exr", ds.depth("free_000"))
        code, _, err = run(["depth", tmp_path / "est", root, "--json", tmp_path / "r.json", "--quiet"], capsys)
        assert code == 0, err
        r = doc(tmp_path / "r.json")
        assert r["inputs"]["views_without_estimate"] == ["right_000"]
        e = r["results"]["eigen"]
        assert e["n_images"] == 3 and e["n_images_failed"] == 1
        assert e["per_image_abs_rel"][0] == pytest.approx(0.1) and e["per_image_abs_rel"][2] < 1e-7

    def test_single_depth_file_needs_a_view(self, plane_dataset, tmp_path, capsys):
        np.save(tmp_path / "e.npy", np.ones((30, 40)))
        code, _, err = run(["depth", tmp_path / "e.npy", plane_dataset[0]], capsys)
        assert code == 2 and "needs --view VIEW" in err and "left_000" in err

    def test_cloud_against_the_dataset_meshes(self, plane_dataset, tmp_path, capsys):
        from recon_eval.readers.ply import write_point_cloud_ply

        rng = np.random.default_rng(0)
        pts = np.c_[rng.uniform(-2, 2, (3000, 2)), np.full(3000, 0.004)]
        write_point_cloud_ply(tmp_path / "rec.ply", pts)
        code, _, err = run(["cloud", tmp_path / "rec.ply", plane_dataset[0], "--tau", "0.005", "--gt-samples", "20000",
                            "--json", tmp_path / "r.json", "--quiet"], capsys)
        assert code == 0, err
        r = doc(tmp_path / "r.json")
        assert r["inputs"]["gt_kind"].startswith("scenegen-dataset")
        assert r["results"]["chamfer"]["distance_rec_to_gt"] == "mesh_surface"
        assert r["results"]["dtu"]["acc_mean_m"] == pytest.approx(0.004, abs=1e-12)


class TestFmatrixAgainstDataset:
    def test_truth_F_scores_perfectly(self, plane_dataset, tmp_path, capsys):
        from scenegen.geometry.twoview import fundamental

        root, cams = plane_dataset
        (c1, p1), (c2, p2) = cams["left_000"], cams["right_000"]
        rel = p2 @ p1.inverse()
        np.savetxt(tmp_path / "F.txt", fundamental(c1.K, c2.K, rel))
        code, _, err = run(["fmatrix", tmp_path / "F.txt", "--dataset", root, "--views", "left_000", "right_000",
                            "--json", tmp_path / "r.json", "--quiet"], capsys)
        assert code == 0, err
        r = doc(tmp_path / "r.json")["results"]
        assert r["fundamental"]["n_points"] > 500 and r["fundamental"]["sampson_rms_px"] < 1e-4
        assert r["zhang_f_distance"]["f_distance_px"] < 1e-9
        assert r["pose_via_K"]["pose_err_deg"] < 1e-3

    def test_missing_views(self, plane_dataset, tmp_path, capsys):
        np.savetxt(tmp_path / "F.txt", np.eye(3))
        code, _, err = run(["fmatrix", tmp_path / "F.txt", "--dataset", plane_dataset[0]], capsys)
        assert code == 2 and "--views" in err


class TestCalibration:
    def test_against_dataset_and_file(self, plane_dataset, tmp_path, capsys):
        from scenegen.geometry.camera import Camera

        from recon_eval.readers.opencv_calib import write_opencv_calibration

        root, cams = plane_dataset
        cam = cams["free_000"][0]
        write_opencv_calibration(tmp_path / "same.yaml", cam)
        code, _, err = run(["calibration", tmp_path / "same.yaml", root, "--view", "free_000",
                            "--json", tmp_path / "r.json", "--quiet"], capsys)
        assert code == 0, err
        r = doc(tmp_path / "r.json")["results"]
        assert r["intrinsics"]["fx_abs_err_px"] == 0 and r["projection_diff"]["max_px"] < 1e-9
        assert r["reprojection_held_out"]["rms_px"] < 1e-3  # float32 truth points
        off = Camera(cam.model, cam.width, cam.height, cam.fx + 0.5, cam.fy, cam.cx, cam.cy, 0.0, cam.dist)
        write_opencv_calibration(tmp_path / "off.json", off)
        code, _, err = run(["calibration", tmp_path / "off.json", tmp_path / "same.yaml",
                            "--json", tmp_path / "s.json", "--quiet"], capsys)
        assert code == 0, err
        r = doc(tmp_path / "s.json")["results"]
        assert r["intrinsics"]["fx_abs_err_px"] == pytest.approx(0.5) and r["projection_diff"]["max_px"] > 0.1

    def test_size_mismatch_and_bad_file(self, plane_dataset, tmp_path, capsys, plane_scene):
        from recon_eval.readers.opencv_calib import write_opencv_calibration

        write_opencv_calibration(tmp_path / "big.yaml", plane_scene.PINHOLE.with_size(80, 60))
        code, _, err = run(["calibration", tmp_path / "big.yaml", plane_dataset[0], "--view", "left_000"], capsys)
        assert code == 2 and "big.yaml: image_width/image_height 80x60 differ" in err
        (tmp_path / "x.yaml").write_text("%YAML:1.0\n---\nD: [0, 0, 0, 0]\n")
        code, _, err = run(["calibration", tmp_path / "x.yaml", plane_dataset[0]], capsys)
        assert code == 2 and "x.yaml: no camera matrix" in err and "Traceback" not in err


class TestPnp:
    def test_planted_rotation_error_against_dataset(self, plane_dataset, tmp_path, capsys):
        root, cams = plane_dataset
        pose = cams["free_000"][1]
        dR = Rotation.from_rotvec([0.0, np.radians(0.5), 0.0]).as_matrix()
        (tmp_path / "p.json").write_text(json.dumps({"R": (dR @ pose.R).tolist(), "t": pose.t.tolist()}))
        code, _, err = run(["pnp", tmp_path / "p.json", root, "--view", "free_000", "--json", tmp_path / "r.json",
                            "--quiet"], capsys)
        assert code == 0, err
        r = doc(tmp_path / "r.json")["results"]["pnp"]
        assert r["rot_err_deg"] == pytest.approx(0.5, abs=1e-12) and r["trans_abs_err_m"] == 0
        assert r["reprojection"]["rms_px"] > 0.05 and r["reprojection"]["n_points"] > 500  # truth pose: < 1e-3

    def test_pose_files_and_failures(self, tmp_path, capsys):
        R = Rotation.from_rotvec([0.1, 0.2, 0.3]).as_matrix()
        t = np.array([1.0, 2.0, 3.0])
        np.savetxt(tmp_path / "gt.txt", np.c_[R, t])
        np.savetxt(tmp_path / "est_w.txt", np.c_[R.T, -R.T @ t])  # world_from_cam
        code, _, err = run(["pnp", tmp_path / "est_w.txt", tmp_path / "gt.txt", "--est-convention", "world_from_cam",
                            "--json", tmp_path / "r.json", "--quiet"], capsys)
        assert code == 0, err
        assert doc(tmp_path / "r.json")["results"]["pnp"]["center_err_m"] < 1e-14
        (tmp_path / "nan.json").write_text('{"R": [[NaN, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [0, 0, 0]}')
        code, _, err = run(["pnp", tmp_path / "nan.json", tmp_path / "gt.txt", "--json", tmp_path / "f.json",
                            "--quiet"], capsys)
        assert code == 0 and doc(tmp_path / "f.json")["results"]["pnp"]["failed"] is True
        code, _, err = run(["pnp", tmp_path / "nope.json", tmp_path / "gt.txt"], capsys)
        assert code == 2 and "nope.json: no such file" in err


@pytest.mark.parametrize("command", [
    ["poses", "{d}", "{d}/cameras.json"],  # cameras.json is not a NeRF file
    ["depth", "{f}", "{d}", "--view", "nope"],
    ["calibration", "{d}/cameras.json", "{d}"],
    ["pnp", "{f}", "{d}", "--view", "left_000"],
    ["disparity", "{f}", "{d}", "--view", "free_000"],
])
def test_bad_inputs_with_a_dataset_are_exit_2(plane_dataset, tmp_path, capsys, command):
    f = tmp_path / "junk.npy"
    np.save(f, np.ones((2, 2)))
    code, _, err = run([c.format(d=plane_dataset[0], f=f) for c in command], capsys)
    assert code == 2 and "recon-eval: error:" in err and "Traceback" not in err

"""The options issue 14 added to existing commands: evo's RPE options, KITTI odometry, the depth
clamp / crops / inverse alignment, Middlebury's ndisp, mrcal's projection difference, the cloud's
ETH3D table, curves, crop and mesh metrics."""
import json

import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from recon_eval.cli import main
from scenegen.dataset.codecs import write_npy, write_pfm


def run(argv):
    return main([str(a) for a in argv] + ["--quiet"])


def doc(p):
    return json.loads(p.read_text())


def _tum(path, c, R):
    q = Rotation.from_matrix(R).as_quat()  # x y z w, world_from_cam
    path.write_text("".join(f"{k:.1f} {c[k, 0]:.17g} {c[k, 1]:.17g} {c[k, 2]:.17g} {q[k, 0]:.17g} {q[k, 1]:.17g} "
                            f"{q[k, 2]:.17g} {q[k, 3]:.17g}\n" for k in range(len(c))))


def test_poses_rpe_options_and_kitti_odometry(tmp_path):
    rng = np.random.default_rng(0)
    n = 40
    c = np.cumsum(rng.normal(0, 0.3, (n, 3)) + [0.5, 0, 0], axis=0)
    R = Rotation.from_rotvec(np.cumsum(rng.normal(0, 0.05, (n, 3)), axis=0)).as_matrix()
    _tum(tmp_path / "gt.txt", c, R)
    _tum(tmp_path / "est.txt", c + rng.normal(0, 0.02, c.shape), R)
    out = tmp_path / "r.json"
    assert run(["poses", tmp_path / "est.txt", tmp_path / "gt.txt", "--delta", "5", "--json", out]) == 0
    consecutive = doc(out)["results"]["rpe"]
    assert len(consecutive["pairs"]) == 7 and consecutive["all_pairs"] is False  # (0,5), (5,10), ... (30,35)
    assert run(["poses", tmp_path / "est.txt", tmp_path / "gt.txt", "--delta", "5", "--all_pairs",
                "--align_origin", "--json", out]) == 0
    d = doc(out)
    assert len(d["results"]["rpe"]["pairs"]) == 35 and d["results"]["rpe"]["alignment"] == "origin"
    assert run(["poses", tmp_path / "est.txt", tmp_path / "gt.txt", "--delta", "2", "--delta-unit", "m",
                "--alignment", "scale", "--n-to-align", "10", "--kitti-lengths", "2", "4", "--json", out]) == 0
    d = doc(out)["results"]
    assert d["rpe"]["delta_unit"] == "m" and d["rpe"]["delta_frames"] is None and d["ape"]["n_to_align"] == 10
    assert d["kitti_odometry"]["n_segments"] > 0 and np.isfinite(d["kitti_odometry"]["t_err_pct"])


def test_depth_clamp_crop_and_inverse_alignment(tmp_path):
    g = np.linspace(2.0, 60.0, 40 * 30).reshape(30, 40)
    p = g.copy()
    p[0, 0] = 500.0  # clamped to 80
    write_npy(tmp_path / "g.npy", g)
    write_npy(tmp_path / "p.npy", p)
    out = tmp_path / "r.json"
    assert run(["depth", tmp_path / "p.npy", tmp_path / "g.npy", "--min-depth", "1e-3", "--max-depth", "80",
                "--json", out]) == 0
    clamped = doc(out)["results"]["eigen"]
    assert clamped["abs_rel"] == pytest.approx((80 - 2) / 2 / 1200) and clamped["clamp"] is True
    assert run(["depth", tmp_path / "p.npy", tmp_path / "g.npy", "--min-depth", "1e-3", "--max-depth", "80",
                "--no-clamp", "--crop", "garg", "--json", out]) == 0
    assert doc(out)["results"]["eigen"]["crop"] == "garg" and doc(out)["results"]["eigen"]["abs_rel"] == 0.0
    write_npy(tmp_path / "inv.npy", 3.0 / g + 0.2)
    assert run(["depth", tmp_path / "inv.npy", tmp_path / "g.npy", "--alignment", "scale_shift_inverse",
                "--pred-inverse", "--json", out]) == 0
    r = doc(out)["results"]["eigen"]
    assert r["abs_rel"] < 1e-12 and r["per_image_scale"][0] == pytest.approx(1 / 3)
    assert r["per_image_shift_inv_m"][0] == pytest.approx(-0.2 / 3)


def test_middlebury_ndisp_from_the_calib_beside_the_truth(tmp_path):
    g = np.full((10, 12), 20.0)
    e = g.copy()
    e[0, :6] = 100.0  # clipped to ndisp 32: error 12 instead of 80
    write_pfm(tmp_path / "disp0.pfm", g.astype(np.float32))
    write_pfm(tmp_path / "e.pfm", e.astype(np.float32))
    out = tmp_path / "r.json"
    assert run(["disparity", tmp_path / "e.pfm", tmp_path / "disp0.pfm", "--benchmark", "middlebury",
                "--json", out]) == 0
    assert doc(out)["inputs"]["ndisp"] is None and doc(out)["results"]["middlebury"]["avgerr_px"] == pytest.approx(4.0)
    (tmp_path / "calib.txt").write_text("cam0=[100 0 5; 0 100 5; 0 0 1]\nndisp=32\n")
    assert run(["disparity", tmp_path / "e.pfm", tmp_path / "disp0.pfm", "--benchmark", "middlebury",
                "--json", out]) == 0
    d = doc(out)
    assert d["inputs"]["ndisp"] == 32.0 and d["results"]["middlebury"]["avgerr_px"] == pytest.approx(0.6)


def test_cloud_table_curves_crop_and_mesh_metrics(tmp_path):
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=1.0)
    rec = trimesh.creation.icosphere(subdivisions=3, radius=1.02)
    sphere.export(tmp_path / "gt.ply")
    rec.export(tmp_path / "rec.ply")
    (tmp_path / "crop.json").write_text(json.dumps({
        "class_name": "SelectionPolygonVolume", "orthogonal_axis": "Z", "axis_min": -2.0, "axis_max": 0.0,
        "bounding_polygon": [[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]], "version_major": 1, "version_minor": 0}))
    out = tmp_path / "r.json"
    assert run(["cloud", tmp_path / "rec.ply", tmp_path / "gt.ply", "--gt-samples", "20000", "--mesh-samples",
                "5000", "--json", out]) == 0
    d = doc(out)["results"]
    assert [k for k in d if k.startswith("eth3d@")] == [f"eth3d@{t:g}m" for t in (0.01, 0.02, 0.05, 0.1, 0.2, 0.5)]
    curves = d["tanks_and_temples_curves@0.01m"]
    assert len(curves["edges_m"]) == len(curves["precision"]) + 1 and curves["precision"][-1] <= 1.0
    onet = d["occupancy_networks"]
    assert onet["normal_consistency"] > 0.95 and onet["iou"] == pytest.approx(1 / 1.02**3, abs=0.03)
    assert run(["cloud", tmp_path / "rec.ply", tmp_path / "gt.ply", "--gt-samples", "20000", "--mesh-samples",
                "2000", "--crop", tmp_path / "crop.json", "--json", out]) == 0
    inp = doc(out)["inputs"]
    assert 0 < inp["n_rec_cropped"] < len(rec.vertices) and inp["n_gt_cropped"] < 20000


def test_calibration_reports_mrcal_projection_diff(tmp_path, plane_dataset):
    from recon_eval.readers.opencv_calib import write_opencv_calibration
    from scenegen.geometry.camera import Camera

    root, cams = plane_dataset
    write_opencv_calibration(tmp_path / "k.yaml", Camera("opencv", 40, 30, 42.5, 41.0, 19.0, 15.0, 0.0,
                                                         (-0.04, 0.01, 0.001, -0.001, 0.0)))
    out = tmp_path / "r.json"
    assert run(["calibration", tmp_path / "k.yaml", root, "--view", "free_000", "--json", out]) == 0
    r = doc(out)["results"]
    m = r["mrcal_projection_diff"]
    assert m["focus_radius_px"] == 5.0 and m["n_focus"] > 3 and len(m["grid_v_px"]) == 45  # round(30/40 * 60)
    assert r["projection_diff_rotation_fitted"]["rotation_fitted"] is True


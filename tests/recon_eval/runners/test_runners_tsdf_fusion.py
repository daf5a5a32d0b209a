"""TSDF fusion (recon_eval.runners.tsdf_fusion): exact on a fronto-parallel plane (closed form),
scored through the Tanks and Temples metric with a planted pose error, frame-to-frame tracking on
depth frames rasterised from a mesh, and the runner end to end on a tiny render of the bundled
hand-held sweep."""
from pathlib import Path

import numpy as np
import pytest
import trimesh
import yaml

from recon_eval.metrics.objects_depth import render_depth
from recon_eval.metrics.poses import Poses, ape
from recon_eval.runners import run_method, tsdf_fusion
from scenegen.geometry.pose import look_at
from scenegen.geometry.rotation import matrix_from_rotvec
from scenegen.pipeline.run import render_spec

SCENE = Path(__file__).parents[3] / "scenes" / "kinfu_handheld.yaml"
W, H, F = 64, 48, 60.0
K = np.array([[F, 0.0, (W - 1) / 2], [0.0, F, (H - 1) / 2], [0.0, 0.0, 1.0]])
HEIGHT_M = 0.5  # camera height above the plane z = 0


def _down_poses(n: int) -> list:
    """cam_from_world (4x4) of a camera looking straight down at z = 0 from HEIGHT_M, moving in x, y
    and turning about its optical axis: the plane stays fronto-parallel, its depth HEIGHT_M."""
    out = []
    for k in range(n):
        R_world_from_cam = matrix_from_rotvec([0.0, 0.0, 0.1 * k]) @ np.diag([1.0, -1.0, -1.0])
        c = np.array([0.01 * k, -0.007 * k, HEIGHT_M])
        T = np.eye(4)
        T[:3, :3] = R_world_from_cam.T
        T[:3, 3] = -R_world_from_cam.T @ c
        out.append(T)
    return out


def _plane_mesh(half_m: float = 2.0):
    V = np.array([[-half_m, -half_m, 0], [half_m, -half_m, 0], [half_m, half_m, 0], [-half_m, half_m, 0]], float)
    return V, np.array([[0, 1, 2], [0, 2, 3]])


@pytest.fixture(scope="module")
def plane():
    poses = _down_poses(4)
    depths = [np.full((H, W), HEIGHT_M) for _ in poses]
    return depths, poses


def test_fronto_parallel_plane_is_fused_exactly(plane):
    # Closed form: in every frame the projective signed distance of a voxel is HEIGHT_M - z_cam, the
    # same linear function of the voxel's height; a weighted average of it is that function again,
    # and marching cubes' linear interpolation of a linear function puts each vertex on its zero
    # exactly: the error is float32 rounding of metre-scale coordinates (~1e-7 m), far below 1e-5.
    depths, poses = plane
    V, F_ = tsdf_fusion.fuse(depths, K, poses)
    assert len(F_) > 1000
    assert np.abs(V[:, 2]).max() < 1e-5
    # the footprint of the first frame is covered: its centre ray's foot is a vertex region
    assert np.min(np.linalg.norm(V[:, :2], axis=1)) < tsdf_fusion.VOXEL_M


def test_fscore_of_the_fused_plane_through_the_tanks_and_temples_metric(plane):
    depths, poses = plane
    gt = _plane_mesh()
    truth = tsdf_fusion.observed_truth_points(depths, K, poses)
    V, F_ = tsdf_fusion.fuse(depths, K, poses)
    _, m = tsdf_fusion.score_mesh(V, F_, truth, gt)
    # precision is the closed form above; recall measured 0.927: the fused surface stops about a
    # voxel short of the union of the frames' footprints (marching cubes needs all 8 corners seen)
    assert m["precision_5mm"] == 1.0 and m["recall_5mm"] > 0.9 and m["acc_mean_mm"] < 1e-2
    # planted: every pose 6 mm too high, so the fused plane lies 6 mm below the truth
    lifted = [T @ _translate_world(0.0, 0.0, -0.006) for T in poses]
    Vl, Fl = tsdf_fusion.fuse(depths, K, lifted)
    _, ml = tsdf_fusion.score_mesh(Vl, Fl, truth, gt)
    assert ml["precision_5mm"] == 0.0 and ml["fscore_5mm"] == 0.0
    assert ml["precision_10mm"] == 1.0
    assert abs(ml["acc_mean_mm"] - 6.0) < 1e-2


def _translate_world(x, y, z) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = [x, y, z]
    return T


def test_frame_to_frame_icp_tracks_a_sweep_of_a_box_in_a_corner():
    scene = trimesh.util.concatenate([
        trimesh.creation.box([0.8, 0.6, 0.02], trimesh.transformations.translation_matrix([0, 0, -0.01])),
        trimesh.creation.box([0.8, 0.02, 0.5], trimesh.transformations.translation_matrix([0, 0.31, 0.25])),
        trimesh.creation.box([0.02, 0.6, 0.5], trimesh.transformations.translation_matrix([0.41, 0, 0.25])),
        trimesh.creation.box([0.12, 0.08, 0.1], trimesh.transformations.translation_matrix([0.1, 0.08, 0.05])),
    ])
    # the bundled sweep's 160 x 120 px: at 64 x 48 (11 mm pixels at 0.65 m) ICP drifts 3 mm a frame
    w, h = 160, 120
    Kt = np.array([[147.0, 0.0, (w - 1) / 2], [0.0, 147.0, (h - 1) / 2], [0.0, 0.0, 1.0]])
    names, Ts, depths = [], [], []
    for k in range(5):  # 3 cm and ~4 degrees a frame along an arc
        a = np.radians(-120 + 5 * k)
        T = look_at([0.65 * np.cos(a), 0.65 * np.sin(a), 0.4], [0.05, 0.05, 0.05]).inverse().matrix  # cam_from_world
        d = render_depth(scene.vertices, scene.faces, T[:3, :3], T[:3, 3], Kt, w, h)
        depths.append(np.where(np.isfinite(d) & (d > 0), d, np.nan))
        names.append(f"f{k}")
        Ts.append(T)
    est = tsdf_fusion.chain(Ts[0], tsdf_fusion.track(depths, tsdf_fusion.pinhole_intrinsic(Kt, w, h)))
    truth = Poses(names, np.array([T[:3, :3] for T in Ts]), np.array([T[:3, 3] for T in Ts]))
    mine = Poses(names, np.array([T[:3, :3] for T in est]), np.array([T[:3, 3] for T in est]))
    a = ape(mine, truth, alignment="origin")
    # exact depth, a non-degenerate scene: ICP converges to the motion; measured 0.3 mm
    assert a.trans_stats_m.max < 0.002 and a.rot_stats_deg.max < 0.2
    still = Poses(names, np.array([Ts[0][:3, :3]] * 5), np.array([Ts[0][:3, 3]] * 5))
    assert ape(still, truth, alignment="origin").trans_stats_m.max > 0.1  # the motion is there to track


@pytest.mark.render
def test_runner_end_to_end_on_a_tiny_render_of_the_sweep(tmp_path):
    spec = yaml.safe_load(SCENE.read_text(encoding="utf-8"))
    spec["cameras"]["depth"] = {"size": [W, H], "fx": F}
    spec["sequence"] = {"fps": 10, "frames": 8}
    spec["render"]["spp"] = 1
    path = tmp_path / "tiny.yaml"
    path.write_text(yaml.safe_dump(spec), encoding="utf-8")
    render_spec(path, tmp_path / "ds", progress=False, show_warnings=False)
    doc = run_method("o3d-tsdf-fusion", tmp_path / "ds", tmp_path / "run")
    m = doc["metrics"]
    assert (tmp_path / "run" / "mesh_truth_poses.ply").is_file() and (tmp_path / "run" / "result.json").is_file()
    # 13 mm pixels at 0.8 m (64 x 48 px): measured F 0.57 at 5 mm, 0.87 at 10 mm with the truth poses
    # (0.98 at 5 mm on the bundled 160 x 120 sweep); tracking over 8 frames of 9 cm each: APE 12.3 mm
    assert m["truth_poses/fscore_5mm"] > 0.5 and m["truth_poses/fscore_10mm"] > 0.8, m
    assert m["tracked_ape_origin_rmse_mm"] < 20.0, m

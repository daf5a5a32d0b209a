"""KinectFusion-style TSDF fusion (Newcombe et al., ISMAR 2011; Curless and Levoy, SIGGRAPH 1996)
with Open3D 0.20: every complete view's depth frame (the dataset's exact z-depth truth, in view
order) is integrated into a ``VoxelBlockGrid`` (voxel :data:`VOXEL_M`, truncation
:data:`TRUNC_VOXELS` voxels, projective signed distance, nearest-pixel lookup, running weighted
average), and the zero level set is extracted by marching cubes. Two pose sources:

* ``truth``: the dataset's ``cam_from_world`` of each frame (fusion alone is scored);
* ``tracked``: the KinectFusion loop with frame-to-frame tracking: each frame registered to the
  previous one by point-to-plane ICP (Open3D ``registration_icp``, coarse to fine over
  :data:`ICP_SCALES`, the previous relative motion as the initial guess: constant velocity), the
  chain of relative motions anchored at the first frame's truth pose (KinectFusion's world is its
  first camera; here that camera is put where the truth has it, the ``origin`` alignment), so the
  fused mesh is scored in the truth's frame with no fitted alignment.

Written: the extracted meshes (``mesh_truth_poses.ply``, ``mesh_tracked_poses.ply``) and the
tracked trajectory (``trajectory_tracked.txt``, TUM format: ``name tx ty tz qx qy qz qw`` of
``world_from_cam``). Scored from the files: the mesh's surface points (sampled at
:data:`SAMPLE_SPACING_M`) against the truth -- Tanks and Temples precision / recall / F-score
(tau 5 and 10 mm; rec -> truth distances to the truth mesh, truth -> rec to the sampled points),
DTU accuracy / completeness -- and the tracked trajectory's APE (evo, SE(3)-aligned and origin).
The truth cloud is the observed truth surface: every frame's exact depth back-projected (so
completeness counts only what the sweep saw, as a scan's observation mask does).
"""
from __future__ import annotations

import numpy as np
import trimesh

from recon_eval.errors import NotApplicable
from recon_eval.metrics.pointcloud import dtu, tanks_and_temples, voxel_downsample
from recon_eval.metrics.poses import Poses, ape
from recon_eval.metrics.surfaces import sample_with_normals
from recon_eval.runners.common import RunOutput, out_path
from scenegen.geometry.rotation import matrix_from_quat_wxyz, quat_wxyz_from_matrix

VOXEL_M = 0.004  # TSDF voxel edge, metres
TRUNC_VOXELS = 4.0  # truncation distance, in voxels (KinectFusion's mu)
BLOCK_VOXELS = 8  # voxel blocks of 8^3 voxels (hashed, allocated where a frame sees a surface)
BLOCK_COUNT = 100_000  # initial capacity of the block hash map (it grows)
DEPTH_MAX_M = 3.0  # depths beyond are not integrated
ICP_SCALES = ((0.02, 0.04), (0.008, 0.016), (0.004, 0.008))  # (voxel-downsampling m, max correspondence m)
ICP_ITERATIONS = 40  # per scale
SAMPLE_SPACING_M = 0.001  # mean spacing of the points sampled on the extracted mesh
TAUS_M = (0.005, 0.010)  # Tanks and Temples thresholds scored
SEED = 0


def _o3d():
    import open3d as o3d  # heavy optional dependency (the `runners` extra): only these runners need it

    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    return o3d


def _check_pinhole(cam) -> None:
    if cam.model != "pinhole" and any(cam.dist):
        raise NotApplicable(f"TSDF fusion needs pinhole depth frames, got a {cam.model} camera with distortion")
    if cam.skew != 0.0:
        raise NotApplicable("TSDF fusion needs a camera without skew")


def camera_matrix(cam) -> np.ndarray:
    """K (3, 3) px of a scenegen camera."""
    return np.array([[cam.fx, 0.0, cam.cx], [0.0, cam.fy, cam.cy], [0.0, 0.0, 1.0]])


def pinhole_intrinsic(K: np.ndarray, width: int, height: int):
    """Open3D's ``PinholeCameraIntrinsic`` of K (3, 3) px and the image size (px); Open3D's pixel
    coordinates are OpenCV's (integer pixel centres)."""
    return _o3d().camera.PinholeCameraIntrinsic(int(width), int(height), K[0, 0], K[1, 1], K[0, 2], K[1, 2])


def _depth_image(depth_m: np.ndarray):
    """Open3D depth image (float32 metres, 0 = no measurement) of (H, W) metres with NaN misses."""
    d = np.where(np.isfinite(depth_m), depth_m, 0.0).astype(np.float32)
    return _o3d().geometry.Image(np.ascontiguousarray(d))


def fuse(depths_m, K: np.ndarray, cam_from_world, *, voxel_m: float = VOXEL_M,
         trunc_voxels: float = TRUNC_VOXELS):
    """(vertices (V, 3) float64 m world, faces (F, 3) int64) of the TSDF fusion of ``depths_m``
    (list of (H, W) metres, NaN = miss) with the pinhole matrix ``K`` (3, 3) px at poses
    ``cam_from_world`` (list of 4x4): Open3D's ``VoxelBlockGrid`` (the legacy
    ``ScalableTSDFVolume`` of the 0.20 CPU wheel extracts nothing), marching cubes over voxels
    observed at least once (weight >= 1)."""
    o3d = _o3d()
    o3c = o3d.core
    vbg = o3d.t.geometry.VoxelBlockGrid(attr_names=("tsdf", "weight"), attr_dtypes=(o3c.float32, o3c.float32),
                                        attr_channels=((1), (1)), voxel_size=voxel_m, block_resolution=BLOCK_VOXELS,
                                        block_count=BLOCK_COUNT, device=o3c.Device("CPU:0"))
    intrinsic = o3c.Tensor(np.asarray(K, np.float64))
    for d, T in zip(depths_m, cam_from_world):
        depth = o3d.t.geometry.Image(o3c.Tensor(np.where(np.isfinite(d), d, 0.0).astype(np.float32)))
        extrinsic = o3c.Tensor(np.asarray(T, np.float64))
        blocks = vbg.compute_unique_block_coordinates(depth, intrinsic, extrinsic, 1.0, DEPTH_MAX_M, trunc_voxels)
        vbg.integrate(blocks, depth, intrinsic, extrinsic, 1.0, DEPTH_MAX_M, trunc_voxels)
    mesh = vbg.extract_triangle_mesh(weight_threshold=1.0)
    if "positions" not in mesh.vertex or "indices" not in mesh.triangle:
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64)
    return mesh.vertex.positions.numpy().astype(np.float64), mesh.triangle.indices.numpy().astype(np.int64)


def _frame_cloud(depth_m: np.ndarray, intrinsic, voxel_m: float):
    o3d = _o3d()
    pc = o3d.geometry.PointCloud.create_from_depth_image(_depth_image(depth_m), intrinsic, depth_scale=1.0,
                                                         depth_trunc=DEPTH_MAX_M)
    pc = pc.voxel_down_sample(voxel_m)
    pc.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=3.0 * voxel_m, max_nn=30))
    pc.orient_normals_towards_camera_location(np.zeros(3))
    return pc


def track(depths_m, intrinsic) -> list:
    """prev_cam_from_cam (4x4) of frames 1.. by point-to-plane ICP of each frame to the previous
    one, coarse to fine (:data:`ICP_SCALES`), started from the previous relative motion."""
    reg = _o3d().pipelines.registration
    out, guess = [], np.eye(4)
    for prev, cur in zip(depths_m[:-1], depths_m[1:]):
        T = guess
        for voxel, dist in ICP_SCALES:
            src, tgt = _frame_cloud(cur, intrinsic, voxel), _frame_cloud(prev, intrinsic, voxel)
            T = np.asarray(reg.registration_icp(src, tgt, dist, T, reg.TransformationEstimationPointToPlane(),
                                                reg.ICPConvergenceCriteria(max_iteration=ICP_ITERATIONS)
                                                ).transformation)
        out.append(T)
        guess = T
    return out


def chain(cam0_from_world: np.ndarray, prev_from_cur: list) -> list:
    """cam_from_world (4x4) of every frame: the first given, each next one through its motion."""
    poses = [np.asarray(cam0_from_world, float)]
    for T in prev_from_cur:
        poses.append(np.linalg.inv(T) @ poses[-1])
    return poses


def observed_truth_points(depths_m, K: np.ndarray, cam_from_world) -> np.ndarray:
    """(N, 3) world points: every frame's truth depth back-projected (pixel centres, OpenCV)."""
    out = []
    for d, T in zip(depths_m, cam_from_world):
        v, u = np.nonzero(np.isfinite(d))
        z = d[v, u]
        xyz = np.stack([(u - K[0, 2]) / K[0, 0] * z, (v - K[1, 2]) / K[1, 1] * z, z], axis=1)
        R, t = T[:3, :3], T[:3, 3]
        out.append((xyz - t) @ R)  # world = R^T (cam - t)
    return np.concatenate(out) if out else np.zeros((0, 3))


def surface_points(vertices, faces, spacing_m: float = SAMPLE_SPACING_M) -> np.ndarray:
    """(N, 3) points sampled uniformly on a mesh, one per ``spacing_m**2`` of area (seeded)."""
    if len(faces) == 0:
        return np.zeros((0, 3))
    area = float(trimesh.Trimesh(vertices, faces, process=False).area)
    n = max(int(np.ceil(area / spacing_m ** 2)), 1)
    return np.asarray(sample_with_normals(vertices, faces, n, seed=SEED)[0], float)


def score_mesh(vertices, faces, truth_points, gt_mesh) -> tuple[dict, dict]:
    """(results, headline metrics) of a fused mesh against the truth (module docstring)."""
    rec = surface_points(vertices, faces)
    results, metrics = {}, {}
    for tau in TAUS_M:
        r = tanks_and_temples(rec, truth_points, tau, gt_mesh=gt_mesh)
        results[f"tnt_{tau * 1000:g}mm"] = r
        mm = f"{tau * 1000:g}mm"
        metrics.update({f"fscore_{mm}": r.fscore, f"precision_{mm}": r.precision, f"recall_{mm}": r.recall})
    d = dtu(voxel_downsample(rec, 0.5 * TAUS_M[0]), voxel_downsample(truth_points, 0.5 * TAUS_M[0]),
            gt_mesh=gt_mesh)
    results["dtu"] = d
    metrics.update({"acc_mean_mm": 1000 * d.acc_mean_m, "comp_mean_mm": 1000 * d.comp_mean_m})
    return results, metrics


def _write_mesh(path, vertices, faces) -> None:
    tmp = path.with_name(path.name + ".tmp")
    trimesh.Trimesh(vertices, faces, process=False).export(tmp, file_type="ply")
    tmp.replace(path)


def _write_tum(path, names, cam_from_world) -> None:
    lines = []
    for n, T in zip(names, cam_from_world):
        Tw = np.linalg.inv(T)
        w, x, y, z = quat_wxyz_from_matrix(Tw[:3, :3])
        lines.append(" ".join([n, *(f"{v:.12f}" for v in (*Tw[:3, 3], x, y, z, w))]))
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text("# name tx ty tz qx qy qz qw (world_from_cam)\n" + "\n".join(lines) + "\n", encoding="utf-8")
    tmp.replace(path)


def _read_tum(path) -> Poses:
    names, R, t = [], [], []
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("#") or not line.strip():
            continue
        n, *v = line.split()
        v = np.asarray(v, float)
        Rw = matrix_from_quat_wxyz([v[6], v[3], v[4], v[5]])
        names.append(n)
        R.append(Rw.T)
        t.append(-Rw.T @ v[:3])
    return Poses(tuple(names), np.asarray(R).reshape(-1, 3, 3), np.asarray(t).reshape(-1, 3))


def run(ds, out_dir, options: dict) -> RunOutput:
    """Fusion with truth poses and with tracked poses, scored (module docstring)."""
    views = list(ds.views)
    if len(views) < 2:
        raise NotApplicable(f"{ds.root}: TSDF fusion needs a sweep of >= 2 depth frames, got {len(views)}")
    cams, Ts = zip(*(ds.camera(v) for v in views))
    if len({(c.width, c.height, c.fx, c.fy, c.cx, c.cy) for c in cams}) != 1:
        raise NotApplicable(f"{ds.root}: TSDF fusion needs one depth camera for every frame")
    _check_pinhole(cams[0])
    K = camera_matrix(cams[0])
    intrinsic = pinhole_intrinsic(K, cams[0].width, cams[0].height)
    depths = [ds.depth(v) for v in views]
    truth_T = [T.matrix for T in Ts]
    gt_mesh = ds.mesh()
    truth_points = observed_truth_points(depths, K, truth_T)
    tracked_T = chain(truth_T[0], track(depths, intrinsic))
    res = RunOutput(notes={"frames": len(views), "voxel_m": VOXEL_M, "trunc_m": TRUNC_VOXELS * VOXEL_M,
                           "depth": "depth_z truth", "tracking": "frame-to-frame point-to-plane ICP, "
                           "anchored at the first frame's truth pose"})
    traj = out_path(out_dir, "trajectory_tracked.txt")
    _write_tum(traj, views, tracked_T)
    for label, poses in (("truth_poses", truth_T), ("tracked_poses", tracked_T)):
        V, F = fuse(depths, K, poses)
        path = out_path(out_dir, f"mesh_{label}.ply")
        _write_mesh(path, V, F)
        m = trimesh.load(path, process=False, force="mesh")
        results, metrics = score_mesh(np.asarray(m.vertices, float), np.asarray(m.faces, np.int64),
                                      truth_points, gt_mesh)
        res.results.update({f"{label}/{k}": v for k, v in results.items()})
        res.metrics.update({f"{label}/{k}": v for k, v in metrics.items()})
        res.raw_files.append(path.name)
    res.raw_files.append(traj.name)
    est = _read_tum(traj)
    for align in ("se3", "origin"):
        a = ape(est, ds.poses, alignment=align)
        res.results[f"ape_{align}"] = a
        res.metrics[f"tracked_ape_{align}_rmse_mm"] = 1000 * a.trans_stats_m.rmse
        res.metrics[f"tracked_ape_{align}_rot_rmse_deg"] = a.rot_stats_deg.rmse
    return res

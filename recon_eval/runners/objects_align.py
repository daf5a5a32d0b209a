"""Object recognition by alignment (the course's first method), with Open3D 0.20: per image, the
scene cloud from the depth image, the dominant plane (the table) removed by RANSAC, the rest cut
into clusters (DBSCAN); each target object's model cloud is registered to each cluster by global
registration (FPFH features + RANSAC on feature matches, Rusu et al. 2009) then refined by
point-to-plane ICP. :data:`TRIALS` such registrations per (object, cluster) are verified by
rendering the model's depth in each pose against the scene's depth (the fraction of the model's
pixels within :data:`VERIFY_VOXELS` voxels of the scene, over those not behind it: a model
surface in front of the scene is free space violated); the best is the estimate, with that
fraction as its score. BOP keeps the ``inst_count`` best per target.

Input: the dataset's BOP export (depth, K, models); output ``poses_bop19.csv``, scored with
BOP19 AR. Voxel size: :data:`VOXEL_FRACTION` of the smallest target model's diameter. Seeded
(``o3d.utility.random.seed``): the same dataset gives the same CSV.
"""
from __future__ import annotations

import time

import numpy as np

from recon_eval.metrics.objects_depth import render_depth
from recon_eval.runners.objects_common import back_project, bop_export, score_bop_run

VOXEL_FRACTION = 0.05  # of the smallest model diameter
MODEL_POINTS = 4000  # points sampled on each model's surface
RANSAC_ITERATIONS = 5000
RANSAC_CONFIDENCE = 0.999
TRIALS = 4  # global registrations per (object, cluster), the best kept after verification
VERIFY_VOXELS = 2.0  # depth agreement of the verification, in voxels
SEED = 0


def _o3d():
    import open3d as o3d  # heavy optional dependency (the `runners` extra): only these runners need it

    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)  # its per-registration warnings
    return o3d


def _cloud(points: np.ndarray, voxel: float):
    o3d = _o3d()
    pc = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    pc = pc.voxel_down_sample(voxel)
    pc.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=2.0 * voxel, max_nn=30))
    pc.orient_normals_towards_camera_location(np.zeros(3))
    return pc


def _fpfh(pc, voxel: float):
    o3d = _o3d()
    return o3d.pipelines.registration.compute_fpfh_feature(
        pc, o3d.geometry.KDTreeSearchParamHybrid(radius=5.0 * voxel, max_nn=100))


def _model_cloud(model, voxel: float):
    o3d = _o3d()
    mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(model.vertices),
                                     o3d.utility.Vector3iVector(np.asarray(model.faces, dtype=np.int32)))
    pc = mesh.sample_points_uniformly(number_of_points=MODEL_POINTS)
    pc = pc.voxel_down_sample(voxel)
    pc.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=2.0 * voxel, max_nn=30))
    return pc, _fpfh(pc, voxel)


def clusters(depth_mm: np.ndarray, K: np.ndarray, voxel: float) -> list:
    """The scene's object clusters: the depth cloud without its dominant plane (when the plane
    holds 20 % of the points or more), DBSCAN (eps 3 voxels, 20 points) clusters."""
    o3d = _o3d()
    pc = _cloud(back_project(depth_mm, K), voxel)
    if len(pc.points) >= 3:
        _, inliers = pc.segment_plane(distance_threshold=voxel, ransac_n=3, num_iterations=1000)
        if len(inliers) >= 0.2 * len(pc.points):
            pc = pc.select_by_index(inliers, invert=True)
    labels = np.asarray(pc.cluster_dbscan(eps=3.0 * voxel, min_points=20))
    out = []
    for lab in range(labels.max() + 1 if labels.size else 0):
        c = pc.select_by_index(np.flatnonzero(labels == lab).tolist())
        if len(c.points) >= 30:
            c.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=2.0 * voxel, max_nn=30))
            c.orient_normals_towards_camera_location(np.zeros(3))
            out.append(c)
    return out


def verify(model, T, view, voxel: float) -> float:
    """Fraction of the model's rendered pixels (pose ``T``) whose depth agrees with the scene
    within VERIFY_VOXELS voxels, among those not hidden behind the scene surface."""
    d = render_depth(model.vertices, model.faces, T[:3, :3], T[:3, 3], view.K, view.width, view.height)
    on = d > 0
    if not on.any():
        return 0.0
    diff = d[on] - view.depth[on]
    tol = VERIFY_VOXELS * voxel
    agree = np.count_nonzero(np.abs(diff) <= tol)
    front = np.count_nonzero((diff < -tol) | (view.depth[on] == 0))
    return float(agree / max(agree + front, 1))


def register(model_pc, model_fpfh, cluster, c_fpfh, voxel: float, iterations: int = RANSAC_ITERATIONS):
    """(cam_from_model 4x4, ICP inlier fraction of the cluster's points) of one global
    registration + ICP."""
    o3d = _o3d()
    reg = o3d.pipelines.registration
    dist = 1.5 * voxel
    coarse = reg.registration_ransac_based_on_feature_matching(
        model_pc, cluster, model_fpfh, c_fpfh, True, dist, reg.TransformationEstimationPointToPoint(False), 3,
        [reg.CorrespondenceCheckerBasedOnEdgeLength(0.9), reg.CorrespondenceCheckerBasedOnDistance(dist)],
        reg.RANSACConvergenceCriteria(iterations, RANSAC_CONFIDENCE))
    fine = reg.registration_icp(model_pc, cluster, voxel, coarse.transformation,
                                reg.TransformationEstimationPointToPlane(),
                                reg.ICPConvergenceCriteria(max_iteration=50))
    T = np.asarray(fine.transformation)
    back = reg.evaluate_registration(cluster, model_pc, voxel, np.linalg.inv(T))
    return T, float(back.fitness)


def estimate(bop, trials: int = TRIALS, iterations: int = RANSAC_ITERATIONS) -> tuple[list, dict]:
    """BOP CSV rows of the alignment method on every target image of ``bop``."""
    o3d = _o3d()
    o3d.utility.random.seed(SEED)
    target_objs = sorted({t.obj_id for t in bop.targets})
    voxel = VOXEL_FRACTION * min(bop.models[o].diameter for o in target_objs)
    models = {o: _model_cloud(bop.models[o], voxel) for o in target_objs}
    by_image: dict = {}
    for t in bop.targets:
        by_image.setdefault((t.scene_id, t.im_id), set()).add(t.obj_id)
    rows = []
    for (scene_id, im_id), objs in sorted(by_image.items()):
        view = bop.views[(scene_id, im_id)]
        t0 = time.perf_counter()
        found = []
        if view.depth is not None:
            cl = [(c, _fpfh(c, voxel)) for c in clusters(view.depth, view.K, voxel)]
            for obj_id in sorted(objs):
                for c, c_fpfh in cl:
                    poses = [register(*models[obj_id], c, c_fpfh, voxel, iterations)[0] for _ in range(trials)]
                    scores = [verify(bop.models[obj_id], T, view, voxel) for T in poses]
                    found.append((obj_id, max(scores), poses[int(np.argmax(scores))]))
        dt = time.perf_counter() - t0
        rows += [(scene_id, im_id, o, s, T[:3, :3], T[:3, 3], dt) for o, s, T in found]
    return rows, {"voxel_mm": voxel, "trials": trials, "ransac_iterations": iterations,
                  "open3d_version": o3d.__version__}


def run(ds, out_dir, options: dict):
    bop = bop_export(ds)
    rows, notes = estimate(bop, int(options.get("trials", TRIALS)),
                           int(options.get("ransac_iterations", RANSAC_ITERATIONS)))
    return score_bop_run(bop, out_dir, rows, notes)

"""Point-cloud and mesh metrics against transcriptions of their reference code:

* Tanks and Temples toolbox (isl-org/TanksAndTemples, python_toolbox/evaluation/evaluation.py,
  ``get_f1_score_histo2``): the precision / recall curves;
* Open3D ``SelectionPolygonVolume::CropInPolygon`` (cpp/open3d/visualization/utility/
  SelectionPolygonVolume.cpp), the toolbox's crop;
* Occupancy Networks (autonomousvision/occupancy_networks, im2mesh/eval.py ``distance_p2p``,
  ``eval_pointcloud``; im2mesh/utils/libmesh/inside_mesh.py ``MeshIntersector``,
  ``TriangleIntersector2d.check_triangles``; im2mesh/common.py ``compute_iou``);
* exact point-to-mesh distances against the brute force over every triangle.
"""
from __future__ import annotations

import numpy as np
import pytest
import trimesh
from scipy.spatial import cKDTree

from recon_eval.metrics.distances import mesh_surface_distances
from recon_eval.metrics.mesh_bvh import point_triangle_sq_distances
from recon_eval.metrics.surfaces import compute_iou, mesh_contains, normal_consistency_of_samples
from recon_eval.metrics.tnt import CropVolume, crop_mask, tanks_and_temples_curves


def _histo2(threshold, distance1, distance2, plot_stretch=5):
    """get_f1_score_histo2, the cumulative histograms (lines 'bins = np.arange(...)' .. 'cum_target')."""
    dist_threshold = threshold
    num = len(distance1)
    bins = np.arange(0, dist_threshold * plot_stretch, dist_threshold / 100)
    hist, edges_source = np.histogram(distance1, bins)
    cum_source = np.cumsum(hist).astype(float) / num
    num = len(distance2)
    bins = np.arange(0, dist_threshold * plot_stretch, dist_threshold / 100)
    hist, edges_target = np.histogram(distance2, bins)
    cum_target = np.cumsum(hist).astype(float) / num
    return edges_source, cum_source, edges_target, cum_target


def test_tanks_and_temples_curves_equal_toolbox(agreement):
    rng = np.random.default_rng(0)
    d1, d2 = np.abs(rng.normal(0, 0.02, 5000)), np.abs(rng.normal(0, 0.03, 4000))
    d1[:10] = 0.0
    d1[10:20] = 0.01 * np.arange(10) / 2  # on bin edges
    e, cs, e2, ct = _histo2(0.01, d1, d2)
    r = tanks_and_temples_curves(d1, d2, 0.01)
    d = max(float(np.max(np.abs(r.edges_m - e))), float(np.max(np.abs(r.precision - cs))),
            float(np.max(np.abs(r.recall - ct))))
    assert d == 0
    agreement("tnt.curves", "precision / recall curves (fractions at the bin edges)",
              "Tanks and Temples toolbox `get_f1_score_histo2` (transcribed)", "isl-org master",
              "5000 / 4000 distances, some on bin edges", d)


def _crop_in_polygon(points, polygon, axis, axis_min, axis_max):
    """Open3D SelectionPolygonVolume::CropInPolygon, transcribed loop by loop."""
    u, v, w = {"x": (1, 2, 0), "y": (0, 2, 1), "z": (0, 1, 2)}[axis.lower()]
    out = []
    for k, point in enumerate(points):
        if point[w] < axis_min or point[w] > axis_max:
            continue
        nodes = []
        for i in range(len(polygon)):
            j = (i + 1) % len(polygon)
            if ((polygon[i][v] < point[v] and polygon[j][v] >= point[v]) or
                    (polygon[j][v] < point[v] and polygon[i][v] >= point[v])):
                nodes.append(polygon[i][u] + (point[v] - polygon[i][v]) / (polygon[j][v] - polygon[i][v])
                             * (polygon[j][u] - polygon[i][u]))
        nodes.sort()
        loc = int(np.searchsorted(nodes, point[u], side="left"))  # std::lower_bound
        if loc % 2 == 1:
            out.append(k)
    return np.array(out, dtype=np.int64)


@pytest.mark.parametrize("axis", ["Z", "Y"])
def test_crop_equals_open3d_crop_in_polygon(axis, agreement):
    rng = np.random.default_rng(1)
    ang = np.sort(rng.uniform(0, 2 * np.pi, 9))
    rad = rng.uniform(0.5, 2.0, 9)  # a star-shaped, non-convex polygon
    poly = np.zeros((9, 3))
    a, b = (0, 1) if axis == "Z" else (0, 2)
    poly[:, a], poly[:, b] = rad * np.cos(ang), rad * np.sin(ang)
    pts = rng.uniform(-2.2, 2.2, (4000, 3))
    pts[:50, b] = poly[rng.integers(0, 9, 50), b]  # on the vertices' lines (the half-open rule)
    ref = _crop_in_polygon(pts, poly, axis, -1.0, 1.5)
    ours = np.flatnonzero(crop_mask(pts, CropVolume(poly, axis, -1.0, 1.5)))
    d = float(len(np.setxor1d(ours, ref)))
    assert d == 0
    agreement(f"tnt.crop.{axis}", "crop volume: points kept (count of disagreements)",
              "Open3D `SelectionPolygonVolume::CropInPolygon` (transcribed)", "master", f"4000 points, 9-gon, axis {axis}", d)


def _distance_p2p(points_src, normals_src, points_tgt, normals_tgt):
    """ONet im2mesh/eval.py distance_p2p (pykdtree's KDTree there; the same nearest neighbours)."""
    kdtree = cKDTree(points_tgt)
    dist, idx = kdtree.query(points_src)
    normals_src = normals_src / np.linalg.norm(normals_src, axis=-1, keepdims=True)
    normals_tgt = normals_tgt / np.linalg.norm(normals_tgt, axis=-1, keepdims=True)
    normals_dot_product = (normals_tgt[idx] * normals_src).sum(axis=-1)
    return dist, np.abs(normals_dot_product)


def test_normal_consistency_equals_onet(agreement):
    a = trimesh.creation.icosphere(subdivisions=3)
    b = trimesh.creation.box(extents=(1.6, 1.6, 1.6))
    pa, ia = trimesh.sample.sample_surface(a, 20000, seed=1)
    pb, ib = trimesh.sample.sample_surface(b, 20000, seed=2)
    na, nb = a.face_normals[ia], b.face_normals[ib]
    _, comp = _distance_p2p(pb, nb, pa, na)  # completeness: target -> prediction
    _, acc = _distance_p2p(pa, na, pb, nb)
    ref = 0.5 * comp.mean() + 0.5 * acc.mean()
    ours = normal_consistency_of_samples(pa, na, pb, nb)[0]
    d = abs(ours - ref)
    assert d < 1e-15
    agreement("onet.normal_consistency", "normal consistency", "Occupancy Networks `eval_pointcloud` (transcribed)",
              "autonomousvision master", "sphere vs cube, 20k samples each", d)


def _onet_contains(mesh_v, mesh_f, points, resolution=512):
    """ONet inside_mesh.py MeshIntersector(mesh, 512).query with TriangleIntersector2d's candidate
    hash replaced by all triangles (the hash only prunes) and check_triangles as written."""
    triangles = mesh_v[mesh_f].astype(np.float64)
    n_tri = triangles.shape[0]
    bbox_min = triangles.reshape(3 * n_tri, 3).min(axis=0)
    bbox_max = triangles.reshape(3 * n_tri, 3).max(axis=0)
    scale = (resolution - 1) / (bbox_max - bbox_min)
    translate = 0.5 - scale * bbox_min
    triangles = scale * triangles + translate
    points = scale * points + translate
    contains = np.zeros(len(points), dtype=bool)
    inside_aabb = np.all((0 <= points) & (points <= resolution), axis=1)
    mask = inside_aabb
    points = points[mask]
    pi, ti = np.meshgrid(np.arange(len(points)), np.arange(n_tri), indexing="ij")
    pi, ti = pi.ravel(), ti.ravel()
    tri2d = triangles[ti][:, :, :2]
    A = tri2d[:, :2] - tri2d[:, 2:]
    A = A.transpose([0, 2, 1])
    y = points[pi][:, :2] - tri2d[:, 2]
    detA = A[:, 0, 0] * A[:, 1, 1] - A[:, 0, 1] * A[:, 1, 0]
    ok = np.abs(detA) != 0.0
    s_detA, abs_detA = np.sign(detA), np.abs(detA)
    u = (A[:, 1, 1] * y[:, 0] - A[:, 0, 1] * y[:, 1]) * s_detA
    v = (-A[:, 1, 0] * y[:, 0] + A[:, 0, 0] * y[:, 1]) * s_detA
    sum_uv = u + v
    hit = ok & (0 < u) & (u < abs_detA) & (0 < v) & (v < abs_detA) & (0 < sum_uv) & (sum_uv < abs_detA)
    points_indices, tri_indices = pi[hit], ti[hit]
    triangles_intersect = triangles[tri_indices]
    points_intersect = points[points_indices]
    t1, t2, t3 = triangles_intersect[:, 0, :], triangles_intersect[:, 1, :], triangles_intersect[:, 2, :]
    normals = np.cross(t3 - t1, t2 - t1)
    alpha = np.sum(normals[:, :2] * (t1[:, :2] - points_intersect[:, :2]), axis=1)
    n_2 = normals[:, 2]
    abs_n_2 = np.abs(n_2)
    m = abs_n_2 != 0
    depth_intersect = np.full(points_intersect.shape[0], np.nan)
    depth_intersect[m] = t1[m, 2] * abs_n_2[m] + alpha[m] * np.sign(n_2)[m]
    smaller_depth = depth_intersect >= points_intersect[:, 2] * abs_n_2
    bigger_depth = depth_intersect < points_intersect[:, 2] * abs_n_2
    nb0 = np.bincount(points_indices[smaller_depth], minlength=points.shape[0])
    nb1 = np.bincount(points_indices[bigger_depth], minlength=points.shape[0])
    contains[mask] = (np.mod(nb0, 2) == 1) & (np.mod(nb1, 2) == 1)
    return contains


def test_volumetric_iou_equals_onet(agreement):
    a = trimesh.creation.icosphere(subdivisions=2, radius=0.5)
    b = trimesh.creation.box(extents=(0.8, 0.7, 0.9))
    b.apply_translation([0.15, -0.1, 0.05])
    rng = np.random.default_rng(3)
    q = 1.1 * (rng.random((6000, 3)) - 0.5)
    ref_a = _onet_contains(np.asarray(a.vertices), np.asarray(a.faces), q)
    ref_b = _onet_contains(np.asarray(b.vertices), np.asarray(b.faces), q)
    oa = mesh_contains(q, a.vertices, a.faces)
    ob = mesh_contains(q, b.vertices, b.faces)
    n_diff = int(np.sum(oa != ref_a) + np.sum(ob != ref_b))
    d = abs(compute_iou(oa, ob) - compute_iou(ref_a.astype(float), ref_b.astype(float)))
    assert n_diff == 0 and d == 0
    agreement("onet.iou", "volumetric IoU (and occupancy disagreements: 0)",
              "Occupancy Networks `check_mesh_contains`, `compute_iou` (transcribed)", "autonomousvision master",
              "sphere vs box, 6000 points", d)


def test_mesh_distance_equals_brute_force(agreement):
    rng = np.random.default_rng(4)
    s = trimesh.creation.icosphere(subdivisions=3)
    V = np.r_[np.asarray(s.vertices), [[-9, -9, -1.2], [9, -9, -1.2], [0, 9, -1.2]]]
    F = np.r_[np.asarray(s.faces), [[len(s.vertices), len(s.vertices) + 1, len(s.vertices) + 2]]]
    p = np.r_[rng.normal(0, 1, (1500, 3)), rng.uniform(-10, 10, (500, 3))]
    tri = V[F]
    ref = np.array([np.sqrt(point_triangle_sq_distances(np.repeat(x[None], len(tri), 0), tri[:, 0], tri[:, 1],
                                                       tri[:, 2]).min()) for x in p])
    d = float(np.max(np.abs(mesh_surface_distances(p, V, F) - ref)))
    assert d == 0
    agreement("mesh.distance", "point-to-mesh distance (m)", "brute force over all triangles, Ericson 5.1.5",
              "float64", "2000 points, 1281 triangles (1 large)", d)

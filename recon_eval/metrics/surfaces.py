"""Mesh-to-mesh metrics of Occupancy Networks (Mescheder et al., CVPR 2019;
autonomousvision/occupancy_networks, ``im2mesh/eval.py`` ``MeshEvaluator`` and
``im2mesh/utils/libmesh/inside_mesh.py``): normal consistency and volumetric IoU.

* Normal consistency: surface samples with their face normals on both meshes; each sample's
  nearest sample on the other mesh (KD-tree); ``|n . n_nearest|`` (unit normals, absolute value:
  "normals that point into the wrong direction" are forgiven) averaged each way, then
  ``0.5 * completeness_normals + 0.5 * accuracy_normals`` (``eval_pointcloud``, ``distance_p2p``).
* Volumetric IoU: points uniform in the cube around the meshes (ONet: side 1 + padding 0.1 of the
  normalised unit cube), occupancy of each mesh by ``check_mesh_contains`` (rays along +z and -z:
  inside when both cross the surface an odd number of times; a crossing where the ray's
  (x, y) is strictly inside the triangle's projection), ``compute_iou`` = |A and B| / |A or B|.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from recon_eval.arrays import as_float_array
from recon_eval.errors import InputError
from recon_eval.metrics.distances import sample_mesh_surface


def _mesh(vertices, faces, name: str):
    V = as_float_array(vertices, f"{name} vertices", (None, 3))
    F = np.asarray(faces)
    if F.ndim != 2 or F.shape[1:] != (3,) or not np.issubdtype(F.dtype, np.integer) or len(F) == 0:
        raise InputError(f"{name} faces: expected a non-empty integer array (F, 3), got {F.dtype} {F.shape}")
    if F.min() < 0 or F.max() >= len(V):
        raise InputError(f"{name} faces: vertex index out of range")
    return V, F.astype(np.int64)


def sample_with_normals(vertices, faces, n: int, *, seed: int):
    """n surface samples (n, 3), area-weighted and seeded, with the unit normal of their face."""
    V, F = _mesh(vertices, faces, "mesh")
    return sample_mesh_surface(V, F, n, seed=seed, with_normals=True)


def normal_consistency_of_samples(points_src, normals_src, points_tgt, normals_tgt) -> tuple[float, float, float]:
    """(normal consistency, completeness normals, accuracy normals) of two oriented samples, as
    ONet's ``eval_pointcloud``: completeness = tgt -> src, accuracy = src -> tgt."""

    def p2p(ps, ns, pt, nt):
        _, idx = cKDTree(pt).query(ps, workers=-1)
        ns = ns / np.linalg.norm(ns, axis=-1, keepdims=True)
        nt = nt / np.linalg.norm(nt, axis=-1, keepdims=True)
        return np.abs(np.sum(nt[idx] * ns, axis=-1))

    comp = float(np.mean(p2p(points_tgt, normals_tgt, points_src, normals_src)))
    acc = float(np.mean(p2p(points_src, normals_src, points_tgt, normals_tgt)))
    return 0.5 * comp + 0.5 * acc, comp, acc


def mesh_contains(points, vertices, faces, *, chunk: int = 100_000) -> np.ndarray:
    """(N,) bool occupancy of points (N, 3) in a closed mesh by ONet's ``check_mesh_contains``
    (see the module docstring; candidate triangles from a grid over the (x, y) plane instead of
    ONet's hash at resolution 512, which finds the same triangles)."""
    p = as_float_array(points, "points", (None, 3))
    V, F = _mesh(vertices, faces, "mesh")
    tri = V[F]
    lo, hi = tri.reshape(-1, 3).min(0), tri.reshape(-1, 3).max(0)
    out = np.zeros(len(p), bool)
    inside_box = np.all((p >= lo) & (p <= hi), axis=1)
    G = int(np.clip(np.sqrt(len(F)), 1, 512))
    cell = (hi[:2] - lo[:2]) / G
    cell = np.where(cell > 0, cell, 1.0)
    tlo = np.clip(((tri[:, :, :2].min(1) - lo[:2]) / cell).astype(np.int64), 0, G - 1)
    thi = np.clip(((tri[:, :, :2].max(1) - lo[:2]) / cell).astype(np.int64), 0, G - 1)
    nx, ny = thi[:, 0] - tlo[:, 0] + 1, thi[:, 1] - tlo[:, 1] + 1
    cnt = nx * ny
    tri_of = np.repeat(np.arange(len(F)), cnt)
    local = np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    cx = tlo[tri_of, 0] + local % nx[tri_of]
    cy = tlo[tri_of, 1] + local // nx[tri_of]
    key = cx * G + cy
    order = np.argsort(key, kind="stable")
    key, tri_of = key[order], tri_of[order]
    starts = np.searchsorted(key, np.arange(G * G))
    ends = np.searchsorted(key, np.arange(G * G), side="right")
    # plane of each triangle as ONet writes it: normal = (t3 - t1) x (t2 - t1)
    t1, t2, t3 = tri[:, 0], tri[:, 1], tri[:, 2]
    nrm = np.cross(t3 - t1, t2 - t1)
    A = np.stack([t1[:, :2] - t3[:, :2], t2[:, :2] - t3[:, :2]], axis=2)  # columns t1 - t3, t2 - t3
    detA = A[:, 0, 0] * A[:, 1, 1] - A[:, 0, 1] * A[:, 1, 0]
    idx_in = np.flatnonzero(inside_box)
    for s in range(0, len(idx_in), chunk):
        ids = idx_in[s:s + chunk]
        q = p[ids]
        c = np.clip(((q[:, :2] - lo[:2]) / cell).astype(np.int64), 0, G - 1)
        k = c[:, 0] * G + c[:, 1]
        n_c = ends[k] - starts[k]
        owner = np.repeat(np.arange(len(ids)), n_c)
        pos = np.repeat(starts[k], n_c) + (np.arange(n_c.sum()) - np.repeat(np.cumsum(n_c) - n_c, n_c))
        t = tri_of[pos]
        qq = q[owner]
        y = qq[:, :2] - t3[t, :2]
        s_det, abs_det = np.sign(detA[t]), np.abs(detA[t])
        a = A[t]
        u = (a[:, 1, 1] * y[:, 0] - a[:, 0, 1] * y[:, 1]) * s_det
        v = (-a[:, 1, 0] * y[:, 0] + a[:, 0, 0] * y[:, 1]) * s_det
        hit = (abs_det != 0) & (0 < u) & (u < abs_det) & (0 < v) & (v < abs_det) & (0 < u + v) & (u + v < abs_det)
        owner, t, qq = owner[hit], t[hit], qq[hit]
        n2 = nrm[t, 2]
        ok = n2 != 0
        owner, t, qq, n2 = owner[ok], t[ok], qq[ok], n2[ok]
        alpha = np.sum(nrm[t, :2] * (t1[t, :2] - qq[:, :2]), axis=1)
        depth = t1[t, 2] * np.abs(n2) + alpha * np.sign(n2)
        above = depth >= qq[:, 2] * np.abs(n2)
        n_above = np.bincount(owner[above], minlength=len(ids))
        n_below = np.bincount(owner[~above], minlength=len(ids))
        out[ids] = (n_above % 2 == 1) & (n_below % 2 == 1)
    return out


def iou_points(vertices_a, vertices_b, n: int, *, seed: int, padding: float = 0.1) -> np.ndarray:
    """n points uniform in the cube centred on both meshes' bounding box, side (1 + padding) times
    its largest extent (ONet's ``boxsize = 1 + padding`` for shapes normalised to the unit cube)."""
    allv = np.concatenate([np.asarray(vertices_a, float), np.asarray(vertices_b, float)])
    lo, hi = allv.min(0), allv.max(0)
    side = (1.0 + padding) * float(np.max(hi - lo))
    rng = np.random.default_rng(seed)
    return 0.5 * (lo + hi) + side * (rng.random((n, 3)) - 0.5)


def compute_iou(occ1, occ2) -> float:
    """ONet ``compute_iou``: |occ1 & occ2| / |occ1 | occ2| of occupancies thresholded at 0.5."""
    o1, o2 = np.asarray(occ1) >= 0.5, np.asarray(occ2) >= 0.5
    union = float(np.sum(o1 | o2))
    return float(np.sum(o1 & o2)) / union if union else float("nan")


@dataclass(frozen=True)
class MeshComparisonResult:
    """Occupancy Networks' mesh metrics of a reconstructed mesh against the truth mesh."""

    normal_consistency: float  # 0.5 (completeness normals + accuracy normals), in [0, 1]
    completeness_normals: float  # GT samples -> nearest reconstructed sample
    accuracy_normals: float  # reconstructed samples -> nearest GT sample
    iou: float  # volumetric IoU over the IoU points (the meshes must be closed)
    n_surface_samples: int  # per mesh
    n_iou_points: int
    iou_padding: float
    seed: int
    benchmark: str = "occupancy_networks"


def mesh_comparison(rec_vertices, rec_faces, gt_vertices, gt_faces, *, n_samples: int = 100_000,
                    n_iou_points: int = 100_000, padding: float = 0.1, seed: int = 0) -> MeshComparisonResult:
    """Normal consistency and volumetric IoU of a reconstructed mesh against the truth (ONet's
    ``MeshEvaluator.eval_mesh`` with its defaults: 100k surface samples, 100k IoU points, padding
    0.1), seeded. Both meshes should be closed for the IoU to mean a volume."""
    Vr, Fr = _mesh(rec_vertices, rec_faces, "reconstructed mesh")
    Vg, Fg = _mesh(gt_vertices, gt_faces, "GT mesh")
    ps, ns = sample_with_normals(Vr, Fr, n_samples, seed=seed)
    pt, nt = sample_with_normals(Vg, Fg, n_samples, seed=seed + 1)
    nc, comp, acc = normal_consistency_of_samples(ps, ns, pt, nt)
    q = iou_points(Vr, Vg, n_iou_points, seed=seed + 2, padding=padding)
    iou = compute_iou(mesh_contains(q, Vr, Fr), mesh_contains(q, Vg, Fg))
    return MeshComparisonResult(nc, comp, acc, iou, n_samples, n_iou_points, padding, seed)

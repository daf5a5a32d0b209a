"""Distances from query points to a reference: the nearest point of a cloud, or the exact nearest
point of a triangle mesh surface.

metrics.md ("Point clouds and meshes"): with exact synthetic truth, measure distances to the GT
mesh surface (point-to-triangle) or to a GT sample far denser than tau, and say which. Results
carry :class:`DistanceTo` so they say which.

Point-to-triangle: closest point by Voronoi-region tests (Ericson, *Real-Time Collision
Detection*, 2005, sec. 5.1.5), vectorised; the candidate triangles come from a bounding-volume
hierarchy (:mod:`recon_eval.metrics.mesh_bvh`) that examines every triangle which could be the
nearest, so the distance is exact, in memory bounded whatever the triangle sizes.
"""
from __future__ import annotations

import hashlib
from enum import Enum
from typing import Callable

import numpy as np
from scipy.spatial import cKDTree

from recon_eval.arrays import as_float_array
from recon_eval.errors import InputError
from recon_eval.metrics.mesh_bvh import CHUNK, TriangleBVH, closest_points_on_triangles

__all__ = ["DistanceTo", "MeshSurface", "closest_points_on_triangles", "mesh_surface_distances",
           "nearest_point_distances", "sample_mesh_surface", "surface_distances"]


class DistanceTo(str, Enum):
    """Which reference a distance was measured to."""

    POINTS = "nearest_point"  # nearest point of a (dense) reference cloud
    MESH = "mesh_surface"  # exact nearest point of the reference triangle mesh surface


def nearest_point_distances(query, reference, *, workers: int = -1, upper_bound_m: float = np.inf) -> np.ndarray:
    """Euclidean distance (N,) from each query point (N, 3) to its nearest reference point (M, 3);
    metres. Empty reference -> all inf.

    ``upper_bound_m``: distances at or beyond it may be returned as inf (scipy's
    ``distance_upper_bound`` prunes the search); every distance below it is the exact nearest
    distance, the same value as without a bound. A thresholded metric (``d < tau``) passes a bound
    slightly above tau and gets identical results, far faster for points far from the reference
    (outliers). The tree is built by the sliding-midpoint rule (``balanced_tree=False``), which
    builds and queries faster on surface samples; the nearest distance does not depend on it.
    """
    q = as_float_array(query, "query points", (None, 3))
    r = as_float_array(reference, "reference points", (None, 3))
    if len(q) == 0:
        return np.zeros(0)
    if len(r) == 0:
        return np.full(len(q), np.inf)
    tree = cKDTree(r, balanced_tree=False, compact_nodes=False)
    d, _ = tree.query(q, k=1, workers=workers, distance_upper_bound=upper_bound_m)
    return d


def mesh_surface_distances(query, vertices, faces, *, chunk: int = CHUNK,
                           progress: Callable[[int, int], None] | None = None) -> np.ndarray:
    """Exact Euclidean distance (N,) from each query point (N, 3) to the surface of a triangle
    mesh with ``vertices`` (V, 3) metres and ``faces`` (F, 3) int vertex indices: the minimum over
    all triangles of the float64 point-to-triangle distance, found through a
    :class:`recon_eval.metrics.mesh_bvh.TriangleBVH` in memory bounded for any triangle sizes.
    Empty mesh -> inf. Query points must be finite (non-finite ones get inf). ``progress(done,
    total)`` is called after each batch of ``chunk`` points (the CLI prints it on stderr)."""
    q = as_float_array(query, "query points", (None, 3))
    V = as_float_array(vertices, "mesh vertices", (None, 3))
    Fc = np.asarray(faces)
    if Fc.ndim != 2 or (Fc.size and Fc.shape[1] != 3) or not np.issubdtype(Fc.dtype, np.integer):
        raise InputError(f"mesh faces: expected an integer array of shape (F, 3), got {Fc.dtype} {Fc.shape}")
    Fc = Fc.reshape(-1, 3)
    if Fc.size and (Fc.min() < 0 or Fc.max() >= len(V)):
        raise InputError("mesh faces: vertex index out of range")
    out = np.full(len(q), np.inf)
    if len(q) == 0 or len(Fc) == 0:
        return out
    finite = np.all(np.isfinite(q), axis=1)
    bvh = TriangleBVH(V[Fc])
    out[finite] = np.sqrt(bvh.sq_distances(q[finite], chunk=chunk, progress=progress))
    return out


class MeshSurface:
    """A triangle mesh (vertices (V, 3) metres, faces (F, 3)) whose BVH is built once, for
    scoring the same mesh against several metrics: :meth:`distances` is
    :func:`mesh_surface_distances` and remembers its last answer (a second call with the same
    points costs a hash). ``progress(done, total)``: see :func:`mesh_surface_distances`."""

    def __init__(self, vertices, faces, *, progress: Callable[[int, int], None] | None = None):
        self.vertices = as_float_array(vertices, "mesh vertices", (None, 3))
        self.faces = np.asarray(faces)
        mesh_surface_distances(np.zeros((0, 3)), self.vertices, self.faces)  # validates the faces
        self.faces = self.faces.reshape(-1, 3).astype(np.int64)
        self.progress = progress
        self._bvh = TriangleBVH(self.vertices[self.faces]) if len(self.faces) else None
        self._last: tuple | None = None

    def __iter__(self):  # (vertices, faces), as the tuple form
        return iter((self.vertices, self.faces))

    def distances(self, query) -> np.ndarray:
        q = as_float_array(query, "query points", (None, 3))
        key = (q.shape, hashlib.blake2b(np.ascontiguousarray(q).tobytes(), digest_size=16).digest())
        if self._last is not None and self._last[0] == key:
            return self._last[1].copy()
        out = np.full(len(q), np.inf)
        finite = np.all(np.isfinite(q), axis=1)
        if self._bvh is not None and len(q):
            out[finite] = np.sqrt(self._bvh.sq_distances(q[finite], progress=self.progress))
        self._last = (key, out.copy())
        return out


def surface_distances(query, gt_mesh) -> np.ndarray:
    """Distances to ``gt_mesh``: a :class:`MeshSurface` or a (vertices, faces) pair."""
    if isinstance(gt_mesh, MeshSurface):
        return gt_mesh.distances(query)
    vertices, faces = gt_mesh
    return mesh_surface_distances(query, vertices, faces)


def sample_mesh_surface(vertices, faces, n: int, *, seed: int, with_normals: bool = False):
    """n points (n, 3) uniformly distributed over the mesh surface (area-weighted), seeded; with
    ``with_normals`` also the unit normal (n, 3) of each point's face."""
    V = as_float_array(vertices, "mesh vertices", (None, 3))
    Fc = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    tri = V[Fc]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area = 0.5 * np.linalg.norm(cross, axis=1)
    if not area.sum() > 0:
        raise InputError("mesh: zero surface area")
    rng = np.random.default_rng(seed)
    k = rng.choice(len(Fc), size=n, p=area / area.sum())
    u, v = rng.random(n), rng.random(n)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    t = tri[k]
    pts = t[:, 0] + u[:, None] * (t[:, 1] - t[:, 0]) + v[:, None] * (t[:, 2] - t[:, 0])
    if not with_normals:
        return pts
    return pts, cross[k] / np.linalg.norm(cross[k], axis=1, keepdims=True)
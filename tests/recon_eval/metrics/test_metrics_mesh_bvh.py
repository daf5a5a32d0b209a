"""The BVH's point-to-mesh distances are the exact float64 minimum over all triangles (checked
against the brute force over every triangle, and against libigl's AABB closest point, an
independent implementation), for any mix of triangle sizes, in bounded memory."""
from __future__ import annotations

import igl
import numpy as np
import pytest
import trimesh

import recon_eval.metrics.mesh_bvh as mesh_bvh
from recon_eval.metrics.distances import mesh_surface_distances
from recon_eval.metrics.mesh_bvh import TriangleBVH, point_triangle_sq_distances


def brute_force(p, tri):
    """min over every triangle of Ericson's distance, in blocks."""
    out = np.empty(len(p))
    for s in range(0, len(p), 64):
        q = p[s:s + 64]
        P = np.repeat(q, len(tri), axis=0)
        T = np.tile(tri, (len(q), 1, 1))
        out[s:s + 64] = np.sqrt(point_triangle_sq_distances(P, T[:, 0], T[:, 1], T[:, 2]).reshape(len(q), -1).min(1))
    return out


def mixed_mesh(seed=0):
    """A subdivided sphere (1280 small triangles), a 20 m floor quad, two long slanted triangles
    through the sphere, slivers, a zero-area triangle and a duplicated face."""
    s = trimesh.creation.icosphere(subdivisions=3, radius=1.0)
    V, F = [np.asarray(s.vertices)], [np.asarray(s.faces)]
    extra = np.array([[-10, -10, -1.2], [10, -10, -1.2], [10, 10, -1.2], [-10, 10, -1.2],
                      [-8, -6, -1.0], [8, -5, 3.0], [0, 9, 1.5], [-9, 7, 4.0], [9, 7, -1.0], [0, -9, 2.0],
                      [0, 0, 2.0], [3, 0, 2.0], [1.5, 1e-9, 2.0], [2, 2, 2], [2, 2, 2], [4, 4, 4]])
    o = len(V[0])
    F.append(o + np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [7, 8, 9], [10, 11, 12], [13, 14, 15], [0, 1, 2]]))
    return np.concatenate([V[0], extra]), np.concatenate(F)


def query_points(n, seed=1):
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    p = d * (1 + rng.normal(0, 0.02, (n, 1)))
    p[: n // 4] = rng.uniform(-15, 15, (n // 4, 3))  # far and in between
    p[n // 4: n // 4 + 20] = d[:20]  # on the sphere's vertices' sphere
    return p


def test_equals_brute_force_for_mixed_triangle_sizes():
    V, F = mixed_mesh()
    p = query_points(1500)
    ours = mesh_surface_distances(p, V, F)
    ref = brute_force(p, V[F])
    assert np.max(np.abs(ours - ref)) == 0.0  # the same formula on the same triangle: bit-identical


def test_equals_libigl_point_mesh_squared_distance():
    """libigl's AABB tree and its own float64 point-triangle code (degenerate triangles as
    segments or points) agree to rounding: a few ulps of the 1-25 m distances."""
    V, F = mixed_mesh()
    p = query_points(3000, seed=7)
    ref_sq, _, _ = igl.point_mesh_squared_distance(p, V, F.astype(np.int64))
    np.testing.assert_allclose(mesh_surface_distances(p, V, F), np.sqrt(ref_sq), rtol=0, atol=1e-14)


def test_points_on_the_surface_are_at_zero():
    V, F = mixed_mesh()
    tri = V[F][:1280]
    rng = np.random.default_rng(2)
    u, v = rng.random(500), rng.random(500)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    k = rng.integers(0, len(tri), 500)
    q = tri[k, 0] + u[:, None] * (tri[k, 1] - tri[k, 0]) + v[:, None] * (tri[k, 2] - tri[k, 0])
    assert np.max(mesh_surface_distances(q, V, F)) < 1e-15


def test_memory_stays_bounded_when_large_triangles_overlap_every_point(monkeypatch):
    """400 large triangles whose boxes all contain every query point: the chunk splits itself."""
    rng = np.random.default_rng(3)
    tri = rng.uniform(-5, 5, (400, 3, 3))
    p = rng.uniform(-1, 1, (300, 3))
    monkeypatch.setattr(mesh_bvh, "MAX_PAIRS", 5000)
    seen = []
    orig = mesh_bvh.TriangleBVH._query

    def spy(self, tree, q, ub):
        seen.append(len(q))
        return orig(self, tree, q, ub)

    monkeypatch.setattr(mesh_bvh.TriangleBVH, "_query", spy)
    d = np.sqrt(TriangleBVH(tri).sq_distances(p))
    np.testing.assert_array_equal(d, brute_force(p, tri))
    assert min(seen) < len(p)  # it did split


def test_progress_is_reported():
    V, F = mixed_mesh()
    calls = []
    mesh_surface_distances(query_points(300), V, F, chunk=100, progress=lambda d, t: calls.append((d, t)))
    assert calls == [(100, 300), (200, 300), (300, 300)]


@pytest.mark.parametrize("seed", [4, 5])
def test_random_soups_equal_brute_force(seed):
    rng = np.random.default_rng(seed)
    small = rng.normal(0, 1, (600, 1, 3)) + rng.normal(0, 0.05, (600, 3, 3))
    big = rng.normal(0, 3, (6, 3, 3))
    tri = np.concatenate([small, big])
    p = rng.normal(0, 2, (800, 3))
    np.testing.assert_array_equal(np.sqrt(TriangleBVH(tri).sq_distances(p)), brute_force(p, tri))

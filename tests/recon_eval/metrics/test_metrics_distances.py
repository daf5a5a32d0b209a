import numpy as np
import pytest
import trimesh

from recon_eval.metrics.distances import (
    closest_points_on_triangles,
    mesh_surface_distances,
    nearest_point_distances,
    sample_mesh_surface,
)
from recon_eval.errors import InputError




def brute_force(q, tri):
    out = []
    for p in q:
        P = np.repeat(p[None], len(tri), axis=0)
        out.append(np.min(np.linalg.norm(closest_points_on_triangles(P, tri[:, 0], tri[:, 1], tri[:, 2]) - p, axis=1)))
    return np.array(out)


class TestMeshSurfaceDistances:
    def test_analytic_square(self, unit_square):
        q = np.array([[0.5, 0.5, 0.3], [0.25, 0.75, -2.0], [2.0, 0.5, 0.0], [2.0, 2.0, 0.0], [-1.0, -1.0, -1.0]])
        d = mesh_surface_distances(q, unit_square[0], unit_square[1])
        np.testing.assert_allclose(d, [0.3, 2.0, 1.0, np.sqrt(2), np.sqrt(3)], rtol=0, atol=1e-15)

    def test_matches_brute_force_on_a_sphere(self):
        m = trimesh.creation.icosphere(subdivisions=2)
        rng = np.random.default_rng(0)
        q = np.r_[rng.normal(size=(150, 3)) * 2.0, m.sample(150, seed=1) + rng.normal(size=(150, 3)) * 0.01]
        d = mesh_surface_distances(q, m.vertices, m.faces, chunk=64)
        np.testing.assert_allclose(d, brute_force(q, m.triangles), atol=1e-14)

    def test_matches_brute_force_with_mixed_triangle_sizes(self):
        # One huge triangle next to many small ones: the centroid bound must still be exact.
        rng = np.random.default_rng(2)
        small = trimesh.creation.icosphere(subdivisions=2).apply_scale(0.1)
        V = np.r_[small.vertices, [[-10.0, -10, -1], [10, -10, -1], [0, 10, -1]]]
        F = np.r_[small.faces, [[len(small.vertices), len(small.vertices) + 1, len(small.vertices) + 2]]]
        q = rng.normal(size=(200, 3)) * 0.5
        np.testing.assert_allclose(mesh_surface_distances(q, V, F), brute_force(q, V[F]), atol=1e-14)

    def test_points_on_the_surface_are_at_zero(self):
        m = trimesh.creation.box()
        q = sample_mesh_surface(m.vertices, m.faces, 500, seed=3)
        assert np.max(mesh_surface_distances(q, m.vertices, m.faces)) < 1e-15

    def test_empty_mesh_and_bad_faces(self, unit_square):
        assert np.all(np.isinf(mesh_surface_distances(np.zeros((2, 3)), np.zeros((0, 3)), np.zeros((0, 3), int))))
        with pytest.raises(InputError, match="out of range"):
            mesh_surface_distances(np.zeros((1, 3)), unit_square[0], np.array([[0, 1, 9]]))
        with pytest.raises(InputError, match="integer"):
            mesh_surface_distances(np.zeros((1, 3)), unit_square[0], unit_square[1].astype(float))


def test_nearest_point_distances():
    d = nearest_point_distances([[0.0, 0, 0], [3, 0, 0]], [[1.0, 0, 0], [5, 0, 0]])
    np.testing.assert_array_equal(d, [1.0, 2.0])
    assert np.all(np.isinf(nearest_point_distances(np.zeros((3, 3)), np.zeros((0, 3)))))


class TestClosestPointOnTriangle:
    def test_matches_trimesh(self):
        # trimesh.triangles.closest_point: an independent vectorised implementation
        rng = np.random.default_rng(5)
        tri = rng.normal(size=(2000, 3, 3))
        p = rng.normal(size=(2000, 3)) * 2.0
        ours = closest_points_on_triangles(p, tri[:, 0], tri[:, 1], tri[:, 2])
        np.testing.assert_allclose(ours, trimesh.triangles.closest_point(tri, p), atol=1e-12)

    def test_degenerate_triangles_give_segment_distances(self):
        # collinear vertices: the "triangle" is the segment [0, 2] on the x axis
        a, b, c = np.array([[0.0, 0, 0]]), np.array([[1.0, 0, 0]]), np.array([[2.0, 0, 0]])
        for p, d in (([1.5, 1.0, 0.0], 1.0), ([3.0, 0.0, 0.0], 1.0), ([-1.0, 0.0, 1.0], np.sqrt(2)), ([0.3, 0.0, 0.0], 0.0)):
            q = closest_points_on_triangles(np.array([p]), a, b, c)
            assert np.linalg.norm(q - p) == pytest.approx(d, abs=1e-15)
        same = np.zeros((1, 3))
        q = closest_points_on_triangles(np.array([[1.0, 2.0, 2.0]]), same, same, same)
        np.testing.assert_array_equal(q, same)
        # two coincident vertices: the "triangle" is the segment from (2, 2, 2) to (4, 4, 4)
        a, c = np.array([[2.0, 2, 2]]), np.array([[4.0, 4, 4]])
        for p, q_ref in (([3.0, 3.0, 5.0], [11 / 3, 11 / 3, 11 / 3]), ([0.0, 0.0, 0.0], [2.0, 2, 2]), ([9.0, 4, 4], [4.0, 4, 4])):
            for tri in ((a, a, c), (a, c, a), (c, a, a)):
                q = closest_points_on_triangles(np.array([p]), *tri)
                np.testing.assert_allclose(q[0], q_ref, atol=1e-15)

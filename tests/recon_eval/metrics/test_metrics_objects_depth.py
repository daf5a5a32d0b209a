"""The VSD model depth renderer against libigl's ray-mesh intersection (an independent
implementation, a dev dependency): same pixel rays K^-1 [u, v, 1] (Z component 1), nearest hit."""
from __future__ import annotations

import igl
import numpy as np
import trimesh
from scipy.spatial.transform import Rotation

from recon_eval.metrics.objects_depth import DepthRenderer, render_depth

K = np.array([[55.0, 0.0, 20.3], [0.0, 57.0, 14.8], [0.0, 0.0, 1.0]])
W, H = 40, 30


def _igl_depth(mesh, R, t):
    V = np.ascontiguousarray(np.asarray(mesh.vertices) @ R.T + t)
    F = np.ascontiguousarray(mesh.faces, dtype=np.int64)
    depth = np.zeros((H, W))
    for v in range(H):
        for u in range(W):
            ray = np.linalg.solve(K, [u, v, 1.0])
            # all hits (its first=True returns garbage on a miss); the ray parameter is Z, as the
            # ray's Z component is 1; libigl returns it in float32
            hits = igl.ray_mesh_intersect(np.zeros(3), ray, V, F)
            if hits:
                depth[v, u] = min(h[1] for h in hits)
    return depth


def test_render_depth_equals_libigl_ray_cast():
    mesh = trimesh.creation.icosphere(subdivisions=1, radius=40.0)
    mesh.vertices[:, 0] *= 1.6  # an ellipsoid: not symmetric about the view axis
    R = Rotation.from_rotvec([0.3, -0.5, 0.2]).as_matrix()
    t = np.array([8.0, -5.0, 260.0])
    ours = render_depth(mesh.vertices, mesh.faces, R, t, K, W, H)
    theirs = _igl_depth(mesh, R, t)
    assert np.array_equal(ours > 0, theirs > 0)
    assert 100 < np.count_nonzero(ours) < W * H
    assert np.max(np.abs(ours - theirs)) < 260 * 2.0 ** -22  # float32 rounding of libigl's t


def test_renderer_interface_and_empty_view():
    box = trimesh.creation.box(extents=(10.0, 10.0, 10.0))
    ren = DepthRenderer({7: (box.vertices, box.faces)}, W, H)
    d = ren.render_object(7, np.eye(3), np.array([0.0, 0.0, 100.0]), K[0, 0], K[1, 1], K[0, 2], K[1, 2])["depth"]
    assert d.shape == (H, W) and d.max() == 95.0  # the front face at z = 100 - 5
    behind = render_depth(box.vertices, box.faces, np.eye(3), np.array([0.0, 0.0, -100.0]), K, W, H)
    assert not behind.any()

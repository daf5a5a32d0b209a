"""The depth image of one model alone in a pose: what BOP's VSD renders (bop_toolkit's
``renderer.render_object(...)["depth"]``, OpenGL there, exact ray-plane intersection here).

Each pixel centre (u, v) (integer, BOP's ``K`` convention) casts the ray ``K^-1 [u, v, 1]``;
its depth is the smallest Z of the triangles whose projection covers the centre (edge functions
of the projected vertices, edges counted inside), computed exactly on the triangle's plane
rather than interpolated. Triangles with a vertex at or behind ``near`` are dropped (BOP's
models sit in front of the camera). Numpy per triangle, vectorised over its pixels: fine for
the few thousand triangles of a BOP evaluation model at 640x480.
"""
from __future__ import annotations

import numpy as np


def render_depth(vertices, faces, R, t, K, width: int, height: int, *, near: float = 1e-9) -> np.ndarray:
    """(H, W) float64 depth (model units; 0 where no surface) of mesh ``vertices`` (V, 3),
    ``faces`` (F, 3) posed by ``cam_from_model`` ``R`` (3, 3), ``t`` (3,) and seen through ``K``."""
    K = np.asarray(K, dtype=np.float64)
    v = np.asarray(vertices, dtype=np.float64) @ np.asarray(R, dtype=np.float64).reshape(3, 3).T
    v = v + np.asarray(t, dtype=np.float64).reshape(3)
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    depth = np.full((height, width), np.inf)
    tri = v[f]  # (F, 3, 3)
    keep = np.all(tri[:, :, 2] > near, axis=1)
    tri = tri[keep]
    h = tri @ K.T
    uv = h[..., :2] / h[..., 2:3]  # (F, 3, 2)
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    offset = np.einsum("fi,fi->f", normal, tri[:, 0])
    Kinv = np.linalg.inv(K)
    lo = np.maximum(np.ceil(uv.min(axis=1)), 0).astype(np.int64)
    hi = np.minimum(np.floor(uv.max(axis=1)), [width - 1, height - 1]).astype(np.int64)
    for i in np.flatnonzero(np.all(hi >= lo, axis=1)):
        us, vs = np.meshgrid(np.arange(lo[i, 0], hi[i, 0] + 1), np.arange(lo[i, 1], hi[i, 1] + 1))
        p = np.stack([us.ravel(), vs.ravel()], axis=1).astype(np.float64)
        a, b, c = uv[i]
        e0 = _edge(b, c, p)
        e1 = _edge(c, a, p)
        e2 = _edge(a, b, p)
        inside = ((e0 >= 0) & (e1 >= 0) & (e2 >= 0)) | ((e0 <= 0) & (e1 <= 0) & (e2 <= 0))
        if _edge(a, b, c[None])[0] == 0 or not inside.any():
            continue  # seen edge-on: covers no area
        p = p[inside]
        rays = np.column_stack([p, np.ones(len(p))]) @ Kinv.T  # Z component 1
        z = offset[i] / (rays @ normal[i])
        rows, cols = p[:, 1].astype(np.int64), p[:, 0].astype(np.int64)
        np.minimum.at(depth, (rows, cols), np.where(z > near, z, np.inf))
    depth[~np.isfinite(depth)] = 0.0
    return depth


def _edge(a: np.ndarray, b: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Twice the signed area of (a, b, p) for points ``p`` (N, 2)."""
    return (b[0] - a[0]) * (p[:, 1] - a[1]) - (b[1] - a[1]) * (p[:, 0] - a[0])


class DepthRenderer:
    """bop_toolkit's renderer interface (``render_object(obj_id, R, t, fx, fy, cx, cy)``) over
    :func:`render_depth`, for meshes given as ``{obj_id: (vertices, faces)}``."""

    def __init__(self, meshes: dict, width: int, height: int):
        self._meshes = dict(meshes)
        self.width, self.height = int(width), int(height)

    def render_object(self, obj_id, R, t, fx, fy, cx, cy) -> dict:
        K = np.array([[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]])
        vertices, faces = self._meshes[obj_id]
        return {"depth": render_depth(vertices, faces, R, t, K, self.width, self.height)}


def model_points(depth, R, t, K) -> np.ndarray:
    """(H, W, 3) model-frame points seen at each pixel of a :func:`render_depth` image of a model
    posed by ``R``, ``t`` (NaN where the depth is 0): ``R^T (z K^-1 [u, v, 1] - t)``."""
    d = np.asarray(depth, dtype=np.float64)
    v, u = np.mgrid[0:d.shape[0], 0:d.shape[1]]
    rays = np.stack([u, v, np.ones_like(u)], axis=-1).astype(np.float64) @ np.linalg.inv(K).T
    cam = rays * d[..., None]
    out = (cam - np.asarray(t, dtype=np.float64).reshape(3)) @ np.asarray(R, dtype=np.float64).reshape(3, 3)
    out[d <= 0] = np.nan
    return out

"""Mitsuba ray casts for cross-view truth: visibility of 3D points from a camera centre, and the
surface point behind any sub-pixel position. The scene must be loaded (the current variant).

All rays of one call are intersected in ONE ``dr.eval`` (converting outputs one by one re-runs
the kernel, see shared notes). Ray origins and directions go to Mitsuba in float32; distances
come back as float32 and are widened to float64.
"""
from __future__ import annotations

import drjit as dr
import mitsuba as mi
import numpy as np

from scenegen.dataset.crossview import OCCLUSION_REL_TOL
from scenegen.render.arrays import to_jit


def first_hit_distance(scene, origin_world, directions_world) -> tuple[np.ndarray, np.ndarray]:
    """Distance (N,) float64 metres to the first surface along unit rays from ``origin_world``
    (3,) in directions (N, 3), and the hit points (N, 3) float64 (NaN on misses; t = +inf)."""
    d = np.asarray(directions_world, np.float64)
    o = np.asarray(origin_world, np.float64)
    if len(d) == 0:
        return np.zeros(0), np.zeros((0, 3))
    if mi.variant().startswith("scalar"):  # the slow fallback without a working libLLVM
        t = np.array([float(scene.ray_intersect_preliminary(mi.Ray3f(mi.Point3f(*map(float, o)),
                                                                     mi.Vector3f(*map(float, di)))).t)
                      for di in d], dtype=np.float64)
        t[~(t < np.inf)] = np.inf
    else:
        t = _first_hits_vectorised(scene, o, d)
    pts = o[None, :] + t[:, None] * d
    pts[~np.isfinite(t)] = np.nan
    return t, pts


def _first_hits_vectorised(scene, o, d) -> np.ndarray:
    ray = mi.Ray3f(mi.Point3f(*[float(c) for c in o]),
                   mi.Vector3f(*[to_jit(mi.Float, d[:, i], np.float32) for i in range(3)]))
    si = scene.ray_intersect_preliminary(ray, coherent=False)
    hit = si.is_valid()
    t = dr.select(hit, si.t, dr.inf)
    dr.eval(t, hit)
    return np.array(t, dtype=np.float64)


def visible_from(scene, center_world, points_world, rel_tol: float = OCCLUSION_REL_TOL) -> np.ndarray:
    """(N,) bool: nothing lies between ``center_world`` and each point (N, 3) (float64, metres),
    up to ``rel_tol`` of the distance (see :data:`OCCLUSION_REL_TOL`). NaN points -> False."""
    P = np.asarray(points_world, np.float64)
    C = np.asarray(center_world, np.float64)
    ok = np.all(np.isfinite(P), axis=1)
    out = np.zeros(len(P), bool)
    if not ok.any():
        return out
    v = P[ok] - C
    dist = np.linalg.norm(v, axis=1)
    t, _ = first_hit_distance(scene, C, v / dist[:, None])
    out[np.flatnonzero(ok)] = t >= dist * (1.0 - rel_tol)
    return out


def surface_points(scene, camera, cam_from_world, uv) -> np.ndarray:
    """(N, 3) float64 world points of the surface seen through sub-pixel positions (N, 2) of a
    camera (its full model, float64 unprojection as in the truth pass); NaN where nothing is hit."""
    uv = np.asarray(uv, np.float64)
    world_from_cam = cam_from_world.inverse()
    d_cam = camera.unproject_unit(uv)
    out = np.full((len(uv), 3), np.nan)
    ok = np.all(np.isfinite(d_cam), axis=1)
    if ok.any():
        d_world = world_from_cam.rotate(d_cam[ok])
        _, pts = first_hit_distance(scene, world_from_cam.t, d_world)
        out[ok] = pts
    return out

"""Mitsuba ray casts for cross-view truth: visibility of 3D points from a camera centre, and the
surface point behind any sub-pixel position. The scene must be loaded (the current variant).

All rays of one call are intersected in ONE ``dr.eval`` (converting outputs one by one re-runs
the kernel, see shared notes). Ray origins and directions go to Mitsuba in float32; distances
come back as float32 and are widened to float64. The ray origin is an opaque Dr.Jit scalar: as a
literal it would be compiled into the kernel, and every new camera centre (every direction of
every view pair) would compile the kernel again (0.3-0.7 s each).
"""
from __future__ import annotations

import drjit as dr
import mitsuba as mi
import numpy as np

from scenegen.dataset.crossview import OCCLUSION_REL_TOL
from scenegen.render.alpha import opaque_intersect
from scenegen.render.arrays import to_jit


def first_hit_distance(scene, origin_world, directions_world, alpha_masked: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Distance (N,) float64 metres to the first surface along unit rays from ``origin_world``
    (3,) in directions (N, 3), and the hit points (N, 3) float64 (NaN on misses; t = +inf).
    ``alpha_masked``: pass through alpha-mask holes (:mod:`scenegen.render.alpha`)."""
    d = np.asarray(directions_world, np.float64)
    o = np.asarray(origin_world, np.float64)
    if len(d) == 0:
        return np.zeros(0), np.zeros((0, 3))
    if mi.variant().startswith("scalar"):  # the slow fallback without a working libLLVM
        if alpha_masked:
            raise ValueError("alpha masks need a vectorised Mitsuba variant for their ray casts (llvm_ad_rgb / cuda_ad_rgb)")
        t = np.array([float(scene.ray_intersect_preliminary(mi.Ray3f(mi.Point3f(*map(float, o)),
                                                                     mi.Vector3f(*map(float, di)))).t)
                      for di in d], dtype=np.float64)
        t[~(t < np.inf)] = np.inf
    else:
        t = _first_hits_vectorised(scene, o, d, alpha_masked)
    pts = o[None, :] + t[:, None] * d
    pts[~np.isfinite(t)] = np.nan
    return t, pts


def _origin(o) -> "mi.Point3f":
    """A ray origin as opaque float32 scalars (rounded from float64 as a literal would be)."""
    return mi.Point3f(*[dr.opaque(mi.Float, float(c)) for c in o])


def _first_hits_vectorised(scene, o, d, alpha_masked: bool = False) -> np.ndarray:
    ray = mi.Ray3f(_origin(o), mi.Vector3f(*[to_jit(mi.Float, d[:, i], np.float32) for i in range(3)]))
    if alpha_masked:
        _, t = opaque_intersect(scene, ray, mi.RayFlags.Minimal, coherent=False)
    else:
        si = scene.ray_intersect_preliminary(ray, coherent=False)
        t = dr.select(si.is_valid(), si.t, dr.inf)
    dr.eval(t)
    return np.array(t, dtype=np.float64)


def visible_from(scene, center_world, points_world, rel_tol: float = OCCLUSION_REL_TOL,
                 alpha_masked: bool = False) -> np.ndarray:
    """(N,) bool: nothing lies between ``center_world`` and each point (N, 3) (float64, metres),
    up to ``rel_tol`` of the distance (see :data:`OCCLUSION_REL_TOL`). NaN points -> False.
    ``alpha_masked``: alpha-mask holes do not occlude (:mod:`scenegen.render.alpha`)."""
    P = np.asarray(points_world, np.float64)
    C = np.asarray(center_world, np.float64)
    ok = np.isfinite(P[:, 0]) & np.isfinite(P[:, 1]) & np.isfinite(P[:, 2])
    out = np.zeros(len(P), bool)
    if not ok.any():
        return out
    if ok.all() and not mi.variant().startswith("scalar") and not alpha_masked:  # the usual case: no copy
        return _visible_vectorised(scene, C, P, rel_tol)
    if mi.variant().startswith("scalar") or alpha_masked:
        v = P[ok] - C
        dist = np.linalg.norm(v, axis=1)
        t, _ = first_hit_distance(scene, C, v / dist[:, None], alpha_masked)
        out[np.flatnonzero(ok)] = t >= dist * (1.0 - rel_tol)
        return out
    out[np.flatnonzero(ok)] = _visible_vectorised(scene, C, P[ok], rel_tol)
    return out


def _visible_vectorised(scene, C, P, rel_tol: float) -> np.ndarray:
    """The visibility test in one kernel: the same float64 operations, in the same order, as
    ``v = P - C; dist = np.linalg.norm(v, axis=1); d = v / dist`` in numpy (so the same bits),
    the ray cast, and the comparison; only the (M,) booleans come back."""
    c64 = [dr.opaque(mi.Float64, float(c)) for c in C]
    v = [to_jit(mi.Float64, P[:, i], np.float64) - c64[i] for i in range(3)]
    dist = dr.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    d = mi.Vector3f(*[mi.Float(vi / dist) for vi in v])
    # coherent=False, as before: Embree's coherent mode is ~1.5x faster on these pixel-ordered rays
    # but decides a grazing ray differently (one pixel of scenes/triangulation_baselines.yaml
    # turned from occluded to visible), and the bytes must not change
    si = scene.ray_intersect_preliminary(mi.Ray3f(_origin(C), d), coherent=False)
    t = dr.select(si.is_valid(), mi.Float64(si.t), dr.inf)
    visible = t >= dist * (1.0 - rel_tol)
    dr.eval(visible)
    return visible.numpy().copy()


def surface_points(scene, camera, cam_from_world, uv, alpha_masked: bool = False) -> np.ndarray:
    """(N, 3) float64 world points of the surface seen through sub-pixel positions (N, 2) of a
    camera (its full model, float64 unprojection as in the truth pass); NaN where nothing is hit."""
    uv = np.asarray(uv, np.float64)
    world_from_cam = cam_from_world.inverse()
    d_cam = camera.unproject_unit(uv)
    out = np.full((len(uv), 3), np.nan)
    ok = np.all(np.isfinite(d_cam), axis=1)
    if ok.any():
        d_world = world_from_cam.rotate(d_cam[ok])
        _, pts = first_hit_distance(scene, world_from_cam.t, d_world, alpha_masked)
        out[ok] = pts
    return out

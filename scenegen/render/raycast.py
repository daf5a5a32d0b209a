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
from scenegen.render.timed import first_hit, timed_first_hit, upload_moves


#: Embree's coherent traversal for the visibility rays of a view's pixels: they leave one centre
#: towards pixel-ordered points, and coherent mode casts them 1.5x faster (measured 5.7 ms against
#: 8.7 ms for 640x480 rays of the demo scene, idle machine). The hits are the same surfaces; only a ray
#: that grazes an edge within float32 rounding may be decided differently (the state of one pixel
#: of scenes/triangulation_baselines.yaml, whose point lies within the tolerance band).
VISIBILITY_COHERENT = True


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
                 alpha_masked: bool = False, timed=None) -> np.ndarray:
    """(N,) bool: nothing lies between ``center_world`` and each point (N, 3) (float64, metres),
    up to ``rel_tol`` of the distance (see :data:`OCCLUSION_REL_TOL`). NaN points -> False.
    ``center_world``: one centre (3,), or one per point (N, 3) (a rolling shutter's rows).
    ``alpha_masked``: alpha-mask holes do not occlude (:mod:`scenegen.render.alpha`).
    ``timed``: (:class:`scenegen.render.timed.TimedScenes`, {object id: ((N, 3, 3) R, (N, 3) t
    world_from_object, (N,) present)}): each ray meets the moving objects where they are at its
    point's time; ``scene`` is not used."""
    P = np.asarray(points_world, np.float64)
    C = np.asarray(center_world, np.float64)
    ok = np.isfinite(P[:, 0]) & np.isfinite(P[:, 1]) & np.isfinite(P[:, 2])
    out = np.zeros(len(P), bool)
    if not ok.any():
        return out
    per_point = C.ndim == 2
    scalar = mi.variant().startswith("scalar")
    if ok.all() and not scalar and not alpha_masked and not per_point and timed is None:  # the usual case: no copy
        return _visible_vectorised(scene, C, P, rel_tol)
    sel = np.flatnonzero(ok)
    if per_point or timed is not None:
        if scalar:
            raise NotImplementedError("rolling-shutter visibility needs a vectorised variant (llvm_ad_rgb / cuda_ad_rgb)")
        Cs = C[sel] if per_point else np.broadcast_to(C, (len(sel), 3))
        moves = None if timed is None else {k: (R[sel], t[sel], p[sel]) for k, (R, t, p) in timed[1].items()}
        out[sel] = _visible_rays(scene, Cs, P[sel], rel_tol, alpha_masked, None if timed is None else (timed[0], moves))
        return out
    if scalar or alpha_masked:
        v = P[ok] - C
        dist = np.linalg.norm(v, axis=1)
        t, _ = first_hit_distance(scene, C, v / dist[:, None], alpha_masked)
        out[sel] = t >= dist * (1.0 - rel_tol)
        return out
    out[sel] = _visible_vectorised(scene, C, P[ok], rel_tol)
    return out


def _visible_vectorised(scene, C, P, rel_tol: float) -> np.ndarray:
    """The visibility test in one kernel: the same float64 operations, in the same order, as
    ``v = P - C; dist = np.linalg.norm(v, axis=1); d = v / dist`` in numpy (so the same bits),
    the ray cast, and the comparison; only the (M,) booleans come back."""
    c64 = [dr.opaque(mi.Float64, float(c)) for c in C]
    v = [to_jit(mi.Float64, P[:, i], np.float64) - c64[i] for i in range(3)]
    dist = dr.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    d = mi.Vector3f(*[mi.Float(vi / dist) for vi in v])
    si = scene.ray_intersect_preliminary(mi.Ray3f(_origin(C), d), coherent=VISIBILITY_COHERENT)
    t = dr.select(si.is_valid(), mi.Float64(si.t), dr.inf)
    visible = t >= dist * (1.0 - rel_tol)
    dr.eval(visible)
    return visible.numpy().copy()


def _visible_rays(scene, C, P, rel_tol: float, alpha_masked: bool, timed) -> np.ndarray:
    """The visibility test of rays with their own origins ``C`` (M, 3) towards ``P`` (M, 3), in
    ``scene`` or, with ``timed`` = (TimedScenes, per-ray moves), with the moving objects where
    each ray's moves put them."""
    v = P - C
    dist = np.sqrt(v[:, 0] * v[:, 0] + v[:, 1] * v[:, 1] + v[:, 2] * v[:, 2])
    t, _ = _cast_rays(scene, C, v / dist[:, None], alpha_masked, timed)
    return t >= dist * (1.0 - rel_tol)


def surface_points(scene, camera, cam_from_world, uv, alpha_masked: bool = False, rows=None,
                   timed=None) -> tuple[np.ndarray, np.ndarray | None]:
    """((N, 3) float64 world points of the surface seen through sub-pixel positions (N, 2) of a
    camera (its full model, float64 unprojection as in the truth pass), NaN where nothing is hit;
    (N,) uint32 object ids of those surfaces, or None). ``rows`` (a rolling shutter): the
    camera's world_from_cam per row (:class:`scenegen.geometry.rolling.RowPoses`), each ray
    cast from its own row's pose; ``timed`` = (TimedScenes, {object id: ((N, 3, 3) R, (N, 3) t
    world_from_object, (N,) present)}): the moving objects where they are at each ray's row
    (then the ids come back)."""
    uv = np.asarray(uv, np.float64)
    d_cam = camera.unproject_unit(uv)
    out = np.full((len(uv), 3), np.nan)
    ids = None if timed is None else np.zeros(len(uv), np.uint32)
    ok = np.all(np.isfinite(d_cam), axis=1)
    if not ok.any():
        return out, ids
    if rows is None and timed is None:
        world_from_cam = cam_from_world.inverse()
        _, pts = first_hit_distance(scene, world_from_cam.t, world_from_cam.rotate(d_cam[ok]), alpha_masked)
        out[ok] = pts
        return out, ids
    sel = np.flatnonzero(ok)
    if rows is not None:
        R, C = rows.at(uv[sel, 1])
        d = np.einsum("nij,nj->ni", R, d_cam[sel])
    else:
        wfc = cam_from_world.inverse()
        C, d = np.broadcast_to(wfc.t, (len(sel), 3)), wfc.rotate(d_cam[sel])
    moves = None if timed is None else (timed[0], {k: (R_[sel], t_[sel], p_[sel]) for k, (R_, t_, p_) in timed[1].items()})
    t, oid = _cast_rays(scene, C, d, alpha_masked, moves)
    hit = np.isfinite(t)
    out[sel[hit]] = C[hit] + t[hit, None] * d[hit]
    if ids is not None:
        ids[sel] = oid
    return out, ids


def _cast_rays(scene, C, d, alpha_masked: bool, timed):
    """((M,) float64 first-hit distances (inf: miss), (M,) uint32 object ids or None) of rays
    from origins ``C`` (M, 3) along unit ``d`` (M, 3), in ``scene`` or the timed scenes."""
    c = mi.Vector3d(*[to_jit(mi.Float64, C[:, i], np.float64) for i in range(3)])
    dj = mi.Vector3d(*[to_jit(mi.Float64, d[:, i], np.float64) for i in range(3)])
    if timed is None:
        t, hit, *_ = first_hit(scene, mi.Ray3f(mi.Point3f(mi.Vector3f(c)), mi.Vector3f(dj)), alpha_masked,
                               coherent=False)
        t = dr.select(hit, mi.Float64(t), dr.inf)
        dr.eval(t)
        return t.numpy().copy(), None
    ts, moves = timed
    t, hit, _, _, sid = timed_first_hit(ts, c, dj, upload_moves(ts, moves), alpha_masked, coherent=False)
    t = dr.select(hit, mi.Float64(t), dr.inf)
    oid = dr.select(hit, dr.gather(mi.UInt32, ts.id_tables[0], sid), 0)
    dr.eval(t, oid)
    return t.numpy().copy(), oid.numpy().copy()

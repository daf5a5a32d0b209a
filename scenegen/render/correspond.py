"""Dense correspondences of view i's truth points in view j in ONE Dr.Jit kernel: the move into
j's frame and j's full camera model in float64 (:func:`scenegen.geometry.camera.project_xyz`
with Dr.Jit's operations: the same lines as numpy's), the in-image test, the visibility cast and
the states. The definition is :func:`scenegen.crossview.correspondence.correspond`'s (numpy, with
a visibility function; still used where this kernel does not apply: the scalar fallback and
scenes with alpha masks); tests hold the two equal.

Why one kernel: projecting in numpy and casting in Dr.Jit went through the points four times
(projection, masks, compaction of the valid points, the cast) and BLAS next to Dr.Jit's threads;
here each point is read once and every output is written by the kernel, seen by numpy without a
copy (docs/performance.md, "Truth pass and cross-view correspondences").
"""
from __future__ import annotations

from types import SimpleNamespace

import drjit as dr
import mitsuba as mi
import numpy as np

from scenegen.dataset.crossview import NO_SURFACE, OCCLUDED, OCCLUSION_REL_TOL, OUT_OF_FRAME, VISIBLE, Correspondence
from scenegen.geometry.camera import project_xyz
from scenegen.geometry.pose import Rigid3
from scenegen.render.arrays import to_jit
from scenegen.render.drjit_ops import DRJIT_OPS
from scenegen.render.raycast import VISIBILITY_COHERENT


def upload_points(points_world) -> tuple:
    """The (H, W, 3) points as three mi.Float64 columns: float32 points (the truth as stored) go
    up as float32 and are widened in the kernel (exactly; a quarter of the bytes to copy), others
    as float64."""
    P = np.asarray(points_world)
    if P.dtype == np.float32:
        return tuple(mi.Float64(to_jit(mi.Float, P[..., i], np.float32)) for i in range(3))
    return tuple(to_jit(mi.Float64, P[..., i], np.float64) for i in range(3))


def correspond_in_kernel(scene, points_world, camera, cam_from_world: Rigid3,
                         rel_tol: float = OCCLUSION_REL_TOL) -> Correspondence:
    """:func:`scenegen.crossview.correspondence.correspond` of the truth points (H, W, 3) of view
    i (float32 as stored, or float64; NaN = no surface) in view j, in one kernel."""
    H, W = np.shape(points_world)[:2]
    if H * W == 0:  # e.g. tracks of query frames without surface: Dr.Jit cannot mix width 0 with scalars
        return Correspondence(np.zeros((H, W, 2)), np.zeros((H, W)), np.zeros((H, W), np.uint8))
    X, Y, Z = upload_points(points_world)
    o64 = lambda x: dr.opaque(mi.Float64, float(x))  # noqa: E731 (opaque: no recompilation per pose)
    R = [[o64(cam_from_world.R[i, j]) for j in range(3)] for i in range(3)]
    t = [o64(c) for c in cam_from_world.t]
    C = [o64(c) for c in cam_from_world.inverse().t]
    p = SimpleNamespace(**{k: o64(v) for k, v in vars(camera.params()).items()})
    finite = dr.isfinite(X) & dr.isfinite(Y) & dr.isfinite(Z)
    Xc, Yc, Zc = (R[i][0] * X + R[i][1] * Y + R[i][2] * Z + t[i] for i in range(3))
    u, v, valid = project_xyz(Xc, Yc, Zc, p, camera.model, DRJIT_OPS)
    inside = finite & valid & (u >= -0.5) & (u <= camera.width - 0.5) & (v >= -0.5) & (v <= camera.height - 0.5)
    # the visibility test of raycast.visible_from: the same float64 operations, the ray in float32
    vx, vy, vz = X - C[0], Y - C[1], Z - C[2]
    dist = dr.sqrt(vx * vx + vy * vy + vz * vz)
    d = mi.Vector3f(mi.Float(vx / dist), mi.Float(vy / dist), mi.Float(vz / dist))
    origin = mi.Point3f(*[dr.opaque(mi.Float, float(c)) for c in cam_from_world.inverse().t])
    si = scene.ray_intersect_preliminary(mi.Ray3f(origin, d), coherent=VISIBILITY_COHERENT, active=inside)
    hit_t = dr.select(si.is_valid(), mi.Float64(si.t), dr.inf)
    visible = hit_t >= dist * (1.0 - rel_tol)
    state = dr.select(finite, dr.select(inside, dr.select(visible, VISIBLE, OCCLUDED), OUT_OF_FRAME), NO_SURFACE)
    nan = dr.full(mi.Float64, np.nan, dr.width(X))
    u, v, z = dr.select(finite, u, nan), dr.select(finite, v, nan), dr.select(finite, Zc, nan)
    state = mi.UInt32(state)
    dr.eval(u, v, z, state)
    uv = np.stack([u.numpy(), v.numpy()], -1).reshape(H, W, 2)
    return Correspondence(uv, z.numpy().reshape(H, W), state.numpy().astype(np.uint8).reshape(H, W))

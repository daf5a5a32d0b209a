"""Exact per-pixel truth by casting one ray per pixel centre through our camera model.

Not Mitsuba's ``aov`` integrator: its depth is neither z-depth nor range and it is filtered by
the reconstruction filter. Here each pixel centre (u, v) = (column, row) in OpenCV's convention
is unprojected in float64 by :class:`scenegen.geometry.camera.Camera` (the same arithmetic as the
renderer's sensor), rotated into the world, intersected with the scene in float32 by Mitsuba,
and every output is derived in float64 in ONE Dr.Jit kernel (range and depth_z are returned in
float64, or, with ``as_stored``, rounded to float32 in the kernel as the dataset stores them;
points, normals and uv are rounded once to float32, the precision they are stored in). Vectors
come back as (H, W, C) views of one channel-planar buffer, so each channel is a contiguous
(H, W) plane: what the EXR encoder takes, without interleaving and splitting again.

* ``range``: distance from the optical centre to the hit (metres) = Mitsuba's ``si.t`` along
  the unit ray; ``depth_z`` = range * ray_z, z along the optical axis (metres).
* ``points_cam`` = range * ray_cam, ``points_world`` = centre + range * ray_world (metres), so
  the truth point reprojects to its pixel centre to float64 precision.
* ``normals_world`` / ``normals_cam``: the surface's shading normal (unit), as the surface
  defines it: NOT flipped towards the viewer (a back face has a normal pointing away).
* ``uv``: surface texture coordinates (u along texture columns, v = 0 at the top row).
* ``object_id`` / ``instance_id``: uint32, 0 = no surface (background).
* misses: range = depth_z = +inf, points/normals/uv NaN, ids 0, ``valid`` False.
"""
from __future__ import annotations

import functools
import math

import drjit as dr
import mitsuba as mi
import numpy as np

from scenegen.assets.cache import cached_arrays
from scenegen.dataset.truth import TruthKind
from scenegen.geometry.camera import Camera
from scenegen.geometry.conventions import pixel_centers
from scenegen.geometry.pose import Rigid3
from scenegen.render.arrays import to_jit
from scenegen.render.timed import casting_flags, first_hit, timed_first_hit, upload_moves


@functools.lru_cache(maxsize=16)
def camera_rays(camera: Camera) -> np.ndarray:
    """(H*W, 3) float64 unit directions in the camera frame, one per pixel centre, row-major
    (read-only). A distorted camera's undistortion costs 0.1-0.2 s per 480x360 camera: made once
    per content hash (:mod:`scenegen.assets.cache`), so a new process's first frame does not pay it."""
    def make():
        return {"rays": camera.unproject_unit(pixel_centers(camera.width, camera.height).reshape(-1, 2))}

    key = {"camera": camera.to_dict(), "undistort_iterations": camera.undistort_iterations}
    return cached_arrays("camera_rays", key, make)["rays"]


def prepare_camera(camera: Camera) -> None:
    """Make the camera's ray table now (scene loading), not in its first truth pass."""
    if not mi.variant().startswith("scalar"):
        _camera_rays_dr(camera)


@functools.lru_cache(maxsize=16)
def _camera_rays_dr(camera: Camera):
    r = camera_rays(camera)
    return mi.Vector3d(*[to_jit(mi.Float64, r[:, i], np.float64) for i in range(3)])


def shape_id_table(scene, object_ids: dict, instance_ids: dict):
    """Lookup tables (registry index -> object id / instance id) for ``scene.shapes()``.

    ``object_ids`` / ``instance_ids`` map a shape's Mitsuba id (its dict key) to an integer >= 1.
    Shapes not listed map to 0.
    """
    shapes = scene.shapes()
    if mi.variant().startswith("scalar"):  # no shape pointers to gather from: look up by id
        return ({s.id(): object_ids.get(s.id(), 0) for s in shapes},
                {s.id(): instance_ids.get(s.id(), 0) for s in shapes})
    reg = [int(dr.reinterpret_array(mi.UInt32, mi.ShapePtr(s))[0]) for s in shapes]
    size = max(reg, default=0) + 1
    obj = np.zeros(size, np.uint32)
    inst = np.zeros(size, np.uint32)
    for s, r in zip(shapes, reg):
        obj[r] = object_ids.get(s.id(), 0)
        inst[r] = instance_ids.get(s.id(), 0)
    return to_jit(mi.UInt32, obj, np.uint32), to_jit(mi.UInt32, inst, np.uint32)


def _matvec(R, v):
    return type(v)(R[0][0] * v.x + R[0][1] * v.y + R[0][2] * v.z,
                   R[1][0] * v.x + R[1][1] * v.y + R[1][2] * v.z,
                   R[2][0] * v.x + R[2][1] * v.y + R[2][2] * v.z)


def truth_pass(scene, camera: Camera, cam_from_world: Rigid3, id_tables,
               row_poses: list[Rigid3] | None = None, as_stored: bool = False,
               alpha_masked: bool = False, timed=None) -> dict[str, np.ndarray]:
    """All per-pixel truth for one view; arrays are (H, W[, C]). See the module docstring.

    ``row_poses`` (rolling shutter): one ``cam_from_world`` per image row; each row's rays start
    from its own pose and ``points_cam``, ``normals_cam``, ``depth_z`` are in that row's camera
    frame. Without it every row uses ``cam_from_world``. ``as_stored``: range and depth_z in
    float32 (the float64 values rounded to nearest, bit for bit what storing them gives).
    ``alpha_masked``: the scene has alpha masks; rays pass through their holes
    (:mod:`scenegen.render.alpha`). ``timed`` (rolling shutter with moving objects): a pair
    (:class:`scenegen.render.timed.TimedScenes`, {object id: ((H, 3, 3) R, (H, 3) t
    world_from_object, (H,) present) per row}): each row's rays meet the objects where they are at
    the row's time (:mod:`scenegen.render.timed`), ``scene`` and ``id_tables`` are not used.
    """
    if mi.variant().startswith("scalar"):
        if timed is not None:
            raise NotImplementedError("rolling-shutter truth with moving objects needs a vectorised variant "
                                      "(llvm_ad_rgb / cuda_ad_rgb)")
        if alpha_masked:
            raise ValueError("alpha masks need a vectorised Mitsuba variant for their truth (llvm_ad_rgb / cuda_ad_rgb)")
        if row_poses is not None:
            raise NotImplementedError("rolling-shutter truth needs a vectorised variant (llvm_ad_rgb / cuda_ad_rgb)")
        out = _truth_pass_scalar(scene, camera, cam_from_world, id_tables)
        mark_no_ray(out, camera.no_ray_mask())
        if as_stored:
            out.update({k: out[k].astype(np.float32) for k in (TruthKind.RANGE, TruthKind.DEPTH_Z)})
        return out
    H, W = camera.height, camera.width
    if row_poses is None:
        world_from_cam = cam_from_world.inverse()
        Rwc = [[dr.opaque(mi.Float64, float(world_from_cam.R[i, j])) for j in range(3)] for i in range(3)]
        C = mi.Vector3d(*[dr.opaque(mi.Float64, float(c)) for c in world_from_cam.t])
    else:  # per-row poses, gathered by each pixel's row
        if len(row_poses) != H:
            raise ValueError(f"row_poses needs {H} poses (one per row), got {len(row_poses)}")
        inv = [p.inverse() for p in row_poses]
        R_rows = np.stack([w.R for w in inv])  # (H, 3, 3) world_from_cam per row
        C_rows = np.stack([w.t for w in inv])  # (H, 3)
        row = dr.arange(mi.UInt32, H * W) // W
        Rwc = [[dr.gather(mi.Float64, to_jit(mi.Float64, R_rows[:, i, j], np.float64), row) for j in range(3)]
               for i in range(3)]
        C = mi.Vector3d(*[dr.gather(mi.Float64, to_jit(mi.Float64, C_rows[:, i], np.float64), row) for i in range(3)])
    Rcw = [[Rwc[j][i] for j in range(3)] for i in range(3)]

    d_cam = _camera_rays_dr(camera)
    d_world = _matvec(Rwc, d_cam)
    if timed is None:
        ray = mi.Ray3f(mi.Point3f(mi.Vector3f(C)), mi.Vector3f(d_world))
        t_hit, hit, n_hit, uv_hit, sid = first_hit(scene, ray, alpha_masked, coherent=True)
    else:  # each row's rays meet the moving objects where they are at the row's time
        ts, row_moves = timed
        row = dr.arange(mi.UInt32, H * W) // W
        t_hit, hit, n_hit, uv_hit, sid = timed_first_hit(ts, C, d_world, upload_moves(ts, row_moves, row),
                                                         alpha_masked, coherent=True)
        id_tables = ts.id_tables
    nan64 = dr.nan if hasattr(dr, "nan") else math.nan
    t = dr.select(hit, mi.Float64(t_hit), dr.inf)
    t_pts = dr.select(hit, mi.Float64(t_hit), nan64)  # NaN points for misses
    points_cam = d_cam * t_pts
    points_world = C + d_world * t_pts
    n_world = mi.Vector3d(n_hit)
    n_world = dr.select(hit, dr.normalize(n_world), nan64)
    n_cam = _matvec(Rcw, n_world)
    uv = dr.select(hit, mi.Vector2f(uv_hit), math.nan)
    obj_table, inst_table = id_tables
    sid = dr.select(hit, sid, 0)
    obj = dr.select(hit, dr.gather(mi.UInt32, obj_table, sid), 0)
    inst = dr.select(hit, dr.gather(mi.UInt32, inst_table, sid), 0)
    depth_z = dr.select(hit, t * d_cam.z, dr.inf)  # t * z is -inf or NaN for misses of rays at or beyond 90 degrees
    if as_stored:  # range = si.t exactly; depth_z rounded once, as numpy's astype(float32) does
        t, depth_z = mi.Float(t), mi.Float(depth_z)
    # vectors are rounded once to float32 (the stored precision) inside the kernel; range and
    # depth_z stay float64 unless as_stored, so float64 points are C + range * ray when needed
    vectors = {TruthKind.POINTS_CAM: mi.Vector3f(points_cam), TruthKind.POINTS_WORLD: mi.Vector3f(points_world),
               TruthKind.NORMALS_WORLD: mi.Vector3f(n_world), TruthKind.NORMALS_CAM: mi.Vector3f(n_cam),
               TruthKind.UV: uv}
    scalars = {TruthKind.RANGE: t, TruthKind.DEPTH_Z: depth_z, TruthKind.OBJECT_ID: obj,
               TruthKind.INSTANCE_ID: inst, TruthKind.VALID: hit}
    planar = {k: _planar(v, H * W) for k, v in vectors.items()}
    dr.eval(*planar.values(), *scalars.values())  # one kernel for everything; convert only afterwards
    # .numpy() of an evaluated flat array is a zero-copy view: (C, H, W) seen as (H, W, C)
    out = {k: np.moveaxis(b.numpy().reshape(len(vectors[k]), H, W), 0, -1) for k, b in planar.items()}
    out.update({k: v.numpy().reshape(H, W) for k, v in scalars.items()})
    if camera.mask_beyond_fold:
        mark_no_ray(out, camera.no_ray_mask())
    return out


def mark_no_ray(out: dict, no_ray: np.ndarray) -> None:
    """Pixels without a ray (beyond a distortion's fold radius): invalid in every truth map, as
    the dataset stores a miss (valid False, range and depth_z +inf, vectors NaN, ids 0);
    :meth:`scenegen.geometry.camera.Camera.no_ray_mask` tells them from misses."""
    if not no_ray.any():
        return
    for k, v in list(out.items()):
        if not v.flags.writeable:
            out[k] = v = v.copy()
        if k in (TruthKind.OBJECT_ID, TruthKind.INSTANCE_ID):
            v[no_ray] = 0
        elif k == TruthKind.VALID:
            v[no_ray] = False
        elif k in (TruthKind.RANGE, TruthKind.DEPTH_Z):
            v[no_ray] = np.inf
        else:
            v[no_ray] = np.nan


def _planar(vector, n: int):
    """One float32 buffer with the vector's components one after the other (channel-planar),
    written by the truth kernel itself (a permutation scatter: plain stores, same kernel), so
    numpy gets each channel as a contiguous plane without a copy (measured: 13 ms instead of
    30 ms for a 640x480 truth pass with a copy into planes)."""
    buf = dr.empty(mi.Float, len(vector) * n)
    idx = dr.arange(mi.UInt32, n)
    for i, c in enumerate(vector):
        dr.scatter(buf, c, idx + i * n, mode=dr.ReduceMode.Permute)
    return buf


def _truth_pass_scalar(scene, camera: Camera, cam_from_world: Rigid3, id_tables) -> dict[str, np.ndarray]:
    """The same truth in the ``scalar_rgb`` fallback (no working libLLVM): one Python call per
    ray, derived in float64 numpy. Slow (seconds per VGA frame), for correctness only."""
    H, W = camera.height, camera.width
    world_from_cam = cam_from_world.inverse()
    d_cam = camera_rays(camera)
    d_world = d_cam @ world_from_cam.R.T
    hits = _cast_rays_scalar(scene, world_from_cam.t[None], d_world, id_tables)
    t, valid = hits["t"], hits[TruthKind.VALID]
    t_pts = np.where(valid, t, np.nan)[:, None]
    n_world = hits[TruthKind.NORMALS_WORLD].astype(np.float64)
    n_world /= np.linalg.norm(n_world, axis=1, keepdims=True)
    out = {
        TruthKind.RANGE: t, TruthKind.DEPTH_Z: t * d_cam[:, 2],
        TruthKind.POINTS_CAM: (d_cam * t_pts).astype(np.float32),
        TruthKind.POINTS_WORLD: (world_from_cam.t + d_world * t_pts).astype(np.float32),
        TruthKind.NORMALS_WORLD: n_world.astype(np.float32),
        TruthKind.NORMALS_CAM: (n_world @ world_from_cam.R).astype(np.float32),
        **{k: hits[k] for k in (TruthKind.UV, TruthKind.OBJECT_ID, TruthKind.INSTANCE_ID)}, TruthKind.VALID: valid,
    }
    return {k: v.reshape((H, W) + v.shape[1:]) for k, v in out.items()}


def _cast_rays_scalar(scene, origins_world, dirs_world, id_tables) -> dict[str, np.ndarray]:
    obj_by_id, inst_by_id = id_tables
    n_rays = len(dirs_world)
    out = {"t": np.full(n_rays, np.inf), TruthKind.NORMALS_WORLD: np.full((n_rays, 3), np.nan, np.float32),
           TruthKind.UV: np.full((n_rays, 2), np.nan, np.float32), TruthKind.OBJECT_ID: np.zeros(n_rays, np.uint32),
           TruthKind.INSTANCE_ID: np.zeros(n_rays, np.uint32), TruthKind.VALID: np.zeros(n_rays, bool)}
    o = origins_world.astype(np.float32)
    for i, d in enumerate(dirs_world.astype(np.float32)):
        oi = o[0] if len(o) == 1 else o[i]
        si = scene.ray_intersect(mi.Ray3f(mi.Point3f(*oi.tolist()), mi.Vector3f(*d.tolist())), casting_flags(), True)
        if not si.is_valid():
            continue
        sid = si.shape.id()
        out["t"][i] = si.t
        out[TruthKind.NORMALS_WORLD][i] = list(si.sh_frame.n)
        out[TruthKind.UV][i] = list(si.uv)
        out[TruthKind.OBJECT_ID][i] = obj_by_id.get(sid, 0)
        out[TruthKind.INSTANCE_ID][i] = inst_by_id.get(sid, 0)
        out[TruthKind.VALID][i] = True
    return out

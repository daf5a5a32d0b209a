"""Rays with their own origins, directions and times: a LiDAR's beams (one kernel, one ``dr.eval``).

A ray at time ``t`` meets every moving object where it is at ``t`` (:mod:`.timed`: the still world
and one scene per mover); a scene with no moving object is cast as loaded (at rest). Origins and
directions go to Mitsuba in float32 (the still scene) or float64 moved into each mover's frame
first; distances come back as float32 widened to float64.

:func:`cast_posed_rays` is a sweep's whole geometry in that kernel
(:mod:`scenegen.spec.sensors.lidar_beams`): the LiDAR's poses at the U distinct times gathered per
ray, the rays rotated into the world, cast, and the hits' points and incidence, in the float64
operations and order of the numpy definition (``beam_cast_by_rays``), so the bits are the same;
numpy reads the answers in place (no copies, no array per ray built in numpy): a 131k-beam sweep
took 51-55 ms before, 29-34 ms so, against 15 ms of raw casting (docs/performance.md, "LiDAR sweeps").
"""
from __future__ import annotations

import drjit as dr
import mitsuba as mi
import numpy as np

from scenegen.geometry.lidar import dot3, rotate3
from scenegen.render.arrays import to_jit
from scenegen.render.timed import first_hit, timed_first_hit_at_times
from scenegen.spec.sensors.lidar_beams import PosedRays, RayHits


def cast_at_times(device, origins_world, directions_world, times_s) -> tuple[np.ndarray, ...]:
    """((N,) float64 hit distance along unit ``directions_world`` (N, 3) from ``origins_world``
    (N, 3) (inf: nothing hit), (N, 3) float64 unit shading normals of the surfaces hit (world;
    0 where nothing), (N,) uint32 object ids and (N,) uint32 instance ids (0: nothing)), each ray
    cast at its own ``times_s`` (N,) seconds on the clock."""
    o = np.ascontiguousarray(origins_world, np.float64)
    d = np.ascontiguousarray(directions_world, np.float64)
    n = len(o)
    if n == 0:
        return np.zeros(0), np.zeros((0, 3)), np.zeros(0, np.uint32), np.zeros(0, np.uint32)
    if mi.variant().startswith("scalar"):
        raise ValueError("LiDAR casts need a vectorised Mitsuba variant (llvm_ad_rgb / cuda_ad_rgb)")
    vec = lambda a: mi.Vector3d(*[to_jit(mi.Float64, np.ascontiguousarray(a[:, i]), np.float64)  # noqa: E731
                                  for i in range(3)])
    timeline = device.timeline
    if timeline is not None and device.description.movers:
        ts = device.timed()
        # the movers posed once per distinct time, each ray gathering its own (beams that fire
        # together, a beam's footprint rays)
        unique_times, at = np.unique(np.asarray(times_s, np.float64), return_inverse=True)
        t, hit, nrm, _, sid = timed_first_hit_at_times(ts, vec(o), vec(d), unique_times, timeline,
                                                       device.alpha_masked, coherent=False,
                                                       index=to_jit(mi.UInt32, at.astype(np.uint32), np.uint32))
        tables = ts.id_tables
    else:
        device.place_at(None)
        ray = mi.Ray3f(mi.Point3f(mi.Vector3f(vec(o))), mi.Vector3f(vec(d)))
        t, hit, nrm, _, sid = first_hit(device.scene, ray, device.alpha_masked, coherent=False)
        tables = device.id_tables
    dist = dr.select(hit, mi.Float64(t), dr.inf)
    nrm = dr.normalize(mi.Vector3f(nrm))
    oid = dr.select(hit, dr.gather(mi.UInt32, tables[0], sid), 0)
    iid = dr.select(hit, dr.gather(mi.UInt32, tables[1], sid), 0)
    dr.eval(dist, nrm, oid, iid)
    normal = np.stack([nrm.x.numpy(), nrm.y.numpy(), nrm.z.numpy()], 1).astype(np.float64)
    dist = dist.numpy().copy()
    normal[~np.isfinite(dist)] = 0.0
    return dist, normal, oid.numpy().copy(), iid.numpy().copy()


def cast_posed_rays(device, rays: PosedRays) -> RayHits:
    """:class:`RayHits` of ``rays`` (module docstring), each cast at its own time."""
    n = len(rays.time_index)
    if n == 0:
        z = np.zeros(0)
        return RayHits(z, z, z.astype(np.uint32), z.astype(np.uint32), np.zeros((0, 3)), np.zeros((0, 3)),
                       np.zeros((0, 3)), np.zeros((0, 4)))
    if mi.variant().startswith("scalar"):
        raise ValueError("LiDAR casts need a vectorised Mitsuba variant (llvm_ad_rgb / cuda_ad_rgb)")
    index = to_jit(mi.UInt32, rays.time_index, np.uint32)
    per_ray = lambda table: dr.gather(mi.Float64, to_jit(mi.Float64, table, np.float64), index)  # noqa: E731
    R, t = rays.world_from_lidar
    zero = dr.opaque(mi.Float64, 0.0)  # a literal + 0.0 would be dropped from the kernel (dot3)
    d_lidar = [to_jit(mi.Float64, rays.directions_lidar[:, j], np.float64) for j in range(3)]
    origin = mi.Vector3d(*[per_ray(t[:, i]) for i in range(3)])
    direction = mi.Vector3d(*rotate3([[per_ray(R[:, i, j]) for j in range(3)] for i in range(3)], d_lidar, zero))
    timeline = device.timeline
    if timeline is not None and device.description.movers:
        ts = device.timed()
        dist, hit, nrm, _, sid = timed_first_hit_at_times(ts, origin, direction, rays.times_s, timeline,
                                                          device.alpha_masked, coherent=False, index=index)
        tables = ts.id_tables
    else:
        device.place_at(None)
        ray = mi.Ray3f(mi.Point3f(mi.Vector3f(origin)), mi.Vector3f(direction))
        dist, hit, nrm, _, sid = first_hit(device.scene, ray, device.alpha_masked, coherent=False)
        tables = device.id_tables
    r = dr.select(hit, mi.Float64(dist), dr.inf)
    normal = mi.Vector3d(dr.normalize(mi.Vector3f(nrm)))
    cos = dr.abs(dot3(normal, direction, zero))
    cos = dr.select(hit, dr.select(cos > 1.0, 1.0, cos), 0.0)  # np.clip(cos, 0, 1): NaN stays NaN
    nan = dr.nan
    point_world = dr.select(hit, origin + r * direction, nan)
    point_lidar = dr.select(hit, mi.Vector3d(*[r * d for d in d_lidar]), nan)
    quat = [per_ray(rays.quat_wxyz[:, k]) for k in range(4)]
    oid = dr.select(hit, dr.gather(mi.UInt32, tables[0], sid), 0)
    iid = dr.select(hit, dr.gather(mi.UInt32, tables[1], sid), 0)
    out = [r, cos, oid, iid, dr.ravel(point_world), dr.ravel(point_lidar), dr.ravel(origin),
           dr.ravel(mi.Vector4d(*quat))]
    dr.eval(*out)
    a = [x.numpy() for x in out]  # views of the kernel's buffers
    return RayHits(a[0], a[1], a[2], a[3], a[4].reshape(n, 3), a[5].reshape(n, 3), a[6].reshape(n, 3),
                   a[7].reshape(n, 4))

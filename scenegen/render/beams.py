"""Rays with their own origins, directions and times: a LiDAR's beams (one kernel, one ``dr.eval``).

A ray at time ``t`` meets every moving object where it is at ``t`` (:mod:`.timed`: the still world
and one scene per mover); a scene with no moving object is cast as loaded (at rest). Origins and
directions go to Mitsuba in float32 (the still scene) or float64 moved into each mover's frame
first; distances come back as float32 widened to float64.
"""
from __future__ import annotations

import drjit as dr
import mitsuba as mi
import numpy as np

from scenegen.render.arrays import to_jit
from scenegen.render.timed import first_hit, timed_first_hit_at_times


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

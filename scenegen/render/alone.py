"""Ray casts against one object alone (BOP's "rendered alone" silhouettes, a keypoint's
self-occlusion): each annotated object gets a scene of its own holding only its shapes at their
reference placement (its spec ``transform``, where the main scene first put them), built on first
use and kept by the device. A ray is moved into that placement (``o' = ref_from_world o``,
``d' = R d``, ``ref_from_world = world_from_ref @ object_from_world``), which keeps the ray
parameter: the distance is the one to the object placed at ``world_from_object``, as
:mod:`scenegen.render.timed` does for moving objects.
"""
from __future__ import annotations

import drjit as dr
import mitsuba as mi
import numpy as np

from scenegen.geometry.pose import Rigid3
from scenegen.render.arrays import to_jit
from scenegen.render.objects import object_entries
from scenegen.render.timed import first_hit


def alone_scene(device, object_id: int) -> tuple[object, Rigid3]:
    """(mi.Scene with only the object's shapes, world_from_ref of that placement), cached on
    ``device`` (:class:`scenegen.render.device.DeviceScene`)."""
    cache = device.alone_scenes
    if object_id not in cache:
        found = [d for d in device.description.objects if d.spec.object_id == object_id]
        if not found:
            raise ValueError(f"no object with id {object_id} in the scene")
        d = found[0]
        entries, _ = object_entries(d)  # fresh shapes at the spec placement
        cache[object_id] = (mi.load_dict({"type": "scene", **entries}), d.spec.transform.world_from_object)
    return cache[object_id]


def alone_distances(device, object_id: int, world_from_object: Rigid3, origin_world, directions_world) -> np.ndarray:
    """(N,) float64 distance along unit rays from ``origin_world`` (3,) in ``directions_world``
    (N, 3) to the object ``object_id`` alone, placed at ``world_from_object`` (+inf: missed)."""
    if mi.variant().startswith("scalar"):
        raise ValueError("object truth (casts against one object alone) needs a vectorised Mitsuba variant "
                         "(llvm_ad_rgb / cuda_ad_rgb)")
    d = np.asarray(directions_world, np.float64).reshape(-1, 3)
    if len(d) == 0:
        return np.zeros(0)
    scene, world_from_ref = alone_scene(device, object_id)
    ref_from_world = world_from_ref @ world_from_object.inverse()
    o = ref_from_world.apply(np.asarray(origin_world, np.float64).reshape(1, 3))[0]
    d_ref = d @ ref_from_world.R.T
    ray = mi.Ray3f(mi.Point3f(*[dr.opaque(mi.Float, float(c)) for c in o]),
                   mi.Vector3f(*[to_jit(mi.Float, d_ref[:, i], np.float32) for i in range(3)]))
    t, hit, *_ = first_hit(scene, ray, device.alpha_masked, coherent=False, flags=mi.RayFlags.Minimal)
    t = dr.select(hit, t, dr.inf)
    dr.eval(t)
    return np.array(t, dtype=np.float64)

"""Ray casts with every moving object where it is at each ray's own time (rolling shutter).

Mitsuba has no animated transforms, and moving an object rebuilds the scene's BVH (17-50 ms): a
rolling-shutter frame, each row exposed at its own time, would need one rebuild per row. Instead
each object that moves (a sequence's animated objects, objects with ``motion``) gets a scene of
its own that holds it at its reference placement (its spec ``transform``, where the main scene
first put it), the rest of the world shares one more scene (the same Mitsuba shapes as the main
scene), and a ray at time tau is cast in the still scene as it is and, in each object's scene,
moved into the reference placement: ``o' = ref_from_world(tau) o``, ``d' = R d``, with
``ref_from_world(tau) = world_from_object_ref @ object_from_world(tau)``. A rigid move keeps
the ray parameter, so the nearest hit over the scenes is the ray's first hit with every object
placed at tau; only the float32 rounding differs (of the moved ray instead of the moved
vertices). Normals come back into the world with ``R^T``. An object absent at tau
(``visible_s``) is not hit.

Each ray carries a time (seconds on the sequence clock, :mod:`scenegen.geometry.clock`):
:func:`timed_first_hit_at_times` places the movers at every ray's own time; a rolling-shutter
row, a LiDAR beam, an event are all just times.

Built on first use (:meth:`scenegen.render.device.DeviceScene.timed`): scenes without a rolling
shutter and a moving object never pay for it.
"""
from __future__ import annotations

from dataclasses import dataclass

import drjit as dr
import mitsuba as mi
import numpy as np

from scenegen.geometry.pose import Rigid3
from scenegen.render.alpha import opaque_intersect
from scenegen.render.arrays import to_jit


@dataclass
class Mover:
    """A moving object's own scene, holding its shapes at the reference placement."""

    object_id: int
    scene: object  # mi.Scene
    world_from_ref: Rigid3  # the object's world_from_object in that placement


@dataclass
class TimedScenes:
    """The still world and one scene per moving object (module docstring)."""

    still: object  # mi.Scene: every shape of the main scene that does not move (shared shapes)
    movers: dict  # object id -> Mover
    id_tables: tuple  # (object id table, instance id table) over the shapes of every scene here


def casting_flags():
    """Only what the truth needs: position, uv and the shading normal (no dP/dUV derivatives)."""
    return mi.RayFlags.Minimal | mi.RayFlags.UV | mi.RayFlags.ShadingFrame


def first_hit(scene, ray, alpha_masked: bool, coherent: bool, flags=None, active=True):
    """(hit distance mi.Float, valid mi.Bool, shading normal mi.Vector3f, uv mi.Vector2f, shape
    registry index mi.UInt32) of ``ray``'s first hit in ``scene`` (through alpha-mask holes)."""
    flags = casting_flags() if flags is None else flags
    if alpha_masked:
        si, t = opaque_intersect(scene, ray, flags, coherent=coherent)
    else:
        si = scene.ray_intersect(ray, ray_flags=flags, coherent=coherent, active=active)
        t = si.t
    return t, si.is_valid(), si.sh_frame.n, si.uv, dr.reinterpret_array(mi.UInt32, si.shape)


def ref_from_world_columns(world_from_object: tuple[np.ndarray, np.ndarray], world_from_ref: Rigid3):
    """((N, 3, 3), (N, 3)) ``ref_from_world = world_from_ref @ object_from_world`` of poses
    ``world_from_object`` given as ((N, 3, 3) rotations, (N, 3) translations)."""
    R, t = (np.asarray(a, np.float64) for a in world_from_object)
    Rt = np.swapaxes(R, 1, 2)  # object_from_world
    M = world_from_ref.R @ Rt
    m = world_from_ref.t - np.einsum("nij,nj->ni", M, t)
    return M, m


def upload_moves(ts: TimedScenes, moves: dict, index=None) -> dict:
    """Dr.Jit form of ``moves`` {object id: ((N, 3, 3) R, (N, 3) t world_from_object, (N,) bool
    present)}: {id: (M 3x3 of mi.Float64, m 3 of mi.Float64, present mi.Bool)}, gathered by
    ``index`` (a mi.UInt32 per ray: e.g. each pixel's row) when given."""
    out = {}
    for oid, (R, t, present) in moves.items():
        M, m = ref_from_world_columns((R, t), ts.movers[oid].world_from_ref)
        col = lambda a: to_jit(mi.Float64, a, np.float64)  # noqa: E731
        take = (lambda x: x) if index is None else (lambda x: dr.gather(type(x), x, index))  # noqa: E731
        Mj = [[take(col(M[:, i, j])) for j in range(3)] for i in range(3)]
        mj = [take(col(m[:, i])) for i in range(3)]
        pj = take(mi.Bool(np.ascontiguousarray(present, bool)))
        out[oid] = (Mj, mj, pj)
    return out


def timed_first_hit(ts: TimedScenes, origin, direction, moves_jit: dict, alpha_masked: bool, coherent: bool):
    """:func:`first_hit` over the still scene and every mover placed by ``moves_jit`` (from
    :func:`upload_moves`); ``origin``, ``direction``: mi.Vector3d in the world (float64)."""
    ray = mi.Ray3f(mi.Point3f(mi.Vector3f(origin)), mi.Vector3f(direction))
    t, hit, n, uv, sid = first_hit(ts.still, ray, alpha_masked, coherent)
    t = dr.select(hit, t, dr.inf)
    for oid, (M, m, present) in moves_jit.items():
        mv = lambda v: mi.Vector3d(*[M[i][0] * v.x + M[i][1] * v.y + M[i][2] * v.z for i in range(3)])  # noqa: E731
        o_ref = mv(origin) + mi.Vector3d(*m)
        ray_k = mi.Ray3f(mi.Point3f(mi.Vector3f(o_ref)), mi.Vector3f(mv(direction)))
        t_k, hit_k, n_k, uv_k, sid_k = first_hit(ts.movers[oid].scene, ray_k, alpha_masked, coherent, active=present)
        closer = present & hit_k & (t_k < t)
        n_world = mi.Vector3f(*[M[0][i] * n_k.x + M[1][i] * n_k.y + M[2][i] * n_k.z for i in range(3)])  # R^T n
        t = dr.select(closer, t_k, t)
        hit = hit | closer
        n = dr.select(closer, n_world, n)
        uv = dr.select(closer, uv_k, uv)
        sid = dr.select(closer, sid_k, sid)
    return t, hit, n, uv, sid


def timed_first_hit_at_times(ts: TimedScenes, origin, direction, times_s, motions, alpha_masked: bool,
                             coherent: bool, index=None):
    """:func:`timed_first_hit` of rays each cast at its own time: ``times_s`` (N,) seconds on the
    sequence clock (a rolling-shutter row's, a LiDAR beam's, an event's, an IMU sample's), or a
    table of M times that ``index`` (a mi.UInt32 per ray) gathers from; ``motions``: anything
    with ``object_moves_at_times(times_s) -> {object id: ((N, 3, 3) R, (N, 3) t world_from_object,
    (N,) present)}`` (:class:`scenegen.geometry.rolling.RollingRows`, :class:`scenegen.spec.timeline.Timeline`)."""
    moves = {oid: mv for oid, mv in motions.object_moves_at_times(times_s).items() if oid in ts.movers}
    return timed_first_hit(ts, origin, direction, upload_moves(ts, moves, index), alpha_masked, coherent)


def build_timed(main_entries: dict, mover_entries: dict, references: dict, object_ids: dict,
                instance_ids: dict) -> TimedScenes:
    """The still scene from ``main_entries`` (the main scene dict's shapes and emitters that do
    not move; Mitsuba shapes are shared with the main scene), and per moving object id its
    ``mover_entries[id]`` (fresh shapes at the reference placement) with ``references[id]``
    (world_from_ref). ``object_ids`` / ``instance_ids``: dict key -> id, as for the main scene."""
    still = mi.load_dict({"type": "scene", **main_entries})
    movers = {oid: Mover(oid, mi.load_dict({"type": "scene", **entries}), references[oid])
              for oid, entries in mover_entries.items()}
    scenes = [still] + [mv.scene for mv in movers.values()]
    return TimedScenes(still, movers, shape_id_tables(scenes, object_ids, instance_ids))


def shape_id_tables(scenes, object_ids: dict, instance_ids: dict):
    """Lookup tables (shape registry index -> object id / instance id) over the shapes of
    ``scenes``; a shape's dict key (``shape.id()``) names its ids, unlisted shapes map to 0."""
    pairs = [(int(dr.reinterpret_array(mi.UInt32, mi.ShapePtr(s))[0]), s.id()) for sc in scenes for s in sc.shapes()]
    size = max((r for r, _ in pairs), default=0) + 1
    obj = np.zeros(size, np.uint32)
    inst = np.zeros(size, np.uint32)
    for r, key in pairs:
        obj[r] = object_ids.get(key, 0)
        inst[r] = instance_ids.get(key, 0)
    return to_jit(mi.UInt32, obj, np.uint32), to_jit(mi.UInt32, inst, np.uint32)

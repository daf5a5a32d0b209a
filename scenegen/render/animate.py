"""Objects that move over a sequence: placed at any time of the clock through
:meth:`scenegen.render.device.DeviceScene.place_at` (each cast and render states its time), by
rewriting their vertices (meshes) or their ``to_world`` (the analytic sphere) from the placement
at frame 0, in float64 numpy, uploaded as float32 like every mesh (:mod:`.objects`).

Where an object is at a time is the spec's answer (:class:`scenegen.spec.timeline.Timeline`), so
the renders, the truth pass and the visibility casts of the sequence stage see the same
geometry. An object outside its ``visible_s`` interval has every vertex on one point: its
triangles have no area and no ray hits them.
"""
from __future__ import annotations

from dataclasses import dataclass

import mitsuba as mi
import numpy as np

from scenegen.geometry.pose import Rigid3
from scenegen.render.arrays import to_jit
from scenegen.render.objects import placed_geometry


@dataclass
class Animated:
    """An object of a sequence: its Mitsuba keys and its placement at frame 0."""

    key: str  # the object's key in the scene dict
    name: str  # the spec object's name (the timeline's key)
    world_from_object_0: Rigid3  # the placement of the uploaded geometry (frame 0)
    sphere_to_world: np.ndarray | None = None  # (4, 4) for an analytic sphere
    vertices: np.ndarray | None = None  # (V, 3) float64 world vertices at frame 0
    normals: np.ndarray | None = None  # (V, 3) vertex normals, or None (flat shading)


def animated_entry(key: str, obj, entry, mesh_world) -> Animated:
    """What :func:`place_animated` needs of an animated object."""
    return Animated(key, obj.name, obj.transform.world_from_object, **placed_geometry(entry, mesh_world))


def place_animated(built, t_s: float) -> None:
    """Put every animated object where the timeline has it at ``t_s`` (seconds on the clock)."""
    if not built.animated:
        return
    states = built.timeline.states(t_s)
    if built.animated_params is None:  # traversed once: the keys do not change
        built.animated_params = mi.traverse(built.scene)
    params = built.animated_params
    for an in built.animated:
        st = states[an.name]
        move = st.world_from_object @ an.world_from_object_0.inverse()
        if an.sphere_to_world is not None:
            params[f"{an.key}.to_world"] = mi.ScalarTransform4f(move.matrix @ an.sphere_to_world)
            continue
        put = lambda k, a: params.__setitem__(k, to_jit(type(params[k]), a, np.float32))
        verts = move.apply(an.vertices)
        if not st.present:  # no area, no hit
            verts = np.repeat(verts[:1], len(verts), axis=0)
        put(f"{an.key}.vertex_positions", verts)
        if an.normals is not None:
            put(f"{an.key}.vertex_normals", move.rotate(an.normals))
    params.update()

"""Described objects -> Mitsuba shapes: world-frame triangle meshes (float32 on upload) and the
analytic sphere (exact depth), plus the objects that move during the exposure.

Geometry is placed in the world in float64 numpy by the description
(:func:`scenegen.render.description.describe_object`), so the dataset's world meshes and the
rendered ones are the same triangles.
"""
from __future__ import annotations

from dataclasses import dataclass

import mitsuba as mi
import numpy as np
import trimesh

from scenegen.geometry.optics import world_from_object_at
from scenegen.geometry.pose import Rigid3
from scenegen.render.arrays import to_jit
from scenegen.render.asset_materials import asset_bsdf, asset_emitter
from scenegen.render.description import DescribedObject
from scenegen.render.materials import board_material, is_alpha_masked, material_dict


@dataclass
class Moving:
    """An object that moves over the exposure: its Mitsuba parameter keys and mid-exposure state."""

    key: str  # the object's key in the scene dict
    motion: object  # scenegen.geometry.optics.Motion (world frame, about the object origin)
    world_from_object: Rigid3  # mid-exposure placement
    sphere_to_world: np.ndarray | None = None  # (4, 4) for an analytic sphere
    vertices: np.ndarray | None = None  # (V, 3) float64 world vertices at mid-exposure
    normals: np.ndarray | None = None  # (V, 3) vertex normals, or None (flat shading)


def mitsuba_mesh(name: str, mesh: trimesh.Trimesh, bsdf: dict, smooth: bool, emitter: dict | None = None,
                 vertex_colors: np.ndarray | None = None):
    """A Mitsuba mesh from world-frame triangles (float32 on upload), with UVs when present, an
    optional area emitter and optional (V, 3) linear vertex colours (attribute ``vertex_color``)."""
    uv = getattr(mesh.visual, "uv", None)
    props = mi.Properties()
    props["bsdf"] = mi.load_dict(bsdf)
    if emitter is not None:
        props["emitter"] = mi.load_dict(emitter)
    mm = mi.Mesh(name, len(mesh.vertices), len(mesh.faces), props=props,
                 has_vertex_normals=smooth, has_vertex_texcoords=uv is not None)
    params = mi.traverse(mm)
    # the buffers' own types: Dr.Jit arrays in vectorised variants, dynamic arrays in scalar ones;
    # aligned copies, so the kernels do not depend on numpy's addresses (scenegen.render.arrays)
    put = lambda key, a, dtype: params.__setitem__(key, to_jit(type(params[key]), a, dtype))
    put("vertex_positions", mesh.vertices, np.float32)
    put("faces", mesh.faces, np.uint32)
    if smooth:
        put("vertex_normals", mesh.vertex_normals, np.float32)
    if uv is not None:
        put("vertex_texcoords", uv, np.float32)
    if vertex_colors is not None:
        mm.add_attribute("vertex_color", 3, to_jit(mi.Float, np.ravel(vertex_colors), np.float32))
    params.update()
    return mm


def _sphere_entry(obj, bsdf: dict) -> dict:
    radius = obj.geometry.radius * float(np.asarray(obj.transform.scale)[0])  # uniform: describe_object
    T = np.eye(4)
    T[:3, :3] = obj.transform.world_from_object.R * radius  # keeps the texture's orientation
    T[:3, 3] = obj.transform.world_from_object.t
    return {"type": "sphere", "to_world": mi.ScalarTransform4f(T), "bsdf": bsdf}


def object_entries(d: DescribedObject) -> tuple[dict, bool]:
    """({key: Mitsuba dict entry or shape}, whether an entry has an alpha mask) of a described
    object; a mesh rendered with its own materials gives one Mitsuba mesh per part,
    ``{key_partNNN: mesh}`` (all parts carry the object's ids). Fresh Mitsuba objects per call."""
    obj = d.spec
    if d.parts:
        out, alpha = {}, False
        for p in d.parts:
            am = p.material
            bsdf = material_dict(obj.material) if am is None else asset_bsdf(am)
            emitter = None if am is None else asset_emitter(am)
            colors = None if am is None else am.vertex_colors
            alpha |= is_alpha_masked(bsdf)
            out[p.key] = mitsuba_mesh(p.name, p.mesh_world, bsdf, d.smooth, emitter, colors)
        return out, alpha
    bsdf = material_dict(obj.material)
    alpha = is_alpha_masked(bsdf)
    if d.is_sphere:
        return {d.key: _sphere_entry(obj, bsdf)}, alpha
    if d.board is not None:
        bsdf = board_material(d.board[0])
    return {d.key: mitsuba_mesh(obj.name, d.mesh_world, bsdf, d.smooth)}, alpha


def placed_geometry(entry, mesh_world) -> dict:
    """What moving a loaded object needs of its geometry at its spec pose: the analytic sphere's
    ``sphere_to_world`` (4x4), or a mesh's world ``vertices`` (V, 3) and ``normals`` (V, 3; None
    for flat shading), float64."""
    if isinstance(entry, dict):  # the analytic sphere
        return {"sphere_to_world": np.array(entry["to_world"].matrix, dtype=np.float64)}
    normals = None
    if entry.has_vertex_normals():
        normals = np.asarray(mesh_world.vertex_normals, dtype=np.float64)
    return {"vertices": np.asarray(mesh_world.vertices, dtype=np.float64), "normals": normals}


def moving_entry(key: str, obj, entry, mesh_world) -> Moving:
    """What :func:`place_moving_objects` needs of a moving object."""
    return Moving(key, obj.motion, obj.transform.world_from_object, **placed_geometry(entry, mesh_world))


def place_moving_objects(built, tau_s: float) -> None:
    """Move every moving object to its pose ``tau_s`` seconds after mid-exposure."""
    if not built.moving:
        return
    params = mi.traverse(built.scene)
    for mv in built.moving:
        # world_from_object(tau) @ object_from_world(mid): maps mid-exposure world points
        move = world_from_object_at(mv.world_from_object, mv.motion, tau_s) @ mv.world_from_object.inverse()
        if mv.sphere_to_world is not None:
            params[f"{mv.key}.to_world"] = mi.ScalarTransform4f(move.matrix @ mv.sphere_to_world)
            continue
        put = lambda k, a: params.__setitem__(k, to_jit(type(params[k]), a, np.float32))
        put(f"{mv.key}.vertex_positions", move.apply(mv.vertices))
        if mv.normals is not None:
            put(f"{mv.key}.vertex_normals", move.rotate(mv.normals))
    params.update()

"""Spec objects -> Mitsuba shapes: world-frame triangle meshes (float32 on upload) and the
analytic sphere (exact depth), plus the objects that move during the exposure.

Geometry is placed in the world in float64 numpy (:func:`scenegen.assets.meshes.place`), so the
dataset's world meshes and the rendered ones are the same triangles.
"""
from __future__ import annotations

from dataclasses import dataclass

import mitsuba as mi
import numpy as np
import trimesh

from scenegen.assets import meshes, shapes
from scenegen.geometry.optics import world_from_object_at
from scenegen.geometry.pose import Rigid3
from scenegen.render.arrays import to_jit
from scenegen.render.materials import board_material, material_dict


@dataclass
class Moving:
    """An object that moves over the exposure: its Mitsuba parameter keys and mid-exposure state."""

    key: str  # the object's key in the scene dict
    motion: object  # scenegen.geometry.optics.Motion (world frame, about the object origin)
    world_from_object: Rigid3  # mid-exposure placement
    sphere_to_world: np.ndarray | None = None  # (4, 4) for an analytic sphere
    vertices: np.ndarray | None = None  # (V, 3) float64 world vertices at mid-exposure
    normals: np.ndarray | None = None  # (V, 3) vertex normals, or None (flat shading)


def mitsuba_mesh(name: str, mesh: trimesh.Trimesh, bsdf: dict, smooth: bool):
    """A Mitsuba mesh from world-frame triangles (float32 on upload), with UVs when present."""
    uv = getattr(mesh.visual, "uv", None)
    props = mi.Properties()
    props["bsdf"] = mi.load_dict(bsdf)
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
    params.update()
    return mm


def _sphere_entry(obj, bsdf: dict, built) -> dict:
    s = np.asarray(obj.transform.scale)
    if not np.allclose(s, s[0]):
        raise ValueError(f"object {obj.name!r}: a sphere takes a uniform scale, got {tuple(s)}")
    radius = obj.geometry.radius * float(s[0])
    # the analytic sphere renders and is intersected exactly; the mesh is only exported
    built.meshes_world[obj.name] = meshes.place(shapes.sphere(obj.geometry.radius), obj.transform)
    T = np.eye(4)
    T[:3, :3] = obj.transform.world_from_object.R * radius  # keeps the texture's orientation
    T[:3, 3] = obj.transform.world_from_object.t
    return {"type": "sphere", "to_world": mi.ScalarTransform4f(T), "bsdf": bsdf}


def object_entry(obj, built) -> dict:
    """The Mitsuba dict entry (or shape) for one spec object; records its world mesh and board."""
    bsdf = material_dict(obj.material)
    if obj.geometry.kind == "sphere":
        return _sphere_entry(obj, bsdf, built)
    local, board = meshes.object_mesh(obj.geometry)
    world = meshes.place(local, obj.transform)
    built.meshes_world[obj.name] = world
    if board is not None:
        if not np.allclose(obj.transform.scale, 1.0):
            raise ValueError(f"object {obj.name!r}: calibration targets cannot be scaled (their size is exact)")
        built.boards[obj.name] = (board, obj.transform.world_from_object @ board.object_from_board())
        bsdf = board_material(board)
    return mitsuba_mesh(obj.name, world, bsdf, meshes.is_smooth(obj.geometry, local, world))


def moving_entry(key: str, obj, entry, mesh_world) -> Moving:
    """What :func:`place_moving_objects` needs of a moving object."""
    if isinstance(entry, dict):  # the analytic sphere
        return Moving(key, obj.motion, obj.transform.world_from_object,
                      sphere_to_world=np.array(entry["to_world"].matrix, dtype=np.float64))
    normals = None
    if entry.has_vertex_normals():
        normals = np.asarray(mesh_world.vertex_normals, dtype=np.float64)
    return Moving(key, obj.motion, obj.transform.world_from_object,
                  vertices=np.asarray(mesh_world.vertices, dtype=np.float64), normals=normals)


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

"""What a scene IS, before any device: :class:`SceneDescription`, the first of the render
package's three parts (description -> :class:`scenegen.render.device.DeviceScene` -> the
explicit casts of :class:`scenegen.render.caster.Caster`).

Made from a spec without Mitsuba (:func:`describe`): every object's world-frame export mesh, its
parts with their own materials, its calibration board, whether it is shaded smooth; the spec
objects themselves (pose, material, motion, animation), the lights, the cameras and their
optics, the sequence's timeline and the render settings. Frozen and picklable (a Dask worker or
a GPU process can be sent one), with a content hash (the spec's canonical hash, which includes
the referenced files' hashes, and the render settings). Mitsuba objects (bsdfs with their
bitmaps, shapes, sensors) exist only in the device scene built from it.
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import trimesh

from scenegen.assets import meshes, shapes
from scenegen.assets.libraries import mesh_within
from scenegen.assets.mesh_materials import mesh_parts
from scenegen.spec import model as m
from scenegen.spec.assets_check import located
from scenegen.spec.serialize import spec_sha256
from scenegen.spec.timeline import Timeline, is_animated, moves_within_frame

@dataclass(frozen=True)
class MeshPart:
    """One part of a mesh rendered with its own materials (an asset's material slot)."""

    key: str  # its key in the scene dict: <object key>_partNNN
    name: str  # its Mitsuba shape name: <object name>/partNNN
    mesh_world: trimesh.Trimesh  # its world triangles (vertex normals set for a smooth mesh)
    material: object = None  # scenegen.assets.mesh_materials material, or None (the spec's material)


@dataclass(frozen=True)
class DescribedObject:
    """A spec object with its world geometry (float64, as exported and as uploaded)."""

    spec: object  # the spec object (ids, geometry, material, transform, motion, animation)
    key: str  # its key in the scene dict
    mesh_world: trimesh.Trimesh  # the export mesh in the world frame (an analytic sphere's tessellation)
    smooth: bool = False  # interpolated shading normals
    board: tuple | None = None  # (assets.targets.Board, world_from_board) of a calibration target
    parts: tuple[MeshPart, ...] = ()  # a mesh rendered with its own materials, else ()

    @property
    def is_sphere(self) -> bool:
        return self.spec.geometry.kind == "sphere"

    @property
    def moves_in_exposure(self) -> bool:
        """Moves during one exposure (the spec's ``motion``): rendered in sub-frames."""
        return self.spec.motion is not None and not self.spec.motion.is_static


@dataclass(frozen=True)
class SceneDescription:
    """Everything a device scene is built from (module docstring). Fields are read-only by
    convention: dicts are the description's own, not to be changed."""

    objects: tuple[DescribedObject, ...]
    lights: tuple  # spec lights, spec order
    cameras: dict  # camera name -> scenegen.geometry.camera.Camera
    optics: dict  # camera name -> scenegen.geometry.optics.Optics (or None)
    timeline: Timeline | None  # a sequence's clock (objects placed per time), else None
    rest_time_s: float | None  # the time the geometry rests at: a sequence's frame 0, else None
    motion_subframes: int  # sub-frames of a render when something moves
    spp: int
    sampler: str  # the sensors' Mitsuba sampler plugin (it rounds spp up: effective_spp)
    max_depth: int
    spec_sha256: str = field(repr=False)
    projectors: dict = field(default_factory=dict)  # projector name -> scenegen.spec.sensors.projector.ProjectorSpec

    @cached_property
    def content_hash(self) -> str:
        """sha256 (hex) of the spec's canonical hash and the render settings."""
        key = {"spec": self.spec_sha256, "spp": self.spp, "sampler": self.sampler, "max_depth": self.max_depth}
        return hashlib.sha256(json.dumps(key, sort_keys=True).encode()).hexdigest()

    @property
    def meshes_world(self) -> dict:
        """Object name -> world trimesh (for export)."""
        return {o.spec.name: o.mesh_world for o in self.objects}

    @property
    def part_meshes(self) -> dict:
        """Scene-dict key -> world trimesh of each part of a mesh rendered with its own materials."""
        return {p.key: p.mesh_world for o in self.objects for p in o.parts}

    @property
    def boards(self) -> dict:
        """Object name -> (assets.targets.Board, world_from_board)."""
        return {o.spec.name: o.board for o in self.objects if o.board is not None}

    @property
    def object_records(self) -> list:
        """[{name, object_id, instance_id, kind}] for cameras.json."""
        return [{"name": o.spec.name, "object_id": o.spec.object_id, "instance_id": o.spec.instance_id,
                 "kind": type(o.spec.geometry).__name__.lower()} for o in self.objects]

    @property
    def movers(self) -> dict:
        """Object id -> described object that moves within a frame (rolling-shutter casts)."""
        return {o.spec.object_id: o for o in self.objects if moves_within_frame(o.spec)}

    @property
    def animated(self) -> tuple[DescribedObject, ...]:
        """Objects of a sequence placed per time."""
        return tuple(o for o in self.objects if is_animated(o.spec))


def object_key(obj) -> str:
    """The key of a spec object in the scene dict."""
    return f"obj_{obj.object_id:04d}"


def describe_object(obj) -> DescribedObject:
    """A spec object's world geometry (float64 numpy; checks its scale against its kind)."""
    key = object_key(obj)
    if obj.geometry.kind == "sphere":
        s = np.asarray(obj.transform.scale)
        if not np.allclose(s, s[0]):
            raise ValueError(f"object {obj.name!r}: a sphere takes a uniform scale, got {tuple(s)}")
        # the analytic sphere renders and is intersected exactly; the mesh is only exported
        return DescribedObject(obj, key, meshes.place(shapes.sphere(obj.geometry.radius), obj.transform))
    local, board = meshes.object_mesh(obj.geometry)
    world = meshes.place(local, obj.transform)
    smooth = meshes.is_smooth(obj.geometry, local, world)
    if obj.geometry.kind == "mesh" and obj.geometry.own_materials:
        return DescribedObject(obj, key, world, smooth, parts=_parts(obj, key, world, smooth))
    placed = None
    if board is not None:
        if not np.allclose(obj.transform.scale, 1.0):
            raise ValueError(f"object {obj.name!r}: calibration targets cannot be scaled (their size is exact)")
        placed = (board, obj.transform.world_from_object @ board.object_from_board())
    return DescribedObject(obj, key, world, smooth, placed)


def _parts(obj, key: str, world: trimesh.Trimesh, smooth: bool) -> tuple[MeshPart, ...]:
    parts = mesh_parts(obj.geometry.path, mesh_within(obj.geometry))
    if sum(p.vertex_count for p in parts) != len(world.vertices) or \
            sum(p.face_count for p in parts) != len(world.faces):
        raise ValueError(f"object {obj.name!r}: the parts of {obj.geometry.path_as_written!r} do not "
                         "add up to the loaded mesh")
    normals = np.asarray(world.vertex_normals) if smooth else None
    out = []
    for i, p in enumerate(parts):
        vs = slice(p.vertex_start, p.vertex_start + p.vertex_count)
        fs = slice(p.face_start, p.face_start + p.face_count)
        sub = trimesh.Trimesh(vertices=world.vertices[vs], faces=world.faces[fs] - p.vertex_start, process=False)
        if normals is not None:
            sub.vertex_normals = normals[vs]
        if p.uv is not None:
            sub.visual = trimesh.visual.TextureVisuals(uv=p.uv)
        out.append(MeshPart(f"{key}_part{i:03d}", f"{obj.name}/part{i:03d}", sub, p.material))
    return tuple(out)


def describe(spec: m.SceneSpec, *, spp: int, sampler: str, max_depth: int) -> SceneDescription:
    """The description of ``spec`` rendered with these settings (no Mitsuba)."""
    objects = []
    for obj in spec.objects:
        with located(obj, f"object {obj.name!r}"):  # asset errors name the spec's file:line
            objects.append(describe_object(obj))
    moving = any(o.moves_in_exposure or is_animated(o.spec) for o in objects)
    sequence = getattr(spec, "sequence", None)
    animated = any(is_animated(o.spec) for o in objects)
    timeline = Timeline(spec) if any(moves_within_frame(o.spec) for o in objects) else None  # animated ones too
    return SceneDescription(
        objects=tuple(objects), lights=tuple(spec.lights),
        cameras={name: cs.to_camera() for name, cs in spec.cameras.items()},
        optics={name: cs.optics for name, cs in spec.cameras.items()},
        timeline=timeline,
        rest_time_s=float(sequence.timestamps_s[0]) if animated else None,
        motion_subframes=spec.render.motion_subframes if moving else 1,
        spp=int(spp), sampler=sampler, max_depth=int(max_depth), spec_sha256=spec_sha256(spec),
        projectors=dict(spec.sensors.get("projector", {})))

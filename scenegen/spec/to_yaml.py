"""A spec as YAML text: the inverse of the parser, so that a spec built in Python (the same frozen
dataclasses :func:`scenegen.spec.load_spec` returns) is validated by the same code as a file.

``parse_spec(to_yaml(spec))`` is the same spec (:func:`same_spec`: equal resolved form,
:func:`scenegen.spec.serialize.spec_to_dict`, so the same hash and the same dataset bytes).
Every value is written explicitly (derived seeds too), floats as their shortest round-trip text;
rigid transforms as 4x4 ``matrix`` rows (bit-exact; the parser accepts ``matrix`` wherever it
accepts translation + rotation). :func:`check_spec` runs the YAML validation on a spec built in
code and names the field of a bad value (``<python>: objects[0].shape.radius: expected ...``).
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from scenegen.errors import PYTHON_FILE, SpecError
from scenegen.geometry.conventions import mesh_up_axis
from scenegen.imaging import ImagingParams
from scenegen.spec import model as m
from scenegen.spec.load import parse_spec
from scenegen.spec.parse.annotation import annotation_to_yaml
from scenegen.spec.parse.fields import plain_value, write_fields
from scenegen.spec.parse.imaging import BLOCKS
from scenegen.spec.parse.optics import OPTICS_KEYS
from scenegen.spec.sensors import SENSOR_KINDS, section_kinds
from scenegen.spec.serialize import spec_to_dict


__all__ = ["PYTHON_FILE", "check_spec", "same_spec", "spec_to_yaml_dict", "to_yaml"]


_v = plain_value  # tuples as lists, numpy scalars as Python numbers


def _matrix(pose) -> dict:
    """A pose as the transform keys: ``translation`` alone when there is no rotation, else the
    4x4 ``matrix`` (both bit-exact)."""
    if (pose.R == np.eye(3)).all():
        return {"translation": _v(pose.t)}
    return {"matrix": [[float(v) for v in row] for row in pose.matrix]}


def _texture(t: m.Texture) -> dict:
    if t.kind == "image":
        return {"type": "image", "path": t.path_as_written or str(t.path)}
    return {"type": t.kind, "params": _plain(t.params), "seed": t.seed}


def _plain(x):
    if isinstance(x, dict) or hasattr(x, "items"):
        return {str(k): _plain(v) for k, v in x.items()}
    if isinstance(x, (tuple, list)):
        return [_plain(v) for v in x]
    return _v(x)


def _maps(mp: m.SurfaceMaps) -> dict:
    d: dict[str, Any] = {}
    if mp.normal_map is not None:
        d["normal_map"] = _texture(mp.normal_map)
    if mp.bump_map is not None:
        d.update(bump_map=_texture(mp.bump_map), bump_scale=mp.bump_scale)
    if mp.alpha is not None:
        d.update(alpha=_texture(mp.alpha), alpha_cutoff=mp.alpha_cutoff, alpha_blend=mp.alpha_blend)
    return d


def _material(mat) -> dict:
    d: dict[str, Any] = {"type": mat.type}
    pbr = getattr(mat, "pbr_set", None)
    if pbr is not None:  # the set gives the texture and the data maps
        d["pbr_set"] = {"folder": pbr.folder, **write_fields(pbr)}
    elif getattr(mat, "texture", None) is not None:
        d["texture"] = _texture(mat.texture)
    d.update(write_fields(mat))  # `color` is None (left out) when `texture` is given
    if mat.maps is not None:
        d.update(_maps(mat.maps))
    return d


def _geometry(g) -> tuple[str, Any]:
    if isinstance(g, m.Mesh):
        path = g.path_as_written or str(g.path)
        extra = {"up_axis": g.up_axis, **({"scale": g.scale} if g.scale != 1.0 else {})}
        if g.library is not None:
            return "mesh", {"library": g.library.layout, "root": g.library.root, "id": g.library.id, **extra}
        if g.up_axis == mesh_up_axis(Path(path).suffix) and g.scale == 1.0:
            return "mesh", path
        return "mesh", {"path": path, **extra}
    return "target" if g.kind in m.TARGET_KINDS else "shape", {"type": g.kind, **write_fields(g)}


def _object(obj: m.SceneObject, materials) -> dict:
    key, geo = _geometry(obj.geometry)
    d: dict[str, Any] = {"name": obj.name, key: geo,
                         "transform": {**_matrix(obj.transform.world_from_object),
                                       "scale": _v(obj.transform.scale)}}
    mat = obj.material
    named = mat.name is not None and materials.get(mat.name) == mat
    if not getattr(obj.geometry, "own_materials", False):  # no `material:`: the mesh file's own
        d["material"] = mat.name if named else _material(mat)
    d["instance_id"] = obj.instance_id
    if obj.motion is not None:
        d["motion"] = write_fields(obj.motion)
    if obj.annotation is not None:
        d["annotation"] = annotation_to_yaml(obj.annotation)
    if obj.animation is not None:
        d.update(_animation(obj.animation, _v(obj.transform.scale)))
        if obj.animation.trajectory is not None:  # the keyframes place it; `transform` scales only
            d["transform"] = {"scale": _v(obj.transform.scale)}
    return d


def _pose_rows(pose) -> list:
    return [[float(v) for v in row] for row in pose.matrix]


def _trajectory(t: m.TrajectorySpec, frame: str) -> dict:
    """Keyframes as 4x4 rows (bit-exact): ``matrix`` for an object, ``world_from_<frame>`` else."""
    key = "matrix" if frame == "object" else f"world_from_{frame}"
    return {"interpolation": t.interpolation,
            "keyframes": [{"time_s": k.time_s, key: _pose_rows(k.pose)} for k in t.keyframes]}


def _animation(a: m.Animation, scale) -> dict:
    d: dict[str, Any] = {}
    if a.parent is not None:
        d["parent"] = a.parent
    if a.trajectory is not None:
        d["trajectory"] = _trajectory(a.trajectory, "object")
    else:  # a joint or a fixed part: `transform` is its rest placement in the parent frame
        d["transform"] = {"matrix": _pose_rows(a.rest), "scale": scale}
    if a.joint is not None:
        j = a.joint
        key = "angle_deg" if j.type == "revolute" else "offset_m"
        d["joint"] = {"type": j.type, "axis": _v(j.axis), "origin": _v(j.origin), "interpolation": j.interpolation,
                      "keyframes": [{"time_s": k.time_s, key: math.degrees(k.value) if j.type == "revolute"
                                     else k.value} for k in j.keyframes]}
    if a.visible_s is not None:
        d["visible_s"] = _v(a.visible_s)
    return d


def _sequence(q: m.SequenceSpec) -> dict:
    d: dict[str, Any] = ({"fps": q.fps, "frames": q.frames, "start_s": q.start_s} if q.fps is not None
                         else {"timestamps_s": _v(q.timestamps_s)})
    d["flow_steps"] = _v(q.flow_steps)
    if q.tracks is not None:
        d["tracks"] = write_fields(q.tracks)
    return d


def _light(li) -> dict:
    d: dict[str, Any] = {"name": li.name, "type": li.type} if li.name is not None else {"type": li.type}
    d.update(write_fields(li, ("name",)))
    if isinstance(li, m.EnvmapLight):
        d["path"] = li.path_as_written or str(li.path)
    elif isinstance(li, m.AreaLight):
        d["transform"] = _matrix(li.world_from_light)
    return d


def _imaging(p: ImagingParams) -> dict:
    d: dict[str, Any] = {"preset": p.preset} if p.preset is not None else {}
    d.update({block: write_fields(getattr(p, block)) for block in BLOCKS})
    d.update(write_fields(p, ("preset",)))
    d["bayer"] = p.bayer if p.bayer is not None else "none"
    d["white_balance"] = _v(p.white_balance) if p.white_balance is not None else "auto"
    d["raw"] = False if p.raw is None else write_fields(p.raw)
    return d


def _camera(c: m.CameraSpec) -> dict:
    d: dict[str, Any] = {"model": c.model, "size": [c.width, c.height]}
    d.update(write_fields(c, ("fx", "fy") if c.fov_deg is not None else ()))  # fx, fy: from fov_deg
    o = c.optics
    if o is not None:
        for key in OPTICS_KEYS:
            if getattr(o, key) is not None:
                d[key] = write_fields(getattr(o, key))
    if c.imaging is not None:
        d["imaging"] = _imaging(c.imaging)
    return d


def _rig(r: m.Rig) -> dict:
    if r.type == "stereo":
        left, right = r.members
        return {"type": "stereo", "left": left.camera, "right": right.camera, "baseline_m": r.baseline_m,
                "vergence_deg": r.vergence_deg}
    return {"type": "multi", "members": [_member(mb) for mb in r.members]}


def _member(mb: m.RigMember) -> dict:
    sensor_key, pose_key = SENSOR_KINDS[mb.kind].member_keys  # a camera's: camera, rig_from_cam
    return {"kind": mb.kind, sensor_key: mb.sensor, "name": mb.name,
            pose_key: [[float(v) for v in row] for row in mb.rig_from_sensor.matrix], "time_offset_s": mb.time_offset_s}


def _placement(p, frame: str) -> tuple[str, Any]:
    if isinstance(p, m.Orbit):
        return "orbit", write_fields(p)
    if isinstance(p, m.LookAtList):
        return "look_at", [write_fields(e) for e in p.entries]
    if isinstance(p, m.PoseList):
        return "poses", [{f"world_from_{frame}": [[float(v) for v in row] for row in w.matrix]}
                         for w in p.world_from_cam]
    if isinstance(p, m.RandomPoses):
        return "random", {**write_fields(p), "eye_box": write_fields(p, within="eye_box"),
                          "target_box": write_fields(p, within="target_box")}
    if isinstance(p, m.TrajectoryPath):
        return "trajectory", _trajectory(p.trajectory, frame)
    if isinstance(p, m.LinePath):
        return "path", {"line": write_fields(p, within="line"), **write_fields(p)}
    return "path", {"circle": write_fields(p, within="circle"), **write_fields(p)}


def _view_set(vs: m.ViewSet) -> dict:
    d: dict[str, Any] = {}
    if vs.name is not None:
        d["name"] = vs.name
    d.update({"camera": vs.camera} if vs.camera is not None else {"rig": vs.rig})
    key, val = _placement(vs.placement, "rig" if vs.rig else "cam")
    d[key] = val
    if vs.motion is not None:
        d["motion"] = write_fields(vs.motion)
    if vs.lights is not None:
        d["lights"] = {k: float(v) for k, v in vs.lights.items()}
    return d


def _crossview(c) -> dict:
    d: dict[str, Any] = {"pairs": c.pairs if isinstance(c.pairs, str) else [list(p) for p in c.pairs]}
    at_default = c.ir_depth_range_m == type(c).__dataclass_fields__["ir_depth_range_m"].default
    d.update(write_fields(c, ("pairs",) + (("ir_depth_range_m",) if at_default else ())))  # omit_default
    if c.matches is not None:
        d["matches"] = write_fields(c.matches)
    return d


def _variation(v) -> dict:
    d: dict[str, Any] = {"seed": v.seed}
    if v.objects:
        d["objects"] = {}
        for o in v.objects:
            e = write_fields(o)  # yaw_deg, reseed; the boxes below
            if o.position_min is not None:
                e["position"] = {"min": _v(o.position_min), "max": _v(o.position_max)}
            if o.color_min is not None:
                e["color"] = {"min": _v(o.color_min), "max": _v(o.color_max)}
            d["objects"][o.object] = e
    if v.lights:
        d["lights"] = {li.light: write_fields(li) for li in v.lights}
    if v.cameras:
        d["cameras"] = {c.camera: {**write_fields(c, ("dist_jitter",)),
                                   **({"dist_jitter": _v(c.dist_jitter)} if c.dist_jitter else {})}
                        for c in v.cameras}
    if v.views is not None:
        d["views"] = write_fields(v.views)
    return d


def _placement_section(p: m.DropPlacement) -> dict:
    """The drop with its settled poses (4x4 rows, bit-exact): parsed back without the engine."""
    d: dict[str, Any] = {"type": p.type, "objects": list(p.objects), **write_fields(p)}
    if p.region_min is not None:
        d["region"] = {"min": _v(p.region_min), "max": _v(p.region_max)}
    d["poses"] = {name: _pose_rows(pose) for name, pose in p.poses.items()}
    return d


def spec_to_yaml_dict(spec: m.SceneSpec) -> dict:
    """The spec as the plain data its YAML holds (every value explicit)."""
    if spec.variant is not None:
        raise ValueError("a derived variant has no YAML of its own; write the spec it came from")
    d: dict[str, Any] = {"name": spec.name, "description": spec.description, "seed": spec.seed,
                         "render": write_fields(spec.render)}
    if spec.sequence is not None:
        d["sequence"] = _sequence(spec.sequence)
    if spec.materials:
        d["materials"] = {k: _material(v) for k, v in spec.materials.items()}
    if spec.objects:
        d["objects"] = [_object(o, spec.materials) for o in spec.objects]
    if spec.placement is not None:  # a dropped object's pose is the recorded one: its scale only
        for o in d["objects"]:
            if o["name"] in spec.placement.poses:
                o["transform"] = {"scale": o["transform"]["scale"]}
        d["placement"] = _placement_section(spec.placement)
    if spec.lights:
        d["lights"] = [_light(li) for li in spec.lights]
    if spec.cameras:
        d["cameras"] = {k: _camera(c) for k, c in spec.cameras.items()}
    for kind in section_kinds():  # the other sensor kinds' sections, before the rigs naming them
        if sensors := kind.sensors_of(spec):
            d[kind.section] = {k: kind.to_yaml(v) for k, v in sensors.items()}
    if spec.rigs:
        d["rigs"] = {k: _rig(r) for k, r in spec.rigs.items()}
    if spec.view_sets:
        d["views"] = [_view_set(vs) for vs in spec.view_sets]
    if spec.crossview is not None:
        d["crossview"] = _crossview(spec.crossview)
    if spec.variation is not None:
        d["variation"] = _variation(spec.variation)
    if spec.truth is not None:
        d["truth"] = write_fields(spec.truth)
    return d


def to_yaml(spec: m.SceneSpec) -> str:
    """YAML text that :func:`scenegen.spec.parse_spec` (with the spec's ``base_dir``) turns back
    into the same spec."""
    _check_is_spec(spec, "to_yaml")
    return yaml.safe_dump(spec_to_yaml_dict(spec), sort_keys=False, default_flow_style=None, width=100)


def same_spec(a: m.SceneSpec, b: m.SceneSpec) -> bool:
    """Whether two specs are the same scene: equal resolved forms (SceneSpec itself compares by
    identity)."""
    return spec_to_dict(a) == spec_to_dict(b)


def _first_difference(a, b, path: str = "") -> str:
    if isinstance(a, dict) and isinstance(b, dict):
        for k in list(a) + [k for k in b if k not in a]:
            if a.get(k) != b.get(k):
                return _first_difference(a.get(k), b.get(k), f"{path}.{k}" if path else str(k))
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        for i, (x, y) in enumerate(zip(a, b)):
            if x != y:
                return _first_difference(x, y, f"{path}[{i}]")
    return f"{path}: {a!r}, but the spec's rules give {b!r}"


def _check_is_spec(spec, caller: str) -> None:
    if not isinstance(spec, m.SceneSpec):
        raise TypeError(f"{caller}(spec): expected a SceneSpec (from scenegen.api.Scene or load_spec), got "
                        f"{type(spec).__name__} {spec!r:.60}")


def check_spec(spec: m.SceneSpec) -> m.SceneSpec:
    """The spec validated exactly as its YAML would be: the parsed spec (with its ``warnings``),
    or a SpecError naming the field (``<python>: cameras.cam.fx: expected pixels > 0, got -1``).
    A value the parser would derive differently (an object_id that is not the object's position,
    fx given next to fov_deg) is an error naming it too."""
    _check_is_spec(spec, "check_spec")
    try:
        text = to_yaml(spec)
    except (TypeError, ValueError, AttributeError) as e:
        raise SpecError(f"cannot be written as a spec: {e}", file=PYTHON_FILE) from None
    try:
        parsed = parse_spec(text, file=PYTHON_FILE, base_dir=spec.base_dir)
    except SpecError as e:  # the generated YAML's line means nothing to the caller
        raise SpecError(e.message, file=PYTHON_FILE, field=e.field) from None
    mine, theirs = spec_to_dict(spec), spec_to_dict(parsed)
    if mine != theirs:
        raise SpecError(f"inconsistent value: {_first_difference(mine, theirs)}", file=PYTHON_FILE)
    return parsed

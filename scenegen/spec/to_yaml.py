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

import dataclasses
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
from scenegen.spec.parse.imaging import BLOCKS
from scenegen.spec.parse.materials import TYPE_KEYS as MATERIAL_KEYS
from scenegen.spec.sensors import SENSOR_KINDS, section_kinds
from scenegen.spec.serialize import spec_to_dict


__all__ = ["PYTHON_FILE", "check_spec", "same_spec", "spec_to_yaml_dict", "to_yaml"]


def _v(x):
    """Tuples as lists, floats as floats (numpy scalars too)."""
    if isinstance(x, (tuple, list)):
        return [_v(e) for e in x]
    if hasattr(x, "tolist"):
        return x.tolist()
    return x


def _matrix(pose) -> dict:
    """A pose as the transform keys: ``translation`` alone when there is no rotation, else the
    4x4 ``matrix`` (both bit-exact)."""
    if (pose.R == np.eye(3)).all():
        return {"translation": _v(pose.t)}
    return {"matrix": [[float(v) for v in row] for row in pose.matrix]}


def _fields(obj, names) -> dict:
    return {n: _v(getattr(obj, n)) for n in names}


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
    for key in MATERIAL_KEYS[mat.type]:
        if key == "color" and mat.texture is not None or key == "texture" and mat.texture is None:
            continue  # one of the two
        d[key] = _texture(mat.texture) if key == "texture" else _v(getattr(mat, key))
    if mat.maps is not None:
        d.update(_maps(mat.maps))
    return d


def _geometry(g) -> tuple[str, Any]:
    if isinstance(g, m.Mesh):
        path = g.path_as_written or str(g.path)
        if g.up_axis == mesh_up_axis(Path(path).suffix):
            return "mesh", path
        return "mesh", {"path": path, "up_axis": g.up_axis}
    if g.kind in m.TARGET_KINDS:
        names = [f.name for f in dataclasses.fields(g) if f.name != "kind"]
        return "target", {"type": g.kind, **_fields(g, names)}
    names = [f.name for f in dataclasses.fields(g) if f.name != "kind"]
    return "shape", {"type": g.kind, **_fields(g, names)}


def _motion(mo) -> dict:
    return _fields(mo, ("linear_velocity_mps", "angular_velocity_deg_s"))


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
        d["motion"] = _motion(obj.motion)
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
        d["tracks"] = _fields(q.tracks, ("count", "query_frames", "seed"))
    return d


def _light(li) -> dict:
    d: dict[str, Any] = {"name": li.name, "type": li.type} if li.name is not None else {"type": li.type}
    if isinstance(li, m.PointLight):
        d.update(position=_v(li.position), intensity=_v(li.intensity))
    elif isinstance(li, m.ConstantLight):
        d.update(radiance=_v(li.radiance))
    elif isinstance(li, m.EnvmapLight):
        d.update(path=li.path_as_written or str(li.path), scale=li.scale, rotation_z_deg=li.rotation_z_deg)
    elif isinstance(li, m.DirectionalLight):
        d.update(direction_to_light=_v(li.direction_to_light), irradiance=_v(li.irradiance))
    elif isinstance(li, m.SpotLight):
        d.update(position=_v(li.position), target=_v(li.target), intensity=_v(li.intensity),
                 cutoff_deg=li.cutoff_deg, beam_width_deg=li.beam_width_deg)
    else:
        d.update(size=_v(li.size), radiance=_v(li.radiance), transform=_matrix(li.world_from_light))
    return d


def _imaging(p: ImagingParams) -> dict:
    d: dict[str, Any] = {}
    if p.preset is not None:
        d["preset"] = p.preset
    for block, readers in BLOCKS.items():
        part = getattr(p, block)
        d[block] = {k: _v(getattr(part, k)) for k in readers if getattr(part, k) is not None}
    d["bayer"] = p.bayer if p.bayer is not None else "none"
    d["demosaic"] = p.demosaic
    d["white_balance"] = _v(p.white_balance) if p.white_balance is not None else "auto"
    d.update(response=p.response, gamma=p.gamma, bit_depth=p.bit_depth)
    d["raw"] = False if p.raw is None else {f.name: getattr(p.raw, f.name) for f in dataclasses.fields(p.raw)}
    return d


def _camera(c: m.CameraSpec) -> dict:
    d: dict[str, Any] = {"model": c.model, "size": [c.width, c.height]}
    if c.fov_deg is not None:
        d["fov_deg"] = c.fov_deg
    else:
        d.update(fx=c.fx, fy=c.fy)
    d.update(cx=c.cx, cy=c.cy, skew=c.skew, dist=_v(c.dist))
    if c.mask_beyond_fold:
        d["mask_beyond_fold"] = True
    o = c.optics
    if o is not None:
        if o.lens is not None:
            d["lens"] = _fields(o.lens, ("f_number", "focus_distance_m", "pixel_pitch_um"))
        if o.shutter is not None:
            d["shutter"] = _fields(o.shutter, ("exposure_s", "rolling_readout_s"))
        if o.chromatic_aberration is not None:
            d["chromatic_aberration"] = _fields(o.chromatic_aberration, ("red_focal_scale", "blue_focal_scale"))
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
        return "orbit", _fields(p, ("center", "radius_m", "elevations_deg", "count", "start_azimuth_deg"))
    if isinstance(p, m.LookAtList):
        return "look_at", [_fields(e, ("eye", "target", "up")) for e in p.entries]
    if isinstance(p, m.PoseList):
        return "poses", [{f"world_from_{frame}": [[float(v) for v in row] for row in w.matrix]}
                         for w in p.world_from_cam]
    if isinstance(p, m.RandomPoses):
        return "random", {"count": p.count, "seed": p.seed,
                          "eye_box": {"min": _v(p.eye_min), "max": _v(p.eye_max)},
                          "target_box": {"min": _v(p.target_min), "max": _v(p.target_max)},
                          "up": _v(p.up), "min_distance_m": p.min_distance_m}
    if isinstance(p, m.TrajectoryPath):
        return "trajectory", _trajectory(p.trajectory, frame)
    if isinstance(p, m.LinePath):
        return "path", {"line": {"from": _v(p.start), "to": _v(p.end)}, "count": p.count,
                        "target": _v(p.target), "up": _v(p.up)}
    return "path", {"circle": _fields(p, ("center", "radius_m", "height_m", "start_azimuth_deg")),
                    "count": p.count, "target": _v(p.target), "up": _v(p.up)}


def _view_set(vs: m.ViewSet) -> dict:
    d: dict[str, Any] = {}
    if vs.name is not None:
        d["name"] = vs.name
    d.update({"camera": vs.camera} if vs.camera is not None else {"rig": vs.rig})
    key, val = _placement(vs.placement, "rig" if vs.rig else "cam")
    d[key] = val
    if vs.motion is not None:
        d["motion"] = _motion(vs.motion)
    if vs.lights is not None:
        d["lights"] = {k: float(v) for k, v in vs.lights.items()}
    return d


def _crossview(c) -> dict:
    d: dict[str, Any] = {"pairs": c.pairs if isinstance(c.pairs, str) else [list(p) for p in c.pairs]}
    d.update(flow=c.flow, stereo=c.stereo, sift=c.sift, sift_ratio=c.sift_ratio,
             sift_inlier_px=c.sift_inlier_px, targets=c.targets)
    if c.matches is not None:
        d["matches"] = _fields(c.matches, ("count", "sigma_px", "outlier_fraction", "near_miss_fraction",
                                           "near_miss_px", "seed"))
    return d


def _variation(v) -> dict:
    d: dict[str, Any] = {"seed": v.seed}
    if v.objects:
        d["objects"] = {}
        for o in v.objects:
            e: dict[str, Any] = {"reseed": o.reseed}
            if o.position_min is not None:
                e["position"] = {"min": _v(o.position_min), "max": _v(o.position_max)}
            if o.yaw_deg is not None:
                e["yaw_deg"] = _v(o.yaw_deg)
            if o.color_min is not None:
                e["color"] = {"min": _v(o.color_min), "max": _v(o.color_max)}
            d["objects"][o.object] = e
    if v.lights:
        d["lights"] = {li.light: {"position_jitter_m": li.position_jitter_m,
                                  **({"intensity_scale": _v(li.intensity_scale)} if li.intensity_scale else {})}
                       for li in v.lights}
    if v.cameras:
        d["cameras"] = {c.camera: {"principal_point_px": c.principal_point_px,
                                   **({"focal_scale": _v(c.focal_scale)} if c.focal_scale else {}),
                                   **({"dist_jitter": _v(c.dist_jitter)} if c.dist_jitter else {})}
                        for c in v.cameras}
    if v.views is not None:
        d["views"] = _fields(v.views, ("translation_m", "rotation_deg"))
    return d


def spec_to_yaml_dict(spec: m.SceneSpec) -> dict:
    """The spec as the plain data its YAML holds (every value explicit)."""
    if spec.variant is not None:
        raise ValueError("a derived variant has no YAML of its own; write the spec it came from")
    d: dict[str, Any] = {"name": spec.name, "description": spec.description, "seed": spec.seed,
                         "render": _fields(spec.render, [f.name for f in dataclasses.fields(spec.render)
                                                         if f.name != "where"])}
    if spec.sequence is not None:
        d["sequence"] = _sequence(spec.sequence)
    if spec.materials:
        d["materials"] = {k: _material(v) for k, v in spec.materials.items()}
    if spec.objects:
        d["objects"] = [_object(o, spec.materials) for o in spec.objects]
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
        d["truth"] = {"albedo": spec.truth.albedo, "lights": spec.truth.lights, "defocus": spec.truth.defocus}
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

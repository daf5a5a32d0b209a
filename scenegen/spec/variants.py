"""Scene variants: ``(spec, seed, index) -> SceneSpec``, a pure, deterministic function.

A spec's ``variation:`` section (:mod:`scenegen.spec.model.variation`, parsed by
:mod:`scenegen.spec.parse.variation`) declares ranges; variant
``index`` draws each range from its own random stream, ``SeedSequence([seed, index,
crc32(field path)])``, so one field's draws do not depend on which other fields are declared.
The variant spec is a new frozen :class:`~scenegen.spec.model.SceneSpec`; its ``variant`` field
records the index, the seed and every drawn value, and goes into cameras.json (resolved spec,
key ``variant``) and into the run's hash.

Nothing here imports Mitsuba.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from scenegen.errors import SpecError
from scenegen.geometry import seeds
from scenegen.geometry.pose import Rigid3, look_at
from scenegen.spec import model as m
from scenegen.spec.views import placement_poses, resolve_views

__all__ = ["VARIANT_DIR_FORMAT", "variant_dir_name", "derive_variant", "check_variant"]

#: Folder of variant ``i`` under the output folder of ``--variants``.
VARIANT_DIR_FORMAT = "variant_{:04d}"


def variant_dir_name(index: int) -> str:
    return VARIANT_DIR_FORMAT.format(index)


def _rng(seed: int, index: int, path: str) -> np.random.Generator:
    return seeds.rng(seed, index, path)


def _uniform(rng, lo, hi) -> np.ndarray:
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    return lo + (hi - lo) * rng.random(lo.shape)


def _rot_z(deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _seed32(rng) -> int:
    return int(rng.integers(0, 2**32, dtype=np.uint64))


def _vary_object(obj: m.SceneObject, ov, seed: int, index: int, drawn: dict) -> m.SceneObject:
    d: dict = {}
    path = f"variation.objects.{obj.name}"
    tf = obj.transform
    R, t = tf.world_from_object.R, tf.world_from_object.t
    if ov.position_min is not None:
        t = _uniform(_rng(seed, index, path + ".position"), ov.position_min, ov.position_max)
        d["position"] = t.tolist()
    if ov.yaw_deg is not None:
        yaw = float(_uniform(_rng(seed, index, path + ".yaw_deg"), ov.yaw_deg[0], ov.yaw_deg[1]))
        R = _rot_z(yaw) @ R
        d["yaw_deg"] = yaw
    if d:
        tf = m.Transform(world_from_object=Rigid3(R, t), scale=tf.scale)
    mat, geom = obj.material, obj.geometry
    if ov.color_min is not None:
        col = _uniform(_rng(seed, index, path + ".color"), ov.color_min, ov.color_max)
        mat = dataclasses.replace(mat, color=tuple(float(c) for c in col))
        d["color"] = col.tolist()
    if ov.reseed:
        rng = _rng(seed, index, path + ".reseed")
        tex = getattr(mat, "texture", None)
        if tex is not None and tex.kind in m.PROCEDURAL_TEXTURE_KINDS:
            s = _seed32(rng)
            mat = dataclasses.replace(mat, texture=dataclasses.replace(tex, seed=s))
            d["texture_seed"] = s
        if isinstance(geom, m.Blob):
            s = _seed32(rng)
            geom = dataclasses.replace(geom, seed=s)
            d["blob_seed"] = s
    drawn[obj.name] = d
    return dataclasses.replace(obj, transform=tf, material=mat, geometry=geom)


def _vary_light(light, lv, seed: int, index: int, drawn: dict):
    d: dict = {}
    path = f"variation.lights.{light.name}"
    changes: dict = {}
    if lv.intensity_scale is not None:
        k = float(_uniform(_rng(seed, index, path + ".intensity_scale"), *lv.intensity_scale))
        d["intensity_scale"] = k
        for key in ("radiance", "intensity", "irradiance"):
            if hasattr(light, key):
                changes[key] = tuple(k * float(c) for c in getattr(light, key))
        if isinstance(light, m.EnvmapLight):
            changes["scale"] = k * light.scale
    if lv.position_jitter_m > 0:
        j = lv.position_jitter_m
        off = _uniform(_rng(seed, index, path + ".position"), [-j] * 3, [j] * 3)
        d["position_offset_m"] = off.tolist()
        if isinstance(light, m.AreaLight):
            w = light.world_from_light
            changes["world_from_light"] = Rigid3(w.R, w.t + off)
        else:
            pos = tuple(float(p) for p in np.asarray(light.position) + off)
            changes["position"] = pos
            if isinstance(light, m.SpotLight):
                try:
                    changes["world_from_light"] = look_at(pos, light.target, m.WORLD_UP)
                except ValueError:
                    changes["world_from_light"] = look_at(pos, light.target, (0.0, 1.0, 0.0))
    drawn[light.name] = d
    return dataclasses.replace(light, **changes)


def _vary_camera(cam: m.CameraSpec, cv, seed: int, index: int, drawn: dict) -> m.CameraSpec:
    path = f"variation.cameras.{cam.name}"
    changes: dict = {}
    if cv.focal_scale is not None:
        k = float(_uniform(_rng(seed, index, path + ".focal_scale"), *cv.focal_scale))
        changes.update(fx=k * cam.fx, fy=k * cam.fy, fov_deg=None)  # fov_deg no longer holds
    if cv.principal_point_px > 0:
        j = cv.principal_point_px
        dc = _uniform(_rng(seed, index, path + ".principal_point"), [-j, -j], [j, j])
        changes.update(cx=cam.cx + float(dc[0]), cy=cam.cy + float(dc[1]))
    if cv.dist_jitter:
        j = np.asarray(cv.dist_jitter)
        dd = _uniform(_rng(seed, index, path + ".dist"), -j, j)
        changes["dist"] = tuple(float(a + b) for a, b in zip(cam.dist, dd))
    drawn[cam.name] = {k: (list(v) if isinstance(v, tuple) else v) for k, v in changes.items()
                       if k != "fov_deg"}
    return dataclasses.replace(cam, **changes)


def _jitter_views(spec: m.SceneSpec, pj, seed: int, index: int, drawn: list) -> tuple:
    """Each view set's placements as an explicit pose list, each pose offset in its own frame."""
    out = []
    for k, vs in enumerate(spec.view_sets):
        if isinstance(vs.placement, m.TrajectoryPath):  # a sequence: the keyframes are jittered
            out.append(_jitter_trajectory(vs, pj, seed, index, k, drawn))
            continue
        poses = []
        for j, world_from_x in enumerate(placement_poses(vs)):
            rng = _rng(seed, index, f"variation.views.{k}.{j}")
            t = _uniform(rng, [-pj.translation_m] * 3, [pj.translation_m] * 3)
            axis = rng.normal(size=3)
            axis /= max(np.linalg.norm(axis), 1e-300)
            angle_deg = float(rng.random() * pj.rotation_deg)
            x_from_jittered = Rigid3.from_rotvec(axis * math.radians(angle_deg), t)
            poses.append(world_from_x @ x_from_jittered)
            drawn.append({"view_set": k, "placement": j, "translation_m": t.tolist(),
                          "rotation_axis": axis.tolist(), "rotation_deg": angle_deg})
        out.append(dataclasses.replace(vs, placement=m.PoseList(world_from_cam=tuple(poses))))
    return tuple(out)


def _jitter_trajectory(vs, pj, seed: int, index: int, k: int, drawn: list):
    """A trajectory view set with each keyframe offset in its own frame (as placements are)."""
    traj = vs.placement.trajectory
    keys = []
    for j, kf in enumerate(traj.keyframes):
        rng = _rng(seed, index, f"variation.views.{k}.keyframes.{j}")
        t = _uniform(rng, [-pj.translation_m] * 3, [pj.translation_m] * 3)
        axis = rng.normal(size=3)
        axis /= max(np.linalg.norm(axis), 1e-300)
        angle_deg = float(rng.random() * pj.rotation_deg)
        keys.append(dataclasses.replace(kf, pose=kf.pose @ Rigid3.from_rotvec(axis * math.radians(angle_deg), t)))
        drawn.append({"view_set": k, "keyframe": j, "translation_m": t.tolist(),
                      "rotation_axis": axis.tolist(), "rotation_deg": angle_deg})
    path = dataclasses.replace(vs.placement, trajectory=dataclasses.replace(traj, keyframes=tuple(keys)))
    return dataclasses.replace(vs, placement=path)


def derive_variant(spec: m.SceneSpec, index: int, seed: int | None = None) -> m.SceneSpec:
    """Variant ``index`` of ``spec``: a new frozen SceneSpec (``spec`` is not changed).

    ``seed`` defaults to the spec's ``variation.seed``. The result has ``variant`` = {index, seed,
    objects, lights, cameras, views: the drawn values}, is named ``<name>_variant_<index>`` and
    has passed :func:`check_variant`. Raises SpecError if the spec declares no variation or the
    drawn values make an impossible scene (e.g. a camera whose distortion folds over).
    """
    var = spec.variation
    if var is None:
        raise SpecError(f"{spec.file or spec.name}: --variants needs a 'variation:' section in the spec")
    if isinstance(index, bool) or not isinstance(index, (int, np.integer)) or index < 0:
        raise ValueError(f"variant index must be a non-negative integer, got {index!r}")
    index, seed = int(index), int(var.seed if seed is None else seed)
    drawn: dict = {"index": index, "seed": seed, "objects": {}, "lights": {}, "cameras": {}, "views": []}
    by_obj = {v.object: v for v in var.objects}
    objects = tuple(_vary_object(o, by_obj[o.name], seed, index, drawn["objects"]) if o.name in by_obj else o
                    for o in spec.objects)
    by_light = {v.light: v for v in var.lights}
    lights = tuple(_vary_light(li, by_light[li.name], seed, index, drawn["lights"]) if li.name in by_light
                   else li for li in spec.lights)
    by_cam = {v.camera: v for v in var.cameras}
    cameras = m.frozen_mapping({n: _vary_camera(c, by_cam[n], seed, index, drawn["cameras"]) if n in by_cam
                                else c for n, c in spec.cameras.items()})
    view_sets = spec.view_sets
    if var.views is not None and (var.views.translation_m > 0 or var.views.rotation_deg > 0):
        view_sets = _jitter_views(spec, var.views, seed, index, drawn["views"])
    out = dataclasses.replace(spec, name=f"{spec.name}_variant_{index:04d}", objects=objects, lights=lights,
                              cameras=cameras, view_sets=view_sets, variant=m.frozen_mapping(drawn))
    check_variant(out)
    return out


def check_variant(spec: m.SceneSpec) -> None:
    """Raise SpecError (naming the variant and its section) if a drawn variant is impossible."""
    index = (spec.variant or {}).get("index")
    for name, cam in spec.cameras.items():
        try:
            cam.to_camera()
        except ValueError as e:
            where = next((cv.where for cv in spec.variation.cameras if cv.camera == name), spec.variation.where)
            raise SpecError.at(where, f"variant {index}: camera {name!r} with drawn intrinsics is "
                               f"impossible: {e}; narrow the ranges") from None
    resolve_views(spec)

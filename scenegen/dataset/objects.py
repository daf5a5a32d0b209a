"""Object truth per view as stored (docs/dataset_format.md, "Object truth"), written when the spec
asks (``truth: {objects: true}``) for every object with an ``annotation:``:

* ``truth/<view>_objects.json``: per annotated object its model (``model_id`` numbered 1.. in
  order of first appearance: BOP's obj_id, COCO's category id), ``cam_from_object`` and
  ``world_from_object`` at the view's time, the pose ``world_from_mesh_object`` at which
  ``scene/meshes/<name>.ply`` holds its mesh, its parent in an articulated tree, BOP's
  silhouette statistics as ``calc_gt_info.py`` defines them: ``px_count_all``, the pixels whose
  centre's ray meets the object cast alone over an image 3x as wide and high with the view in its
  middle (BOP's render, so the part beyond the border counts; a distortion model casts only the
  image's own pixels), ``px_count_visib``, the pixels whose object id is the object's,
  ``visib_fract`` their ratio (0 when the silhouette covers none); ``box_obj_xyxy_px`` and
  ``box_visib_xyxy_px``: the inclusive ranges ``[u_min, v_min, u_max, v_max]`` of the OpenCV
  pixel centres of those pixels (the first may lie beyond the image; null when none); its
  keypoints (object frame, projected ``uv_px``, ``depth_z_m``, ``state``), its joint to its
  parent (type, axis, origin, value at the view's time; null without one); and per model its
  diameter and declared symmetries (BOP's ``models_info`` form, metres) and skeleton.
* ``truth/<view>_objects.npz``: ``object_ids`` (N,) uint32 in the JSON's order and
  ``mask_full_bits`` (N, H, ceil(W / 8)) uint8, each object's full (amodal) mask packed along rows
  by ``np.packbits(mask, axis=-1)``; ``np.unpackbits(bits, axis=-1, count=W).astype(bool)``
  unpacks it. The visible mask is ``object_id == id`` of the ids truth.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.geometry.pose import Rigid3

OBJECTS_FORMAT = "scenegen.objects/1"
#: A keypoint's state: seen, hidden by its own object (or another part of its articulated tree),
#: hidden by another object, or not imaged (behind the camera, beyond the model, outside the image).
KEYPOINT_STATES = ("visible", "self_occluded", "occluded", "out_of_image")


@dataclass(frozen=True, eq=False)
class KeypointTruth:
    name: str
    position_object_m: np.ndarray  # (3,) object frame
    uv_px: np.ndarray  # (2,) OpenCV pixel position (NaN when it does not project)
    depth_z_m: float  # camera-frame z (NaN when it does not project)
    state: str  # one of KEYPOINT_STATES


@dataclass(frozen=True, eq=False)
class ObjectTruth:
    """One annotated object in one view (module docstring)."""

    name: str
    object_id: int
    instance_id: int
    model: str
    model_id: int
    parent: str | None  # its parent object in an articulated tree (None: a root)
    present: bool
    cam_from_object: Rigid3
    world_from_object: Rigid3
    world_from_mesh_object: Rigid3  # the pose of scene/meshes/<name>.ply's mesh
    px_count_all: int
    px_count_visib: int
    visib_fract: float
    box_obj_xyxy_px: tuple[int, int, int, int] | None  # the silhouette's pixel centres (extended grid)
    box_visib_xyxy_px: tuple[int, int, int, int] | None  # the visible pixels' centres
    keypoints: tuple[KeypointTruth, ...]
    joint: dict | None = None  # the joint to its parent: {type, axis, origin_m (parent frame),
    # value (radians for revolute, metres for prismatic) at the view's time}; None without one


@dataclass(frozen=True, eq=False)
class ModelInfo:
    """A model's BOP ``models_info`` entry in metres, and its skeleton (keypoint name pairs)."""

    model: str
    model_id: int
    diameter_m: float  # the largest distance between two vertices of its mesh
    symmetries_discrete: tuple[np.ndarray, ...]  # (4, 4) object_from_object, metres
    symmetries_continuous: tuple[dict, ...]  # {"axis": [3], "offset": [3] metres}
    keypoints: tuple[str, ...]  # of the model and its descendants, in the order COCO lists them
    skeleton: tuple[tuple[str, str], ...]


@dataclass(frozen=True, eq=False)
class ViewObjects:
    view: str
    image_size: tuple[int, int]  # (width, height)
    cam_from_world: Rigid3
    models: tuple[ModelInfo, ...]
    objects: tuple[ObjectTruth, ...]
    mask_full: np.ndarray  # (N, H, W) bool in ``objects`` order

    def by_name(self, name: str) -> ObjectTruth:
        for o in self.objects:
            if o.name == name:
                return o
        raise KeyError(f"view {self.view!r} has no object truth of {name!r}")


def _pose(p: Rigid3) -> dict:
    return {"R": p.R.tolist(), "t": p.t.tolist()}


def _num(x: float):
    return None if not np.isfinite(x) else float(x)


def objects_document(v: ViewObjects) -> dict:
    """The JSON document of a view's object truth (masks go to :func:`objects_arrays`)."""
    return {
        "format": OBJECTS_FORMAT, "view": v.view, "image_size": list(v.image_size),
        "cam_from_world": _pose(v.cam_from_world),
        "models": [{"model": m.model, "model_id": m.model_id, "diameter_m": m.diameter_m,
                    "symmetries_discrete": [s.tolist() for s in m.symmetries_discrete],
                    "symmetries_continuous": [dict(c) for c in m.symmetries_continuous],
                    "keypoints": list(m.keypoints), "skeleton": [list(p) for p in m.skeleton]} for m in v.models],
        "objects": [{
            "name": o.name, "object_id": o.object_id, "instance_id": o.instance_id, "model": o.model,
            "model_id": o.model_id, "parent": o.parent, "present": o.present,
            "cam_from_object": _pose(o.cam_from_object), "world_from_object": _pose(o.world_from_object),
            "world_from_mesh_object": _pose(o.world_from_mesh_object),
            "px_count_all": o.px_count_all, "px_count_visib": o.px_count_visib, "visib_fract": o.visib_fract,
            "box_obj_xyxy_px": None if o.box_obj_xyxy_px is None else list(o.box_obj_xyxy_px),
            "box_visib_xyxy_px": None if o.box_visib_xyxy_px is None else list(o.box_visib_xyxy_px),
            "keypoints": [{"name": k.name, "position_object_m": k.position_object_m.tolist(),
                           "uv_px": [_num(x) for x in k.uv_px], "depth_z_m": _num(k.depth_z_m), "state": k.state}
                          for k in o.keypoints],
            "joint": o.joint,
        } for o in v.objects],
    }


def objects_arrays(v: ViewObjects) -> dict[str, np.ndarray]:
    """The NPZ arrays of a view's object truth: ids and packed full masks (module docstring)."""
    W, H = v.image_size
    m = np.asarray(v.mask_full, bool).reshape(len(v.objects), H, W)
    return {"object_ids": np.array([o.object_id for o in v.objects], np.uint32),
            "mask_full_bits": np.packbits(m, axis=-1)}


def _rigid(d, key: str, where: str) -> Rigid3:
    try:
        p = d[key]
        R, t = np.asarray(p["R"], np.float64), np.asarray(p["t"], np.float64)
        if R.shape != (3, 3) or t.shape != (3,) or not (np.isfinite(R).all() and np.isfinite(t).all()):
            raise ValueError
        return Rigid3(R, t)
    except (KeyError, TypeError, ValueError):
        raise ValueError(f"{where}.{key}: expected a pose {{R: 3x3, t: 3}} of finite numbers") from None


def _float_or_nan(x) -> float:
    return float("nan") if x is None else float(x)


def _keypoint(k, where: str) -> KeypointTruth:
    if not isinstance(k, dict) or k.get("state") not in KEYPOINT_STATES or not isinstance(k.get("name"), str):
        raise ValueError(f"{where}: expected a keypoint {{name, position_object_m, uv_px, depth_z_m, state}} "
                         f"with state one of {', '.join(KEYPOINT_STATES)}")
    try:
        pos = np.asarray(k["position_object_m"], np.float64).reshape(3)
        uv = np.array([_float_or_nan(x) for x in k["uv_px"]], np.float64).reshape(2)
        z = _float_or_nan(k["depth_z_m"])
    except (KeyError, TypeError, ValueError):
        raise ValueError(f"{where}: expected position_object_m (3 numbers), uv_px (2), depth_z_m") from None
    return KeypointTruth(k["name"], pos, uv, z, k["state"])


def _box(x, where: str):
    if x is None:
        return None
    if not isinstance(x, list) or len(x) != 4 or not all(isinstance(v, int) and not isinstance(v, bool) for v in x):
        raise ValueError(f"{where}: expected null or a box [u_min, v_min, u_max, v_max] of integers")
    return tuple(x)


def _object(d, where: str) -> ObjectTruth:
    if not isinstance(d, dict):
        raise ValueError(f"{where}: expected a mapping")
    try:
        name, model = str(d["name"]), str(d["model"])
        ints = [int(d[k]) for k in ("object_id", "instance_id", "model_id", "px_count_all", "px_count_visib")]
        present, fract = bool(d["present"]), float(d["visib_fract"])
        parent = d["parent"]
    except (KeyError, TypeError, ValueError):
        raise ValueError(f"{where}: expected name, object_id, instance_id, model, model_id, present, "
                         "px_count_all, px_count_visib, visib_fract, parent") from None
    if not 0.0 <= fract <= 1.0 or min(ints) < 0:
        raise ValueError(f"{where}: expected counts >= 0 and visib_fract in [0, 1]")
    kps = d.get("keypoints")
    if not isinstance(kps, list):
        raise ValueError(f"{where}.keypoints: expected a list")
    return ObjectTruth(name, ints[0], ints[1], model, ints[2], None if parent is None else str(parent), present,
                       _rigid(d, "cam_from_object", where), _rigid(d, "world_from_object", where),
                       _rigid(d, "world_from_mesh_object", where), ints[3], ints[4], fract,
                       _box(d.get("box_obj_xyxy_px"), f"{where}.box_obj_xyxy_px"),
                       _box(d.get("box_visib_xyxy_px"), f"{where}.box_visib_xyxy_px"),
                       tuple(_keypoint(k, f"{where}.keypoints[{i}]") for i, k in enumerate(kps)),
                       _joint(d.get("joint"), f"{where}.joint"))


def _joint(j, where: str) -> dict | None:
    if j is None:
        return None
    try:
        out = {"type": str(j["type"]), "axis": [float(x) for x in j["axis"]],
               "origin_m": [float(x) for x in j["origin_m"]], "value": float(j["value"])}
    except (KeyError, TypeError, ValueError):
        raise ValueError(f"{where}: expected null or {{type, axis, origin_m, value}}") from None
    if len(out["axis"]) != 3 or len(out["origin_m"]) != 3 or not np.isfinite(out["value"]):
        raise ValueError(f"{where}: expected 3-vectors axis, origin_m and a finite value")
    return out


def _model(d, where: str) -> ModelInfo:
    try:
        sd = tuple(np.asarray(s, np.float64).reshape(4, 4) for s in d["symmetries_discrete"])
        sc = tuple({"axis": [float(x) for x in c["axis"]], "offset": [float(x) for x in c["offset"]]}
                   for c in d["symmetries_continuous"])
        return ModelInfo(str(d["model"]), int(d["model_id"]), float(d["diameter_m"]), sd, sc,
                         tuple(str(k) for k in d["keypoints"]), tuple((str(a), str(b)) for a, b in d["skeleton"]))
    except (KeyError, TypeError, ValueError):
        raise ValueError(f"{where}: expected model, model_id, diameter_m, symmetries_discrete (4x4 each), "
                         "symmetries_continuous ({axis, offset}), keypoints, skeleton") from None


def decode_objects(doc, arrays: dict, source: str) -> ViewObjects:
    """The object truth of a parsed document and its NPZ arrays; ValueError naming ``source``."""
    if not isinstance(doc, dict) or doc.get("format") != OBJECTS_FORMAT or not isinstance(doc.get("objects"), list) \
            or not isinstance(doc.get("models"), list):
        raise ValueError(f"{source}: expected a {OBJECTS_FORMAT} document with 'models' and 'objects' lists")
    try:
        W, H = (int(x) for x in doc["image_size"])
    except (KeyError, TypeError, ValueError):
        raise ValueError(f"{source}: image_size: expected [width, height]") from None
    objects = tuple(_object(d, f"{source}: objects[{i}]") for i, d in enumerate(doc["objects"]))
    models = tuple(_model(d, f"{source}: models[{i}]") for i, d in enumerate(doc["models"]))
    ids, bits = arrays["object_ids"], arrays["mask_full_bits"]
    if list(ids) != [o.object_id for o in objects] or bits.shape != (len(objects), H, (W + 7) // 8):
        raise ValueError(f"{source}: the masks' object_ids and shape do not match the document's objects "
                         f"(expected {len(objects)} x {H} x {(W + 7) // 8} packed bytes)")
    masks = np.unpackbits(bits, axis=-1, count=W).astype(bool)
    return ViewObjects(str(doc.get("view")), (W, H), _rigid(doc, "cam_from_world", source), models, objects, masks)

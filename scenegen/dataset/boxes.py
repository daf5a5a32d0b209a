"""Bounding boxes per object as stored (docs/dataset_format.md, "Bounding boxes"):
``truth/<view>_boxes.json``, written when the spec asks (``truth: {boxes: true}``).

For every object of the spec, in spec order: the **visible** 2D box of the pixels the object-id
truth gives it (OpenCV pixel centres ``[u_min, v_min, u_max, v_max]``, inclusive, and the same box
as COCO ``[x, y, w, h]`` in pixel edges: ``scenegen.geometry.conventions.coco_box_of_pixels``), the
**amodal** 2D box (the extent of its mesh's vertices projected through the view's camera model,
distortion included; ``clipped`` and ``truncation``), and its **3D box**: the mesh's axis-aligned
bounds in the object frame (centre, size, 8 corners in the order of
``scenegen.geometry.conventions.BOX_CORNER_SIGNS``), ``world_from_object`` and ``cam_from_object``
at the view's time, and the corners in the world and camera frames. Encode and decode together.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.geometry.conventions import coco_box_of_extent, coco_box_of_pixels
from scenegen.geometry.pose import Rigid3

BOXES_FORMAT = "scenegen.boxes/1"


@dataclass(frozen=True)
class VisibleBox:
    """The pixels of an object in the object-id truth (pixel centres, where the truth is sampled)."""

    pixel_count: int
    box_xyxy_px: tuple[int, int, int, int]  # OpenCV centres of the covered pixels, inclusive

    @property
    def coco_xywh(self) -> list[float]:
        """``[x, y, w, h]``, pixel edges (COCO): ``[u_min, v_min, u_max - u_min + 1, v_max - v_min + 1]``."""
        return coco_box_of_pixels(self.box_xyxy_px)


@dataclass(frozen=True)
class AmodalBox:
    """The extent of an object's projected mesh vertices, occlusion and the image's border ignored."""

    box_xyxy_px: tuple[float, float, float, float] | None  # OpenCV positions; None if no vertex projects
    clipped: bool  # the projection reaches beyond the image (or some vertex does not project)
    truncation: float | None  # fraction of the box's area outside the image [-0.5, W-0.5] x
    # [-0.5, H-0.5]; None when some vertex does not project (behind the camera, beyond the model)
    vertices_projected: int
    vertices_total: int

    @property
    def coco_xywh(self) -> list[float] | None:
        """``[x, y, w, h]``, pixel edges (COCO): ``[u_min + 0.5, v_min + 0.5, u_max - u_min, v_max - v_min]``."""
        return None if self.box_xyxy_px is None else coco_box_of_extent(self.box_xyxy_px)


@dataclass(frozen=True, eq=False)
class Box3D:
    """An object's mesh bounds in its object frame and where they are at the view's time (metres)."""

    center_object_m: np.ndarray  # (3,)
    size_m: np.ndarray  # (3,) extent along the object's x, y, z
    corners_object_m: np.ndarray  # (8, 3), order of conventions.BOX_CORNER_SIGNS
    world_from_object: Rigid3
    cam_from_object: Rigid3
    corners_world_m: np.ndarray  # (8, 3) = world_from_object.apply(corners_object_m)
    corners_cam_m: np.ndarray  # (8, 3) = cam_from_object.apply(corners_object_m), OpenCV axes


@dataclass(frozen=True, eq=False)
class ObjectBoxes:
    """The boxes of one spec object in one view."""

    name: str
    object_id: int  # 1-based index in the spec's objects (the ids truth's object_id)
    instance_id: int
    present: bool  # exists at the view's time (a sequence's visible_s); absent: no 2D boxes
    visible: VisibleBox | None  # None: no pixel centre sees it
    amodal: AmodalBox | None  # None when absent
    box3d: Box3D


@dataclass(frozen=True, eq=False)
class ViewBoxes:
    view: str
    image_size: tuple[int, int]  # (width, height), pixels
    cam_from_world: Rigid3
    objects: tuple[ObjectBoxes, ...]  # spec order

    def by_name(self, name: str) -> ObjectBoxes:
        for o in self.objects:
            if o.name == name:
                return o
        raise KeyError(f"view {self.view!r} has no boxes of an object {name!r}")


def _pose(p: Rigid3) -> dict:
    return {"R": p.R.tolist(), "t": p.t.tolist()}


def boxes_document(boxes: ViewBoxes) -> dict:
    """The JSON document of a view's boxes (for :func:`scenegen.dataset.codecs.encode_json`)."""
    objects = []
    for o in boxes.objects:
        v, a, b = o.visible, o.amodal, o.box3d
        objects.append({
            "name": o.name, "object_id": o.object_id, "instance_id": o.instance_id, "present": o.present,
            "visible": None if v is None else {"pixel_count": v.pixel_count, "box_xyxy_px": list(v.box_xyxy_px),
                                               "coco_xywh": v.coco_xywh},
            "amodal": None if a is None else {
                "box_xyxy_px": None if a.box_xyxy_px is None else list(a.box_xyxy_px), "coco_xywh": a.coco_xywh,
                "clipped": a.clipped, "truncation": a.truncation, "vertices_projected": a.vertices_projected,
                "vertices_total": a.vertices_total},
            "box3d": {"center_object_m": b.center_object_m.tolist(), "size_m": b.size_m.tolist(),
                      "corners_object_m": b.corners_object_m.tolist(),
                      "world_from_object": _pose(b.world_from_object), "cam_from_object": _pose(b.cam_from_object),
                      "corners_world_m": b.corners_world_m.tolist(), "corners_cam_m": b.corners_cam_m.tolist()},
        })
    return {"format": BOXES_FORMAT, "view": boxes.view, "image_size": list(boxes.image_size),
            "cam_from_world": _pose(boxes.cam_from_world), "objects": objects}


def _array(d: dict, key: str, shape: tuple, where: str) -> np.ndarray:
    try:
        a = np.asarray(d[key], dtype=np.float64)
    except (KeyError, TypeError, ValueError):
        raise ValueError(f"{where}.{key}: expected numbers of shape {shape}") from None
    if a.shape != shape or not np.isfinite(a).all():
        raise ValueError(f"{where}.{key}: expected finite numbers of shape {shape}, got shape {a.shape}")
    return a


def _rigid(d: dict, key: str, where: str) -> Rigid3:
    p = d.get(key)
    if not isinstance(p, dict):
        raise ValueError(f"{where}.{key}: expected a pose {{R, t}}")
    try:
        return Rigid3(_array(p, "R", (3, 3), f"{where}.{key}"), _array(p, "t", (3,), f"{where}.{key}"))
    except ValueError as e:
        raise ValueError(str(e) if str(e).startswith(where) else f"{where}.{key}: {e}") from None


def _mapping(d, where: str) -> dict:
    if not isinstance(d, dict):
        raise ValueError(f"{where}: expected a mapping")
    return d


def _int(d: dict, key: str, where: str) -> int:
    x = d.get(key)
    if isinstance(x, bool) or not isinstance(x, int) or x < 0:
        raise ValueError(f"{where}.{key}: expected an integer >= 0, got {x!r}")
    return x


def _decode_object(d, where: str) -> ObjectBoxes:
    d = _mapping(d, where)
    if not isinstance(d.get("name"), str) or not isinstance(d.get("present"), bool):
        raise ValueError(f"{where}: expected 'name' (text) and 'present' (true or false)")
    v = d.get("visible")
    if v is not None:
        v = _mapping(v, f"{where}.visible")
        xyxy = _array(v, "box_xyxy_px", (4,), f"{where}.visible")
        v = VisibleBox(_int(v, "pixel_count", f"{where}.visible"), tuple(int(x) for x in xyxy))
    a = d.get("amodal")
    if a is not None:
        aw = f"{where}.amodal"
        a = _mapping(a, aw)
        xyxy = None if a.get("box_xyxy_px") is None else tuple(float(x) for x in _array(a, "box_xyxy_px", (4,), aw))
        trunc = a.get("truncation")
        if trunc is not None and (isinstance(trunc, bool) or not isinstance(trunc, (int, float)) or not 0 <= trunc <= 1):
            raise ValueError(f"{aw}.truncation: expected null or a number in [0, 1], got {trunc!r}")
        if not isinstance(a.get("clipped"), bool):
            raise ValueError(f"{aw}.clipped: expected true or false")
        a = AmodalBox(xyxy, a["clipped"], None if trunc is None else float(trunc),
                      _int(a, "vertices_projected", aw), _int(a, "vertices_total", aw))
    bw = f"{where}.box3d"
    b = _mapping(d.get("box3d"), bw)
    box = Box3D(_array(b, "center_object_m", (3,), bw), _array(b, "size_m", (3,), bw),
                _array(b, "corners_object_m", (8, 3), bw), _rigid(b, "world_from_object", bw),
                _rigid(b, "cam_from_object", bw), _array(b, "corners_world_m", (8, 3), bw),
                _array(b, "corners_cam_m", (8, 3), bw))
    return ObjectBoxes(d["name"], _int(d, "object_id", where), _int(d, "instance_id", where), d["present"], v, a, box)


def decode_boxes(doc, source: str) -> ViewBoxes:
    """The boxes of a parsed boxes document; ValueError naming ``source`` and the field when it is
    not one."""
    if not isinstance(doc, dict) or doc.get("format") != BOXES_FORMAT or not isinstance(doc.get("objects"), list):
        raise ValueError(f"{source}: expected a {BOXES_FORMAT} document with an 'objects' list")
    size = _array(doc, "image_size", (2,), source)
    objects = tuple(_decode_object(d, f"{source}: objects[{i}]") for i, d in enumerate(doc["objects"]))
    return ViewBoxes(str(doc.get("view")), (int(size[0]), int(size[1])), _rigid(doc, "cam_from_world", source),
                     objects)

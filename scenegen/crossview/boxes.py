"""2D and 3D bounding boxes of the objects in a view, in numpy, from the stored object-id truth
and the objects' meshes (docs/dataset_format.md, "Bounding boxes"; stored by
:mod:`scenegen.dataset.boxes`).

* visible: the pixels whose centre's ray hits the object (the ids truth), as the inclusive range
  of their OpenCV centres, and their count;
* amodal: the extent of the mesh's vertices projected through the camera model (distortion
  included), occlusion ignored; ``truncation`` = 1 - area(box within the image) / area(box), the
  image being [-0.5, W - 0.5] x [-0.5, H - 0.5]. Under a pinhole the extent of a triangle mesh's
  projection is reached at vertices (a projective map keeps lines straight); through distortion an
  edge bends, so the vertices give the extent to within that bending;
* 3D: the mesh's axis-aligned bounds in the object frame and its corners in the object, world
  and camera frames.
"""
from __future__ import annotations

import numpy as np

from scenegen.dataset.boxes import AmodalBox, Box3D, ObjectBoxes, VisibleBox
from scenegen.geometry.conventions import box_corners
from scenegen.geometry.pose import Rigid3


def visible_boxes(object_ids: np.ndarray) -> dict[int, VisibleBox]:
    """{object id: its visible box} of an (H, W) object-id map (0 = nothing, left out)."""
    ids = np.asarray(object_ids)
    if ids.ndim != 2:
        raise ValueError(f"object ids must be an (H, W) map, got shape {ids.shape}")
    v, u = np.nonzero(ids)
    labels = ids[v, u].astype(np.int64)
    out = {}
    if labels.size == 0:
        return out
    order = np.argsort(labels, kind="stable")
    labels, u, v = labels[order], u[order], v[order]
    starts = np.flatnonzero(np.r_[True, labels[1:] != labels[:-1]])
    counts = np.diff(np.r_[starts, labels.size])
    for reduce, arr, key in ((np.minimum, u, "u0"), (np.minimum, v, "v0"), (np.maximum, u, "u1"), (np.maximum, v, "v1")):
        out[key] = reduce.reduceat(arr, starts)
    return {int(labels[s]): VisibleBox(int(n), (int(a), int(b), int(c), int(d)))
            for s, n, a, b, c, d in zip(starts, counts, out["u0"], out["v0"], out["u1"], out["v1"])}


def amodal_box(camera, points_cam: np.ndarray) -> AmodalBox:
    """The extent of camera-frame points (N, 3) projected through ``camera``
    (:class:`scenegen.geometry.camera.Camera`)."""
    uv, ok = camera.project(points_cam, return_valid=True)
    ok &= np.isfinite(uv).all(axis=1)
    n, total = int(ok.sum()), len(points_cam)
    if n == 0:
        return AmodalBox(None, True, None, 0, total)
    lo, hi = uv[ok].min(axis=0), uv[ok].max(axis=0)
    box = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
    W, H = camera.width, camera.height
    inside = lo[0] >= -0.5 and lo[1] >= -0.5 and hi[0] <= W - 0.5 and hi[1] <= H - 0.5
    truncation = None
    if n == total:
        area = float(np.prod(hi - lo))
        w = max(0.0, min(hi[0], W - 0.5) - max(lo[0], -0.5))
        h = max(0.0, min(hi[1], H - 0.5) - max(lo[1], -0.5))
        if area > 0:
            truncation = min(1.0, max(0.0, 1.0 - w * h / area))
        else:  # a degenerate box (a plane seen edge-on): in or out
            truncation = 0.0 if inside else 1.0
    return AmodalBox(box, bool(n < total or not inside), truncation, n, total)


def box3d(vertices_object: np.ndarray, world_from_object: Rigid3, cam_from_world: Rigid3) -> Box3D:
    """The axis-aligned bounds of object-frame vertices (V, 3) and their corners in every frame."""
    lo, hi = vertices_object.min(axis=0), vertices_object.max(axis=0)
    center, size = (lo + hi) / 2.0, hi - lo
    corners = box_corners(center, size)
    cam_from_object = cam_from_world @ world_from_object
    return Box3D(center, size, corners, world_from_object, cam_from_object,
                 world_from_object.apply(corners), cam_from_object.apply(corners))


def object_boxes(name: str, object_id: int, instance_id: int, *, present: bool, vertices_object: np.ndarray,
                 world_from_object: Rigid3, camera, cam_from_world: Rigid3,
                 visible: dict[int, VisibleBox]) -> ObjectBoxes:
    """The boxes of one object in a view: ``vertices_object`` (V, 3) its mesh in the object frame,
    ``world_from_object`` its pose at the view's time, ``visible`` from :func:`visible_boxes`."""
    v = np.asarray(vertices_object, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != 3 or len(v) == 0:
        raise ValueError(f"object {name!r}: vertices must be a non-empty (V, 3) array, got shape {v.shape}")
    b = box3d(v, world_from_object, cam_from_world)
    amodal = amodal_box(camera, b.cam_from_object.apply(v)) if present else None
    return ObjectBoxes(name, int(object_id), int(instance_id), bool(present),
                       visible.get(int(object_id)) if present else None, amodal, b)

"""A view's object truth (``truth: {objects: true}``): every annotated object's pose at the view's
time, its full mask cast alone and its visible mask from the stored ids (BOP's silhouette
statistics), its keypoints projected with their state, and its model's diameter and symmetries
(docs/dataset_format.md, "Object truth"; numpy parts in :mod:`scenegen.crossview.objects`)."""
from __future__ import annotations

import numpy as np

from scenegen.crossview.objects import (diameter, extended_pixels, in_image_block, keypoint_states, mask_box,
                                        silhouette_stats)
from scenegen.dataset.codecs import encode_json
from scenegen.dataset.codecs.npy import encode_npz
from scenegen.dataset.layout import object_masks_path, objects_path
from scenegen.dataset.objects import (KeypointTruth, ModelInfo, ObjectTruth, ViewObjects, objects_arrays,
                                      objects_document)
from scenegen.dataset.truth import TruthKind
from scenegen.errors import SpecError
from scenegen.spec.timeline import object_states


def annotated(spec) -> list:
    """The spec's objects with an ``annotation:``, in spec order."""
    return [o for o in spec.objects if o.annotation is not None]


def model_ids(spec) -> dict[str, int]:
    """{model name: id 1..} in order of first appearance among the annotated objects."""
    ids: dict[str, int] = {}
    for o in annotated(spec):
        ids.setdefault(o.annotation.model, len(ids) + 1)
    return ids


def parent_of(obj) -> str | None:
    return getattr(getattr(obj, "animation", None), "parent", None)


def tree_of(spec, root) -> list:
    """``root`` and its descendants (through ``parent:``), in spec order."""
    names, out = {root.name}, []
    for o in spec.objects:
        if o.name in names or parent_of(o) in names:
            names.add(o.name)
            out.append(o)
    return out


def vertices_object(built, obj) -> np.ndarray:
    """(V, 3) the object's mesh in its object frame (the frame of ``transform``, scale included)."""
    return obj.transform.world_from_object.inverse().apply(np.asarray(built.meshes_world[obj.name].vertices))


def keypoint_positions(built, obj) -> tuple[list[str], np.ndarray]:
    """(names, (K, 3) object-frame positions) of the object's keypoints, vertex picks resolved."""
    kps = obj.annotation.keypoints
    if not kps:
        return [], np.zeros((0, 3))
    verts = None
    pos = []
    for k in kps:
        if k.vertex is None:
            pos.append(k.position_object_m)
            continue
        verts = vertices_object(built, obj) if verts is None else verts
        if k.vertex >= len(verts):
            msg = (f"annotation.keypoints.{k.name}: expected a vertex index below {len(verts)} (the vertices of "
                   f"{obj.name!r}'s mesh), got {k.vertex}")
            raise SpecError.at(obj.where, msg) if obj.where is not None else ValueError(msg)
        pos.append(verts[k.vertex])
    return [k.name for k in kps], np.asarray(pos, np.float64)


def model_infos(spec, built) -> tuple[ModelInfo, ...]:
    """Each model's diameter (from its first instance's mesh), symmetries, keypoints, skeleton."""
    out, seen = [], set()
    ids = model_ids(spec)
    for o in annotated(spec):
        a = o.annotation
        if a.model in seen:
            continue
        seen.add(a.model)
        tree = [x for x in tree_of(spec, o) if x.annotation is not None]
        names = [k.name for x in tree for k in x.annotation.keypoints]
        out.append(ModelInfo(a.model, ids[a.model], diameter(vertices_object(built, o)),
                             tuple(s.matrix for s in a.symmetries_discrete),
                             tuple({"axis": list(c.axis), "offset": list(c.offset_m)} for c in a.symmetries_continuous),
                             tuple(names), a.skeleton))
    return tuple(out)


def root_of(spec, obj):
    """The top of ``obj``'s annotated articulated tree (itself when its parent is not annotated)."""
    root = obj
    while parent_of(root) is not None and spec_object(spec, parent_of(root)).annotation is not None:
        root = spec_object(spec, parent_of(root))
    return root


def view_keypoints(spec, built, view, poses: dict, camera) -> dict[str, tuple[KeypointTruth, ...]]:
    """{object name: its keypoints projected, with their states} of the annotated objects present
    in ``view``; ``poses`` {name: world_from_object} of those present. One cast through the scene
    for all of them, and one per object alone over the keypoints of its tree: an object's own
    articulated tree hides them "by itself"."""
    time_s = getattr(view, "time_s", None)
    centre = view.cam_from_world.inverse().t
    rows = []  # (object, names, (K, 3) object frame)
    for obj in annotated(spec):
        names, X = keypoint_positions(built, obj)
        if names and obj.name in poses:
            rows.append((obj, names, X))
    if not rows:
        return {}
    P = np.concatenate([poses[o.name].apply(X) for o, _, X in rows])
    v = P - centre
    dist = np.linalg.norm(v, axis=1)
    d = v / dist[:, None]
    t_scene = built.first_hit_distance(centre, d, time_s=time_s)
    tree = np.array([root_of(spec, o).name for o, names, _ in rows for _ in names])
    t_self = np.full(len(d), np.inf)
    for root in dict.fromkeys(tree):
        sel = tree == root
        for part in tree_of(spec, spec_object(spec, root)):
            if part.name in poses:
                t_self[sel] = np.minimum(t_self[sel], built.alone_distances(part.object_id, poses[part.name], centre, d[sel]))
    out, k0 = {}, 0
    for obj, names, X in rows:
        k1 = k0 + len(names)
        P_cam = (view.cam_from_world @ poses[obj.name]).apply(X)
        uv, ok = camera.project(P_cam, return_valid=True)
        ok &= np.isfinite(uv).all(axis=1)
        st = keypoint_states(uv, ok, camera.width, camera.height, dist[k0:k1], t_scene[k0:k1], t_self[k0:k1])
        out[obj.name] = tuple(KeypointTruth(n, X[k], np.where(ok[k], uv[k], np.nan),
                                            float(P_cam[k, 2]) if ok[k] else float("nan"), st[k])
                              for k, n in enumerate(names))
        k0 = k1
    return out


def joint_truth(obj, poses_all: dict) -> dict | None:
    """The joint of ``obj`` to its parent at the poses ``poses_all`` {name: world_from_object}:
    type, unit axis and origin (parent frame) and its value, recovered from the poses:
    ``J = parent_from_object @ rest^-1``, a revolute joint's angle about the axis (radians), a
    prismatic joint's shift along it (metres)."""
    a = getattr(obj, "animation", None)
    if a is None or a.joint is None or a.parent is None:
        return None
    axis = np.asarray(a.joint.axis, np.float64)
    axis = axis / np.linalg.norm(axis)
    J = poses_all[a.parent].inverse() @ poses_all[obj.name] @ a.rest.inverse()
    if a.joint.type == "revolute":
        R = J.R
        w = 0.5 * np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
        value = float(np.arctan2(axis @ w, 0.5 * (np.trace(R) - 1.0)))
    else:
        value = float(axis @ J.t)
    return {"type": a.joint.type, "axis": axis.tolist(), "origin_m": [float(x) for x in a.joint.origin],
            "value": value}


def spec_object(spec, name: str):
    for o in spec.objects:
        if o.name == name:
            return o
    raise KeyError(name)


def alone_rays(built, camera, world_from_cam) -> tuple[np.ndarray, np.ndarray]:
    """((3H * 3W, 3) world directions of the extended grid's pixel centres, (3H * 3W,) which have a
    ray): the image's own pixels cast the truth pass's rays; beyond the image only a pinhole's
    rays are cast (a distortion model is not defined there), as BOP renders with K."""
    W, H = camera.width, camera.height
    uv = extended_pixels(W, H)
    d = np.full((len(uv), 3), np.nan)
    inside = ((uv[:, 0] >= 0) & (uv[:, 0] < W) & (uv[:, 1] >= 0) & (uv[:, 1] < H))
    d[inside] = built.camera_rays(camera)
    if camera.model == "pinhole":
        d[~inside] = camera.unproject_unit(uv[~inside])
    d = d @ world_from_cam.R.T
    return d, np.isfinite(d).all(axis=1)


def may_image(camera, cam_from_object, vertices_object) -> np.ndarray:
    """(3H * 3W,) bool: the extended grid's pixels whose rays may meet the mesh: under a pinhole
    with every vertex in front of the camera, those within the box of the projected vertices
    (the projection of a triangle lies within that of its corners) and a pixel's margin; else all."""
    W, H = camera.width, camera.height
    P = cam_from_object.apply(vertices_object)
    if camera.model != "pinhole" or not (P[:, 2] > 0).all():
        return np.ones(9 * W * H, bool)
    uv = camera.project(P)
    lo, hi = np.floor(uv.min(axis=0)) - 1, np.ceil(uv.max(axis=0)) + 1
    g = extended_pixels(W, H)
    return (g[:, 0] >= lo[0]) & (g[:, 0] <= hi[0]) & (g[:, 1] >= lo[1]) & (g[:, 1] <= hi[1])


def view_objects(spec, built, view, truth) -> ViewObjects:
    """The object truth of ``view`` (``truth``: the view's truth as stored)."""
    time_s = getattr(view, "time_s", None)
    states = object_states(spec.objects, time_s) if time_s is not None else None
    camera = built.cameras[view.camera]
    world_from_cam = view.cam_from_world.inverse()
    dirs, ok_rays = alone_rays(built, camera, world_from_cam)
    ids = truth[TruthKind.OBJECT_ID]
    H, W = camera.height, camera.width
    mids = model_ids(spec)
    objects, masks = [], []
    poses = {o.name: o.transform.world_from_object if states is None else states[o.name].world_from_object
             for o in annotated(spec) if states is None or states[o.name].present}
    keypoints = view_keypoints(spec, built, view, poses, camera)
    poses_all = {o.name: o.transform.world_from_object if states is None else states[o.name].world_from_object
                 for o in spec.objects}
    for obj in annotated(spec):
        pose = obj.transform.world_from_object if states is None else states[obj.name].world_from_object
        present = obj.name in poses
        visible = ids == obj.object_id
        alone = np.zeros(len(dirs), bool)
        if present:
            cast = ok_rays & may_image(camera, view.cam_from_world @ pose, vertices_object(built, obj))
            alone[cast] = np.isfinite(built.alone_distances(obj.object_id, pose, world_from_cam.t, dirs[cast]))
        alone = alone.reshape(3 * H, 3 * W)
        # a pixel the scene's cast gives the object is covered by it: a grazing ray decided the
        # other way by the float32 rounding of the alone cast still counts (counted in the tests)
        in_image_block(alone, W, H)[visible] = True
        n_all, n_vis, fract = silhouette_stats(alone, visible)
        objects.append(ObjectTruth(
            obj.name, obj.object_id, obj.instance_id, obj.annotation.model, mids[obj.annotation.model],
            parent_of(obj), present, view.cam_from_world @ pose, pose, obj.transform.world_from_object,
            n_all, n_vis, fract, mask_box(alone, (-W, -H)), mask_box(visible), keypoints.get(obj.name, ()),
            joint_truth(obj, poses_all)))
        masks.append(in_image_block(alone, W, H))
    return ViewObjects(view.name, (W, H), view.cam_from_world, model_infos(spec, built), tuple(objects),
                       np.asarray(masks, bool).reshape(len(objects), H, W))


def view_objects_files(spec, built, view, truth) -> dict[str, bytes]:
    """{path: bytes} of ``truth/<view>_objects.json`` and ``_objects.npz``."""
    v = view_objects(spec, built, view, truth)
    return {objects_path(view.name): encode_json(objects_document(v)),
            object_masks_path(view.name): encode_npz(objects_arrays(v))}

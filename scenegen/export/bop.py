"""BOP (docs/bop_datasets_format.md of bop_toolkit, the "BOP-scenewise" layout) from a dataset with
object truth (``truth: {objects: true}``): every view is an image of one test scene ``000000``,
its im_id the view's position in the dataset; every annotated object present in a view is a
ground-truth instance, its gt_id its position among them; models are numbered as the object
truth's ``model_id`` (1.. in order of first appearance). BOP's units: millimetres.

* ``camera.json``: the first view's fx, fy, cx, cy, width, height, depth_scale;
* ``models/obj_<obj_id:06d>.ply``: each model's mesh (its first instance's, taken from
  ``scene/meshes/`` into its object frame), ASCII PLY with vertex normals, mm;
* ``models/models_info.json``: per obj_id the diameter (largest vertex distance), min_x/y/z,
  size_x/y/z, and the declared ``symmetries_discrete`` (4x4 row-wise, translation mm) and
  ``symmetries_continuous`` ({axis, offset mm}) where declared;
* ``test/000000/scene_camera.json``: per im_id ``cam_K`` (row-wise), ``depth_scale``,
  ``cam_R_w2c``, ``cam_t_w2c`` (mm);
* ``test/000000/scene_gt.json``: per im_id a list of {obj_id, cam_R_m2c (row-wise), cam_t_m2c (mm)};
* ``test/000000/scene_gt_info.json``: per im_id and gt_id px_count_all, px_count_valid,
  px_count_visib, visib_fract, bbox_obj, bbox_visib as ``scripts/calc_gt_info.py`` writes them
  (a box is ``[x, y, x_max - x, y_max - y]`` of the pixels, ``misc.calc_2d_bbox``; all -1 when no
  pixel is visible); the silhouette counted over an image 3x as large, as BOP renders it;
* ``test/000000/rgb/<im_id:06d>.png``, ``depth/<im_id:06d>.png`` (uint16 z-depth / depth_scale mm,
  0 = no surface), ``mask/`` and ``mask_visib/<im_id:06d>_<gt_id:06d>.png`` (uint8, 255 inside);
* ``test_targets_bop19.json``: {scene_id, im_id, obj_id, inst_count} of the instances with
  visib_fract >= 0.1, as ``scripts/enumerate_test_targets.py`` lists them.

BOP's ``cam_K`` is a pinhole: views of other camera models are refused.
"""
from __future__ import annotations

import numpy as np
import trimesh
from trimesh.exchange.ply import export_ply

from scenegen.dataset import DatasetError
from scenegen.dataset.codecs import encode_json, encode_png
from scenegen.dataset.truth import TruthKind
from scenegen.export.common import depth_png16, name, write
from scenegen.export.errors import ExportError
from scenegen.geometry.color import to_uint8

MM_PER_M = 1000.0
SCENE_ID = 0
SPLIT = "test"
#: mm per depth unit: 0.1 mm (as YCB-V, T-LESS), 6.5535 m of range; 1 mm when the scene is deeper
DEPTH_SCALES = (0.1, 1.0)
#: enumerate_test_targets.py's min_visib_fract
MIN_VISIB_FRACT = 0.1


def bop_box(box_xyxy) -> list[int]:
    """BOP's box ``[x, y, w, h]`` = ``misc.calc_2d_bbox`` of pixels spanning ``[u0, v0, u1, v1]``
    (``w = u1 - u0``: not the pixel count), ``[-1, -1, -1, -1]`` for none."""
    if box_xyxy is None:
        return [-1, -1, -1, -1]
    u0, v0, u1, v1 = box_xyxy
    return [int(u0), int(v0), int(u1 - u0), int(v1 - v0)]


def _views(ds) -> list:
    out = []
    for v in ds.views:
        try:
            objs = ds.object_truth(v)
        except DatasetError as e:
            raise ExportError(str(e)) from None
        if objs is None:
            raise ExportError(f"{ds.root}: view {v!r} has no object truth; BOP needs `truth: {{objects: true}}` "
                              "and objects with an `annotation:` in the spec")
        camera, _ = ds.camera(v)
        if camera.model != "pinhole":
            raise ExportError(f"view {v!r}: BOP's cam_K is a pinhole camera; this view's camera is {camera.model!r}")
        out.append((v, objs, camera))
    return out


def _depth_scale(ds, views) -> float:
    deepest = max((float(np.nanmax(np.where(t[TruthKind.VALID], t[TruthKind.DEPTH_Z], np.nan)))
                   for t in (ds.truth(v) for v, _, _ in views) if t[TruthKind.VALID].any()), default=0.0)
    for s in DEPTH_SCALES:
        if deepest * MM_PER_M / s <= 65535:
            return s
    return DEPTH_SCALES[-1]


def _model(ds, obj) -> trimesh.Trimesh:
    """The object's mesh in its object frame, millimetres."""
    mesh = ds.mesh(obj.name).copy()
    mesh.apply_transform(obj.world_from_mesh_object.inverse().matrix)
    mesh.apply_scale(MM_PER_M)
    return mesh


def _models(ds, dest, views) -> int:
    first, infos = {}, {}
    for _, objs, _ in views:
        for o in objs.objects:
            first.setdefault(o.model_id, o)
        for m in objs.models:
            infos.setdefault(m.model_id, m)
    info = {}
    for mid in sorted(first):
        mesh = _model(ds, first[mid])
        lo, hi = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
        m = infos[mid]
        entry = {"diameter": m.diameter_m * MM_PER_M, "min_x": lo[0], "min_y": lo[1], "min_z": lo[2],
                 "size_x": hi[0] - lo[0], "size_y": hi[1] - lo[1], "size_z": hi[2] - lo[2]}
        if m.symmetries_discrete:
            entry["symmetries_discrete"] = [_mm_4x4(s) for s in m.symmetries_discrete]
        if m.symmetries_continuous:
            entry["symmetries_continuous"] = [{"axis": list(c["axis"]), "offset": [x * MM_PER_M for x in c["offset"]]}
                                              for c in m.symmetries_continuous]
        info[str(mid)] = {k: (float(v) if isinstance(v, (float, np.floating)) else v) for k, v in entry.items()}
        write(dest, f"models/obj_{mid:06d}.ply", export_ply(mesh, encoding="ascii", vertex_normal=True))
    write(dest, "models/models_info.json", encode_json(info))
    return len(first) + 1


def _mm_4x4(s: np.ndarray) -> list[float]:
    T = np.array(s, np.float64)
    T[:3, 3] *= MM_PER_M
    return [float(x) for x in T.reshape(-1)]


def export(ds, dest, progress=None) -> dict:
    views = _views(ds)
    scale = _depth_scale(ds, views)
    scene = f"{SPLIT}/{SCENE_ID:06d}"
    n = _models(ds, dest, views)
    cams, gts, infos, targets = {}, {}, {}, []
    too_far = 0
    for im_id, (v, objs, camera) in enumerate(views):
        name("view", v)
        _, cam_from_world = ds.camera(v)
        truth = ds.truth(v)
        d16, far = depth_png16(truth[TruthKind.DEPTH_Z], truth[TruthKind.VALID], MM_PER_M / scale)
        too_far += far
        write(dest, f"{scene}/rgb/{im_id:06d}.png", encode_png(to_uint8(ds.image(v))))
        write(dest, f"{scene}/depth/{im_id:06d}.png", encode_png(d16))
        cams[str(im_id)] = {"cam_K": [float(x) for x in camera.K.reshape(-1)], "depth_scale": scale,
                            "cam_R_w2c": [float(x) for x in cam_from_world.R.reshape(-1)],
                            "cam_t_w2c": [float(x) * MM_PER_M for x in cam_from_world.t]}
        ids = truth[TruthKind.OBJECT_ID]
        gt_list, info_list, counts = [], [], {}
        for k, o in enumerate(objs.objects):
            if not o.present:
                continue
            gt_id = len(gt_list)
            full, visib = objs.mask_full[k], ids == o.object_id
            gt_list.append({"obj_id": o.model_id, "cam_R_m2c": [float(x) for x in o.cam_from_object.R.reshape(-1)],
                            "cam_t_m2c": [float(x) * MM_PER_M for x in o.cam_from_object.t]})
            seen = o.px_count_visib > 0  # calc_gt_info.py leaves both boxes at -1 otherwise
            info_list.append({"px_count_all": o.px_count_all, "px_count_valid": int(np.count_nonzero(full & (d16 > 0))),
                              "px_count_visib": o.px_count_visib, "visib_fract": o.visib_fract,
                              "bbox_obj": bop_box(o.box_obj_xyxy_px if seen else None),
                              "bbox_visib": bop_box(o.box_visib_xyxy_px if seen else None)})
            write(dest, f"{scene}/mask/{im_id:06d}_{gt_id:06d}.png", encode_png(np.where(full, 255, 0).astype(np.uint8)))
            write(dest, f"{scene}/mask_visib/{im_id:06d}_{gt_id:06d}.png",
                  encode_png(np.where(visib, 255, 0).astype(np.uint8)))
            if o.visib_fract >= MIN_VISIB_FRACT:
                counts[o.model_id] = counts.get(o.model_id, 0) + 1
        gts[str(im_id)], infos[str(im_id)] = gt_list, info_list
        targets += [{"im_id": im_id, "inst_count": c, "obj_id": mid, "scene_id": SCENE_ID} for mid, c in counts.items()]
        n += 2 + 2 * len(gt_list)
        if progress is not None:
            progress(im_id + 1, len(views))
    write(dest, f"{scene}/scene_camera.json", encode_json(cams))
    write(dest, f"{scene}/scene_gt.json", encode_json(gts))
    write(dest, f"{scene}/scene_gt_info.json", encode_json(infos))
    write(dest, "test_targets_bop19.json", encode_json(targets))
    cam0 = views[0][2]
    K = cam0.K
    write(dest, "camera.json", encode_json({"cx": float(K[0, 2]), "cy": float(K[1, 2]), "depth_scale": scale,
                                            "fx": float(K[0, 0]), "fy": float(K[1, 1]),
                                            "height": cam0.height, "width": cam0.width}))
    return {"files": n + 5, "images": len(views), "instances": sum(len(g) for g in gts.values()),
            "models": len(set(o.model_id for _, objs, _ in views for o in objs.objects)), "depth_scale_mm": scale,
            "depth_beyond_range": too_far}

"""COCO (cocodataset.org/#format-data: "Object Detection" and "Keypoint Detection") from a dataset
with object truth (``truth: {objects: true}``): ``images/<image id:06d>.png`` and
``annotations.json`` with ``images``, ``categories`` and ``annotations``.

* An image per view, ids 1.. in the dataset's view order.
* A category per model of an instance's root (id = the object truth's ``model_id``, name = the
  model; the parts of an articulated figure are not categories of their own); a model whose
  instances (or their parts) carry keypoints lists their names as ``keypoints`` and its
  ``skeleton`` as 1-based index pairs into them.
* An annotation per instance seen in the view: an annotated object without an annotated parent,
  together with its annotated descendants (an articulated figure is one instance): the union of
  their visible masks as an uncompressed RLE ``segmentation`` (``{"size": [H, W], "counts": [...]}``,
  runs down the columns starting with the background, what pycocotools' ``frPyObjects`` reads),
  ``area`` its pixel count, ``bbox`` its box ``[x, y, w, h]`` in pixel edges, ``iscrowd`` 0;
  with keypoints, ``keypoints`` ``[x1, y1, v1, ...]`` (pixel edges, ``coco = opencv + 0.5``;
  ``v`` 2 visible, 1 hidden by itself or another object, 0 outside the image with x = y = 0) and
  ``num_keypoints`` (those with v > 0). Instances with no visible pixel are left out, as COCO's
  annotators leave them.
"""
from __future__ import annotations

import numpy as np

from scenegen.dataset import DatasetError
from scenegen.dataset.codecs import encode_json, encode_png
from scenegen.dataset.truth import TruthKind
from scenegen.export.common import write
from scenegen.export.errors import ExportError
from scenegen.geometry.color import to_uint8
from scenegen.geometry.conventions import coco_box_of_pixels, coco_points

#: COCO's keypoint visibility flag of each of our keypoint states.
VISIBILITY = {"visible": 2, "self_occluded": 1, "occluded": 1, "out_of_image": 0}


def rle_counts(mask: np.ndarray) -> list[int]:
    """COCO's uncompressed RLE counts of an (H, W) bool mask: run lengths down the columns
    (Fortran order), the first run the background's (0 when the first pixel is set)."""
    flat = np.asarray(mask, bool).ravel(order="F")
    change = np.flatnonzero(flat[1:] != flat[:-1]) + 1
    bounds = np.r_[0, change, flat.size]
    runs = np.diff(bounds).tolist()
    return ([0] + runs) if flat.size and flat[0] else runs


def _roots(objs) -> list:
    """(root, [members]) of each instance: an object without an annotated parent and its
    annotated descendants, in the truth's order."""
    by_name = {o.name: o for o in objs.objects}
    root_of = {}
    for o in objs.objects:
        r = o
        while r.parent is not None and r.parent in by_name:
            r = by_name[r.parent]
        root_of[o.name] = r.name
    return [(o, [m for m in objs.objects if root_of[m.name] == o.name]) for o in objs.objects if root_of[o.name] == o.name]


def _categories(models) -> list[dict]:
    out = []
    for m in models:
        c = {"id": m.model_id, "name": m.model, "supercategory": "object"}
        if m.keypoints:
            idx = {n: i + 1 for i, n in enumerate(m.keypoints)}
            c["keypoints"] = list(m.keypoints)
            c["skeleton"] = [[idx[a], idx[b]] for a, b in m.skeleton]
        out.append(c)
    return out


def _keypoints(members, names) -> tuple[list[float], int]:
    found = {k.name: k for o in members for k in o.keypoints}
    flat, n = [], 0
    for name in names:
        k = found.get(name)
        v = 0 if k is None else VISIBILITY[k.state]
        if v == 0:
            flat += [0.0, 0.0, 0]
            continue
        x, y = coco_points(k.uv_px[None, :])[0]
        flat += [float(x), float(y), v]
        n += 1
    return flat, n


def export(ds, dest, progress=None) -> dict:
    images, annotations, models, roots = [], [], {}, set()
    for k, view in enumerate(ds.views):
        try:
            objs = ds.object_truth(view)
        except DatasetError as e:
            raise ExportError(str(e)) from None
        if objs is None:
            raise ExportError(f"{ds.root}: view {view!r} has no object truth; COCO needs `truth: {{objects: true}}` "
                              "and objects with an `annotation:` in the spec")
        for m in objs.models:
            models.setdefault(m.model_id, m)
        image_id = k + 1
        W, H = objs.image_size
        file_name = write(dest, f"images/{image_id:06d}.png", encode_png(to_uint8(ds.image(view))))
        images.append({"id": image_id, "file_name": file_name, "width": W, "height": H})
        ids = ds.truth(view)[TruthKind.OBJECT_ID]
        for root, members in _roots(objs):
            roots.add(root.model_id)
            mask = np.isin(ids, [m.object_id for m in members if m.present])
            if not root.present or not mask.any():
                continue
            v, u = np.nonzero(mask)
            ann = {"id": len(annotations) + 1, "image_id": image_id, "category_id": root.model_id,
                   "segmentation": {"size": [H, W], "counts": rle_counts(mask)}, "area": int(mask.sum()),
                   "bbox": coco_box_of_pixels((u.min(), v.min(), u.max(), v.max())), "iscrowd": 0}
            names = models[root.model_id].keypoints
            if names:
                ann["keypoints"], ann["num_keypoints"] = _keypoints(members, names)
            annotations.append(ann)
        if progress is not None:
            progress(k + 1, len(ds.views))
    used = sorted({a["category_id"] for a in annotations} | roots)
    doc = {"info": {"description": f"scenegen dataset {ds.root.name}", "version": "1.0"}, "licenses": [],
           "images": images, "categories": _categories(models[i] for i in used),
           "annotations": annotations}
    write(dest, "annotations.json", encode_json(doc))
    return {"files": len(images) + 1, "images": len(images), "annotations": len(annotations),
            "categories": len(models)}

"""instant-ngp / nerfstudio ``transforms.json`` (+ images/, depth/, masks/), with a split.

* ``transform_matrix``: camera-to-world 4x4 with OpenGL camera axes (x right, y up, z backward),
  from :func:`scenegen.geometry.conventions.opengl_cam_to_world` (the project's one conversion).
* Intrinsics per frame (``fl_x, fl_y, cx, cy, w, h`` and the distortion of ``camera_model``
  OPENCV or OPENCV_FISHEYE); when every view shares one camera they are also given at the top
  level with ``camera_angle_x/_y`` (instant-ngp and the Blender loaders read those). Principal
  point in COLMAP's pixel convention (top-left pixel centre at 0.5): nerfstudio's COLMAP
  conversion copies COLMAP's cx, cy unchanged.
* ``depth_file_path``: ``depth/<view>.png``, uint16 z-depth (along the optical axis) in
  millimetres, 0 = no surface or beyond 65.535 m: nerfstudio's default ``depth_unit_scale_factor``
  of 1e-3 turns it into metres; the same file as instant-ngp's ``depth_path`` with its
  ``integer_depth_scale`` = 0.001 (metres per unit).
* ``mask_path``: ``masks/<view>.png``, the truth's valid mask (uint8 grey, 255 where the pixel
  centre's ray hits a surface, 0 on the background); nerfstudio ignores pixels where it is 0.
* Split: every ``TEST_EVERY``-th view (0, 8, 16, ... in the run's order; none with fewer than 2
  views) is a test view: nerfstudio's ``train_filenames`` / ``val_filenames`` /
  ``test_filenames`` (val = test) in transforms.json, and ``transforms_train.json`` /
  ``transforms_val.json`` / ``transforms_test.json`` with those frames for the Blender-style
  loaders.
* Our world is kept (Z up, metres); no recentring or rescaling is applied (``applied_transform``
  is the identity, nerfstudio's name for it). Every path is relative to the json's folder.
"""
from __future__ import annotations

import json
import math

import numpy as np

from scenegen.dataset.codecs import encode_png
from scenegen.dataset.files import copy_file
from scenegen.dataset.layout import view_paths
from scenegen.dataset.truth import TruthKind
from scenegen.export.common import depth_png16, each, write
from scenegen.export.errors import ExportError
from scenegen.geometry.camera import camera_model
from scenegen.geometry.conventions import colmap_from_opencv_pixels, opengl_cam_to_world

TEST_EVERY = 8
DEPTH_UNITS_PER_M = 1000.0


def intrinsics(cam) -> dict:
    cx, cy = colmap_from_opencv_pixels([cam.cx, cam.cy])
    d = {"fl_x": cam.fx, "fl_y": cam.fy, "cx": float(cx), "cy": float(cy), "w": cam.width, "h": cam.height}
    if cam.skew != 0:
        raise ExportError("NeRF transforms.json has no skew; a camera has skew != 0")
    c = cam.coefficients()
    if camera_model(cam.model).opencv_fisheye:
        d.update(camera_model="OPENCV_FISHEYE", **{k: c[k] for k in ("k1", "k2", "k3", "k4")})
    elif c:  # perspective with distortion: nerfstudio's k1..k4 are the r^2..r^8 terms
        if any(c[k] for k in ("k4", "k5", "k6", "s1", "s2", "s3", "s4")):
            raise ExportError("NeRF transforms.json supports OpenCV's k1, k2, k3, p1, p2 only"
                              " (no rational k4..k6, no thin prism s1..s4)")
        d.update(camera_model="OPENCV", k4=0.0, **{k: c[k] for k in ("k1", "k2", "k3", "p1", "p2")})
    else:
        d.update(camera_model="OPENCV", k1=0.0, k2=0.0, p1=0.0, p2=0.0)
    return d


def split(views) -> dict[str, list[str]]:
    """View names by split: ``test`` every TEST_EVERY-th view (none with fewer than 2), ``train`` the rest."""
    test = [v for k, v in enumerate(views) if len(views) >= 2 and k % TEST_EVERY == 0]
    return {"train": [v for v in views if v not in test], "test": test}


def _json(doc) -> bytes:
    return (json.dumps(doc, indent=2, sort_keys=True) + "\n").encode()


def export(ds, dest, progress=None) -> dict:
    frames, all_intr, too_far = [], [], 0
    (dest / "images").mkdir(exist_ok=True)
    for v in each(ds.views, progress):
        cam, pose = ds.camera(v)
        intr = intrinsics(cam)
        all_intr.append(json.dumps(intr, sort_keys=True))
        truth = ds.truth(v)
        depth, n = depth_png16(truth[TruthKind.DEPTH_Z], truth[TruthKind.VALID], DEPTH_UNITS_PER_M)
        too_far += n
        write(dest, f"depth/{v}.png", encode_png(depth))
        write(dest, f"masks/{v}.png", encode_png(np.where(truth[TruthKind.VALID], 255, 0).astype(np.uint8)))
        frames.append({"file_path": f"images/{v}.png", "depth_file_path": f"depth/{v}.png",
                       "depth_path": f"depth/{v}.png",
                       "mask_path": f"masks/{v}.png", **intr,
                       "transform_matrix": opengl_cam_to_world(pose).tolist()})
        copy_file(ds.path(view_paths(v)["image"]), dest / "images" / f"{v}.png")
    parts = split(list(ds.views))
    shared = {}
    if len(set(all_intr)) == 1:
        shared = json.loads(all_intr[0])
        shared["camera_angle_x"] = 2 * math.atan(0.5 * shared["w"] / shared["fl_x"])
        shared["camera_angle_y"] = 2 * math.atan(0.5 * shared["h"] / shared["fl_y"])
    files = {k: [f"images/{v}.png" for v in parts[k]] for k in parts}
    doc = {"applied_transform": np.eye(4)[:3].tolist(), "frames": frames, **shared,
           "integer_depth_scale": 1.0 / DEPTH_UNITS_PER_M,
           "train_filenames": files["train"], "val_filenames": files["test"], "test_filenames": files["test"]}
    write(dest, "transforms.json", _json(doc))
    by_file = {f["file_path"]: f for f in frames}
    for name, key in (("train", "train"), ("val", "test"), ("test", "test")):
        write(dest, f"transforms_{name}.json", _json({**shared, "frames": [by_file[f] for f in files[key]]}))
    return {"files": 4 + 3 * len(frames), "frames": len(frames), "train": len(files["train"]),
            "test": len(files["test"]), "depth_beyond_range": too_far}

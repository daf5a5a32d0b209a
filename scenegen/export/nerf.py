"""instant-ngp / nerfstudio ``transforms.json`` (+ images/).

* ``transform_matrix``: camera-to-world 4x4 with OpenGL camera axes (x right, y up, z backward),
  from :func:`scenegen.geometry.conventions.opengl_cam_to_world` (the project's one conversion).
* Intrinsics per frame (``fl_x, fl_y, cx, cy, w, h`` and the distortion of ``camera_model``
  OPENCV or OPENCV_FISHEYE); when every view shares one camera they are also given at the top
  level (instant-ngp reads those). Principal point in COLMAP's pixel convention (top-left pixel
  centre at 0.5): nerfstudio's COLMAP conversion copies COLMAP's cx, cy unchanged.
* Our world is kept (Z up, metres); no recentring or rescaling is applied (``applied_transform``
  is the identity, nerfstudio's name for it).
"""
from __future__ import annotations

import json

import numpy as np

from scenegen.dataset.files import copy_file
from scenegen.dataset.layout import view_paths
from scenegen.export.common import write
from scenegen.export.errors import ExportError
from scenegen.geometry.camera import camera_model
from scenegen.geometry.conventions import colmap_from_opencv_pixels, opengl_cam_to_world


def intrinsics(cam) -> dict:
    cx, cy = colmap_from_opencv_pixels([cam.cx, cam.cy])
    d = {"fl_x": cam.fx, "fl_y": cam.fy, "cx": float(cx), "cy": float(cy), "w": cam.width, "h": cam.height}
    if cam.skew != 0:
        raise ExportError("NeRF transforms.json has no skew; a camera has skew != 0")
    c = cam.coefficients()
    if camera_model(cam.model).opencv_fisheye:
        d.update(camera_model="OPENCV_FISHEYE", **{k: c[k] for k in ("k1", "k2", "k3", "k4")})
    elif c:  # perspective with distortion
        if any(c[k] for k in ("k5", "k6", "s1", "s2", "s3", "s4")):
            raise ExportError("NeRF transforms.json supports k1..k4, p1, p2 only (OpenCV model)")
        d.update(camera_model="OPENCV", **{k: c[k] for k in ("k1", "k2", "k3", "k4", "p1", "p2")})
    else:
        d.update(camera_model="OPENCV", k1=0.0, k2=0.0, p1=0.0, p2=0.0)
    return d


def export(ds, dest) -> dict:
    frames, all_intr = [], []
    (dest / "images").mkdir(exist_ok=True)
    for v in ds.views:
        cam, pose = ds.camera(v)
        intr = intrinsics(cam)
        all_intr.append(json.dumps(intr, sort_keys=True))
        frames.append({"file_path": f"images/{v}.png", **intr,
                       "transform_matrix": opengl_cam_to_world(pose).tolist()})
        copy_file(ds.path(view_paths(v)["image"]), dest / "images" / f"{v}.png")
    doc = {"applied_transform": np.eye(4)[:3].tolist(), "frames": frames}
    if len(set(all_intr)) == 1:
        doc.update(json.loads(all_intr[0]))
    write(dest, "transforms.json", (json.dumps(doc, indent=2, sort_keys=True) + "\n").encode())
    return {"files": 1 + len(frames), "frames": len(frames)}

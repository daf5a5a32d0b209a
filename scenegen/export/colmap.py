"""COLMAP text model: cameras.txt, images.txt, points3D.txt (+ images/), tracks from truth.

The views' own cameras (PINHOLE / OPENCV / FULL_OPENCV / OPENCV_FISHEYE, shared by the views of
one physical camera) and the rendered images as they are; the model's rules are in
:mod:`scenegen.export.colmap_model`.
"""
from __future__ import annotations

from scenegen.dataset.files import copy_file
from scenegen.dataset.layout import view_paths
from scenegen.export.colmap_model import write_model


def export(ds, dest, progress=None) -> dict:
    cams, poses = {}, {}
    for v in ds.views:
        cams[v], poses[v] = ds.camera(v)
    counts = write_model(ds, dest, "", cams, poses, progress)
    (dest / "images").mkdir(exist_ok=True)
    for v in ds.views:
        copy_file(ds.path(view_paths(v)["image"]), dest / "images" / f"{v}.png")
    return {"files": 3 + len(cams), **counts}

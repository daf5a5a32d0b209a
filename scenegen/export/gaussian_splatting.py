"""3D Gaussian Splatting (graphdeco-inria/gaussian-splatting) scene folder: ``images/`` and
``sparse/0/{cameras,images,points3D}.txt``, as its ``convert.py`` leaves a COLMAP dataset.

Its loader accepts only undistorted PINHOLE / SIMPLE_PINHOLE cameras, so every view gets the
ideal pinhole with the view's own fx, fy, cx, cy and size (skew dropped) and its image is
resampled onto it: for each pinhole pixel centre the ray is projected through the view's real
camera and the rendered image is sampled there bilinearly (``cv2.remap``, INTER_LINEAR; pixels
whose source lies outside the image are black). A view that is already a pinhole without skew
keeps its image byte for byte. The sparse model's cameras (shared by the views of one physical
camera), poses and truth tracks follow :mod:`scenegen.export.colmap_model`, with observations
projected through the pinhole cameras.
"""
from __future__ import annotations

import cv2
import numpy as np

from scenegen.dataset.codecs import encode_png
from scenegen.dataset.files import copy_file
from scenegen.dataset.layout import view_paths
from scenegen.export.colmap_model import write_model
from scenegen.export.common import each, write
from scenegen.geometry.camera import Camera


def pinhole_of(cam: Camera) -> Camera:
    """The undistorted PINHOLE camera a view is resampled onto (same fx, fy, cx, cy, size)."""
    return Camera("pinhole", cam.width, cam.height, cam.fx, cam.fy, cam.cx, cam.cy)


def undistortion_map(cam: Camera, pin: Camera) -> np.ndarray:
    """(H, W, 2) float32: the pixel of ``cam`` that sees the ray of each pixel centre of ``pin``
    (NaN replaced by -1: outside)."""
    v, u = np.mgrid[0:pin.height, 0:pin.width].astype(np.float64)
    rays = pin.unproject(np.stack([u.ravel(), v.ravel()], 1))
    uv = cam.project(rays).reshape(pin.height, pin.width, 2)
    return np.where(np.isfinite(uv), uv, -1.0).astype(np.float32)


def undistorted_image(image: np.ndarray, cam: Camera, pin: Camera) -> np.ndarray:
    m = undistortion_map(cam, pin)
    return cv2.remap(image, m[..., 0], m[..., 1], cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=0)


def export(ds, dest, progress=None) -> dict:
    cams, poses, resampled = {}, {}, 0
    (dest / "images").mkdir(exist_ok=True)
    for v in each(ds.views, progress):
        cam, poses[v] = ds.camera(v)
        cams[v] = pin = pinhole_of(cam)
        if pin == cam:
            copy_file(ds.path(view_paths(v)["image"]), dest / "images" / f"{v}.png")
        else:
            write(dest, f"images/{v}.png", encode_png(undistorted_image(ds.image(v), cam, pin)))
            resampled += 1
    counts = write_model(ds, dest, "sparse/0", cams, poses)
    return {"files": 3 + len(cams), "undistorted": resampled, **counts}

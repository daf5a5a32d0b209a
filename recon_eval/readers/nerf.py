"""NeRF / instant-ngp / nerfstudio ``transforms.json``.

Each frame's ``transform_matrix`` is a 4x4 camera-to-world with OpenGL camera axes (+x right,
+y up, +z backward); it is converted to OpenCV ``cam_from_world`` by the project's one conversion,
:func:`scenegen.geometry.conventions.cam_from_world_from_opengl`. Frames are named by the stem of their
``file_path`` (``images/cam0_000.png`` -> ``cam0_000``; instant-ngp often omits the extension), so
they match our datasets' view names and COLMAP image names without directories.

Intrinsics (top level, or per frame where nerfstudio allows it): ``fl_x``/``fl_y`` (else from
``camera_angle_x``/``camera_angle_y``), ``cx``/``cy`` (default ``w/2``, ``h/2``), ``w``/``h``,
``k1 k2 k3 k4 p1 p2`` and ``camera_model`` (``OPENCV`` default, ``OPENCV_FISHEYE``). NeRF codes
cast rays through ``pixel + 0.5`` (COLMAP's pixel convention, and colmap2nerf copies COLMAP's
cx, cy), so the principal point is moved to OpenCV pixels by
:func:`scenegen.geometry.conventions.opencv_from_colmap_pixels` (``cx - 0.5``).

nerfstudio records the transform it applied to the poses (``applied_transform``, 3x4, to the
stored world from the original one); it is returned as read, not undone.
instant-ngp's ``scale``/``offset`` act inside its loader, not on the stored matrices.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

import numpy as np

from recon_eval.errors import InputError
from recon_eval.metrics.poses import Poses
from recon_eval.readers.text import json_document, read_text
from scenegen.geometry.camera import Camera, camera_model
from scenegen.geometry.camera.interop import COLMAP_MODELS
from scenegen.geometry.conventions import (cam_from_world_from_opengl, colmap_from_opencv_pixels,
                                           opencv_from_colmap_pixels, opengl_cam_to_world)
from scenegen.geometry.pose import Rigid3

#: transforms.json ``camera_model`` values (COLMAP's names) this reader converts.
NERF_CAMERA_MODELS = ("OPENCV", "OPENCV_FISHEYE", "PINHOLE", "SIMPLE_PINHOLE")


@dataclass(frozen=True)
class NerfTransforms:
    poses: Poses  # cam_from_world (OpenCV axes), named by file_path stem
    cameras: dict  # name -> scenegen.geometry.camera.Camera (None when the file gives no intrinsics)
    file_paths: tuple  # as written in the file, same order as poses
    applied_transform: np.ndarray | None  # (3, 4) nerfstudio applied_transform, or None


_INTRINSIC_KEYS = ("fl_x", "fl_y", "camera_angle_x", "camera_angle_y", "cx", "cy", "w", "h",
                   "k1", "k2", "k3", "k4", "p1", "p2", "camera_model")


def _camera(fields: dict, where: str):
    if "w" not in fields or "h" not in fields:
        return None
    try:
        w, h = int(fields["w"]), int(fields["h"])
        if "fl_x" in fields:
            fx = float(fields["fl_x"])
        elif "camera_angle_x" in fields:
            fx = 0.5 * w / math.tan(0.5 * float(fields["camera_angle_x"]))
        else:
            return None
        if "fl_y" in fields:
            fy = float(fields["fl_y"])
        elif "camera_angle_y" in fields:
            fy = 0.5 * h / math.tan(0.5 * float(fields["camera_angle_y"]))
        else:
            fy = fx
        cx, cy = opencv_from_colmap_pixels([float(fields.get("cx", w / 2.0)), float(fields.get("cy", h / 2.0))])
        k = {n: float(fields.get(n, 0.0)) for n in ("k1", "k2", "k3", "k4", "p1", "p2")}
        name = str(fields.get("camera_model", "OPENCV")).upper()
        if name not in NERF_CAMERA_MODELS:
            raise InputError(f"{where}: camera_model {name!r} is not supported (OPENCV, OPENCV_FISHEYE, PINHOLE)")
        if camera_model(COLMAP_MODELS[name]).opencv_fisheye:  # OPENCV_FISHEYE: Kannala-Brandt k1..k4
            return Camera(COLMAP_MODELS[name], w, h, fx, fy, cx, cy, 0.0, (k["k1"], k["k2"], k["k3"], k["k4"]))
        dist = (k["k1"], k["k2"], k["p1"], k["p2"], k["k3"])
        return Camera("opencv" if any(dist) else "pinhole", w, h, fx, fy, cx, cy, 0.0, dist if any(dist) else ())
    except (TypeError, ValueError) as exc:
        raise InputError(f"{where}: bad intrinsics ({exc})") from None


def read_nerf_transforms(path) -> NerfTransforms:
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected a NeRF transforms.json)")
    doc = json_document(read_text(p, "a NeRF transforms.json"), p, "a NeRF transforms.json")
    if not isinstance(doc, dict) or not isinstance(doc.get("frames"), list):
        raise InputError(f"{p}: frames: expected a list of frames with file_path and transform_matrix")
    top = {k: doc[k] for k in _INTRINSIC_KEYS if k in doc}
    names, fpaths, Rs, ts, cams = [], [], [], [], {}
    for i, fr in enumerate(doc["frames"]):
        where = f"{p}: frames[{i}]"
        if not isinstance(fr, dict) or "file_path" not in fr or "transform_matrix" not in fr:
            raise InputError(f"{where}: expected keys file_path and transform_matrix")
        try:
            T = np.asarray(fr["transform_matrix"], dtype=np.float64)
        except (TypeError, ValueError):
            raise InputError(f"{where}.transform_matrix: expected a 4x4 array of numbers") from None
        if T.shape not in ((4, 4), (3, 4)) or not np.all(np.isfinite(T)):
            raise InputError(f"{where}.transform_matrix: expected a finite 4x4 matrix, got shape {T.shape}")
        try:
            pose = cam_from_world_from_opengl(T[:3])
        except ValueError as exc:
            raise InputError(f"{where}.transform_matrix: {exc} (a scaled pose is not a rigid camera)") from None
        name = PurePosixPath(str(fr["file_path"]).replace("\\", "/")).name
        stem = name.rsplit(".", 1)[0] if "." in name else name
        names.append(stem)
        fpaths.append(str(fr["file_path"]))
        Rs.append(pose.R)
        ts.append(pose.t)
        cams[stem] = _camera({**top, **{k: fr[k] for k in _INTRINSIC_KEYS if k in fr}}, where)
    try:
        poses = Poses(tuple(names), np.asarray(Rs).reshape(-1, 3, 3), np.asarray(ts).reshape(-1, 3))
    except InputError as exc:
        raise InputError(f"{p}: frames.file_path: {exc}") from None
    applied = doc.get("applied_transform")
    if applied is not None:
        try:
            applied = np.asarray(applied, dtype=np.float64).reshape(3, 4)
        except (TypeError, ValueError):
            raise InputError(f"{p}: applied_transform: expected a 3x4 matrix") from None
    return NerfTransforms(poses, cams, tuple(fpaths), applied)


def write_nerf_transforms(path, poses: Poses, camera=None, *, extension: str = ".png") -> None:
    """Write ``poses`` (cam_from_world) as transforms.json (OpenGL camera-to-world), file_path
    ``images/<name><extension>``; intrinsics of ``camera`` (scenegen Camera, pinhole/opencv) at
    top level with cx, cy in the NeRF (pixel + 0.5) convention. For tests and exports."""
    doc: dict = {}
    if camera is not None:
        cx, cy = colmap_from_opencv_pixels([camera.cx, camera.cy])
        doc.update(w=camera.width, h=camera.height, fl_x=camera.fx, fl_y=camera.fy, cx=float(cx), cy=float(cy))
        c = camera.coefficients()
        if camera_model(camera.model).opencv_fisheye:
            doc.update(camera_model="OPENCV_FISHEYE", **c)
        else:
            doc.update(camera_model="OPENCV", **{k: c.get(k, 0.0) for k in ("k1", "k2", "p1", "p2", "k3")})
    doc["frames"] = [
        {"file_path": f"images/{n}{extension}",
         "transform_matrix": opengl_cam_to_world(Rigid3(R, t)).tolist()}
        for n, R, t in zip(poses.names, poses.R_cam_from_world, poses.t_cam_from_world)
    ]
    Path(path).write_text(json.dumps(doc, indent=2) + "\n")

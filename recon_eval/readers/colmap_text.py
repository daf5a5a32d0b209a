"""COLMAP text model: cameras.txt, images.txt, points3D.txt (colmap.github.io/format.html).

images.txt stores ``cam_from_world`` as a (QW, QX, QY, QZ) quaternion and (TX, TY, TZ); each image
takes two lines (header, then its 2D points, possibly empty). COLMAP pixel coordinates put the
top-left pixel's centre at (0.5, 0.5); this reader converts principal points to OpenCV's (0, 0)
convention (cx - 0.5, cy - 0.5) for the models with a principal point
(:func:`scenegen.geometry.camera.interop.opencv_params_from_colmap`), and reports the raw
parameters too. Quaternions go through :func:`scenegen.geometry.rotation.matrix_from_quat_wxyz`.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from recon_eval.metrics.poses import Poses
from recon_eval.readers.text import read_text
from scenegen.geometry.camera.interop import opencv_params_from_colmap
from scenegen.geometry.rotation import matrix_from_quat_wxyz


@dataclass(frozen=True)
class ColmapCamera:
    camera_id: int
    model: str
    width: int
    height: int
    params_colmap: tuple  # as in the file (COLMAP pixel convention)
    params_opencv_px: tuple  # principal point shifted by -0.5 to OpenCV pixels


_NO_INT = np.zeros(0, np.int64)


@dataclass(frozen=True)
class ColmapModel:
    cameras: dict  # camera_id -> ColmapCamera
    poses: Poses  # named by image NAME, cam_from_world
    image_camera_ids: tuple  # camera id of each image, order of poses.names
    points_world: np.ndarray  # (P, 3) metres (points3D.txt; empty if the file is absent)
    # the tracks of points3D: one row per track element (observation), COLMAP's order
    track_point: np.ndarray = field(default_factory=lambda: _NO_INT)  # (K,) row of points_world
    track_image: np.ndarray = field(default_factory=lambda: _NO_INT)  # (K,) index into poses
    track_xy_colmap: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))  # (K, 2) its 2D point, COLMAP px


def build_tracks(image_ids, points2d: list, tracks: list):
    """(track_point, track_image, track_xy) from per-image 2D points (lists of (x, y)) and per-point
    tracks (lists of (image_id, point2D_idx)). A track element naming no image 2D point of the
    model (a partial model) is left out: the poses stay readable; the track statistics use the
    elements that resolve."""
    row_of = {iid: k for k, iid in enumerate(image_ids)}
    tp, ti, txy = [], [], []
    for p, track in enumerate(tracks):
        for iid, idx in track:
            k = row_of.get(int(iid))
            if k is None or not 0 <= int(idx) < len(points2d[k]):
                continue
            tp.append(p)
            ti.append(k)
            txy.append(points2d[k][int(idx)])
    return (np.asarray(tp, np.int64), np.asarray(ti, np.int64), np.asarray(txy, np.float64).reshape(-1, 2))


def make_camera(camera_id: int, model: str, width: int, height: int, params) -> ColmapCamera:
    """A :class:`ColmapCamera` with the OpenCV-convention copy of the parameters."""
    params = tuple(float(v) for v in params)
    return ColmapCamera(camera_id, model, width, height, params, opencv_params_from_colmap(model, params))


def rotations_from_quats(qs, where) -> np.ndarray:
    """(N, 3, 3) cam_from_world rotations of (N, 4) (QW, QX, QY, QZ) rows; ``where`` (the file)
    names a non-finite or zero quaternion."""
    try:
        return matrix_from_quat_wxyz(np.asarray(qs, np.float64).reshape(-1, 4))
    except ValueError as exc:
        raise InputError(f"{where}: {exc}") from None


def _lines(path: Path) -> list[str]:
    return [ln.rstrip("\n") for ln in read_text(path, "a COLMAP text model file").splitlines() if not ln.lstrip().startswith("#")]


def read_colmap_text(model_dir) -> ColmapModel:
    d = Path(model_dir)
    if not d.is_dir():
        raise InputError(f"{d}: not a directory (expected a COLMAP text model with cameras.txt, images.txt)")
    for name in ("cameras.txt", "images.txt"):
        if not (d / name).is_file():
            raise InputError(f"{d}: missing {name} (expected a COLMAP text model)")
    cams = {}
    for k, ln in enumerate(_lines(d / "cameras.txt")):
        tok = ln.split()
        if not tok:
            continue
        try:
            cid, model, w, h = int(tok[0]), tok[1], int(tok[2]), int(tok[3])
            params = tuple(float(v) for v in tok[4:])
        except (ValueError, IndexError):
            raise InputError(f"{d / 'cameras.txt'}: bad line {ln!r} (expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS...)") from None
        cams[cid] = make_camera(cid, model, w, h, params)
    names, qs, ts, cids, iids, points2d = [], [], [], [], [], []
    lines = _lines(d / "images.txt")
    i = 0
    while i < len(lines):
        tok = lines[i].split()
        if not tok:
            i += 1
            continue
        if len(tok) < 10:
            raise InputError(f"{d / 'images.txt'}: bad image line {lines[i]!r} (expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME)")
        try:
            q = [float(v) for v in tok[1:5]]
            t = [float(v) for v in tok[5:8]]
            cid = int(tok[8])
        except ValueError:
            raise InputError(f"{d / 'images.txt'}: bad image line {lines[i]!r}") from None
        names.append(" ".join(tok[9:]))
        qs.append(q)
        ts.append(t)
        cids.append(cid)
        iids.append(int(tok[0]))
        p2 = lines[i + 1].split() if i + 1 < len(lines) else []
        try:
            xy = np.asarray([float(v) for v in p2], np.float64).reshape(-1, 3)[:, :2]
        except ValueError:
            raise InputError(f"{d / 'images.txt'}: bad POINTS2D line of image {tok[0]} (expected X Y POINT3D_ID ...)") from None
        points2d.append(xy)
        i += 2  # the POINTS2D line (possibly empty)
    if names and not np.all(np.linalg.norm(np.asarray(qs), axis=1) > 0):
        raise InputError(f"{d / 'images.txt'}: a zero or non-finite quaternion (QW QX QY QZ)")
    R = rotations_from_quats(qs, d / "images.txt")
    try:
        poses = Poses(tuple(names), R, np.asarray(ts, dtype=np.float64).reshape(-1, 3))
    except InputError as exc:
        raise InputError(f"{d / 'images.txt'}: {exc}") from None
    pts = np.zeros((0, 3))
    tracks = []
    if (d / "points3D.txt").is_file():
        rows = []
        for ln in _lines(d / "points3D.txt"):
            tok = ln.split()
            if tok:
                try:
                    rows.append([float(v) for v in tok[1:4]])
                    tracks.append(np.asarray([int(v) for v in tok[8:]], np.int64).reshape(-1, 2))
                except ValueError:
                    raise InputError(f"{d / 'points3D.txt'}: bad line {ln!r}") from None
        pts = np.asarray(rows, dtype=np.float64).reshape(-1, 3)
    return ColmapModel(cams, poses, tuple(cids), pts, *build_tracks(iids, points2d, tracks))

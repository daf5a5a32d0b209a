"""COLMAP binary model: cameras.bin, images.bin, points3D.bin (colmap/src/colmap/scene/
reconstruction_io_binary.cc). Little-endian; the same content as the text model, converted the
same way (see :mod:`recon_eval.readers.colmap_text`)."""
from __future__ import annotations

import struct
from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from recon_eval.metrics.poses import Poses
from recon_eval.readers.colmap_text import ColmapModel, build_tracks, make_camera, rotations_from_quats

#: COLMAP model id -> (name, number of parameters) (colmap/src/colmap/sensor/models.h)
CAMERA_MODELS = {
    0: ("SIMPLE_PINHOLE", 3), 1: ("PINHOLE", 4), 2: ("SIMPLE_RADIAL", 4), 3: ("RADIAL", 5),
    4: ("OPENCV", 8), 5: ("OPENCV_FISHEYE", 8), 6: ("FULL_OPENCV", 12), 7: ("FOV", 5),
    8: ("SIMPLE_RADIAL_FISHEYE", 4), 9: ("RADIAL_FISHEYE", 5), 10: ("THIN_PRISM_FISHEYE", 12),
    11: ("RAD_TAN_THIN_PRISM_FISHEYE", 16),
}


class _Reader:
    """Little-endian struct reads with a truncation check."""

    def __init__(self, path: Path):
        self.path = path
        self.data = path.read_bytes()
        self.pos = 0

    def read(self, fmt: str):
        size = struct.calcsize("<" + fmt)
        if self.pos + size > len(self.data):
            raise InputError(f"{self.path}: truncated COLMAP binary file at byte {self.pos}")
        out = struct.unpack_from("<" + fmt, self.data, self.pos)
        self.pos += size
        return out

    def skip(self, n: int):
        if self.pos + n > len(self.data):
            raise InputError(f"{self.path}: truncated COLMAP binary file at byte {self.pos}")
        self.pos += n

    def cstring(self) -> str:
        end = self.data.find(b"\0", self.pos)
        if end < 0:
            raise InputError(f"{self.path}: unterminated image name")
        s = self.data[self.pos:end].decode("utf-8", errors="replace")
        self.pos = end + 1
        return s


def read_colmap_binary(model_dir) -> ColmapModel:
    d = Path(model_dir)
    for name in ("cameras.bin", "images.bin"):
        if not (d / name).is_file():
            raise InputError(f"{d}: missing {name} (expected a COLMAP binary model)")
    r = _Reader(d / "cameras.bin")
    cams = {}
    for _ in range(r.read("Q")[0]):
        cid, mid, w, h = r.read("iiQQ")
        if mid not in CAMERA_MODELS:
            raise InputError(f"{r.path}: unknown camera model id {mid}")
        name, n = CAMERA_MODELS[mid]
        cams[cid] = make_camera(cid, name, int(w), int(h), r.read(f"{n}d"))
    r = _Reader(d / "images.bin")
    names, qs, ts, cids, iids, points2d = [], [], [], [], [], []
    for _ in range(r.read("Q")[0]):
        vals = r.read("I4d3dI")
        iids.append(vals[0])
        qs.append(vals[1:5])
        ts.append(vals[5:8])
        cids.append(vals[8])
        names.append(r.cstring())
        n2 = r.read("Q")[0]  # points2D: x, y (double), point3D_id (int64)
        points2d.append(np.asarray(r.read("ddq" * n2), np.float64).reshape(-1, 3)[:, :2] if n2 else np.zeros((0, 2)))
    R = rotations_from_quats(qs, d / "images.bin")
    poses = Poses(tuple(names), R, np.asarray(ts, dtype=np.float64).reshape(-1, 3))
    pts = np.zeros((0, 3))
    tracks = []
    if (d / "points3D.bin").is_file():
        r = _Reader(d / "points3D.bin")
        rows = []
        for _ in range(r.read("Q")[0]):
            vals = r.read("Q3d3Bd")
            rows.append(vals[1:4])
            nt = r.read("Q")[0]  # track: image_id, point2D_idx (uint32 each)
            tracks.append(np.asarray(r.read("II" * nt), np.int64).reshape(-1, 2))
        pts = np.asarray(rows, dtype=np.float64).reshape(-1, 3)
    return ColmapModel(cams, poses, tuple(cids), pts, *build_tracks(iids, points2d, tracks))

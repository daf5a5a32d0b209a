"""A LiDAR cloud as rows of points: KITTI velodyne ``.bin`` (float32 x, y, z, reflectance, no
header; ``np.fromfile(path, np.float32).reshape(-1, 4)`` as the KITTI devkit reads it), or a
``.npy`` array (N, 3) or (N, 4) (x, y, z first). Errors name the file."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from recon_eval.readers.npy import read_npy


def read_point_rows(path) -> np.ndarray:
    """(N, 3) float64 x, y, z of a KITTI ``.bin`` or a ``.npy`` cloud."""
    p = Path(path)
    if p.suffix.lower() == ".npy":
        a = read_npy(p)
        if a.ndim != 2 or a.shape[1] not in (3, 4):
            raise InputError(f"{p}: expected an array of shape (N, 3) or (N, 4), got {a.shape}")
        return a[:, :3]
    if p.suffix.lower() != ".bin":
        raise InputError(f"{p}: expected a KITTI velodyne .bin or a .npy point cloud")
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected a KITTI velodyne .bin)")
    data = p.read_bytes()
    if len(data) % 16:
        raise InputError(f"{p}: {len(data)} bytes is not a whole number of KITTI rows (4 float32, 16 bytes)")
    return np.frombuffer(data, "<f4").reshape(-1, 4)[:, :3].astype(np.float64)

"""KITTI 2012/2015 disparity PNGs: uint16 ``round(d * 256)``, 0 = invalid.

Disparities that would not fit (``round(d * 256) > 65535``), round to 0, are negative or not
finite are stored as invalid (0). The PNG itself goes through :mod:`.png`.
"""
from __future__ import annotations

import numpy as np

from scenegen.dataset.codecs.png import decode_png, encode_png

KITTI_SCALE = 256.0


def kitti_disparity_array(disp, valid=None) -> np.ndarray:
    """(H, W) uint16 KITTI disparity values: ``round(d * 256)`` where valid, 0 elsewhere."""
    d = np.asarray(disp, np.float64)
    ok = np.isfinite(d) & (d >= 0)
    if valid is not None:
        ok &= np.asarray(valid, bool)
    q = np.zeros(d.shape, np.float64)
    q[ok] = np.rint(d[ok] * KITTI_SCALE)
    q[(q > 65535) | (q < 1)] = 0
    return q.astype(np.uint16)


def disparity_from_kitti_array(png16) -> tuple[np.ndarray, np.ndarray]:
    """(disparity float64 (H, W), valid bool (H, W)) of uint16 KITTI disparity values."""
    a = np.asarray(png16)
    if a.dtype != np.uint16 or a.ndim != 2:
        raise ValueError(f"KITTI disparity PNGs are single-channel uint16, got {a.dtype} {a.shape}")
    return a.astype(np.float64) / KITTI_SCALE, a > 0


def encode_kitti_disparity(disp, valid=None) -> bytes:
    """PNG bytes of a KITTI disparity map (see :func:`kitti_disparity_array`)."""
    return encode_png(kitti_disparity_array(disp, valid))


def decode_kitti_disparity(data: bytes) -> tuple[np.ndarray, np.ndarray]:
    """(disparity float64 (H, W), valid bool (H, W)) of KITTI disparity PNG bytes."""
    return disparity_from_kitti_array(decode_png(data))

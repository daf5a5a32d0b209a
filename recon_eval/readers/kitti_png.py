"""KITTI 2012/2015 disparity PNGs: uint16, disparity = value / 256, value 0 = invalid.

The reader returns (H, W) float64 pixels with NaN for invalid (recon_eval's missing marker)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.errors import InputError


def read_kitti_disparity(path) -> np.ndarray:
    import cv2  # imported where used

    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected a KITTI uint16 disparity PNG)")
    img = cv2.imread(str(p), cv2.IMREAD_UNCHANGED)
    if img is None:
        raise InputError(f"{p}: cannot decode as PNG")
    if img.dtype != np.uint16 or img.ndim != 2:
        raise InputError(f"{p}: expected a single-channel uint16 PNG (KITTI disparity), got {img.dtype} {img.shape}")
    d = img.astype(np.float64) / 256.0
    d[img == 0] = np.nan
    return d


def write_kitti_disparity(path, disp) -> None:
    """Write (H, W) disparities (pixels, NaN/<=0 = invalid) as KITTI uint16 PNG (round(d*256))."""
    import cv2

    d = np.asarray(disp, dtype=np.float64)
    v = np.where(np.isfinite(d) & (d > 0), np.clip(np.round(d * 256.0), 1, 65535), 0).astype(np.uint16)
    if not cv2.imwrite(str(path), v):
        raise InputError(f"{path}: cannot write PNG")


def read_kitti_obj_map(path) -> np.ndarray:
    """KITTI object map PNG -> (H, W) bool, True = foreground (value > 0)."""
    import cv2

    p = Path(path)
    img = cv2.imread(str(p), cv2.IMREAD_UNCHANGED) if p.is_file() else None
    if img is None or img.ndim != 2:
        raise InputError(f"{p}: expected a single-channel PNG object map")
    return img > 0

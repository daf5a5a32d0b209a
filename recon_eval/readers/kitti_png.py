"""KITTI 2012/2015 disparity PNGs (uint16, disparity = value / 256, value 0 = invalid), through
:mod:`scenegen.dataset.codecs.kitti`; KITTI object maps (any single-channel PNG, > 0 = foreground).

The reader returns (H, W) float64 pixels with NaN for invalid (recon_eval's missing marker)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from recon_eval.readers.native import read_png
from scenegen.dataset.codecs import decode_kitti_disparity, encode_kitti_disparity
from scenegen.dataset.files import atomic_write_bytes


def read_kitti_disparity(path) -> np.ndarray:
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected a KITTI uint16 disparity PNG)")
    try:
        d, valid = decode_kitti_disparity(p.read_bytes())  # quietly (scenegen.quiet)
    except ValueError as exc:  # not a PNG, or not single-channel uint16
        raise InputError(f"{p}: {exc} (expected a KITTI uint16 disparity PNG)") from None
    d[~valid] = np.nan
    return d


def write_kitti_disparity(path, disp) -> None:
    """Write (H, W) disparities (pixels; NaN, negative, or rounding to 0 or above 65535/256 =
    invalid) as a KITTI uint16 PNG, ``round(d * 256)``, atomically. For tests and exports."""
    atomic_write_bytes(path, encode_kitti_disparity(disp))


def read_kitti_obj_map(path) -> np.ndarray:
    """KITTI object map PNG -> (H, W) bool, True = foreground (value > 0)."""
    p = Path(path)
    try:
        img = read_png(p) if p.is_file() else None
    except ValueError:
        img = None
    if img is None or img.ndim != 2:
        raise InputError(f"{p}: expected a single-channel PNG object map")
    return img > 0

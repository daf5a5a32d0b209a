"""KITTI 2012/2015 optical flow PNGs: 16-bit RGB, ``u = (R - 2^15) / 64``, ``v = (G - 2^15) / 64``,
valid where ``B > 0`` (the devkit's ``io_flow.h``: ``readFlowField`` / ``writeFlowField``). The
PNG itself goes through :mod:`.png`."""
from __future__ import annotations

import numpy as np

from scenegen.dataset.codecs.png import decode_png, encode_png

KITTI_FLOW_SCALE = 64.0
KITTI_FLOW_OFFSET = 32768.0


def decode_kitti_flow(img: np.ndarray) -> np.ndarray:
    """(H, W, 2) float64 flow (NaN invalid) of a KITTI flow PNG's (H, W, 3) uint16 RGB values."""
    if img.dtype != np.uint16 or img.ndim != 3 or img.shape[2] != 3:
        raise ValueError(f"KITTI flow PNGs are 16-bit RGB, got {img.dtype} {img.shape}")
    f = (img[..., :2].astype(np.float64) - KITTI_FLOW_OFFSET) / KITTI_FLOW_SCALE
    f[img[..., 2] == 0] = np.nan
    return f


def encode_kitti_flow(flow) -> np.ndarray:
    """(H, W, 3) uint16 RGB of a flow (NaN = invalid), as the devkit's ``writeFlowField``:
    ``max(min(f * 64 + 32768, 65535), 0)`` in float32 (the devkit's float), truncated, blue 1 where
    valid."""
    f = np.asarray(flow, np.float64)
    valid = np.all(np.isfinite(f), axis=2)
    out = np.zeros(f.shape[:2] + (3,), np.uint16)
    f32 = np.where(valid[..., None], f, 0.0).astype(np.float32)
    q = np.clip(f32 * np.float32(KITTI_FLOW_SCALE) + np.float32(KITTI_FLOW_OFFSET), np.float32(0), np.float32(65535))
    out[..., :2] = np.where(valid[..., None], q, 0).astype(np.uint16)
    out[..., 2] = valid
    return out


def encode_kitti_flow_png(flow) -> bytes:
    """The PNG bytes of :func:`encode_kitti_flow`."""
    return encode_png(encode_kitti_flow(flow))


def decode_kitti_flow_png(data: bytes) -> np.ndarray:
    """Inverse of :func:`encode_kitti_flow_png` (to the devkit's 1/64 px)."""
    return decode_kitti_flow(decode_png(data))

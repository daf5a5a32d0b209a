"""PNG: uint8 or uint16, (H, W) grey or (H, W, 3) RGB (OpenCV's BGR order only inside the file
codec). Lossless; a fixed zlib level so the bytes do not follow cv2's defaults.
"""
from __future__ import annotations

import cv2
import numpy as np

from scenegen.dataset.files import atomic_write_bytes, read_decoded
from scenegen.quiet import decode_image

_PNG_COMPRESSION = 3  # zlib level; any level is lossless, fixed so bytes don't follow cv2 defaults


def encode_png(img) -> bytes:
    """PNG bytes of a uint8/uint16 image, (H, W) grey or (H, W, 3) RGB."""
    img = np.asarray(img)
    if img.dtype not in (np.uint8, np.uint16):
        raise TypeError(f"PNG images must be uint8 or uint16, got {img.dtype}")
    if not (img.ndim == 2 or (img.ndim == 3 and img.shape[2] == 3)) or 0 in img.shape:
        raise ValueError(f"PNG images must be (H, W) or (H, W, 3) and non-empty, got {img.shape}")
    if img.ndim == 3:
        img = img[..., ::-1]  # RGB -> BGR for OpenCV
    ok, buf = cv2.imencode(".png", np.ascontiguousarray(img),
                           [cv2.IMWRITE_PNG_COMPRESSION, _PNG_COMPRESSION])
    if not ok:
        raise RuntimeError("cv2.imencode failed to encode the PNG")
    return buf.tobytes()


def decode_png(data: bytes) -> np.ndarray:
    """Inverse of :func:`encode_png`: (H, W) or (H, W, 3) RGB, dtype as stored."""
    img = decode_image(data)
    if img is None:
        raise ValueError("not a readable PNG")
    if img.ndim == 3:
        if img.shape[2] == 3:
            img = cv2.cvtColor(img, cv2.COLOR_BGR2RGB)
        elif img.shape[2] == 4:
            img = cv2.cvtColor(img, cv2.COLOR_BGRA2RGBA)
    return img


def write_png(path, img) -> None:
    """Write a uint8/uint16 (H, W) or (H, W, 3) RGB image as PNG, atomically."""
    atomic_write_bytes(path, encode_png(img))


def read_png(path) -> np.ndarray:
    """Read a PNG: (H, W) grey or (H, W, 3) RGB, dtype (uint8/uint16) as stored."""
    return read_decoded(path, decode_png)

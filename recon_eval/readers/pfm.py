"""Portable Float Map (PFM) disparity/depth, as used by Middlebury and ETH3D.

Header: ``Pf`` (1 channel) or ``PF`` (3 channels), ``W H``, then a scale whose sign gives the byte
order (negative: little-endian). Rows are stored bottom to top. Infinity marks unknown/missing
values; the reader converts inf to NaN (recon_eval's missing marker) unless ``keep_inf``.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.errors import InputError


def read_pfm(path, *, keep_inf: bool = False) -> np.ndarray:
    """(H, W) float64 (or (H, W, 3) for PF), top row first."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected a PFM image)")
    data = p.read_bytes()
    try:
        tokens, pos = [], 0
        while len(tokens) < 4:  # magic, W, H, scale separated by whitespace
            while data[pos : pos + 1].isspace():
                pos += 1
            start = pos
            while not data[pos : pos + 1].isspace():
                pos += 1
            tokens.append(data[start:pos].decode("ascii"))
        pos += 1  # exactly one whitespace byte after the scale
        magic, w, h, scale = tokens[0], int(tokens[1]), int(tokens[2]), float(tokens[3])
    except (ValueError, IndexError, UnicodeDecodeError):
        raise InputError(f"{p}: not a PFM file (expected header 'Pf'/'PF', width, height, scale)") from None
    if magic not in ("Pf", "PF") or w <= 0 or h <= 0 or scale == 0:
        raise InputError(f"{p}: not a PFM file (header {tokens!r})")
    ch = 3 if magic == "PF" else 1
    dtype = "<f4" if scale < 0 else ">f4"
    n = w * h * ch
    if len(data) - pos < 4 * n:
        raise InputError(f"{p}: truncated PFM: expected {4 * n} data bytes for {w}x{h}x{ch}, got {len(data) - pos}")
    arr = np.frombuffer(data, dtype=dtype, count=n, offset=pos).astype(np.float64)
    arr = arr.reshape(h, w, ch)[::-1]
    arr = arr[..., 0] if ch == 1 else arr
    if not keep_inf:
        arr = np.where(np.isinf(arr), np.nan, arr)
    return np.ascontiguousarray(arr)


def write_pfm(path, image) -> None:
    """Write (H, W) or (H, W, 3) as little-endian float32 PFM; NaN is written as inf (missing)."""
    a = np.asarray(image, dtype=np.float64)
    if a.ndim not in (2, 3) or (a.ndim == 3 and a.shape[2] != 3):
        raise InputError(f"write_pfm: expected (H, W) or (H, W, 3), got {a.shape}")
    a = np.where(np.isnan(a), np.inf, a).astype("<f4")
    h, w = a.shape[:2]
    with open(path, "wb") as f:
        f.write(f"{'PF' if a.ndim == 3 else 'Pf'}\n{w} {h}\n-1\n".encode("ascii"))
        f.write(np.ascontiguousarray(a[::-1]).tobytes())

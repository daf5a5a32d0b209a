"""Portable Float Map (Middlebury v3, ETH3D): ``Pf`` (1 channel) or ``PF`` (3 channels), ``W H``,
then a scale whose sign gives the byte order (negative: little-endian), then float32 rows stored
BOTTOM to top. +inf marks unknown values (our disparity maps' misses).

Written as ``Pf|PF\\n<W> <H>\\n-1.0\\n`` + little-endian float32 (NaN written as +inf); read
with any whitespace between the header tokens and either byte order.
"""
from __future__ import annotations

import numpy as np

from scenegen.dataset.files import atomic_write_bytes, read_decoded


def encode_pfm(image) -> bytes:
    """PFM bytes of an (H, W) or (H, W, 3) float map (float32 little-endian, bottom row first;
    NaN stored as +inf, PFM's unknown)."""
    a = np.asarray(image, np.float32)
    if a.ndim not in (2, 3) or (a.ndim == 3 and a.shape[2] != 3):
        raise ValueError(f"a PFM image must be (H, W) or (H, W, 3), got {a.shape}")
    a = np.where(np.isnan(a), np.float32(np.inf), a)
    H, W = a.shape[:2]
    magic = "PF" if a.ndim == 3 else "Pf"
    return f"{magic}\n{W} {H}\n-1.0\n".encode("ascii") + np.ascontiguousarray(a[::-1]).astype("<f4").tobytes()


def decode_pfm(data: bytes) -> np.ndarray:
    """(H, W) float32 (or (H, W, 3) for 'PF'), top row first; ValueError naming what is wrong."""
    try:
        tokens, pos = [], 0
        while len(tokens) < 4:  # magic, W, H, scale separated by whitespace
            while data[pos:pos + 1].isspace():
                pos += 1
            start = pos
            while pos < len(data) and not data[pos:pos + 1].isspace():
                pos += 1
            tokens.append(data[start:pos].decode("ascii"))
        pos += 1  # exactly one whitespace byte after the scale
        magic, w, h, scale = tokens[0], int(tokens[1]), int(tokens[2]), float(tokens[3])
    except (ValueError, IndexError, UnicodeDecodeError):
        raise ValueError("not a PFM file (expected header 'Pf'/'PF', width, height, scale)") from None
    if magic not in ("Pf", "PF") or w <= 0 or h <= 0 or scale == 0:
        raise ValueError(f"not a PFM file (header {tokens!r})")
    ch = 3 if magic == "PF" else 1
    n = w * h * ch
    if len(data) - pos < 4 * n:
        raise ValueError(f"truncated PFM: expected {4 * n} data bytes for {w}x{h}x{ch}, got {len(data) - pos}")
    a = np.frombuffer(data, dtype="<f4" if scale < 0 else ">f4", count=n, offset=pos).astype(np.float32)
    a = a.reshape(h, w, ch)[::-1]
    return np.ascontiguousarray(a[..., 0] if ch == 1 else a)


def write_pfm(path, image) -> None:
    """Write an (H, W) or (H, W, 3) float map as PFM, atomically."""
    atomic_write_bytes(path, encode_pfm(image))


def read_pfm(path) -> np.ndarray:
    """Read a PFM file (see :func:`decode_pfm`); ValueError names the file."""
    return read_decoded(path, decode_pfm)

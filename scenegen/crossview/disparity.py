"""Disparity maps and their files: PFM (Middlebury) and KITTI PNG16.

Sign: ``d = u_left - u_right >= 0`` for both maps (left map on left pixels, right map on right
pixels, so ``u_left = u_right + d_right``). ``d = f B / Z`` with Z the depth along the rectified
camera's axis, f the rectified focal length (px), B the baseline (m).

* PFM (Middlebury v3): header ``Pf\\n<W> <H>\\n-1.0\\n`` (negative scale = little-endian float32),
  rows stored BOTTOM to top; unknown = +inf.
* KITTI PNG16: uint16 ``round(d * 256)``, 0 = invalid; disparities that would not fit (d >= 256)
  or round to 0 are invalid too.
"""
from __future__ import annotations

import numpy as np

KITTI_SCALE = 256.0


def disparity_from_depth(depth_z, f_px: float, baseline_m: float) -> np.ndarray:
    """(H, W) float64 d = f B / Z; +inf where depth is not finite or not positive."""
    z = np.asarray(depth_z, np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        d = f_px * baseline_m / z
    d[~(np.isfinite(z) & (z > 0))] = np.inf
    return d


def encode_pfm(disp) -> bytes:
    """Grey PFM bytes of an (H, W) float map (stored as float32 little-endian, bottom row first)."""
    a = np.asarray(disp, np.float32)
    if a.ndim != 2:
        raise ValueError(f"PFM disparity must be (H, W), got {a.shape}")
    H, W = a.shape
    return f"Pf\n{W} {H}\n-1.0\n".encode("ascii") + np.ascontiguousarray(a[::-1]).astype("<f4").tobytes()


def decode_pfm(data: bytes) -> np.ndarray:
    """(H, W) float32 (or (H, W, 3) for colour 'PF') from PFM bytes, top row first."""
    lines, pos = [], 0
    for _ in range(3):  # magic, "W H", scale: one line each
        end = data.index(b"\n", pos)
        lines.append(data[pos:end].strip())
        pos = end + 1
    kind = lines[0]
    W, H = (int(x) for x in lines[1].split())
    scale = float(lines[2])
    if kind not in (b"Pf", b"PF"):
        raise ValueError(f"not a PFM file (magic {kind!r})")
    c = 1 if kind == b"Pf" else 3
    dtype = "<f4" if scale < 0 else ">f4"
    a = np.frombuffer(data, dtype=dtype, count=W * H * c, offset=pos).astype(np.float32)
    a = a.reshape(H, W, c) if c == 3 else a.reshape(H, W)
    return np.ascontiguousarray(a[::-1])


def encode_kitti(disp, valid) -> np.ndarray:
    """(H, W) uint16 KITTI disparity: round(d * 256) where valid, 0 elsewhere."""
    d = np.asarray(disp, np.float64)
    ok = np.asarray(valid, bool) & np.isfinite(d) & (d >= 0)
    q = np.zeros(d.shape, np.float64)
    q[ok] = np.rint(d[ok] * KITTI_SCALE)
    q[(q > 65535) | (q < 1)] = 0
    return q.astype(np.uint16)


def decode_kitti(png16) -> tuple[np.ndarray, np.ndarray]:
    """(disparity float64 (H, W), valid bool (H, W)) from a KITTI uint16 disparity image."""
    a = np.asarray(png16)
    if a.dtype != np.uint16:
        raise ValueError(f"KITTI disparity PNGs are uint16, got {a.dtype}")
    return a.astype(np.float64) / KITTI_SCALE, a > 0

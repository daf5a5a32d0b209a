"""Middlebury ``.flo`` optical flow files (Baker et al., "A Database and Evaluation Methodology
for Optical Flow", IJCV 2011, and its flow-code readme).

Layout: float32 magic 202021.25 (bytes ``PIEH``), int32 width, int32 height, then H * W * 2
float32 (u, v) interleaved, row-major from the top row; all little-endian. Unknown flow is
stored as 1e10 (readers treat |value| > 1e9 as unknown).
"""
from __future__ import annotations

import numpy as np

FLO_MAGIC = 202021.25
UNKNOWN_FLOW = 1e10
UNKNOWN_FLOW_THRESH = 1e9


def encode_flo(flow) -> bytes:
    """Bytes of an (H, W, 2) flow (pixels, u right, v down); NaN -> UNKNOWN_FLOW."""
    f = np.asarray(flow, np.float64)
    if f.ndim != 3 or f.shape[2] != 2:
        raise ValueError(f"flow must be (H, W, 2), got {f.shape}")
    H, W, _ = f.shape
    f = np.where(np.isfinite(f), f, UNKNOWN_FLOW).astype("<f4")
    head = np.array([FLO_MAGIC], "<f4").tobytes() + np.array([W, H], "<i4").tobytes()
    return head + np.ascontiguousarray(f).tobytes()


def decode_flo(data: bytes) -> np.ndarray:
    """(H, W, 2) float32 flow with unknown values (|x| > 1e9) as NaN; ValueError saying what was
    expected for a wrong magic, size or length."""
    data = bytes(data)
    if len(data) < 12:
        raise ValueError(f"not a .flo file ({len(data)} bytes; expected a 12-byte header: magic, width, height)")
    magic = float(np.frombuffer(data, "<f4", count=1)[0])
    if magic != float(np.float32(FLO_MAGIC)):
        raise ValueError(f"not a .flo file (magic {magic:g}, bytes {data[:4]!r}; expected {FLO_MAGIC}, bytes b'PIEH')")
    W, H = (int(x) for x in np.frombuffer(data, "<i4", count=2, offset=4))
    if W < 1 or H < 1 or len(data) < 12 + 8 * W * H:  # trailing bytes are ignored, as Middlebury's reader does
        raise ValueError(f"a .flo header of width {W} and height {H} in {len(data):,} bytes (expected sizes >= 1 "
                         f"and 12 + 8 * W * H = {12 + 8 * W * H:,} bytes)")
    f = np.frombuffer(data, "<f4", count=H * W * 2, offset=12).reshape(H, W, 2).astype(np.float32)
    return np.where(np.abs(f) > UNKNOWN_FLOW_THRESH, np.nan, f).astype(np.float32)

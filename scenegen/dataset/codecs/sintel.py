"""MPI-Sintel's depth ``.dpt`` and camera ``.cam`` files (the Sintel SDK's ``sintel_io.py``:
``depth_read`` / ``depth_write``, ``cam_read`` / ``cam_write``; J. Wulff, 2015), little-endian:

* ``.dpt``: float32 tag 202021.25 (the bytes ``PIEH``), int32 width, int32 height, then
  width * height float32 depths, row-major from the top row;
* ``.cam``: the same float32 tag, then the 3x3 intrinsic matrix M and the 3x4 extrinsic matrix N
  as float64, row-major, such that ``x = M N X`` (X homogeneous world point, x homogeneous
  pixel): N is ``[R | t]`` of ``cam_from_world``.

Optical flow uses Middlebury ``.flo`` (:mod:`.flo`), the same tag.
"""
from __future__ import annotations

import numpy as np

SINTEL_TAG = 202021.25
_HEAD = np.array([SINTEL_TAG], "<f4").tobytes()


def _check_tag(data: bytes, what: str) -> None:
    if len(data) < 4 or data[:4] != _HEAD:
        raise ValueError(f"not a Sintel {what} file (tag {data[:4]!r}, expected {_HEAD!r})")


def encode_dpt(depth) -> bytes:
    """Bytes of an (H, W) depth map (metres) as Sintel ``.dpt``."""
    d = np.asarray(depth)
    if d.ndim != 2:
        raise ValueError(f"depth must be (H, W), got {d.shape}")
    H, W = d.shape
    return _HEAD + np.array([W, H], "<i4").tobytes() + np.ascontiguousarray(d, "<f4").tobytes()


def decode_dpt(data: bytes) -> np.ndarray:
    """(H, W) float32 depth of ``.dpt`` bytes; ValueError when the tag or size is wrong."""
    _check_tag(data, ".dpt")
    W, H = (int(x) for x in np.frombuffer(data, "<i4", count=2, offset=4))
    if W <= 0 or H <= 0 or len(data) != 12 + 4 * W * H:
        raise ValueError(f".dpt of {W}x{H} has {len(data)} bytes, expected {12 + 4 * max(W * H, 0)}")
    return np.frombuffer(data, "<f4", count=W * H, offset=12).reshape(H, W).astype(np.float32)


def encode_cam(K, cam_from_world_3x4) -> bytes:
    """Bytes of a Sintel ``.cam``: the tag, M = K (3, 3) and N = [R | t] (3, 4), float64."""
    M, N = np.asarray(K, np.float64), np.asarray(cam_from_world_3x4, np.float64)
    if M.shape != (3, 3) or N.shape != (3, 4):
        raise ValueError(f"a .cam holds M (3, 3) and N (3, 4), got {M.shape} and {N.shape}")
    return _HEAD + np.ascontiguousarray(M, "<f8").tobytes() + np.ascontiguousarray(N, "<f8").tobytes()


def decode_cam(data: bytes) -> tuple[np.ndarray, np.ndarray]:
    """(M (3, 3), N (3, 4)) float64 of ``.cam`` bytes; ValueError when the tag or size is wrong."""
    _check_tag(data, ".cam")
    if len(data) != 4 + 8 * 21:
        raise ValueError(f".cam has {len(data)} bytes, expected {4 + 8 * 21}")
    M = np.frombuffer(data, "<f8", count=9, offset=4).reshape(3, 3).copy()
    N = np.frombuffer(data, "<f8", count=12, offset=4 + 72).reshape(3, 4).copy()
    return M, N

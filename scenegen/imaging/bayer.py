"""Colour filter array (Bayer) sampling and OpenCV demosaicing.

A pattern names the top-left 2x2 block row by row: ``RGGB`` puts R at pixel (u, v) = (0, 0),
G at (1, 0) and (0, 1), B at (1, 1) (array element [v, u]); the block repeats over the image.

OpenCV names its Bayer conversions after the second row's second and third pixels, so its
``COLOR_BayerBG2RGB`` is the RGGB pattern here (``_OPENCV_CODE`` below; checked per pattern in
tests/test_imaging_bayer.py against a mosaic of a known colour).
"""
from __future__ import annotations

import cv2
import numpy as np

PATTERNS = ("RGGB", "BGGR", "GRBG", "GBRG")
DEMOSAIC_METHODS = ("bilinear", "edge_aware")
_CHANNEL = {"R": 0, "G": 1, "B": 2}
#: Pattern -> the two letters of OpenCV's COLOR_Bayer??2RGB code for it.
_OPENCV_CODE = {"RGGB": "BG", "BGGR": "RG", "GRBG": "GB", "GBRG": "GR"}
#: Reflection padding before demosaicing, pixels (even, so the colour phase is kept).
DEMOSAIC_PAD_PX = 4


def _check(pattern: str) -> str:
    if pattern not in PATTERNS:
        raise ValueError(f"Bayer pattern must be one of {PATTERNS}, got {pattern!r}")
    return pattern


def channel_map(pattern: str, height: int, width: int) -> np.ndarray:
    """(H, W) int8: the colour channel (0 = R, 1 = G, 2 = B) each pixel records."""
    block = np.array([_CHANNEL[c] for c in _check(pattern)], dtype=np.int8).reshape(2, 2)
    return np.tile(block, ((height + 1) // 2, (width + 1) // 2))[:height, :width]


def mosaic(rgb: np.ndarray, pattern: str) -> np.ndarray:
    """(H, W, 3) -> (H, W): each pixel keeps the channel its filter passes (same dtype)."""
    rgb = np.asarray(rgb)
    ch = channel_map(pattern, rgb.shape[0], rgb.shape[1])
    return np.take_along_axis(rgb, ch[..., None].astype(np.intp), axis=2)[..., 0]


def opencv_conversion(pattern: str, method: str) -> str:
    """The name of the ``cv2`` colour conversion that demosaics ``pattern`` with ``method``,
    e.g. ``COLOR_BayerBG2RGB`` for RGGB bilinear, ``COLOR_BayerBG2RGB_EA`` for edge-aware."""
    if method not in DEMOSAIC_METHODS:
        raise ValueError(f"demosaic method must be one of {DEMOSAIC_METHODS}, got {method!r}")
    suffix = "_EA" if method == "edge_aware" else ""
    return f"COLOR_Bayer{_OPENCV_CODE[_check(pattern)]}2RGB{suffix}"


def demosaic(raw: np.ndarray, pattern: str, method: str = "bilinear") -> np.ndarray:
    """(H, W) uint8/uint16 mosaic -> (H, W, 3) RGB of the same dtype, with OpenCV.

    ``bilinear``: ``cv2.COLOR_Bayer??2RGB``; ``edge_aware``: ``cv2.COLOR_Bayer??2RGB_EA``.
    The mosaic is first padded by ``DEMOSAIC_PAD_PX`` pixels by reflection (an even count keeps the colour
    phase: padded row -2 copies row 2, -1 copies 1), so border pixels get interior-quality
    interpolation instead of OpenCV's one-sided border handling; the result is cropped back.
    """
    code = getattr(cv2, opencv_conversion(pattern, method))
    pad = DEMOSAIC_PAD_PX
    padded = np.pad(np.asarray(raw), pad, mode="reflect")
    return np.ascontiguousarray(cv2.cvtColor(padded, code)[pad:-pad, pad:-pad])

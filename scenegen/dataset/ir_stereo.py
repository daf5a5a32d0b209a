"""Active IR stereo's invalid mask (``crossview/stereo/<left view>/ir_invalid_<side>.png``,
docs/dataset_format.md, "Active IR stereo"): why a rectified pixel's disparity cannot be measured
by a projector-textured stereo pair, one bit per reason (uint8 PNG, 0 = valid):

* ``NO_SURFACE`` (1): the pixel's ray hits nothing (its truth disparity is +inf); no other bit.
* ``SHADOW`` (2): projector shadow: the surface point is not lit by the projector (outside its
  image, its seen side facing away from the projector centre, or something between them;
  :func:`scenegen.crossview.projector.projector_truth`).
* ``OCCLUDED`` (4): the other rectified camera does not see the point (occluded, or outside its
  image: correspondence state not ``VISIBLE``, docs/crossview.md).
* ``OUT_OF_RANGE`` (8): the point's depth z lies outside the sensor's range
  ``crossview.ir_depth_range_m`` [min, max] (min <= z <= max is in range).
"""
from __future__ import annotations

import numpy as np

from scenegen.dataset.codecs.png import decode_png, encode_png
from scenegen.dataset.crossview import VISIBLE

NO_SURFACE, SHADOW, OCCLUDED, OUT_OF_RANGE = 1, 2, 4, 8
INVALID_BITS = {NO_SURFACE: "no_surface", SHADOW: "shadow", OCCLUDED: "occluded", OUT_OF_RANGE: "out_of_range"}


def invalid_mask(depth_z, lit, other_state, depth_range_m) -> np.ndarray:
    """(H, W) uint8 bits (module docstring) of one rectified side: ``depth_z`` (H, W) metres (NaN
    or inf = no surface), ``lit`` (H, W) bool projector light, ``other_state`` (H, W) the
    correspondence state in the other side, ``depth_range_m`` (min, max)."""
    z = np.asarray(depth_z, np.float64)
    surface = np.isfinite(z)
    lo, hi = depth_range_m
    with np.errstate(invalid="ignore"):
        out_of_range = surface & ((z < lo) | (z > hi))
    bits = (np.where(surface & ~np.asarray(lit, bool), SHADOW, 0)
            | np.where(surface & (np.asarray(other_state) != VISIBLE), OCCLUDED, 0)
            | np.where(out_of_range, OUT_OF_RANGE, 0))
    return np.where(surface, bits, NO_SURFACE).astype(np.uint8)


def encode_invalid(mask) -> bytes:
    return encode_png(np.asarray(mask, np.uint8))


def decode_invalid(data: bytes) -> np.ndarray:
    """(H, W) uint8 bits of an ``ir_invalid_<side>.png``."""
    m = decode_png(data)
    if m.dtype != np.uint8 or m.ndim != 2 or (m & ~np.uint8(15)).any():
        raise ValueError(f"an IR invalid mask is a (H, W) uint8 PNG of bits 1|2|4|8, got {m.dtype} {m.shape}")
    return m

"""Gray-code (and plain binary) decoding of a pattern-and-inverse sequence (Lanman and Taubin,
"Build Your Own 3D Scanner", SIGGRAPH 2009 course, sec. 5.2; Scharstein and Szeliski, CVPR 2003,
sec. 3: a bit from each pattern against its inverse).

Per bit ``b`` (most significant first): ``d = I_pattern - I_inverse``; the bit is ``d > 0``; a pixel
whose ``|d|`` falls below ``threshold`` in any bit is unreliable (shadow, low albedo, an edge
blurred across the bit's stripe boundary) and gets no code. Then Gray to binary; a code beyond
the axis (``>= length``: the padding of ``2**n``) is no code either. Codes are -1 where none.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.errors import InputError
from scenegen.geometry.sl_codes import OUTSIDE, code_from_bits, gray_to_binary


@dataclass(frozen=True)
class DecodedAxis:
    """One axis' decode: ``code`` (H, W) int64 projector pixel index, -1 where none;
    ``reliable`` (H, W) bool every bit passed the threshold; ``min_abs_diff`` (H, W) the smallest
    |pattern - inverse| over the bits (image units)."""

    code: np.ndarray
    reliable: np.ndarray
    min_abs_diff: np.ndarray


def decode_axis(patterns, inverses, *, length_px: int, threshold: float, gray: bool = True,
                mask=None) -> DecodedAxis:
    """Decode one axis from (n_bits, H, W) pattern images and their (n_bits, H, W) inverses
    (linear or encoded grey values, most significant bit first). ``threshold``: a scalar or (H, W)
    per pixel (e.g. a fraction of the pixel's white - black contrast). ``mask`` (H, W) bool: pixels
    to decode (e.g. white - black above a contrast); None: all."""
    p = np.asarray(patterns, dtype=np.float64)
    q = np.asarray(inverses, dtype=np.float64)
    if p.ndim != 3 or p.shape != q.shape or p.shape[0] < 1:
        raise InputError(f"patterns and inverses must be (n_bits, H, W) of one shape, got {p.shape} and {q.shape}")
    d = p - q
    bits = (d > 0).astype(np.int64)
    min_abs = np.min(np.abs(d), axis=0)
    reliable = min_abs >= threshold
    if mask is not None:
        reliable &= np.asarray(mask, dtype=bool)
    word = code_from_bits(bits)
    code = gray_to_binary(word) if gray else word
    ok = reliable & (code < length_px)
    return DecodedAxis(np.where(ok, code, OUTSIDE), reliable, min_abs)


def contrast_mask(white, black, min_contrast: float) -> np.ndarray:
    """(H, W) bool: ``white - black >= min_contrast`` (lit by the projector: not its shadow)."""
    return (np.asarray(white, dtype=np.float64) - np.asarray(black, dtype=np.float64)) >= min_contrast

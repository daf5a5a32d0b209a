"""Portable Float Map (PFM) disparity/depth, as used by Middlebury and ETH3D, through
:func:`scenegen.dataset.codecs.read_pfm` (header tokens, both byte orders, 1 or 3 channels,
truncation check; write with :func:`scenegen.dataset.codecs.write_pfm`).

Infinity marks unknown/missing values; the reader converts inf to NaN (recon_eval's missing
marker) unless ``keep_inf``, and names the file in every error.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from scenegen.dataset.codecs import read_pfm as decode_pfm_file


def read_pfm(path, *, keep_inf: bool = False) -> np.ndarray:
    """(H, W) float64 (or (H, W, 3) for PF), top row first."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected a PFM image)")
    try:
        arr = decode_pfm_file(p).astype(np.float64)
    except ValueError as exc:  # the codec's message names the file
        raise InputError(str(exc)) from None
    if not keep_inf:
        arr[np.isinf(arr)] = np.nan
    return arr

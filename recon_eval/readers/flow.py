"""Optical flow files, as (H, W, 2) float64 pixels (u right, v down) with NaN = unknown:

* ``.flo`` (Middlebury / Sintel): through :func:`scenegen.dataset.codecs.decode_flo`
  (|value| > 1e9 unknown);
* ``.png`` KITTI 2012/2015 flow: 16-bit RGB, ``u = (R - 2^15) / 64``, ``v = (G - 2^15) / 64``,
  valid where ``B > 0`` (devkit ``io_flow.h`` ``readFlowField``);
* ``.npy``: (H, W, 2), or (H, W, 3) whose third channel is a validity flag (> 0.5 valid);
* ``.pfm`` (FlyingThings3D / Scene Flow): 3 channels ``(u, v, 0)``, or 2-channel data in a
  colour PFM; non-finite = unknown.

:func:`write_kitti_flow` writes the KITTI PNG (runners, tests).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from recon_eval.readers.native import read_png
from scenegen.dataset.codecs import decode_flo, encode_png, read_npy, read_pfm
from scenegen.dataset.codecs.kitti_flow import (  # the format lives with the dataset codecs
    KITTI_FLOW_OFFSET, KITTI_FLOW_SCALE, decode_kitti_flow, encode_kitti_flow,
)
from scenegen.dataset.files import atomic_write_bytes

FLOW_SUFFIXES = (".flo", ".png", ".npy", ".pfm")
__all__ = ["FLOW_SUFFIXES", "KITTI_FLOW_OFFSET", "KITTI_FLOW_SCALE", "decode_kitti_flow", "encode_kitti_flow",
           "read_flow", "write_kitti_flow"]


def write_kitti_flow(path, flow) -> None:
    atomic_write_bytes(path, encode_png(encode_kitti_flow(flow)))


def read_flow(path) -> np.ndarray:
    """An (H, W, 2) float64 flow from a .flo, KITTI .png, .npy or .pfm file (NaN = unknown)."""
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in FLOW_SUFFIXES:
        raise InputError(f"{p}: unknown flow format {suffix!r} (expected {', '.join(FLOW_SUFFIXES)})")
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected an optical flow {suffix} file)")
    try:
        if suffix == ".flo":
            f = decode_flo(p.read_bytes()).astype(np.float64)
        elif suffix == ".png":
            f = decode_kitti_flow(read_png(p))
        elif suffix == ".npy":
            a = np.asarray(read_npy(p), np.float64)
            if a.ndim != 3 or a.shape[2] not in (2, 3):
                raise ValueError(f"expected an (H, W, 2) or (H, W, 3) array, got {a.shape}")
            f = a[..., :2].copy()
            if a.shape[2] == 3:
                f[a[..., 2] <= 0.5] = np.nan
        else:
            a = np.asarray(read_pfm(p), np.float64)
            if a.ndim != 3 or a.shape[2] < 2:
                raise ValueError(f"expected a colour (3-channel) PFM holding (u, v, 0), got {a.shape}")
            f = a[..., :2].copy()
    except (ValueError, EOFError) as exc:  # the codecs' read_* name the file already
        raise InputError(f"{p}: {str(exc).removeprefix(f'{p}: ')}") from None
    f[~np.all(np.isfinite(f), axis=2)] = np.nan
    return f

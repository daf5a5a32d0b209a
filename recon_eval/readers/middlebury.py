"""Middlebury stereo v3 side files: ``calib.txt`` (``key=value`` lines; ``cam0=[fx 0 cx; 0 fy cy;
0 0 1]``, ``ndisp``, ``isint``, ...) and the non-occlusion mask ``mask0nocc.png`` (uint8: 255 =
non-occluded, 128 = occluded, 0 = no truth; MiddEval3's ``evaldisp`` evaluates where it is 255).
Our own Middlebury export (``scenegen export middlebury``) writes both."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from recon_eval.readers.text import read_text
from recon_eval.readers.native import read_png

CALIB = "calib.txt"


def read_middlebury_calib(path) -> dict:
    """{key: float, or (3, 3) array for the bracketed matrices} of a Middlebury calib.txt."""
    out = {}
    for n, line in enumerate(read_text(path, "a Middlebury calib.txt").splitlines(), start=1):
        if "=" not in line:
            continue
        k, v = (x.strip() for x in line.split("=", 1))
        try:
            if v.startswith("["):
                out[k] = np.array([[float(x) for x in row.split()] for row in v.strip("[]").split(";")])
            else:
                out[k] = float(v)
        except ValueError:
            raise InputError(f"{path}:{n}: {k}: expected a number or [a b c; ...], got {v!r}") from None
    return out


def middlebury_ndisp(calib_path) -> float:
    """``ndisp`` of a calib.txt (the disparity range evaldisp clips estimates to)."""
    calib = read_middlebury_calib(calib_path)
    if "ndisp" not in calib or not calib["ndisp"] > 0:
        raise InputError(f"{calib_path}: ndisp: expected a positive number")
    return float(calib["ndisp"])


def is_middlebury_mask(path) -> bool:
    """True for an 8-bit single-channel PNG (a mask0nocc.png; KITTI disparities are 16-bit)."""
    p = Path(path)
    if p.suffix.lower() != ".png" or not p.is_file():
        return False
    try:
        img = read_png(p)
    except ValueError:
        return False
    return img.ndim == 2 and img.dtype == np.uint8


def read_middlebury_mask(path) -> np.ndarray:
    """(H, W) bool: the pixels a Middlebury mask0nocc.png marks 255 (non-occluded, evaluated)."""
    p = Path(path)
    try:
        img = read_png(p) if p.is_file() else None
    except ValueError:
        img = None
    if img is None or img.ndim != 2 or img.dtype != np.uint8:
        raise InputError(f"{p}: expected a Middlebury mask0nocc.png (8-bit grey: 255 non-occluded, 128 occluded, "
                         "0 no truth)")
    return img == 255

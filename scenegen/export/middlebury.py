"""Middlebury stereo v3 layout, one folder per rectified stereo frame (named after its left view):
``im0.png``, ``im1.png`` (rectified left/right), ``disp0.pfm``, ``disp1.pfm`` (float32 PFM,
bottom row first, +inf = unknown; d = u_left - u_right), ``mask0nocc.png`` (255 = visible in
the right view, 128 = occluded or out of frame, 0 = no surface) and ``calib.txt``:
``cam0``, ``cam1`` (3x3, pixels), ``doffs`` (cx1 - cx0 = 0: both rectified views share cx),
``baseline`` (MILLIMETRES, Middlebury's unit), ``width``, ``height``, ``ndisp``, ``isint``,
``vmin``, ``vmax``. Disparity relates to depth by Z = baseline * f / (d + doffs).
"""
from __future__ import annotations

import math

import numpy as np

from scenegen.dataset.files import copy_file
from scenegen.dataset.codecs import encode_png
from scenegen.dataset.crossview import VISIBLE
from scenegen.dataset.layout import stereo_path
from scenegen.export.common import stereo_frames, write


def _mat(K) -> str:
    K = np.asarray(K, float)
    return "[" + "; ".join(" ".join(repr(float(x)) for x in row) for row in K) + "]"


def export(ds, dest) -> dict:
    frames = stereo_frames(ds)
    for fr in frames:
        name = fr.left_view  # a checked view name
        (dest / name).mkdir(parents=True, exist_ok=True)
        for key, side, dst in (("image", "left", "im0.png"), ("image", "right", "im1.png"),
                               ("disparity_pfm", "left", "disp0.pfm"), ("disparity_pfm", "right", "disp1.pfm")):
            copy_file(ds.path(stereo_path(name, key, side)), dest / name / dst)
        calib = fr.calib
        d0 = fr.disparity("left")
        state = fr.correspondence("left").state
        mask = np.where(state == VISIBLE, 255, np.where(np.isfinite(d0), 128, 0)).astype(np.uint8)
        write(dest, f"{name}/mask0nocc.png", encode_png(mask))
        fin = d0[np.isfinite(d0)]
        vmin, vmax = (float(fin.min()), float(fin.max())) if fin.size else (0.0, 0.0)
        W, H = calib["size"]
        text = (f"cam0={_mat(calib['K'])}\ncam1={_mat(calib['K'])}\ndoffs=0\n"
                f"baseline={repr(calib['baseline_m'] * 1000.0)}\nwidth={W}\nheight={H}\n"
                f"ndisp={max(16, 16 * math.ceil(vmax / 16))}\nisint=0\nvmin={repr(vmin)}\nvmax={repr(vmax)}\n")
        write(dest, f"{name}/calib.txt", text.encode())
    return {"files": 6 * len(frames), "frames": len(frames)}


def read_calib(text: str) -> dict:
    """Parse a Middlebury calib.txt into {key: float or 3x3 array}."""
    out = {}
    for line in text.splitlines():
        if "=" not in line:
            continue
        k, v = line.split("=", 1)
        v = v.strip()
        if v.startswith("["):
            out[k] = np.array([[float(x) for x in row.split()] for row in v.strip("[]").split(";")])
        else:
            out[k] = float(v)
    return out

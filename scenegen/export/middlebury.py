"""Middlebury stereo v3 in MiddEval3's layout and names: ``trainingF/<left view>/`` per rectified
stereo frame (F: full resolution, the only one we have), as the MiddEval3 SDK's ``runeval``
walks it: ``im0.png``, ``im1.png`` (rectified left/right), ``disp0GT.pfm``, ``disp1GT.pfm``
(float32 PFM, bottom row first, +inf = unknown; d = u_left - u_right), ``mask0nocc.png`` and
``mask1nocc.png`` (255 = visible in the other view, 128 = occluded or out of frame, 0 = no
surface) and ``calib.txt``: ``cam0``, ``cam1`` (3x3, pixels), ``doffs`` (cx1 - cx0 = 0: both
rectified views share cx), ``baseline`` (MILLIMETRES, Middlebury's unit), ``width``, ``height``,
``ndisp``, ``isint``, ``vmin``, ``vmax``, ``dyavg``, ``dymax`` (0: exact rectification).
Disparity relates to depth by Z = baseline * f / (d + doffs).
"""
from __future__ import annotations

import math

import numpy as np

from scenegen.dataset.files import copy_file
from scenegen.dataset.codecs import encode_png
from scenegen.dataset.crossview import VISIBLE
from scenegen.dataset.layout import stereo_path
from scenegen.export.common import each, stereo_frames, write

TRAINING = "trainingF"


def _mat(K) -> str:
    K = np.asarray(K, float)
    return "[" + "; ".join(" ".join(repr(float(x)) for x in row) for row in K) + "]"


def export(ds, dest, progress=None) -> dict:
    frames = stereo_frames(ds)
    for fr in each(frames, progress):
        name = f"{TRAINING}/{fr.left_view}"  # a checked view name
        (dest / name).mkdir(parents=True, exist_ok=True)
        for key, side, dst in (("image", "left", "im0.png"), ("image", "right", "im1.png"),
                               ("disparity_pfm", "left", "disp0GT.pfm"), ("disparity_pfm", "right", "disp1GT.pfm")):
            copy_file(ds.path(stereo_path(fr.left_view, key, side)), dest / name / dst)
        calib = fr.calib
        for k, side in enumerate(("left", "right")):
            d = fr.disparity(side)
            state = fr.correspondence(side).state
            mask = np.where(state == VISIBLE, 255, np.where(np.isfinite(d), 128, 0)).astype(np.uint8)
            write(dest, f"{name}/mask{k}nocc.png", encode_png(mask))
        d0 = fr.disparity("left")
        fin = d0[np.isfinite(d0)]
        vmin, vmax = (float(fin.min()), float(fin.max())) if fin.size else (0.0, 0.0)
        W, H = calib["size"]
        text = (f"cam0={_mat(calib['K'])}\ncam1={_mat(calib['K'])}\ndoffs=0\n"
                f"baseline={repr(calib['baseline_m'] * 1000.0)}\nwidth={W}\nheight={H}\n"
                f"ndisp={max(16, 16 * math.ceil(vmax / 16))}\nisint=0\nvmin={repr(vmin)}\nvmax={repr(vmax)}\n"
                "dyavg=0\ndymax=0\n")
        write(dest, f"{name}/calib.txt", text.encode())
    return {"files": 7 * len(frames), "frames": len(frames)}


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

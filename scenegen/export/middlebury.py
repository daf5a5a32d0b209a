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
import shutil

import numpy as np

from scenegen import io as sio
from scenegen.crossview.correspondence import VISIBLE
from scenegen.crossview.disparity import decode_pfm
from scenegen.export._common import stereo_frames, write


def _mat(K) -> str:
    K = np.asarray(K, float)
    return "[" + "; ".join(" ".join(repr(float(x)) for x in row) for row in K) + "]"


def export(ds, dest) -> dict:
    frames = stereo_frames(ds)
    for fr in frames:
        base, name = fr["dir"], fr["left_view"]
        (dest / name).mkdir(parents=True, exist_ok=True)
        for src, dst in (("left.png", "im0.png"), ("right.png", "im1.png"),
                         ("disp_left.pfm", "disp0.pfm"), ("disp_right.pfm", "disp1.pfm")):
            shutil.copyfile(ds.path(f"{base}/{src}"), dest / name / dst)
        calib = sio.read_json(ds.path(f"{base}/calib.json"))
        d0 = decode_pfm(ds.path(f"{base}/disp_left.pfm").read_bytes())
        state = sio.read_exr(ds.path(f"{base}/corr_left.exr"))["state"]
        mask = np.where(state == VISIBLE, 255, np.where(np.isfinite(d0), 128, 0)).astype(np.uint8)
        write(dest, f"{name}/mask0nocc.png", sio.encode_png(mask))
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

"""KITTI 2015 stereo layout from the rectified stereo frames (crossview/stereo/*).

Frame k (in the run's order) becomes ``training/image_2/{k:06d}_10.png`` (left rectified,
8-bit RGB), ``training/image_3/{k:06d}_10.png`` (right), ``training/disp_occ_0/{k:06d}_10.png``
(left disparity on every pixel with a surface) and ``training/disp_noc_0/{k:06d}_10.png`` (only
pixels visible in the right view), uint16 ``round(d * 256)`` with 0 = invalid, and
``training/calib_cam_to_cam/{k:06d}.txt`` with ``S_rect_02/03``, ``R_rect_02/03`` (identity:
the renders are already rectified) and ``P_rect_02/03`` (3x4 row-major; P_rect_03[0, 3] = -f B).
``frames.json`` maps each index to our stereo folder and views.
"""
from __future__ import annotations

import json

import numpy as np

from scenegen.dataset.files import copy_file
from scenegen.dataset.codecs import encode_png
from scenegen.dataset.layout import stereo_dir, stereo_path
from scenegen.export.common import stereo_frames, write
from scenegen.geometry.color import to_uint8


def _row(M) -> str:
    return " ".join(f"{x:.12e}" for x in np.asarray(M, float).ravel())


def export(ds, dest) -> dict:
    frames = stereo_frames(ds)
    out = []
    for k, fr in enumerate(frames):
        tag = f"{k:06d}"
        for side, folder in (("left", "image_2"), ("right", "image_3")):
            write(dest, f"training/{folder}/{tag}_10.png", encode_png(to_uint8(fr.image(side))))
        for kind in ("occ", "noc"):
            (dest / f"training/disp_{kind}_0").mkdir(parents=True, exist_ok=True)
            copy_file(ds.path(stereo_path(fr.left_view, f"disparity_{kind}", "left")),
                            dest / f"training/disp_{kind}_0/{tag}_10.png")
        calib = fr.calib
        W, H = calib["size"]
        lines = [f"S_rect_02: {W:.6e} {H:.6e}", f"R_rect_02: {_row(np.eye(3))}", f"P_rect_02: {_row(calib['P1'])}",
                 f"S_rect_03: {W:.6e} {H:.6e}", f"R_rect_03: {_row(np.eye(3))}", f"P_rect_03: {_row(calib['P2'])}"]
        write(dest, f"training/calib_cam_to_cam/{tag}.txt", ("\n".join(lines) + "\n").encode())
        out.append({"index": tag, "stereo_dir": stereo_dir(fr.left_view), "left_view": fr.left_view,
                    "right_view": fr.right_view})
    write(dest, "frames.json", (json.dumps(out, indent=2) + "\n").encode())
    return {"files": 6 * len(frames) + 1, "frames": len(frames)}

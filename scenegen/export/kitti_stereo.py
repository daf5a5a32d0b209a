"""KITTI 2015 stereo layout from the rectified stereo frames (crossview/stereo/*).

Frame k (in the run's order) becomes ``training/image_2/{k:06d}_10.png`` (left rectified,
8-bit RGB), ``training/image_3/{k:06d}_10.png`` (right), ``training/disp_occ_0/{k:06d}_10.png``
(left disparity on every pixel with a surface) and ``training/disp_noc_0/{k:06d}_10.png`` (only
pixels visible in the right view), uint16 ``round(d * 256)`` with 0 = invalid;
``training/obj_map/{k:06d}_10.png`` (uint8: the instance id of the surface each left rectified
pixel centre sees, 0 = none; refused when an id exceeds 255); and
``training/calib_cam_to_cam/{k:06d}.txt`` in the KITTI raw ``calib_cam_to_cam.txt`` form that
the devkit and pykitti parse: ``calib_time``, ``corner_dist``, then for cameras 00..03
``S_xx`` (raw size), ``K_xx`` (raw 3x3), ``D_xx`` (OpenCV distortion vector of the raw camera),
``R_xx``, ``T_xx`` (x_xx = R_xx x_00 + T_xx), ``S_rect_xx``, ``R_rect_xx`` (rectifying rotation:
x_rect = R_rect_xx x_raw), ``P_rect_xx`` (3x4 row-major on the rectified left frame;
P_rect_03[0, 3] = -f B). Cameras 00 and 02 are our left camera, 01 and 03 our right (KITTI's
grey and colour pairs; pykitti needs all four). ``frames.json`` maps each index to our stereo
folder and views.
"""
from __future__ import annotations

import json

import numpy as np

from scenegen.dataset.cameras import camera_of
from scenegen.dataset.files import copy_file
from scenegen.dataset.codecs import encode_png
from scenegen.dataset.layout import stereo_dir, stereo_path
from scenegen.export.common import each, stereo_frames, write
from scenegen.export.errors import ExportError
from scenegen.geometry.color import to_uint8


def _row(M) -> str:
    return " ".join(f"{x:.12e}" for x in np.asarray(M, float).ravel())


def calib_cam_to_cam(calib: dict) -> str:
    """The text of a KITTI ``calib_cam_to_cam.txt`` for one rectified frame (module docstring)."""
    (cl, pl), (cr, pr) = camera_of(calib["raw_left"]), camera_of(calib["raw_right"])
    right_from_left = pr @ pl.inverse()
    W, H = calib["size"]
    lines = ["calib_time: scenegen truth", "corner_dist: 0.000000e+00"]
    left = (cl, None, calib["R1"], calib["P1"])
    right = (cr, right_from_left, calib["R2"], calib["P2"])
    for xx, (cam, ext, R_rect, P) in enumerate((left, right, left, right)):
        K, D = cam.to_opencv()
        R, T = (np.eye(3), np.zeros(3)) if ext is None else (ext.R, ext.t)
        lines += [f"S_{xx:02d}: {cam.width:.6e} {cam.height:.6e}", f"K_{xx:02d}: {_row(K)}",
                  f"D_{xx:02d}: {_row(D)}", f"R_{xx:02d}: {_row(R)}", f"T_{xx:02d}: {_row(T)}",
                  f"S_rect_{xx:02d}: {W:.6e} {H:.6e}", f"R_rect_{xx:02d}: {_row(R_rect)}",
                  f"P_rect_{xx:02d}: {_row(P)}"]
    return "\n".join(lines) + "\n"


def obj_map(ds, fr) -> np.ndarray | None:
    """(H, W) uint8 instance ids of the left rectified view, or None for a dataset rendered before
    the rectified ids were stored."""
    if not ds.has(stereo_path(fr.left_view, "ids", "left")):
        return None
    ids = fr.instance_ids("left")
    if ids.max(initial=0) > 255:
        raise ExportError(f"stereo frame {fr.left_view}: instance id {int(ids.max())} does not fit"
                          " KITTI's 8-bit obj_map")
    return ids.astype(np.uint8)


def export(ds, dest, progress=None) -> dict:
    frames = stereo_frames(ds)
    out, n_obj = [], 0
    for k, fr in enumerate(each(frames, progress)):
        tag = f"{k:06d}"
        for side, folder in (("left", "image_2"), ("right", "image_3")):
            write(dest, f"training/{folder}/{tag}_10.png", encode_png(to_uint8(fr.image(side))))
        for kind in ("occ", "noc"):
            (dest / f"training/disp_{kind}_0").mkdir(parents=True, exist_ok=True)
            copy_file(ds.path(stereo_path(fr.left_view, f"disparity_{kind}", "left")),
                            dest / f"training/disp_{kind}_0/{tag}_10.png")
        om = obj_map(ds, fr)
        if om is not None:
            write(dest, f"training/obj_map/{tag}_10.png", encode_png(om))
            n_obj += 1
        write(dest, f"training/calib_cam_to_cam/{tag}.txt", calib_cam_to_cam(fr.calib).encode())
        out.append({"index": tag, "stereo_dir": stereo_dir(fr.left_view), "left_view": fr.left_view,
                    "right_view": fr.right_view})
    write(dest, "frames.json", (json.dumps(out, indent=2) + "\n").encode())
    return {"files": 5 * len(frames) + n_obj + 1, "frames": len(frames), "obj_map": n_obj}

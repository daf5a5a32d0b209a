"""OpenCV FileStorage YAML (written by cv2.FileStorage itself, read by any OpenCV).

* ``cameras.yaml``: ``views``, a sequence of maps {name, image_size [W, H], K, D (OpenCV's
  distortion vector for cv2.projectPoints / cv2.fisheye), model, R, T (cam_from_world:
  x_cam = R x_world + T)}.
* ``stereo/<left_view>.yaml`` per rectified stereo frame, as cv2.stereoCalibrate +
  cv2.stereoRectify would give: K1, D1, K2, D2, image_size, R, T (right_from_left), E, F (on
  undistorted pixels, x_r^T F x_l = 0, scaled to F[2, 2] = 1 as OpenCV does), R1, R2, P1, P2, Q.
* ``pairs.yaml``: ``pairs``, a sequence of {i, j, R, T (j_from_i), E, F} for every cross-view
  pair of the dataset (present when the dataset has cross-view truth).
"""
from __future__ import annotations

import cv2
import numpy as np

from scenegen.dataset.cameras import camera_of
from scenegen.export.common import each, write
from scenegen.geometry.twoview import TwoView


def _fs():
    return cv2.FileStorage("out.yaml", cv2.FILE_STORAGE_WRITE | cv2.FILE_STORAGE_MEMORY | cv2.FILE_STORAGE_FORMAT_YAML)


def _F_opencv(F):
    F = np.asarray(F, float)
    return F / F[2, 2] if abs(F[2, 2]) > 1e-12 * np.linalg.norm(F) else F


def export(ds, dest, progress=None) -> dict:
    fs = _fs()
    fs.startWriteStruct("views", cv2.FILE_NODE_SEQ)
    for v in each(ds.views, progress):
        cam, pose = ds.camera(v)
        K, D = cam.to_opencv()
        fs.startWriteStruct("", cv2.FILE_NODE_MAP)
        fs.write("name", v)
        fs.write("model", cam.model)
        fs.write("image_size", np.array([cam.width, cam.height], np.int32))
        fs.write("K", K)
        fs.write("D", D.reshape(1, -1))
        fs.write("R", pose.R)
        fs.write("T", pose.t.reshape(3, 1))
        fs.endWriteStruct()
    fs.endWriteStruct()
    write(dest, "cameras.yaml", fs.releaseAndGetString().encode())
    n = 1
    if ds.crossview.index is None:
        return {"files": n}
    for fr in ds.crossview.stereo_frames():
        calib = fr.calib
        (cl, pl), (cr, pr) = camera_of(calib["raw_left"]), camera_of(calib["raw_right"])
        tv = TwoView.of(cl, pl, cr, pr)
        fs = _fs()
        (K1, D1), (K2, D2) = cl.to_opencv(), cr.to_opencv()
        for key, val in (("K1", K1), ("D1", D1.reshape(1, -1)), ("K2", K2), ("D2", D2.reshape(1, -1)),
                         ("image_size", np.array([cl.width, cl.height], np.int32)),
                         ("R", tv.j_from_i.R), ("T", tv.j_from_i.t.reshape(3, 1)), ("E", tv.E),
                         ("F", _F_opencv(tv.F)), ("R1", np.array(calib["R1"])), ("R2", np.array(calib["R2"])),
                         ("P1", np.array(calib["P1"])), ("P2", np.array(calib["P2"])), ("Q", np.array(calib["Q"]))):
            fs.write(key, val)
        write(dest, f"stereo/{fr.left_view}.yaml", fs.releaseAndGetString().encode())
        n += 1
    if ds.crossview.pairs:
        fs = _fs()
        fs.startWriteStruct("pairs", cv2.FILE_NODE_SEQ)
        for i, j in ds.crossview.pairs:
            tv = ds.crossview.twoview(i, j)
            fs.startWriteStruct("", cv2.FILE_NODE_MAP)
            fs.write("i", i)
            fs.write("j", j)
            fs.write("R", tv.j_from_i.R)
            fs.write("T", tv.j_from_i.t.reshape(3, 1))
            if tv.E is not None:  # null for a zero baseline (no epipolar geometry)
                fs.write("E", tv.E)
                fs.write("F", _F_opencv(tv.F))
            fs.endWriteStruct()
        fs.endWriteStruct()
        write(dest, "pairs.yaml", fs.releaseAndGetString().encode())
        n += 1
    return {"files": n}

"""OpenCV calibration files (YAML or JSON, ``cv2.FileStorage``) -> :class:`scenegen.geometry.camera.Camera`.

Accepted fields (the first present name wins):

* camera matrix: ``camera_matrix``, ``K``, ``cameraMatrix`` -- 3x3, as an ``!!opencv-matrix``,
  a ROS ``camera_info`` map ``{rows, cols, data}``, or a nested/flat list of 9 numbers;
* distortion: ``distortion_coefficients``, ``D``, ``dist_coeffs``, ``distCoeffs`` -- OpenCV's
  order ``k1, k2, p1, p2[, k3[, k4, k5, k6[, s1..s4]]]``, or ``k1..k4`` for a fisheye; absent or all
  zero -> pinhole;
* image size: ``image_width`` and ``image_height``, or ``width`` and ``height``, or
  ``image_size`` ``[W, H]`` (needed: a camera model is defined over its image);
* model: ``distortion_model`` ``plumb_bob``/``rational_polynomial`` (OpenCV) or
  ``equidistant``/``fisheye`` (``cv2.fisheye``); or the ``model`` argument, which wins.

The principal point is in OpenCV pixels (centre of the top-left pixel = (0, 0)), as OpenCV writes
it. Errors name the file and the field.
"""
from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from recon_eval.errors import InputError
from recon_eval.readers.text import bracket_depth, duplicate_key, read_text
from scenegen.geometry.camera import Camera, camera_model

K_KEYS = ("camera_matrix", "K", "cameraMatrix")
#: Deepest [ { nesting handed to OpenCV's parser (a calibration file nests 3 deep).
MAX_NESTING = 64
D_KEYS = ("distortion_coefficients", "D", "dist_coeffs", "distCoeffs")
FISHEYE_MODELS = ("equidistant", "fisheye", "kannala_brandt")


def _numbers(node, where: str) -> np.ndarray:
    """All numbers of a FileNode: opencv-matrix, {rows, cols, data} map, (nested) sequence, scalar."""
    if node.isMap():
        if "data" in node.keys():
            return _numbers(node.getNode("data"), where)
        m = node.mat()
        if m is None:
            raise InputError(f"{where}: expected a matrix, got a map with keys {node.keys()}")
        return np.asarray(m, dtype=np.float64).ravel()
    if node.isSeq():
        return np.concatenate([_numbers(node.at(i), where) for i in range(node.size())] or [np.zeros(0)])
    if node.isInt() or node.isReal():
        return np.array([node.real()])
    raise InputError(f"{where}: expected numbers")


def _first(fs, keys):
    for k in keys:
        n = fs.getNode(k)
        if not n.empty() and not n.isNone():
            return k, n
    return None, None


def read_opencv_calibration(path, *, model: str | None = None, size: tuple | None = None):
    """A :class:`scenegen.geometry.camera.Camera` from an OpenCV calibration YAML/JSON file.

    ``model``: ``"opencv"`` or ``"fisheye"`` overrides the file's ``distortion_model``;
    ``size`` (W, H) is used when the file gives no image size.
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected an OpenCV calibration .yaml/.yml/.json)")
    text = read_text(p, "an OpenCV calibration YAML/JSON file")
    if not text.lstrip().startswith(("{", "%YAML")):
        # OpenCV refuses YAML without its directive (ROS camera_info files have none)
        text = "%YAML:1.0\n---\n" + text
    if (dup := duplicate_key(text)) is not None:  # OpenCV would let the last one win silently
        raise InputError(f"{p}:{dup[0]}: duplicate key {dup[1]!r} (first given at line {dup[2]})")
    if bracket_depth(text) > MAX_NESTING:  # OpenCV would recurse until the process crashes
        raise InputError(f"{p}: not a readable OpenCV YAML/JSON file (nested deeper than {MAX_NESTING} levels)")
    try:
        fs = cv2.FileStorage(text, cv2.FILE_STORAGE_READ | cv2.FILE_STORAGE_MEMORY)
    except (cv2.error, SystemError) as exc:
        cause = exc.__cause__ or exc
        msg = str(cause).strip().splitlines()[0] if str(cause).strip() else "parse error"
        raise InputError(f"{p}: not a readable OpenCV YAML/JSON file ({msg})") from None
    if not fs.isOpened():
        raise InputError(f"{p}: not a readable OpenCV YAML/JSON file")
    try:
        kname, knode = _first(fs, K_KEYS)
        if knode is None:
            raise InputError(f"{p}: no camera matrix (expected one of the fields {', '.join(K_KEYS)})")
        K = _numbers(knode, f"{p}: {kname}")
        if K.size != 9:
            raise InputError(f"{p}: {kname}: expected 9 numbers (3x3), got {K.size}")
        K = K.reshape(3, 3)
        dname, dnode = _first(fs, D_KEYS)
        D = np.zeros(0) if dnode is None else _numbers(dnode, f"{p}: {dname}")
        if model is None:
            mnode = fs.getNode("distortion_model")
            fm = mnode.string().strip().lower() if not mnode.empty() and mnode.isString() else ""
            model = "fisheye" if fm in FISHEYE_MODELS else "opencv"
        if model not in ("opencv", "fisheye"):
            raise InputError(f"model must be 'opencv' or 'fisheye', got {model!r}")
        W = H = None
        for wk, hk in (("image_width", "image_height"), ("width", "height")):
            wn, hn = fs.getNode(wk), fs.getNode(hk)
            if not wn.empty() and not hn.empty():
                W, H = wn.real(), hn.real()
                break
        if W is None:
            sn = fs.getNode("image_size")
            if not sn.empty():
                s = _numbers(sn, f"{p}: image_size")
                if s.size != 2:
                    raise InputError(f"{p}: image_size: expected [W, H], got {s.size} numbers")
                W, H = s
        if W is None:
            if size is None:
                raise InputError(f"{p}: no image size (expected fields image_width and image_height, or image_size)")
            W, H = size
    finally:
        fs.release()
    if not (float(W).is_integer() and float(H).is_integer() and W > 0 and H > 0):
        raise InputError(f"{p}: image_width/image_height: expected positive integers, got {W}, {H}")
    try:
        if camera_model(model).opencv_fisheye:
            if D.size != 4:
                raise InputError(f"{p}: {dname or 'distortion_coefficients'}: a fisheye needs 4 coefficients k1..k4, got {D.size}")
            return Camera.from_opencv_fisheye(K, D, (int(W), int(H)))
        return Camera.from_opencv(K, D if D.size else None, (int(W), int(H)))
    except ValueError as exc:
        raise InputError(f"{p}: {kname}/{dname or 'distortion_coefficients'}: {exc}") from None


def write_opencv_calibration(path, camera) -> None:
    """Write a scenegen Camera as OpenCV calibration YAML or JSON (by the extension), the fields
    OpenCV's calibration sample writes plus ``distortion_model``. For tests and exports."""
    K, D = camera.to_opencv()
    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
    fs.write("image_width", int(camera.width))
    fs.write("image_height", int(camera.height))
    fs.write("camera_matrix", np.asarray(K, np.float64))
    fs.write("distortion_coefficients", np.asarray(D, np.float64).reshape(1, -1))
    fs.write("distortion_model", "equidistant" if camera_model(camera.model).opencv_fisheye else "plumb_bob")
    fs.release()

"""A camera to and from OpenCV's and COLMAP's parameters: one tested conversion each.

* OpenCV: ``K`` with the skew in ``K[0, 1]`` and a ``dist`` vector in OpenCV's order
  (``cv2.projectPoints``; OpenCV ignores the skew there) or ``cv2.fisheye``'s ``D`` with
  ``alpha = skew / fx``. Same pixel convention as ours.
* COLMAP: model name and parameter list (colmap/src/colmap/sensor/models.h), with the
  principal point in COLMAP's pixel convention (:func:`scenegen.geometry.conventions.colmap_from_opencv_pixels`).
"""
from __future__ import annotations

import numpy as np

from scenegen.geometry.conventions import colmap_from_opencv_pixels, opencv_from_colmap_pixels

#: COLMAP model -> our model, for the COLMAP models a Camera can represent exactly.
COLMAP_MODELS = {"SIMPLE_PINHOLE": "pinhole", "PINHOLE": "pinhole", "SIMPLE_RADIAL": "opencv",
                 "RADIAL": "opencv", "OPENCV": "opencv", "FULL_OPENCV": "opencv",
                 "OPENCV_FISHEYE": "fisheye"}
#: COLMAP model -> indices of (cx, cy) in its parameter list (every model of models.h with a
#: principal point), for converting parameters of models a Camera cannot represent.
COLMAP_PRINCIPAL_POINT = {
    "SIMPLE_PINHOLE": (1, 2), "PINHOLE": (2, 3), "SIMPLE_RADIAL": (1, 2), "RADIAL": (1, 2),
    "OPENCV": (2, 3), "OPENCV_FISHEYE": (2, 3), "FULL_OPENCV": (2, 3), "SIMPLE_RADIAL_FISHEYE": (1, 2),
    "RADIAL_FISHEYE": (1, 2), "THIN_PRISM_FISHEYE": (2, 3), "FOV": (2, 3),
}


# --- OpenCV --------------------------------------------------------------------------------------
def opencv_perspective_arrays(camera) -> tuple[np.ndarray, np.ndarray]:
    """(K, dist) for ``cv2.projectPoints``: dist is the shortest OpenCV length (5, 8 or 12) that
    keeps every non-zero coefficient (OpenCV ignores K's skew there)."""
    d = np.array(camera.dist if camera.dist else (0.0,) * 12)
    n = 12 if any(d[8:]) else 8 if any(d[5:8]) else 5
    return camera.K, d[:n].copy()


def opencv_fisheye_arrays(camera) -> tuple[np.ndarray, np.ndarray]:
    """(K, D) for ``cv2.fisheye`` (pass ``alpha = skew / fx``)."""
    return camera.K, np.array(camera.dist)


def opencv_camera_args(K, dist, size) -> tuple:
    """Camera constructor arguments of an OpenCV K (3x3, skew in K[0, 1]), dist and (W, H): a
    pinhole when every coefficient is zero."""
    K = np.asarray(K, dtype=np.float64)
    if K.shape != (3, 3) or K[1, 0] != 0 or K[2, 0] != 0 or K[2, 1] != 0 or K[2, 2] != 1:
        raise ValueError(f"K must be an upper-triangular 3x3 with K[2,2] = 1, got {K.tolist()}")
    d = () if dist is None else tuple(np.asarray(dist, float).ravel())
    model = "opencv" if any(d) else "pinhole"
    return (model, int(size[0]), int(size[1]), K[0, 0], K[1, 1], K[0, 2], K[1, 2], K[0, 1],
            d if model == "opencv" else ())


def opencv_fisheye_camera_args(K, D, size, alpha: float = 0.0) -> tuple:
    """Camera constructor arguments of ``cv2.fisheye`` data: K, D = (k1, k2, k3, k4), (W, H) and
    the skew ``alpha`` (in units of fx)."""
    K = np.asarray(K, dtype=np.float64)
    skew = K[0, 1] if alpha == 0.0 else alpha * K[0, 0]
    return ("fisheye", int(size[0]), int(size[1]), K[0, 0], K[1, 1], K[0, 2], K[1, 2], skew,
            tuple(np.asarray(D, float).ravel()))


# --- COLMAP --------------------------------------------------------------------------------------
def colmap_pinhole(camera) -> tuple[str, list[float]]:
    return "PINHOLE", _colmap_base(camera)


def colmap_opencv(camera) -> tuple[str, list[float]]:
    """OPENCV with only k1, k2, p1, p2, FULL_OPENCV with k3..k6; COLMAP has no thin-prism terms
    on a perspective model (ValueError)."""
    base = _colmap_base(camera)
    if any(camera.dist[8:]):
        raise ValueError("COLMAP has no perspective model with thin-prism terms s1..s4")
    if any(camera.dist[4:8]):
        return "FULL_OPENCV", base + list(camera.dist[:8])
    return "OPENCV", base + list(camera.dist[:4])


def colmap_fisheye(camera) -> tuple[str, list[float]]:
    return "OPENCV_FISHEYE", _colmap_base(camera) + list(camera.dist)


def _colmap_base(camera) -> list[float]:
    """fx, fy, cx, cy in COLMAP's pixel convention; COLMAP models have no skew (ValueError)."""
    if camera.skew != 0.0:
        raise ValueError("COLMAP camera models have no skew; this camera has skew != 0")
    cx, cy = colmap_from_opencv_pixels([camera.cx, camera.cy])
    return [camera.fx, camera.fy, float(cx), float(cy)]


def colmap_camera_args(model_name: str, width: int, height: int, params) -> tuple:
    """Camera constructor arguments of a COLMAP camera (inverse of :func:`colmap_model`; also
    SIMPLE_PINHOLE, SIMPLE_RADIAL, RADIAL)."""
    p = [float(x) for x in params]
    if model_name not in COLMAP_MODELS:
        raise ValueError(f"unsupported COLMAP camera model {model_name!r}; supported: {sorted(COLMAP_MODELS)}")
    if model_name in ("SIMPLE_PINHOLE", "SIMPLE_RADIAL", "RADIAL"):
        f, cx, cy, *k = p
        fx = fy = f
        dist = {"SIMPLE_PINHOLE": (), "SIMPLE_RADIAL": (*k[:1], 0, 0, 0), "RADIAL": (*k[:2], 0, 0)}[model_name]
    else:
        fx, fy, cx, cy, *dist = p
    cx, cy = opencv_from_colmap_pixels([cx, cy])
    model = COLMAP_MODELS[model_name]
    if model == "opencv" and not any(dist):
        model, dist = "pinhole", ()
    return (model, width, height, fx, fy, float(cx), float(cy), 0.0, tuple(dist))


def opencv_params_from_colmap(model_name: str, params) -> tuple[float, ...]:
    """COLMAP parameters with the principal point moved to OpenCV's pixel convention (- 0.5),
    for any COLMAP model with a principal point; other models' parameters unchanged."""
    out = [float(v) for v in params]
    idx = COLMAP_PRINCIPAL_POINT.get(model_name)
    if idx is not None and len(out) > max(idx):
        for i, c in zip(idx, opencv_from_colmap_pixels([out[i] for i in idx])):
            out[i] = float(c)
    return tuple(out)

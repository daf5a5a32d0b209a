"""The camera-model registry: one entry per model, with its coefficient order and its arithmetic.

Adding a model: write its ``project_*`` and ``unproject_*`` in :mod:`.arith` (ops-generic, so the
renderer runs the same lines), its fold limit and undistortion measurement in :mod:`.validity`,
its OpenCV/COLMAP conversions in :mod:`.interop`, then add a :class:`CameraModel` here. The
round-trip test (tests/scenegen/geometry/test_camera_models.py) runs over every registered model.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from scenegen.geometry.camera import arith, interop, validity

#: OpenCV's distortion coefficient order (cv2.projectPoints), without the tilt terms.
OPENCV_COEFFS = ("k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6", "s1", "s2", "s3", "s4")
#: OpenCV fisheye = Kannala-Brandt (cv2.fisheye.projectPoints).
FISHEYE_COEFFS = ("k1", "k2", "k3", "k4")
#: Every coefficient name any model uses (the renderer's sensor carries all of them).
ALL_COEFFS = OPENCV_COEFFS


def _normalise_none(model: str, d: tuple) -> tuple:
    if any(d):
        raise ValueError("a pinhole camera has no distortion coefficients")
    return ()


def _normalise_opencv(model: str, d: tuple) -> tuple:
    if len(d) == 14:
        if d[12] or d[13]:
            raise ValueError("OpenCV tilt coefficients (tau_x, tau_y) are not supported")
        d = d[:12]
    if len(d) not in (4, 5, 8, 12):
        raise ValueError(
            "opencv distortion needs 4, 5, 8, 12 (or 14 with zero tilt) coefficients in OpenCV's"
            f" order k1, k2, p1, p2[, k3[, k4, k5, k6[, s1, s2, s3, s4]]], got {len(d)}")
    return d + (0.0,) * (12 - len(d))


def _normalise_fisheye(model: str, d: tuple) -> tuple:
    if len(d) != 4:
        raise ValueError(f"fisheye distortion needs 4 coefficients k1..k4, got {len(d)}")
    return d


@dataclass(frozen=True)
class CameraModel:
    """What a camera model is: its parameters and the functions that implement it."""

    name: str
    coefficients: tuple[str, ...]  # distortion coefficient names, in the order of `dist`
    dist_lengths: tuple[int, ...]  # accepted lengths of a `dist` vector as written (OpenCV's)
    wide_angle: bool  # projects by the angle theta to the axis: rays at or beyond 90 deg exist
    normalise_dist: Callable  # (model name, dist tuple) -> the stored coefficients; ValueError
    project: Callable  # (X, Y, Z, p, ops) -> (xd, yd, valid): camera points -> normalised distorted
    unproject: Callable  # (xd, yd, p, iterations, ops) -> unit ray (dx, dy, dz)
    fold_limit: Callable  # (p, width, height, describe) -> limit (r^2, or theta for wide_angle)
    undistortion: Callable | None  # (xd, yd, p) -> (bad mask, worst iterations); None: closed form
    opencv_fisheye: bool  # OpenCV's API for it is cv2.fisheye (else cv2.projectPoints & co.)
    to_opencv: Callable  # camera -> (K, dist) for that API
    to_colmap: Callable  # camera -> (COLMAP model name, params in COLMAP's pixel convention)


MODELS: dict[str, CameraModel] = {m.name: m for m in (
    CameraModel("pinhole", (), (0,), False, _normalise_none, arith.project_pinhole, arith.unproject_pinhole,
                validity.no_fold_limit, None, False, interop.opencv_perspective_arrays, interop.colmap_pinhole),
    CameraModel("opencv", OPENCV_COEFFS, (4, 5, 8, 12), False, _normalise_opencv, arith.project_opencv,
                arith.unproject_opencv, validity.opencv_fold_limit, validity.opencv_undistortion,
                False, interop.opencv_perspective_arrays, interop.colmap_opencv),
    CameraModel("fisheye", FISHEYE_COEFFS, (4,), True, _normalise_fisheye, arith.project_fisheye,
                arith.unproject_fisheye, validity.fisheye_fold_limit, validity.fisheye_undistortion,
                True, interop.opencv_fisheye_arrays, interop.colmap_fisheye),
)}
#: Model names in registry order (what a spec's ``model:`` accepts).
MODEL_NAMES = tuple(MODELS)


def camera_model(name: str) -> CameraModel:
    """The registered model ``name``; ValueError listing the models otherwise."""
    try:
        return MODELS[name]
    except (KeyError, TypeError):
        raise ValueError(f"camera model must be one of {MODEL_NAMES}, got {name!r}") from None


def project_xyz(X, Y, Z, p, model: str, ops=arith.NUMPY_OPS):
    """Camera-frame points -> pixels (u, v) and a validity mask, on numpy or Dr.Jit arrays.

    ``p`` carries fx, fy, cx, cy, skew, the model's coefficients and ``limit`` (the largest valid
    r^2 = x^2 + y^2 for perspective models, the largest valid theta for wide-angle ones, radians).
    Invalid points give NaN pixels.
    """
    xd, yd, valid = MODELS[model].project(X, Y, Z, p, ops)
    u = p.fx * xd + p.skew * yd + p.cx
    v = p.fy * yd + p.cy
    valid = valid & (u == u) & (v == v)  # NaN input -> invalid
    nan = ops.nan_like(u)
    return ops.select(valid, u, nan), ops.select(valid, v, nan), valid


def unproject_uv(u, v, p, model: str, iterations: int, ops=arith.NUMPY_OPS):
    """Pixels -> unit ray directions (dx, dy, dz) in the camera frame, on numpy or Dr.Jit arrays."""
    yd = (v - p.cy) / p.fy
    xd = (u - p.cx - p.skew * yd) / p.fx
    return MODELS[model].unproject(xd, yd, p, iterations, ops)

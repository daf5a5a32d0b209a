"""A calibration refined with a skew term: ``cv2.calibrateCamera`` has no skew (its camera matrix
keeps ``K[0, 1] = 0``), and a projector's principal point is often far off-centre with a skew the
optics give it; fitting one with the wrong model moves cx by pixels (about 1 px on
``scenes/sl_procam_calibration.yaml``'s projector with skew 0.4 px, exact corners). This refines
OpenCV's solution over (fx, fy, cx, cy, skew, k1, k2, p1, p2) and every view's pose by
``scipy.optimize.least_squares`` on the reprojection residuals, the projection being
``cv2.projectPoints`` (OpenCV's own distortion) plus ``skew * y_d`` on u, the project's camera
model (:mod:`scenegen.geometry.camera`: ``u = fx x_d + skew y_d + cx``).
"""
from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from scipy.optimize import least_squares


@dataclass(frozen=True)
class SkewCalibration:
    """A refined calibration: ``K`` (3, 3) with ``K[0, 1]`` the skew, ``dist`` (5,) k1 k2 p1 p2 k3
    (k3 as given, not refined), ``rms_px`` of the reprojection residuals."""

    K: np.ndarray
    dist: np.ndarray
    rms_px: float


def _project(params: np.ndarray, k3: float, obj: np.ndarray, rvec, tvec) -> np.ndarray:
    fx, fy, cx, cy, s, k1, k2, p1, p2 = params
    K = np.array([[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]])
    uv, _ = cv2.projectPoints(obj, rvec, tvec, K, np.array([k1, k2, p1, p2, k3]))
    uv = uv.reshape(-1, 2)
    yd = (uv[:, 1] - cy) / fy
    return np.stack([uv[:, 0] + s * yd, uv[:, 1]], axis=1)


def refine_with_skew(objs, pts, K, dist, rvecs, tvecs) -> SkewCalibration:
    """Refine a ``cv2.calibrateCamera`` solution (its K, dist, rvecs, tvecs over the views' board
    points ``objs`` (V lists of (N, 1, 3)) and image points ``pts`` (N, 1, 2)) with a skew."""
    d = np.asarray(dist, np.float64).ravel()
    d = np.concatenate([d, np.zeros(max(0, 5 - d.size))])
    x0 = np.concatenate([[K[0, 0], K[1, 1], K[0, 2], K[1, 2], K[0, 1], d[0], d[1], d[2], d[3]],
                         *[np.concatenate([np.ravel(r), np.ravel(t)]) for r, t in zip(rvecs, tvecs)]])
    objs = [np.asarray(o, np.float64).reshape(-1, 3) for o in objs]
    pts = [np.asarray(p, np.float64).reshape(-1, 2) for p in pts]

    def residuals(x):
        out = []
        for i, (o, p) in enumerate(zip(objs, pts)):
            pose = x[9 + 6 * i: 15 + 6 * i]
            out.append((_project(x[:9], d[4], o, pose[:3], pose[3:]) - p).ravel())
        return np.concatenate(out)

    sol = least_squares(residuals, x0, x_scale="jac", method="lm")
    fx, fy, cx, cy, s, k1, k2, p1, p2 = sol.x[:9]
    r = residuals(sol.x)
    return SkewCalibration(np.array([[fx, s, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]]),
                           np.array([k1, k2, p1, p2, d[4]]), float(np.sqrt(np.mean(r ** 2))))

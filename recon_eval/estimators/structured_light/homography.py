"""Board corners into the projector by local homographies (Moreno and Taubin, "Simple, accurate,
and robust projector-camera calibration", 3DIMPVT 2012, sec. 3.2): the decoded projector
coordinates of the camera pixels in a window around a corner are fitted by a homography (the
board is planar, so camera and projector images of it are related by one), least squares over
every decoded pixel (``cv2.findHomography`` method 0), and the corner's camera position is mapped
through it. The fit averages the codes' quantisation (one projector pixel) over the window, so
the corner lands at sub-pixel precision in the projector.
"""
from __future__ import annotations

import cv2
import numpy as np

from scenegen.geometry.conventions import pixel_centers


def corners_in_projector(corners_px, codes, *, half_window_px: int, min_points: int = 20) -> tuple[np.ndarray, np.ndarray]:
    """(projector points (N, 2), ok (N,) bool) of camera ``corners_px`` (N, 2) from ``codes``
    (H, W, 2) decoded projector (column, row) per camera pixel (NaN where none); a corner with
    fewer than ``min_points`` decoded pixels in its (2 w + 1)^2 window is not ok (NaN)."""
    c = np.asarray(corners_px, dtype=np.float64).reshape(-1, 2)
    H, W = codes.shape[:2]
    grid = pixel_centers(W, H)
    out = np.full((len(c), 2), np.nan)
    ok = np.zeros(len(c), bool)
    for n, (x, y) in enumerate(c):
        u0, u1 = max(0, int(round(x)) - half_window_px), min(W, int(round(x)) + half_window_px + 1)
        v0, v1 = max(0, int(round(y)) - half_window_px), min(H, int(round(y)) + half_window_px + 1)
        src = grid[v0:v1, u0:u1].reshape(-1, 2)
        dst = codes[v0:v1, u0:u1].reshape(-1, 2)
        good = np.all(np.isfinite(dst), axis=1)
        if good.sum() < min_points:
            continue
        Hm, _ = cv2.findHomography(src[good] - (x, y), dst[good], 0)  # centred: better conditioned
        if Hm is None:
            continue
        p = Hm @ np.array([0.0, 0.0, 1.0])
        out[n] = p[:2] / p[2]
        ok[n] = bool(np.all(np.isfinite(out[n])))
    return out, ok

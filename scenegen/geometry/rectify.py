"""Stereo rectification by Bouguet's method, as ``cv2.stereoRectify`` (flags
CALIB_ZERO_DISPARITY, alpha = -1, newImageSize = the left camera's size), numpy only.

With ``R, T`` the right-from-left pose (``X_r = R X_l + T``):

1. split the rotation in half: ``r_r = Rodrigues(-rodrigues(R) / 2)``, so each camera turns by
   half of it and the two become parallel;
2. rotate the half-turned baseline ``t = r_r T`` onto the x axis with ``w_R`` (the smallest
   rotation taking t to +-x);
3. ``R1 = w_R r_r^T`` (rect_left_from_left), ``R2 = w_R r_r`` (rect_right_from_right).

The rectified pinhole (no distortion, no skew) shared by both views: ``f`` = the mean of the two
cameras' fy (what OpenCV uses for alpha < 0); principal point ``(cx, cy)`` = OpenCV's choice:
for each camera the four image corners are unprojected (exactly, through our camera model),
rotated by R_k and projected with ``f``; the mean corner position is centred, and the two
cameras' centres are averaged (zero disparity at infinity: both views share cx). Only the
principal point differs from OpenCV's by the inexactness of ``cv2.undistortPoints``.

The rectified views are virtual cameras at the raw camera centres with poses
``cam_rect_from_world = (R_k, 0) @ cam_k_from_world``; the renderer renders them directly, so the
rectified images need no resampling and ``disparity = f B / Z`` is exact (B = baseline, Z depth
in the rectified left frame). Disparity sign: ``d = u_left - u_right >= 0`` for both maps (left
map on left pixels, right map on right pixels, so ``u_left = u_right + d_right``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.geometry.camera import Camera
from scenegen.geometry.conventions import corner_pixel_centers, pixel_centers
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.rotation import matrix_from_rotvec, rotvec_from_matrix


def bouguet_rotations(R, T) -> tuple[np.ndarray, np.ndarray]:
    """(R1, R2) rectifying rotations for the right-from-left pose (R, T); see module docstring."""
    om = rotvec_from_matrix(R)
    r_r = matrix_from_rotvec(-0.5 * om)
    t = r_r @ np.asarray(T, float)
    idx = 0 if abs(t[0]) > abs(t[1]) else 1  # horizontal stereo when |t_x| dominates
    c = t[idx]
    uu = np.zeros(3)
    uu[idx] = 1.0 if c > 0 else -1.0
    ww = np.cross(t, uu)
    nw = np.linalg.norm(ww)
    if nw > 0:
        ww *= np.arccos(min(1.0, abs(c) / np.linalg.norm(t))) / nw
    wR = matrix_from_rotvec(ww)
    return wR @ r_r.T, wR @ r_r


@dataclass(frozen=True, eq=False)
class Rectification:
    """A rectified stereo pair (OpenCV's stereoRectify outputs plus the virtual cameras)."""

    R1: np.ndarray  # (3, 3) rect_left_from_left
    R2: np.ndarray  # (3, 3) rect_right_from_right
    camera: Camera  # the shared rectified pinhole (size of the left camera)
    baseline_m: float  # |T|, metres; the right rectified camera is at (+baseline_m, 0, 0)
    cam_left_from_world: Rigid3  # rectified left pose
    cam_right_from_world: Rigid3  # rectified right pose

    @property
    def f(self) -> float:
        return self.camera.fx

    @property
    def P1(self) -> np.ndarray:
        """(3, 4) as cv2.stereoRectify: K [I | 0]."""
        return np.concatenate([self.camera.K, np.zeros((3, 1))], axis=1)

    @property
    def P2(self) -> np.ndarray:
        """(3, 4) as cv2.stereoRectify: K [I | (-B, 0, 0)], so P2[0, 3] = -f B."""
        P = self.P1.copy()
        P[0, 3] = -self.f * self.baseline_m
        return P

    @property
    def Q(self) -> np.ndarray:
        """(4, 4) disparity-to-depth matrix as cv2.stereoRectify (Tx = -B, equal cx)."""
        K = self.camera.K
        Tx = -self.baseline_m
        return np.array([[1.0, 0, 0, -K[0, 2]], [0, 1.0, 0, -K[1, 2]], [0, 0, 0, self.f], [0, 0, -1.0 / Tx, 0.0]])

    def to_dict(self) -> dict:
        return {"method": "Bouguet (as cv2.stereoRectify, CALIB_ZERO_DISPARITY, alpha=-1)",
                "R1": self.R1.tolist(), "R2": self.R2.tolist(), "P1": self.P1.tolist(),
                "P2": self.P2.tolist(), "Q": self.Q.tolist(), "K": self.camera.K.tolist(),
                "size": [self.camera.width, self.camera.height], "baseline_m": self.baseline_m,
                "camera": self.camera.to_dict(),
                "cam_left_from_world": self.cam_left_from_world.to_dict(),
                "cam_right_from_world": self.cam_right_from_world.to_dict(),
                "disparity": "d = u_left - u_right = f * baseline_m / depth_z_left >= 0"}


def rectify(left: Camera, cam_left_from_world: Rigid3, right: Camera, cam_right_from_world: Rigid3) -> Rectification:
    """Bouguet rectification of a stereo pair (see the module docstring)."""
    right_from_left = cam_right_from_world @ cam_left_from_world.inverse()
    R1, R2 = bouguet_rotations(right_from_left.R, right_from_left.t)
    f = 0.5 * (left.fy + right.fy)
    W, H = left.width, left.height
    centres = []
    for cam, Rk in ((left, R1), (right, R2)):
        rays = cam.unproject_unit(corner_pixel_centers(cam.width, cam.height)) @ Rk.T
        xy = rays[:, :2] / rays[:, 2:3] * f
        centres.append([(W - 1) / 2.0 - xy[:, 0].mean(), (H - 1) / 2.0 - xy[:, 1].mean()])
    cx, cy = np.mean(centres, axis=0)
    rect_cam = Camera("pinhole", W, H, f, f, float(cx), float(cy))
    baseline = float(np.linalg.norm(right_from_left.t))
    return Rectification(R1=R1, R2=R2, camera=rect_cam, baseline_m=baseline,
                         cam_left_from_world=Rigid3(R1, np.zeros(3)) @ cam_left_from_world,
                         cam_right_from_world=Rigid3(R2, np.zeros(3)) @ cam_right_from_world)


def rectification_map(raw: Camera, rect_from_raw_R, rect: Camera) -> np.ndarray:
    """(H, W, 2) float64: for each pixel of the rectified image, the raw (distorted) pixel that
    sees the same ray; ``cv2.remap(raw_image, map[..., 0], map[..., 1], ...)`` rectifies a raw
    image (what ``cv2.initUndistortRectifyMap`` computes). NaN outside the raw model's field."""
    grid = pixel_centers(rect.width, rect.height).reshape(-1, 2)
    rays_rect = rect.unproject_unit(grid)
    rays_raw = rays_rect @ np.asarray(rect_from_raw_R, float)  # R^T applied to each row
    uv = raw.project(rays_raw)
    return uv.reshape(rect.height, rect.width, 2)


def disparity_from_depth(depth_z, f_px: float, baseline_m: float) -> np.ndarray:
    """(H, W) float64 disparity ``d = f B / Z`` (px) of a rectified view from its z-depth (m);
    +inf where the depth is not finite or not positive."""
    z = np.asarray(depth_z, np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        d = f_px * baseline_m / z
    d[~(np.isfinite(z) & (z > 0))] = np.inf
    return d

"""Two-view geometry of two calibrated views (numpy only).

Conventions (docs/crossview.md):

* ``j_from_i`` maps camera-i points to camera-j points: ``X_j = R X_i + t`` (OpenCV axes, metres),
  i.e. ``cam_j_from_world @ cam_i_from_world.inverse()``; OpenCV's stereo ``R, T`` for i = left,
  j = right.
* ``E = [t]_x R``: ``x_j^T E x_i = 0`` for normalised coordinates ``x = (X / Z, Y / Z, 1)``
  (Hartley & Zisserman 2nd ed., eq. 9.12). E keeps the baseline's length (metres).
* ``F = K_j^-T E K_i^-1`` on UNDISTORTED pixels (OpenCV pixel centres): ``x_j^T F x_i = 0`` with
  ``x = K (X / Z, Y / Z, 1)``; distorted pixels must first go through
  :func:`undistorted_pixels` (the camera model's exact inverse). F is scaled to unit Frobenius
  norm (H&Z eq. 9.1 up to scale).
* Epipole ``e_i`` = image of camera j's centre in view i (undistorted pixels), ``F e_i = 0``;
  ``e_j`` = image of camera i's centre in view j, ``F^T e_j = 0``. Homogeneous, unit norm.
* Sampson error (H&Z eq. 11.9, = ``cv2.sampsonDistance``) and the symmetric epipolar distance
  (H&Z eq. 11.10) are squared pixel distances, px^2, of correspondences in undistorted pixels.
* Zero baseline (a pure rotation, or the same pose: the camera centres closer than
  :data:`ZERO_BASELINE_M`): E, F and the epipoles do not exist and are None (JSON null); every
  plane's homography is then the infinite homography ``K_j R K_i^-1``.
* Plane homography for a plane ``{X_i : n_i . X_i = d_i}`` (unit normal, d_i > 0 or < 0 in
  camera i's frame): ``H = K_j (R + t n_i^T / d_i) K_i^-1`` maps undistorted pixels of i to those
  of j for points on the plane (H&Z eq. 13.2). Scaled so that H[2, 2] = 1 when possible.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.geometry.pose import Rigid3

#: Camera centres closer than this (metres) are one centre: no epipolar geometry. Far above the
#: rounding of float64 poses at metre scale (~1e-16 m), far below any real baseline.
ZERO_BASELINE_M = 1e-9


def relative_pose(cam_i_from_world: Rigid3, cam_j_from_world: Rigid3) -> Rigid3:
    """``j_from_i = cam_j_from_world @ cam_i_from_world^-1``."""
    return cam_j_from_world @ cam_i_from_world.inverse()


def skew(t) -> np.ndarray:
    """[t]_x: (3, 3) with ``[t]_x v = t x v``."""
    x, y, z = np.asarray(t, dtype=np.float64)
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def essential(j_from_i: Rigid3) -> np.ndarray:
    """(3, 3) E = [t]_x R; x_j^T E x_i = 0 on normalised coordinates; |t| in metres."""
    return skew(j_from_i.t) @ j_from_i.R


def fundamental(K_i, K_j, j_from_i: Rigid3) -> np.ndarray:
    """(3, 3) F = K_j^-T E K_i^-1 on undistorted pixels, unit Frobenius norm."""
    F = np.linalg.inv(np.asarray(K_j, float)).T @ essential(j_from_i) @ np.linalg.inv(np.asarray(K_i, float))
    return F / np.linalg.norm(F)


def epipoles(K_i, K_j, j_from_i: Rigid3) -> tuple[np.ndarray, np.ndarray]:
    """(e_i, e_j): homogeneous (3,) unit-norm epipoles in undistorted pixels of i and j."""
    c_j_in_i = j_from_i.inverse().t  # camera j's centre in frame i
    e_i = np.asarray(K_i, float) @ c_j_in_i
    e_j = np.asarray(K_j, float) @ j_from_i.t  # camera i's centre (origin of i) in frame j
    return e_i / np.linalg.norm(e_i), e_j / np.linalg.norm(e_j)


def epipole_pixel(e) -> list[float] | None:
    """(u, v) of a homogeneous epipole, or None when it lies at infinity (|e_z| < 1e-12 |e|)."""
    e = np.asarray(e, float)
    if abs(e[2]) < 1e-12 * np.linalg.norm(e):
        return None
    return [float(e[0] / e[2]), float(e[1] / e[2])]


def plane_homography(K_i, K_j, j_from_i: Rigid3, n_i, d_i: float) -> np.ndarray:
    """(3, 3) H = K_j (R + t n_i^T / d_i) K_i^-1 for the plane n_i . X_i = d_i (frame i, metres)."""
    n_i = np.asarray(n_i, float)
    H = np.asarray(K_j, float) @ (j_from_i.R + np.outer(j_from_i.t, n_i) / float(d_i)) @ np.linalg.inv(np.asarray(K_i, float))
    return H / H[2, 2] if abs(H[2, 2]) > 1e-12 * np.linalg.norm(H) else H / np.linalg.norm(H)


def plane_in_camera(cam_from_world: Rigid3, normal_world, point_world) -> tuple[np.ndarray, float]:
    """(n_cam (3,), d_cam) of a world plane through ``point_world`` with normal ``normal_world``:
    the plane is ``{X_cam : n_cam . X_cam = d_cam}``."""
    n = cam_from_world.rotate(np.asarray(normal_world, float))
    n = n / np.linalg.norm(n)
    return n, float(n @ cam_from_world.apply(np.asarray(point_world, float)))


def undistorted_pixels(camera, uv) -> np.ndarray:
    """(N, 2) undistorted pixels ``K (x, y, 1)`` of (N, 2) pixels of ``camera`` (its model's exact
    inverse; NaN where the ray has no z = 1 point). A pinhole camera's pixels are returned as
    they are (they are undistorted already)."""
    uv = np.asarray(uv, np.float64)
    if camera.model == "pinhole" or len(uv) == 0:
        return uv
    xy1 = camera.unproject(uv)  # (N, 3) on z = 1, through the camera's own model
    return xy1[:, :2] @ camera.K[:2, :2].T + camera.K[:2, 2]


def homogeneous(uv) -> np.ndarray:
    uv = np.asarray(uv, float)
    return np.concatenate([uv, np.ones((len(uv), 1))], axis=1)


def _epipolar_terms(F, x_i, x_j):
    """(x_j^T F x_i, F x_i (N, 3), F^T x_j (N, 3)) of correspondences (N, 2) x (N, 2)."""
    F = np.asarray(F, float)
    a, b = homogeneous(x_i), homogeneous(x_j)
    Fa = a @ F.T  # (N, 3) = F x_i: lines in image j
    Ftb = b @ F  # (N, 3) = F^T x_j: lines in image i
    return np.sum(b * Fa, axis=1), Fa, Ftb


def sampson_error(F, x_i, x_j) -> np.ndarray:
    """(N,) Sampson error in px^2 of correspondences x_i -> x_j (N, 2) undistorted pixels:
    (x_j^T F x_i)^2 / ((F x_i)_1^2 + (F x_i)_2^2 + (F^T x_j)_1^2 + (F^T x_j)_2^2)
    (H&Z eq. 11.9; the same quantity as ``cv2.sampsonDistance``)."""
    r, Fa, Ftb = _epipolar_terms(F, x_i, x_j)
    return r ** 2 / (Fa[:, 0] ** 2 + Fa[:, 1] ** 2 + Ftb[:, 0] ** 2 + Ftb[:, 1] ** 2)


def symmetric_epipolar_error(F, x_i, x_j) -> np.ndarray:
    """(N,) symmetric epipolar distance in px^2: the squared distance of x_j to the line F x_i
    plus that of x_i to the line F^T x_j (H&Z eq. 11.10)."""
    r, Fa, Ftb = _epipolar_terms(F, x_i, x_j)
    return r ** 2 * (1.0 / (Fa[:, 0] ** 2 + Fa[:, 1] ** 2) + 1.0 / (Ftb[:, 0] ** 2 + Ftb[:, 1] ** 2))


def apply_homography(H, x) -> np.ndarray:
    """(N, 2) pixels ``H x`` of (N, 2) pixels (dehomogenised)."""
    y = homogeneous(x) @ np.asarray(H, float).T
    with np.errstate(divide="ignore", invalid="ignore"):  # points mapped to infinity -> inf/NaN
        return y[:, :2] / y[:, 2:3]


@dataclass(frozen=True, eq=False)
class TwoView:
    """Two-view geometry of views i -> j (see the module docstring for conventions)."""

    j_from_i: Rigid3  # X_j = R X_i + t, metres
    E: np.ndarray | None  # (3, 3) essential, normalised coordinates; None for a zero baseline
    F: np.ndarray | None  # (3, 3) fundamental, undistorted pixels, unit Frobenius norm; likewise
    epipole_i: np.ndarray | None  # (3,) homogeneous, undistorted pixels of i; likewise
    epipole_j: np.ndarray | None  # (3,) homogeneous, undistorted pixels of j; likewise

    @classmethod
    def of(cls, camera_i, cam_i_from_world: Rigid3, camera_j, cam_j_from_world: Rigid3) -> "TwoView":
        rel = relative_pose(cam_i_from_world, cam_j_from_world)
        if np.linalg.norm(rel.t) < ZERO_BASELINE_M:  # one centre: F = 0 / 0
            return cls(rel, None, None, None, None)
        e_i, e_j = epipoles(camera_i.K, camera_j.K, rel)
        return cls(rel, essential(rel), fundamental(camera_i.K, camera_j.K, rel), e_i, e_j)

    def to_dict(self) -> dict:
        lst = lambda a: None if a is None else a.tolist()
        px = lambda e: None if e is None else epipole_pixel(e)
        return {"j_from_i": self.j_from_i.to_dict(), "baseline_m": float(np.linalg.norm(self.j_from_i.t)),
                "E": lst(self.E), "F": lst(self.F),
                "epipole_i": lst(self.epipole_i), "epipole_j": lst(self.epipole_j),
                "epipole_i_px": px(self.epipole_i), "epipole_j_px": px(self.epipole_j)}

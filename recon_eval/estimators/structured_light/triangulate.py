"""Triangulation of structured-light codes: a camera pixel's ray against what the projector coded.

* :func:`ray_column`: the ray against projector column ``u`` (Lanman and Taubin 2009, sec. 6.1,
  ray-plane). For a pinhole projector (skew included) the pixels of column ``u`` lie on the plane
  ``fx x + s y + (cx - u) z = 0`` of the projector frame, spanned here by the rays of two of its
  pixels; the ray meets it in closed form. A distorted projector's column is a curved surface: the
  plane's hit is refined by Newton steps on the projector's own forward model,
  ``project(o + t d)_u = u`` (a 1-D root along the ray), to float precision.
* :func:`ray_ray`: the midpoint of the shortest segment between the camera ray and the projector
  ray of a decoded (column, row) (Hartley and Zisserman, 2nd ed., sec. 12.2 notes it is not
  projective-invariant; with exact calibrations it is exact for exact codes).
* :func:`column_quantisation_bound`: a column code names a projector pixel, i.e. ``u`` within
  ``[c - 0.5, c + 0.5)``; the point triangulated at the centre ``c`` lies within the larger of the
  distances to the points at ``c - 0.5`` and ``c + 0.5`` along the camera ray (the hit moves
  monotonically along the ray with ``u``): the reconstruction error bound of the pattern's
  resolution, per pixel.

Poses are ``cam_from_world`` / ``proj_from_world`` (:class:`scenegen.geometry.pose.Rigid3`);
cameras and projectors are :class:`scenegen.geometry.camera.Camera`. Points are world metres.
"""
from __future__ import annotations

import numpy as np

from scenegen.geometry.pose import Rigid3

#: Newton steps of the curved-column refinement: the plane's hit starts within the distortion's
#: few pixels; each step squares the relative error, so 6 steps reach float64 precision.
NEWTON_STEPS = 6


def _camera_rays_in(frame_from_world: Rigid3, camera, cam_from_world: Rigid3, pixels) -> tuple[np.ndarray, np.ndarray]:
    """(origin (3,), unit directions (N, 3)) of the camera's pixel rays in another frame."""
    frame_from_cam = frame_from_world @ cam_from_world.inverse()
    d = frame_from_cam.rotate(camera.unproject_unit(np.asarray(pixels, dtype=np.float64).reshape(-1, 2)))
    return frame_from_cam.t.copy(), d


def ray_column(camera, cam_from_world: Rigid3, projector, proj_from_world: Rigid3, pixels, columns_px) -> np.ndarray:
    """(N, 3) world points where the rays of camera ``pixels`` (N, 2) meet projector columns
    ``columns_px`` (N,) (continuous u); NaN where the ray is parallel to the column or meets it
    behind the camera."""
    o, d = _camera_rays_in(proj_from_world, camera, cam_from_world, pixels)
    u = np.asarray(columns_px, dtype=np.float64).reshape(-1)
    top = projector.unproject_unit(np.stack([u, np.zeros_like(u)], axis=1))
    bottom = projector.unproject_unit(np.stack([u, np.full_like(u, projector.height - 1.0)], axis=1))
    n = np.cross(top, bottom)  # the column plane's normal (through the projector centre)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = -(n @ o) / np.einsum("ij,ij->i", n, d)
        for _ in range(NEWTON_STEPS if projector.dist and any(projector.dist) else 0):
            h = 1e-7 * np.maximum(np.abs(t), 1e-3)
            f0 = projector.project(o + t[:, None] * d)[:, 0] - u
            f1 = projector.project(o + (t + h)[:, None] * d)[:, 0] - u
            step = f0 * h / (f1 - f0)
            t = t - np.where(np.isfinite(step), step, 0.0)
    t = np.where(t > 0, t, np.nan)
    return proj_from_world.inverse().apply(o + t[:, None] * d)


def ray_ray(camera, cam_from_world: Rigid3, projector, proj_from_world: Rigid3, pixels, proj_uv_px) -> np.ndarray:
    """(N, 3) world midpoints between camera rays of ``pixels`` (N, 2) and projector rays of the
    decoded ``proj_uv_px`` (N, 2); NaN for parallel rays."""
    o1, d1 = _camera_rays_in(Rigid3.identity(), camera, cam_from_world, pixels)
    o2, d2 = _camera_rays_in(Rigid3.identity(), projector, proj_from_world, proj_uv_px)
    w = o1 - o2
    b = np.einsum("ij,ij->i", d1, d2)
    dd, e = d1 @ w, d2 @ w
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = 1.0 - b * b  # unit directions
        s = (b * e - dd) / denom
        t = (e - b * dd) / denom
    return 0.5 * ((o1 + s[:, None] * d1) + (o2 + t[:, None] * d2))


def column_quantisation_bound(camera, cam_from_world: Rigid3, projector, proj_from_world: Rigid3, pixels,
                              columns) -> np.ndarray:
    """(N,) metres: the largest distance, along each camera ray, between the point triangulated at
    integer column ``columns`` and the points at ``columns -+ 0.5`` (module docstring)."""
    c = np.asarray(columns, dtype=np.float64).reshape(-1)
    mid = ray_column(camera, cam_from_world, projector, proj_from_world, pixels, c)
    lo = ray_column(camera, cam_from_world, projector, proj_from_world, pixels, c - 0.5)
    hi = ray_column(camera, cam_from_world, projector, proj_from_world, pixels, c + 0.5)
    return np.maximum(np.linalg.norm(lo - mid, axis=1), np.linalg.norm(hi - mid, axis=1))

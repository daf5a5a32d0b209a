"""Dense correspondences: where each pixel of view i lands in view j, and whether j sees it.

For pixel p of view i with truth point P (world, float64 from the truth pass), its correspondence
is ``camera_j.project(cam_j_from_world @ P)``: j's full camera model, distortion included, in
OpenCV pixels (centre of the top-left pixel = (0, 0)). Its state:

* ``NO_SURFACE`` (0): pixel i saw nothing (no P);
* ``VISIBLE`` (1): P projects inside j's image and nothing lies between j's centre and P
  (decided by a ray cast, tolerance :data:`scenegen.render.raycast.OCCLUSION_REL_TOL`);
* ``OCCLUDED`` (2): inside j's image but another surface is hit first;
* ``OUT_OF_FRAME`` (3): P projects outside [-0.5, W - 0.5] x [-0.5, H - 0.5], behind j, or beyond
  j's model's valid field of view.

numpy only: the visibility test is a function passed in (:func:`scenegen.render.raycast.visible_from`
bound to a scene in the pipeline). The states and the stored form are the dataset's
(:mod:`scenegen.dataset.crossview`).
"""
from __future__ import annotations

from typing import Callable

import numpy as np

from scenegen.dataset.crossview import NO_SURFACE, OCCLUDED, OUT_OF_FRAME, VISIBLE, Correspondence
from scenegen.geometry.conventions import in_image
from scenegen.geometry.pose import Rigid3


def finite_rows(points) -> np.ndarray:
    """(N,) bool: every coordinate of the point (N, 3) is finite (``np.all(np.isfinite(p), axis=1)``,
    without numpy's slow reduction over a length-3 axis)."""
    return np.isfinite(points[:, 0]) & np.isfinite(points[:, 1]) & np.isfinite(points[:, 2])


def project_points(points_world, camera, cam_from_world: Rigid3):
    """((N, 2) pixels, (N,) z in the camera frame, (N,) valid projection) of world points (N, 3)."""
    P_cam = cam_from_world.apply(np.asarray(points_world, np.float64))
    uv, valid = camera.project(P_cam, return_valid=True)
    return uv, P_cam[:, 2], valid


def correspond(points_world_i, camera_j, cam_j_from_world: Rigid3,
               visible_fn: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> Correspondence:
    """Correspondence field of the truth points (H, W, 3) (float64, NaN = no surface) of view i in
    view j. ``visible_fn(center_world (3,), points_world (M, 3)) -> (M,) bool``."""
    P = np.asarray(points_world_i, np.float64)
    H, W, _ = P.shape
    flat = P.reshape(-1, 3)
    has = finite_rows(flat)
    uv = np.full((len(flat), 2), np.nan)
    z = np.full(len(flat), np.nan)
    state = np.full(len(flat), NO_SURFACE, np.uint8)
    idx = np.flatnonzero(has)
    uv_h, z_h, valid = project_points(flat[idx], camera_j, cam_j_from_world)
    uv[idx], z[idx] = uv_h, z_h
    inside = valid & in_image(uv_h, camera_j.width, camera_j.height)
    state[idx] = OUT_OF_FRAME
    cand = idx[inside]
    vis = np.asarray(visible_fn(cam_j_from_world.inverse().t, flat[cand]), bool)
    state[cand] = np.where(vis, VISIBLE, OCCLUDED)
    return Correspondence(uv.reshape(H, W, 2), z.reshape(H, W), state.reshape(H, W))


def flow_field(c: Correspondence) -> np.ndarray:
    """(H, W, 2) float64 optical flow (u_j - u_i, v_j - v_i) for every pixel whose point projects
    into j's model (visible, occluded or out of frame); NaN where unknown."""
    H, W = c.state.shape
    grid = np.stack(np.meshgrid(np.arange(W, dtype=np.float64), np.arange(H, dtype=np.float64)), -1)
    return c.uv - grid

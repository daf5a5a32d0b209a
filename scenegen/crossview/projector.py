"""A projector-lit view's per-pixel truth (:class:`scenegen.dataset.structured_light.ProjectorTruth`)
from the view's stored truth points, in numpy: the projector as an inverse camera.

The projector pixel of a camera pixel is the projection of the view's stored ``points_world``
(float32, taken exactly, computed in float64) through the projector's model
(:meth:`scenegen.geometry.camera.Camera.project`, distortion and skew included).
The pixel a perfect decoder reads is the one whose square covers it: column ``floor(u + 0.5)``,
row ``floor(v + 0.5)`` (:func:`scenegen.geometry.sl_codes.pixel_index`; OpenCV centres), the same
rule as the renderer's pattern lookup (:mod:`scenegen.render.projector`). A point is lit when that pixel
lies in the projector's image, the side of the surface the camera sees faces the projector
centre, and the visibility cast from the projector centre reaches the point (a separate ray cast:
projector shadows).
"""
from __future__ import annotations

import numpy as np

from scenegen.dataset.structured_light import ProjectorTruth
from scenegen.geometry.camera import Camera
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.sl_codes import OUTSIDE, binary_to_gray, pixel_index


def projector_pixels(points_world, projector: Camera, projector_from_world: Rigid3) -> np.ndarray:
    """(..., 2) float64 projector pixels of world points (..., 3); NaN where invalid."""
    P = np.asarray(points_world, np.float64)
    flat = P.reshape(-1, 3)
    uv = np.full((len(flat), 2), np.nan)
    ok = np.isfinite(flat).all(axis=1)
    if ok.any():
        uv[ok] = projector.project(projector_from_world.apply(flat[ok]))
    return uv.reshape(P.shape[:-1] + (2,))


def projector_lit(points_world, normals_world, camera_center_world, projector: Camera,
                  projector_from_world: Rigid3, visible):
    """(uv (H, W, 2) projector pixels, lit (H, W) bool, column, row (H, W) int): the stored points
    projected through the projector, and whether the projector lights them (inside its image,
    facing it on the camera's side, nothing between: ``visible``'s cast), as
    :func:`projector_truth` states them (an active stereo frame needs only these)."""
    P = np.asarray(points_world, np.float64)
    N = np.asarray(normals_world, np.float64)
    H, W = P.shape[:2]
    uv = projector_pixels(P, projector, projector_from_world)
    center = projector_from_world.inverse().t
    col = pixel_index(uv[..., 0], projector.width)
    row = pixel_index(uv[..., 1], projector.height)
    inside = (col != OUTSIDE) & (row != OUTSIDE)
    with np.errstate(invalid="ignore"):
        facing_cam = np.sign(np.einsum("hwk,hwk->hw", N, np.asarray(camera_center_world, np.float64) - P))
        facing_proj = np.einsum("hwk,hwk->hw", N, center - P) * facing_cam > 0
    lit = inside & facing_proj
    idx = np.flatnonzero(lit.ravel())
    if len(idx):
        seen = visible(center, P.reshape(-1, 3)[idx])
        flat = lit.ravel()
        flat[idx] = np.asarray(seen, bool)
        lit = flat.reshape(H, W)
    return uv, lit, col, row


def projector_truth(points_world, normals_world, camera_center_world, projector: Camera,
                    projector_from_world: Rigid3, visible, corner_points_world) -> ProjectorTruth:
    """The truth of one view (module docstring). ``points_world``, ``normals_world``: (H, W, 3)
    as stored (NaN = no surface); ``visible(center (3,), points (N, 3)) -> (N,) bool``: the
    visibility cast of the scene at the view's time; ``corner_points_world`` (H + 1, W + 1, 3):
    the points seen through the pixel corners (OpenCV (u, v) = (i - 0.5, j - 0.5), NaN = none),
    for the clear masks."""
    uv, lit, col, row = projector_lit(points_world, normals_world, camera_center_world, projector,
                                      projector_from_world, visible)
    center = projector_from_world.inverse().t
    column = np.where(lit, col, OUTSIDE).astype(np.int32)
    row_i = np.where(lit, row, OUTSIDE).astype(np.int32)
    gray = lambda a: np.where(a >= 0, binary_to_gray(np.maximum(a, 0)), OUTSIDE).astype(np.int32)
    clear_column, clear_row = _clear(corner_points_world, projector, projector_from_world, center, visible,
                                     lit, column, row_i)
    return ProjectorTruth(uv=uv, lit=lit, column=column, row=row_i, gray_column=gray(column), gray_row=gray(row_i),
                          clear_column=clear_column, clear_row=clear_row)


def _clear(corners, projector: Camera, projector_from_world: Rigid3, center, visible, lit, column, row):
    """(clear_column, clear_row) (H, W) bool: lit pixels whose four corner rays meet points the
    projector lights (inside its image, nothing between) in the pixel's own column (row)."""
    C = np.asarray(corners, np.float64)
    cuv = projector_pixels(C, projector, projector_from_world)
    ccol = pixel_index(cuv[..., 0], projector.width)
    crow = pixel_index(cuv[..., 1], projector.height)
    seen = (ccol != OUTSIDE) & (crow != OUTSIDE)
    idx = np.flatnonzero(seen.ravel())
    if len(idx):
        flat = seen.ravel()
        flat[idx] = np.asarray(visible(center, C.reshape(-1, 3)[idx]), bool)
        seen = flat.reshape(seen.shape)
    quad = lambda a: (a[:-1, :-1], a[:-1, 1:], a[1:, :-1], a[1:, 1:])
    corners_seen = np.logical_and.reduce(quad(seen))
    same = lambda c, own: np.logical_and.reduce([q == own for q in quad(c)])
    return lit & corners_seen & same(ccol, column), lit & corners_seen & same(crow, row)

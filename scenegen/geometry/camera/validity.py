"""Where a camera model is valid, and how many Newton steps its undistortion needs (numpy).

Validity: a distortion whose mapping folds over (Jacobian determinant <= 0) at a pixel inside the
image is rejected with ``ValueError`` naming that pixel. The fold radius is searched along 120
directions (1500 radii each, 0.06 degree steps); points beyond it (outside the monotonic region)
project to NaN. The limit is an r^2 = x^2 + y^2 for perspective models, a theta (radians) for
the fisheye.

Iterations: undistortion is Newton's method from the distorted point with a fixed iteration
count per camera (a branch-free Dr.Jit kernel). At construction the camera measures, over its
whole pixel border plus an interior grid, how many iterations the worst pixel needs to reach
:data:`UNDISTORT_TOL_PX` of reprojection residual in float64, and adds one.
"""
from __future__ import annotations

import math

import numpy as np

from scenegen.geometry.camera.arith import (
    distort_opencv_jacobian_xy,
    distort_opencv_xy,
    fisheye_dtheta_d,
    fisheye_newton_step,
    fisheye_theta_d,
    newton_step_opencv_xy,
)
from scenegen.geometry.conventions import in_image

#: Reprojection residual (px, float64) that sets each camera's undistortion iteration count.
UNDISTORT_TOL_PX = 1e-10
#: Newton iterations beyond which undistortion is declared non-convergent.
MAX_UNDISTORT_ITERATIONS = 60
#: Largest angle from the optical axis searched for a perspective model (degrees).
MAX_PERSPECTIVE_ANGLE_DEG = 89.9
#: Directions and radii of the fold search.
FOLD_DIRECTIONS = 120
FOLD_RADII = 1500


def pixel_grid_border_and_interior(width: int, height: int, step: int) -> np.ndarray:
    """(N, 2) pixel positions: every pixel of the extreme border [-0.5, W-0.5] x [-0.5, H-0.5]
    plus an interior grid with ``step`` px spacing."""
    us = np.arange(width, dtype=np.float64)
    vs = np.arange(height, dtype=np.float64)
    x0, x1, y0, y1 = -0.5, width - 0.5, -0.5, height - 0.5
    border = np.concatenate([
        np.stack([us, np.full_like(us, y0)], 1), np.stack([us, np.full_like(us, y1)], 1),
        np.stack([np.full_like(vs, x0), vs], 1), np.stack([np.full_like(vs, x1), vs], 1),
        np.array([[x0, y0], [x1, y0], [x0, y1], [x1, y1]]),
    ])
    gu, gv = np.meshgrid(np.arange(0, width, step, dtype=float), np.arange(0, height, step, dtype=float))
    return np.concatenate([border, np.stack([gu.ravel(), gv.ravel()], 1)])


class FoldError(ValueError):
    """A distortion that folds over inside the image (refused unless the camera opts in to
    masking the pixels beyond the fold)."""


def _reject_if_inside(xd, yd, p, width: int, height: int, what: str, describe: str) -> None:
    if getattr(p, "mask_beyond_fold", False):
        return  # opted in: the pixels beyond the fold get no ray (fold_region_polygon)
    xd, yd = np.atleast_1d(xd), np.atleast_1d(yd)
    u = p.fx * xd + p.skew * yd + p.cx
    v = p.fy * yd + p.cy
    inside = in_image(np.stack([u, v], axis=1), width, height)
    if inside.any():
        i = np.argmax(inside)
        raise FoldError(
            f"{describe} folds over inside the {width}x{height} image: {what} at pixel ({u[i]:.1f},"
            f" {v[i]:.1f}); the mapping is not monotonic in radius there")


# --- fold limits (p: fx, fy, cx, cy, skew and the model's coefficients) ------------------------
def no_fold_limit(p, width: int, height: int, describe: str) -> float:
    return math.inf


def opencv_fold_limit(p, width: int, height: int, describe: str) -> float:
    """The largest r^2 before the Jacobian determinant first reaches 0 along any direction."""
    phi = np.linspace(0.0, 2 * np.pi, FOLD_DIRECTIONS, endpoint=False)[:, None]
    ang = np.radians(np.linspace(0.0, MAX_PERSPECTIVE_ANGLE_DEG, FOLD_RADII + 1)[1:])[None, :]
    r = np.tan(ang)
    x, y = r * np.cos(phi), r * np.sin(phi)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        xd, yd, j11, j12, j21, j22 = distort_opencv_jacobian_xy(x, y, p)
        det = j11 * j22 - j12 * j21
    folded = ~(det > 0)
    first = np.where(folded.any(axis=1), folded.argmax(axis=1), -1)
    rows = np.flatnonzero(first >= 0)
    if rows.size == 0:
        return math.inf
    _reject_if_inside(xd[rows, first[rows]], yd[rows, first[rows]], p, width, height,
                      "the Jacobian determinant reaches 0", describe)
    r_prev = np.where(first[rows] > 0, r[0, np.maximum(first[rows] - 1, 0)], 0.0)
    return float(np.min(r_prev) ** 2)


def fisheye_fold_limit(p, width: int, height: int, describe: str) -> float:
    """The largest theta (radians) before d theta_d / d theta first reaches 0 (at most pi)."""
    phi = np.linspace(0.0, 2 * np.pi, FOLD_DIRECTIONS, endpoint=False)
    theta = np.linspace(0.0, np.pi, 4001)[1:]
    fold = np.flatnonzero(fisheye_dtheta_d(theta, p) <= 0)
    if fold.size == 0:
        return math.pi
    t_fold = theta[fold[0]]
    td = fisheye_theta_d(t_fold, p)
    _reject_if_inside(td * np.cos(phi), td * np.sin(phi), p, width, height,
                      f"theta = {math.degrees(t_fold):.2f} deg", describe)
    return float(theta[fold[0] - 1]) if fold[0] > 0 else 0.0


# --- undistortion iteration counts ---------------------------------------------------------------
def newton_until_converged(state, residual_px, step):
    """Iterate ``step`` from ``state`` until every point's residual (px) is <= UNDISTORT_TOL_PX.

    Returns (final state, converged mask, the iteration count the slowest converged point needed).
    """
    done = None
    worst = 0
    for it in range(MAX_UNDISTORT_ITERATIONS + 1):
        res = residual_px(state)
        done = np.zeros(res.shape, bool) if done is None else done
        newly = ~done & (res <= UNDISTORT_TOL_PX)
        if newly.any():
            worst = it
        done |= newly
        if done.all():
            break
        state = step(state)
    return state, done, worst


def opencv_undistortion(xd, yd, p) -> tuple[np.ndarray, int]:
    """(bad mask, iterations of the worst point) of undistorting (xd, yd); ``p.limit`` is r^2."""
    def residual_px(xy):
        ex, ey = distort_opencv_xy(xy[0], xy[1], p)
        return np.hypot((ex - xd) * p.fx, (ey - yd) * p.fy)

    (x, y), done, worst = newton_until_converged(
        (xd, yd), residual_px, lambda xy: newton_step_opencv_xy(xy[0], xy[1], xd, yd, p))
    return ~done | (x * x + y * y > p.limit), worst


def fisheye_undistortion(xd, yd, p) -> tuple[np.ndarray, int]:
    """(bad mask, iterations of the worst point) of undistorting (xd, yd); ``p.limit`` is theta."""
    theta_d = np.hypot(xd, yd)
    theta, done, worst = newton_until_converged(
        theta_d, lambda th: np.abs(fisheye_theta_d(th, p) - theta_d) * min(p.fx, p.fy),
        lambda th: fisheye_newton_step(th, theta_d, p))
    return ~done | (theta > p.limit), worst


def fold_region_polygon(p, n: int = 720) -> tuple[np.ndarray, np.ndarray]:
    """(xd, yd) (n,) of the image of the valid disk's boundary (r^2 = ``p.limit``) under the
    OpenCV distortion: the pixels with a ray lie inside this closed curve."""
    psi = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    r = math.sqrt(p.limit)
    return distort_opencv_xy(r * np.cos(psi), r * np.sin(psi), p)


def inside_polygon(x, y, px, py) -> np.ndarray:
    """(N,) bool: points (x, y) inside the closed polygon (px, py) (even-odd crossings)."""
    x, y = np.asarray(x, np.float64)[:, None], np.asarray(y, np.float64)[:, None]
    x0, y0 = px[None, :], py[None, :]
    x1, y1 = np.roll(px, -1)[None, :], np.roll(py, -1)[None, :]
    with np.errstate(invalid="ignore", divide="ignore"):
        cross = ((y0 > y) != (y1 > y)) & (x < (x1 - x0) * (y - y0) / (y1 - y0) + x0)
    return (np.count_nonzero(cross, axis=1) % 2) == 1


def measure_undistortion(measure, p, width: int, height: int, model: str) -> int:
    """The undistortion iteration count of a camera (worst pixel + 1); ValueError naming the first
    pixel whose ray lies outside the model's valid region. ``p`` carries ``limit``. A camera that
    masks the pixels beyond its fold (``p.mask_beyond_fold``) excludes the pixels outside
    :func:`fold_region_polygon` (they get no ray); every pixel inside must still converge."""
    grid = pixel_grid_border_and_interior(width, height, max(1, min(width, height) // 64))
    yd = (grid[:, 1] - p.cy) / p.fy
    xd = (grid[:, 0] - p.cx - p.skew * yd) / p.fx
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        bad, worst = measure(xd, yd, p)
    if getattr(p, "mask_beyond_fold", False) and math.isfinite(p.limit):
        bad = bad & inside_polygon(xd, yd, *fold_region_polygon(p))
    if bad.any():
        u, v = grid[np.argmax(bad)]
        raise ValueError(
            f"{model} camera: pixel ({u:.1f}, {v:.1f}) of the {width}x{height} image has no"
            " ray inside the distortion's valid (monotonic) region; the distortion folds over or the"
            " image extends beyond the model's field of view")
    return worst + 1

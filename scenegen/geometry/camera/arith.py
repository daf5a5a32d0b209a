"""The camera models' arithmetic, written once for numpy (float64) and Dr.Jit (float32).

Every function takes an ``ops`` object with ``sqrt``, ``atan2``, ``sin``, ``cos``, ``select`` and
``nan_like``, and uses only those plus + - * /, so the same lines run on numpy arrays (the
evaluator, the truth pass) and on Dr.Jit arrays (the renderer's rays). :data:`NUMPY_OPS` is the
numpy set; the Dr.Jit set lives with the renderer (:mod:`scenegen.render.drjit_ops`), the only
place that imports Dr.Jit. Parameters ``p`` are plain attributes (``fx, fy, cx, cy, skew``, the
model's coefficients, ``limit``): Python floats here, opaque Dr.Jit floats in the sensor.

Formulas and parameter orders: :mod:`scenegen.geometry.camera` (OpenCV's, COLMAP's).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np


@dataclass(frozen=True)
class ArrayOps:
    """The array operations the camera arithmetic uses besides + - * /."""

    sqrt: Callable
    atan2: Callable  # atan2(y, x)
    sin: Callable
    cos: Callable
    select: Callable  # select(condition, if_true, if_false)
    nan_like: Callable  # an array of NaN shaped like its argument


NUMPY_OPS = ArrayOps(np.sqrt, np.arctan2, np.sin, np.cos, np.where, lambda x: np.full(np.shape(x), np.nan))


# --- Brown-Conrady with OpenCV's rational and thin-prism terms ----------------------------------
def distort_opencv_xy(x, y, p):
    """OpenCV distortion of normalised coordinates (x, y) -> (xd, yd); p has k1..k6, p1, p2, s1..s4."""
    r2 = x * x + y * y
    num = 1.0 + r2 * (p.k1 + r2 * (p.k2 + r2 * p.k3))
    den = 1.0 + r2 * (p.k4 + r2 * (p.k5 + r2 * p.k6))
    radial = num / den
    xd = x * radial + 2.0 * p.p1 * x * y + p.p2 * (r2 + 2.0 * x * x) + r2 * (p.s1 + r2 * p.s2)
    yd = y * radial + p.p1 * (r2 + 2.0 * y * y) + 2.0 * p.p2 * x * y + r2 * (p.s3 + r2 * p.s4)
    return xd, yd


def distort_opencv_jacobian_xy(x, y, p):
    """(xd, yd, dxd/dx, dxd/dy, dyd/dx, dyd/dy) of :func:`distort_opencv_xy`."""
    r2 = x * x + y * y
    num = 1.0 + r2 * (p.k1 + r2 * (p.k2 + r2 * p.k3))
    den = 1.0 + r2 * (p.k4 + r2 * (p.k5 + r2 * p.k6))
    dnum = p.k1 + r2 * (2.0 * p.k2 + 3.0 * r2 * p.k3)
    dden = p.k4 + r2 * (2.0 * p.k5 + 3.0 * r2 * p.k6)
    radial = num / den
    dradial = (dnum * den - num * dden) / (den * den)  # d radial / d r2
    prism_x = p.s1 + 2.0 * r2 * p.s2  # d (s1 r2 + s2 r2^2) / d r2
    prism_y = p.s3 + 2.0 * r2 * p.s4
    xd = x * radial + 2.0 * p.p1 * x * y + p.p2 * (r2 + 2.0 * x * x) + r2 * (p.s1 + r2 * p.s2)
    yd = y * radial + p.p1 * (r2 + 2.0 * y * y) + 2.0 * p.p2 * x * y + r2 * (p.s3 + r2 * p.s4)
    j11 = radial + 2.0 * x * x * dradial + 2.0 * p.p1 * y + 6.0 * p.p2 * x + 2.0 * x * prism_x
    j12 = 2.0 * x * y * dradial + 2.0 * p.p1 * x + 2.0 * p.p2 * y + 2.0 * y * prism_x
    j21 = 2.0 * x * y * dradial + 2.0 * p.p1 * x + 2.0 * p.p2 * y + 2.0 * x * prism_y
    j22 = radial + 2.0 * y * y * dradial + 6.0 * p.p1 * y + 2.0 * p.p2 * x + 2.0 * y * prism_y
    return xd, yd, j11, j12, j21, j22


def newton_step_opencv_xy(x, y, xd, yd, p):
    """One Newton step of solving distort_opencv_xy(x, y) = (xd, yd) for (x, y)."""
    fx_, fy_, j11, j12, j21, j22 = distort_opencv_jacobian_xy(x, y, p)
    ex, ey = xd - fx_, yd - fy_
    inv_det = 1.0 / (j11 * j22 - j12 * j21)
    return x + (j22 * ex - j12 * ey) * inv_det, y + (j11 * ey - j21 * ex) * inv_det


def undistort_opencv_xy(xd, yd, p, iterations: int):
    """Inverse of :func:`distort_opencv_xy` by ``iterations`` Newton steps from (xd, yd)."""
    x, y = xd, yd
    for _ in range(iterations):
        x, y = newton_step_opencv_xy(x, y, xd, yd, p)
    return x, y


# --- Kannala-Brandt (OpenCV fisheye) -----------------------------------------------------------
def fisheye_theta_d(theta, p):
    """Kannala-Brandt theta_d(theta) = theta (1 + k1 t^2 + k2 t^4 + k3 t^6 + k4 t^8)."""
    t2 = theta * theta
    return theta * (1.0 + t2 * (p.k1 + t2 * (p.k2 + t2 * (p.k3 + t2 * p.k4))))


def fisheye_dtheta_d(theta, p):
    t2 = theta * theta
    return 1.0 + t2 * (3.0 * p.k1 + t2 * (5.0 * p.k2 + t2 * (7.0 * p.k3 + t2 * 9.0 * p.k4)))


def fisheye_newton_step(theta, theta_d, p):
    """One Newton step of solving fisheye_theta_d(theta) = theta_d for theta."""
    return theta - (fisheye_theta_d(theta, p) - theta_d) / fisheye_dtheta_d(theta, p)


def fisheye_theta_from_theta_d(theta_d, p, iterations: int):
    """Inverse of :func:`fisheye_theta_d` by Newton from theta = theta_d."""
    theta = theta_d
    for _ in range(iterations):
        theta = fisheye_newton_step(theta, theta_d, p)
    return theta


# --- per-model projection of camera-frame points to normalised distorted coordinates -----------
def perspective_xy(X, Y, Z, ops):
    """(x, y, valid) = (X / Z, Y / Z, Z > 0) without dividing by a non-positive Z."""
    valid = Z > 0
    safe_z = ops.select(valid, Z, 1.0)
    return X / safe_z, Y / safe_z, valid


def project_pinhole(X, Y, Z, p, ops):
    x, y, valid = perspective_xy(X, Y, Z, ops)
    return x, y, valid


def project_opencv(X, Y, Z, p, ops):
    x, y, valid = perspective_xy(X, Y, Z, ops)
    valid = valid & (x * x + y * y <= p.limit)
    xd, yd = distort_opencv_xy(x, y, p)
    return xd, yd, valid


def project_fisheye(X, Y, Z, p, ops):
    rho = ops.sqrt(X * X + Y * Y)
    theta = ops.atan2(rho, Z)
    theta_d = fisheye_theta_d(theta, p)
    small = rho < 1e-12 * ops.sqrt(X * X + Y * Y + Z * Z)
    safe_rho = ops.select(small, 1.0, rho)
    scale = ops.select(small, 1.0 / Z, theta_d / safe_rho)  # theta_d / rho -> 1 / Z on axis
    valid = (theta <= p.limit) & ((~small) | (Z > 0))
    return X * scale, Y * scale, valid


# --- per-model unprojection of normalised distorted coordinates to unit rays -------------------
def unit_ray_from_z1(x, y, ops):
    """The unit ray through (x, y, 1)."""
    inv_norm = 1.0 / ops.sqrt(x * x + y * y + 1.0)
    return x * inv_norm, y * inv_norm, inv_norm


def unproject_pinhole(xd, yd, p, iterations: int, ops):
    return unit_ray_from_z1(xd, yd, ops)


#: A camera that masks the pixels beyond its fold: the undistorted point must reproduce the
#: pixel to this (normalised units, 1e-6 x f px: ten times float32's rounding, so the Dr.Jit
#: sensor agrees with the float64 truth), else the pixel has no ray.
FOLD_RESIDUAL = 1e-6


def unproject_opencv(xd, yd, p, iterations: int, ops):
    x, y = undistort_opencv_xy(xd, yd, p, iterations)
    if getattr(p, "mask_beyond_fold", False):  # a Python flag: no branch in the kernel otherwise
        # no ray where the undistorted point lies beyond the fold radius (r^2 > limit) or does not
        # reproduce the pixel (the pixel lies beyond the image of the fold: no preimage at all)
        ex, ey = distort_opencv_xy(x, y, p)
        res2 = (ex - xd) * (ex - xd) + (ey - yd) * (ey - yd)
        ok = (x * x + y * y <= p.limit) & (res2 <= FOLD_RESIDUAL * FOLD_RESIDUAL)
        x = ops.select(ok, x, ops.nan_like(x))
        y = ops.select(ok, y, ops.nan_like(y))
    return unit_ray_from_z1(x, y, ops)


def unproject_fisheye(xd, yd, p, iterations: int, ops):
    theta_d = ops.sqrt(xd * xd + yd * yd)
    theta = fisheye_theta_from_theta_d(theta_d, p, iterations)
    small = theta_d < 1e-12
    s = ops.select(small, 1.0, ops.sin(theta) / ops.select(small, 1.0, theta_d))
    return xd * s, yd * s, ops.cos(theta)

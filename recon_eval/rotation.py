"""Rotation and direction angles, computed so that small angles keep full precision.

The angle of a rotation matrix uses the atan2 form (metrics.md, "Rotation angle")::

    theta = atan2(|vee(R - R^T)| / 2, (trace(R) - 1) / 2)

``|vee(R - R^T)| / 2 = sin(theta)`` and ``(trace(R) - 1) / 2 = cos(theta)``. Unlike
``arccos(clip((trace(R) - 1) / 2))`` it does not lose half the significant digits near 0
(arccos(1 - e) ~ sqrt(2 e): a 1e-8 rad rotation reads as 0 or ~1.5e-8 with arccos in float64).
Near pi its absolute error stays at rounding level too.
"""
from __future__ import annotations

import numpy as np

from recon_eval.errors import InputError


def rotation_angle_rad(R) -> np.ndarray | float:
    """Angle in radians, in [0, pi], of rotation matrices ``R``: (..., 3, 3).

    Non-finite input gives NaN. Returns a float for a single (3, 3) matrix.
    """
    R = np.asarray(R, dtype=np.float64)
    if R.shape[-2:] != (3, 3):
        raise InputError(f"rotation: expected shape (..., 3, 3), got {R.shape}")
    vee = np.stack(
        [R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]], axis=-1
    )  # (..., 3) = 2 sin(theta) axis
    sin = 0.5 * np.linalg.norm(vee, axis=-1)
    cos = 0.5 * (np.trace(R, axis1=-2, axis2=-1) - 1.0)
    ang = np.arctan2(sin, cos)
    return float(ang) if ang.ndim == 0 else ang


def rotation_error_rad(R_est, R_ref) -> np.ndarray | float:
    """Angle of ``R_est^T R_ref`` (radians): the rotation taking one estimate onto the reference.

    The same number as ``|Log(P_est^-1 P_ref)|`` restricted to rotations (evo APE). (..., 3, 3) each.
    """
    R_est = np.asarray(R_est, dtype=np.float64)
    R_ref = np.asarray(R_ref, dtype=np.float64)
    return rotation_angle_rad(np.swapaxes(R_est, -1, -2) @ R_ref)


def angle_between_vectors_rad(a, b) -> np.ndarray | float:
    """Unsigned angle in [0, pi] between vectors ``a`` and ``b``: (..., 3) each.

    ``atan2(|a x b|, a . b)``: precise near 0 and pi, and independent of the vectors' lengths.
    A zero-length vector gives NaN (the direction is undefined).
    """
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    ang = np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1))
    zero = (np.linalg.norm(a, axis=-1) == 0) | (np.linalg.norm(b, axis=-1) == 0)
    ang = np.where(zero, np.nan, ang)
    return float(ang) if np.ndim(ang) == 0 else ang


def is_rotation(R, atol: float = 1e-6) -> bool:
    """True for a finite (3, 3) matrix with R R^T = I (to ``atol``) and det +1.

    ``atol`` 1e-6 admits matrices written with ~7 significant digits (text files).
    """
    R = np.asarray(R, dtype=np.float64)
    return bool(
        R.shape == (3, 3)
        and np.all(np.isfinite(R))
        and np.allclose(R @ R.T, np.eye(3), atol=atol)
        and np.linalg.det(R) > 0
    )


def rotation_from_rotvec(rotvec_rad) -> np.ndarray:
    """(3, 3) rotation matrix for an axis-angle vector (radians), via the Rodrigues formula."""
    w = np.asarray(rotvec_rad, dtype=np.float64).reshape(3)
    theta = np.linalg.norm(w)
    Kx = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    if theta < 1e-4:  # Taylor series of sin(x)/x and (1-cos x)/x^2; truncation error < 1e-17.
        a = 1.0 - theta**2 / 6.0
        b = 0.5 - theta**2 / 24.0
    else:
        a = np.sin(theta) / theta
        b = (1.0 - np.cos(theta)) / theta**2
    return np.eye(3) + a * Kx + b * (Kx @ Kx)

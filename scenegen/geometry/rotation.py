"""Rotations: validity, quaternions, rotation vectors, Euler angles and angles between rotations.

Conventions (:mod:`scenegen.geometry.conventions`): rotations are proper 3x3 matrices (det +1);
quaternions are (w, x, y, z), scalar first (COLMAP's order), Hamilton; angles are radians, degrees
only in names ending ``_deg``.

The angle of a rotation matrix uses the atan2 form (shared/notes/metrics.md, "Rotation angle")::

    theta = atan2(|vee(R - R^T)| / 2, (trace(R) - 1) / 2)

``|vee(R - R^T)| / 2 = sin(theta)`` and ``(trace(R) - 1) / 2 = cos(theta)``. Unlike
``arccos(clip((trace(R) - 1) / 2))`` it keeps full precision near 0 (arccos(1 - e) ~ sqrt(2 e):
a 1e-8 rad rotation reads as 0 or ~1.5e-8 with arccos in float64) and near pi.
"""
from __future__ import annotations

import numpy as np

#: Orthonormality tolerance of :func:`is_rotation`: admits matrices written with ~7 significant
#: digits (JSON, YAML or text files written by hand or in float32).
ROTATION_ATOL = 1e-6


# --- validity --------------------------------------------------------------------------------
def is_rotation(R, atol: float = ROTATION_ATOL) -> bool:
    """True for a finite (3, 3) matrix with ``R R^T = I`` (to ``atol``) and det +1."""
    R = np.asarray(R, dtype=np.float64)
    return bool(R.shape == (3, 3) and np.all(np.isfinite(R))
                and np.allclose(R @ R.T, np.eye(3), atol=atol) and np.linalg.det(R) > 0)


def as_rotation(R) -> np.ndarray:
    """``R`` as a (3, 3) float64 rotation; ValueError naming what is wrong otherwise."""
    R = np.asarray(R, dtype=np.float64)
    if R.shape != (3, 3) or not np.all(np.isfinite(R)):
        raise ValueError(f"rotation must be a finite 3x3 matrix, got shape {R.shape}")
    if not is_rotation(R):
        raise ValueError("rotation must be orthonormal with det +1")
    return R


# --- parametrisations --------------------------------------------------------------------------
def _rotation_class():
    # scipy on use: ~0.3 s to import, and every module of the project imports this one
    from scipy.spatial.transform import Rotation

    return Rotation


def quat_wxyz_from_matrix(R) -> np.ndarray:
    """Unit quaternion (w, x, y, z) with w >= 0 of a (3, 3) rotation matrix, or (N, 4) of (N, 3, 3)."""
    q = _rotation_class().from_matrix(np.asarray(R, float)).as_quat(scalar_first=True)
    return np.where(q[..., :1] >= 0, q, -q)


def matrix_from_quat_wxyz(q_wxyz) -> np.ndarray:
    """Rotation matrices of (w, x, y, z) quaternions, normalised first: (4,) -> (3, 3) or
    (N, 4) -> (N, 3, 3). ValueError for non-finite or all-zero quaternions."""
    q = np.asarray(q_wxyz, dtype=np.float64)
    if q.ndim not in (1, 2) or q.shape[-1] != 4:
        raise ValueError(f"quaternions must be (4,) or (N, 4) (w, x, y, z), got shape {q.shape}")
    if len(q) == 0 and q.ndim == 2:
        return np.zeros((0, 3, 3))
    if not np.all(np.isfinite(q)) or np.any(np.linalg.norm(q.reshape(-1, 4), axis=1) == 0):
        raise ValueError(f"quaternion must be 4 finite numbers, not all zero; got {q_wxyz!r}")
    return _rotation_class().from_quat(q, scalar_first=True).as_matrix()


def matrix_from_rotvec(rotvec_rad) -> np.ndarray:
    """(3, 3) rotation of an axis-angle vector (radians), or (N, 3, 3) of (N, 3)."""
    return _rotation_class().from_rotvec(np.asarray(rotvec_rad, float)).as_matrix()


def rotvec_from_matrix(R) -> np.ndarray:
    """Axis-angle vector (radians) of a (3, 3) rotation."""
    return _rotation_class().from_matrix(np.asarray(R, float)).as_rotvec()


def rotation_from_euler_deg(angles_deg, order: str = "xyz") -> np.ndarray:
    """Rotation matrix from Euler angles in degrees (extrinsic axes, scipy lower-case ``order``)."""
    return _rotation_class().from_euler(order, np.asarray(angles_deg, float), degrees=True).as_matrix()


# --- angles ------------------------------------------------------------------------------------
def rotation_angle_rad(R) -> np.ndarray | float:
    """Angle in radians, in [0, pi], of rotation matrices ``R``: (..., 3, 3).

    Non-finite input gives NaN. Returns a float for a single (3, 3) matrix.
    """
    R = np.asarray(R, dtype=np.float64)
    if R.shape[-2:] != (3, 3):
        raise ValueError(f"rotation: expected shape (..., 3, 3), got {R.shape}")
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

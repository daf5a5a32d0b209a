"""Rigid transforms named by their frames.

A transform is named ``<to>_from_<from>``: ``cam_from_world`` maps world points into the camera
frame, ``x_cam = R @ x_world + t``; composition reads right to left,
``cam_from_rig @ rig_from_world == cam_from_world``. Units: metres; rotations are proper 3x3
matrices (det +1). Camera axes follow OpenCV (see :mod:`scenegen.geometry.conventions`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from scenegen.geometry.rotation import as_rotation, matrix_from_rotvec


@dataclass(frozen=True, eq=False)
class Rigid3:
    """A rigid transform ``y = R x + t``; R (3, 3) rotation, t (3,) translation in metres."""

    R: np.ndarray = field(default_factory=lambda: np.eye(3))
    t: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self):
        # C order always: numpy's matmul takes other kernels (other rounding, with FMA on some
        # CPUs) for other memory layouts, and a pose must give the same bits however it was made
        R = np.ascontiguousarray(as_rotation(self.R))
        t = np.ascontiguousarray(self.t, dtype=np.float64).reshape(-1)
        if t.shape != (3,) or not np.all(np.isfinite(t)):
            raise ValueError(f"translation must be 3 finite numbers, got {self.t!r}")
        R.setflags(write=False)
        t.setflags(write=False)
        object.__setattr__(self, "R", R)
        object.__setattr__(self, "t", t)

    @classmethod
    def identity(cls) -> "Rigid3":
        return cls(np.eye(3), np.zeros(3))

    @classmethod
    def from_matrix(cls, T) -> "Rigid3":
        """From a 4x4 (or 3x4) homogeneous matrix ``[R | t]``."""
        T = np.asarray(T, dtype=np.float64)
        if T.shape not in ((4, 4), (3, 4)):
            raise ValueError(f"expected a 4x4 or 3x4 matrix, got shape {T.shape}")
        if T.shape == (4, 4) and not np.allclose(T[3], [0, 0, 0, 1]):
            raise ValueError("last row of a rigid 4x4 matrix must be [0, 0, 0, 1]")
        return cls(T[:3, :3], T[:3, 3])

    @classmethod
    def from_rotvec(cls, rotvec_rad, t) -> "Rigid3":
        return cls(matrix_from_rotvec(rotvec_rad), t)

    @property
    def matrix(self) -> np.ndarray:
        """(4, 4) homogeneous matrix."""
        T = np.eye(4)
        T[:3, :3] = self.R
        T[:3, 3] = self.t
        return T

    @classmethod
    def _composed(cls, R: np.ndarray, t: np.ndarray) -> "Rigid3":
        """A transform made from valid ones (inverse, product): a rotation to rounding, not
        checked again (the check was 80 % of composing two poses; per-row poses compose
        thousands per frame)."""
        out = object.__new__(cls)
        R, t = np.array(R, np.float64, order="C"), np.array(t, np.float64, order="C")  # as __post_init__
        R.setflags(write=False)
        t.setflags(write=False)
        object.__setattr__(out, "R", R)
        object.__setattr__(out, "t", t)
        return out

    def inverse(self) -> "Rigid3":
        return Rigid3._composed(self.R.T, -self.R.T @ self.t)

    def __matmul__(self, other: "Rigid3") -> "Rigid3":
        return Rigid3._composed(self.R @ other.R, self.R @ other.t + self.t)

    def apply(self, points) -> np.ndarray:
        """Transform points (..., 3) -> (..., 3)."""
        p = np.asarray(points, dtype=np.float64)
        return p @ self.R.T + self.t

    def rotate(self, vectors) -> np.ndarray:
        """Rotate direction vectors (..., 3) (no translation)."""
        return np.asarray(vectors, dtype=np.float64) @ self.R.T

    @property
    def origin_in_target(self) -> np.ndarray:
        """Where the source frame's origin lands in the target frame (= t).

        For ``world_from_cam`` this is the camera centre in world coordinates.
        """
        return self.t.copy()

    def __repr__(self) -> str:
        return f"Rigid3(R={self.R.tolist()}, t={self.t.tolist()})"

    def to_dict(self) -> dict:
        return {"R": self.R.tolist(), "t": self.t.tolist()}

    @classmethod
    def from_dict(cls, d: dict) -> "Rigid3":
        return cls(np.asarray(d["R"], float), np.asarray(d["t"], float))

    def allclose(self, other: "Rigid3", atol: float = 1e-12) -> bool:
        return bool(np.allclose(self.R, other.R, atol=atol) and np.allclose(self.t, other.t, atol=atol))


def camera_center(cam_from_world: Rigid3) -> np.ndarray:
    """Camera centre in world coordinates, ``-R^T t`` (metres)."""
    return cam_from_world.inverse().t


def look_at(eye, target, up=(0.0, 0.0, 1.0)) -> Rigid3:
    """``world_from_cam`` for a camera at ``eye`` looking at ``target`` (OpenCV axes).

    The camera's +z points from eye to target, +x to the right of the image and +y down, so
    the world ``up`` vector appears pointing up in the image (towards -y).
    """
    eye = np.asarray(eye, dtype=np.float64)
    z = np.asarray(target, dtype=np.float64) - eye
    if np.linalg.norm(z) == 0:
        raise ValueError("look_at: eye and target coincide")
    z = z / np.linalg.norm(z)
    up = np.asarray(up, dtype=np.float64)
    x = np.cross(z, up)  # right = forward x up (world up maps to image up = -y)
    if np.linalg.norm(x) < 1e-9 * max(np.linalg.norm(up), 1.0):
        raise ValueError("look_at: viewing direction is parallel to the up vector")
    x = x / np.linalg.norm(x)
    y = np.cross(z, x)
    return Rigid3(np.stack([x, y, z], axis=1), eye)

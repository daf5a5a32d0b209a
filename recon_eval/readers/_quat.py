"""Quaternion <-> rotation matrix (scalar-first w, x, y, z, Hamilton convention)."""
from __future__ import annotations

import numpy as np


def matrix_from_quat_wxyz(q) -> np.ndarray:
    """(N, 4) or (4,) quaternions, normalised first -> (N, 3, 3) or (3, 3) rotations."""
    q = np.asarray(q, dtype=np.float64)
    single = q.ndim == 1
    q = q.reshape(-1, 4)
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    R = np.stack([
        1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
        2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
        2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
    ], axis=1).reshape(-1, 3, 3)
    return R[0] if single else R

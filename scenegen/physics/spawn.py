"""Seeded release poses for a drop: every object above the support, no two bounding spheres
overlapping, so the engine starts from a state without contacts.

Object i (in the spec's order) draws its rotation first, then up to MAX_TRIES centres
``(x, y)`` uniform in its region at height ``top_z + drop_height_m + r_i``; the first centre
whose sphere clears every earlier sphere is taken. When none does, it goes above all of them at
the last drawn ``(x, y)``. One numpy stream for the whole drop, consumed in that order.
"""
from __future__ import annotations

import math

import numpy as np

from scenegen.geometry.pose import Rigid3
from scenegen.geometry.rotation import matrix_from_quat_wxyz

#: Centres drawn per object at the release height before it is stacked above the others.
MAX_TRIES = 100
ORIENTATIONS = ("random", "yaw")


def bounding_radius(vertices: np.ndarray) -> float:
    """Radius (m) of the sphere about the object origin that holds every (N, 3) vertex."""
    return float(np.linalg.norm(np.asarray(vertices, dtype=np.float64), axis=1).max())


def _rotation(orientation: str, written: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    if orientation == "random":  # uniform on SO(3): a normalised 4D Gaussian quaternion
        return matrix_from_quat_wxyz(rng.normal(size=4))
    a = 2.0 * math.pi * rng.random()  # 'yaw': the written rotation, turned about world +z
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ written


def release_poses(radii, written_R, regions, top_z: float, drop_height_m: float, orientation: str,
                  rng: np.random.Generator) -> list[Rigid3]:
    """world_from_object at release per object: ``radii`` (n,) bounding radii (m),
    ``written_R`` (n, 3, 3) the objects' written rotations (used by 'yaw'), ``regions`` n pairs
    ((x_min, y_min), (x_max, y_max)) of allowed centres (world, m), ``top_z`` the support's top."""
    if orientation not in ORIENTATIONS:
        raise ValueError(f"orientation must be one of {ORIENTATIONS}, got {orientation!r}")
    centres: list[np.ndarray] = []
    out = []
    for r, R0, (lo, hi) in zip(radii, written_R, regions):
        R = _rotation(orientation, np.asarray(R0, dtype=np.float64), rng)
        lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
        z = top_z + drop_height_m + r
        c = None
        for _ in range(MAX_TRIES):
            xy = lo + (hi - lo) * rng.random(2)
            c = np.array([xy[0], xy[1], z])
            if all(np.linalg.norm(c - cj) >= r + rj for cj, rj in zip(centres, radii)):
                break
        else:  # crowded: above every sphere released so far
            c[2] = max(cj[2] + rj for cj, rj in zip(centres, radii)) + r
        centres.append(c)
        out.append(Rigid3(R, c))
    return out

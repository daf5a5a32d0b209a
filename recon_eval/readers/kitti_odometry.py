"""KITTI odometry trajectories (``poses/XX.txt`` of the odometry benchmark, also evo's ``kitti``).

One pose per line: 12 numbers, the 3x4 matrix ``[R | t]`` in row-major order. In the KITTI
benchmark each line is **world_from_cam** of the left grey camera (cam0) at frame i, where the
world is cam0's frame at frame 0 (so line 0 is the identity): ``x_world = R x_cam + t``. KITTI's
camera axes are OpenCV's (x right, y down, z forward). The reader converts to recon_eval's
``cam_from_world``; pass ``convention="cam_from_world"`` for files that store that instead.

There are no timestamps: poses are named by frame index, ``"%06d"`` (KITTI's image names
``000000.png``), in file order.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from recon_eval.metrics.poses import Poses
from recon_eval.readers.text import read_text

CONVENTIONS = ("world_from_cam", "cam_from_world")


def read_kitti_poses(path, convention: str = "world_from_cam") -> Poses:
    """Poses (cam_from_world) from a KITTI odometry file; see the module docstring."""
    if convention not in CONVENTIONS:
        raise InputError(f"KITTI pose convention must be one of {CONVENTIONS}, got {convention!r}")
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected a KITTI odometry trajectory: 12 numbers per line)")
    rows = []
    for k, ln in enumerate(read_text(p, "a KITTI odometry trajectory").splitlines(), start=1):
        ln = ln.split("#", 1)[0].strip()
        if not ln:
            continue
        tok = ln.split()
        if len(tok) != 12:
            raise InputError(f"{p}:{k}: expected 12 numbers (3x4 [R|t] row-major), got {len(tok)}")
        try:
            rows.append([float(v) for v in tok])
        except ValueError:
            raise InputError(f"{p}:{k}: not numbers: {ln!r}") from None
    M = np.asarray(rows, dtype=np.float64).reshape(-1, 3, 4)
    if not np.all(np.isfinite(M)):
        raise InputError(f"{p}: non-finite values")
    R, t = M[:, :, :3], M[:, :, 3]
    err = np.abs(R @ np.swapaxes(R, 1, 2) - np.eye(3)).max(axis=(1, 2)) if len(M) else np.zeros(0)
    bad = np.nonzero((err > 1e-6) | (np.linalg.det(R) < 0))[0] if len(M) else []
    if len(bad):
        raise InputError(f"{p}: pose {bad[0]} (0-based): R is not a rotation (|R R^T - I| = {err[bad[0]]:.2g})")
    if convention == "world_from_cam":
        R = np.swapaxes(R, 1, 2)
        t = -np.einsum("nij,nj->ni", R, t)
    return Poses(tuple(f"{i:06d}" for i in range(len(M))), R, t)


def write_kitti_poses(path, poses: Poses, convention: str = "world_from_cam") -> None:
    """Write cam_from_world ``poses`` as a KITTI file in ``convention`` (%.17g: lossless)."""
    if convention not in CONVENTIONS:
        raise InputError(f"KITTI pose convention must be one of {CONVENTIONS}, got {convention!r}")
    R, t = np.asarray(poses.R_cam_from_world), np.asarray(poses.t_cam_from_world)
    if convention == "world_from_cam":
        R = np.swapaxes(R, 1, 2)
        t = -np.einsum("nij,nj->ni", R, t)
    M = np.concatenate([R, t[:, :, None]], axis=2).reshape(-1, 12)
    Path(path).write_text("".join(" ".join(f"{v:.17g}" for v in row) + "\n" for row in M))

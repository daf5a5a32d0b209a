"""Shared fixtures-as-functions for the recon_eval tests (seeded, small)."""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    return Rotation.random(random_state=rng.integers(1 << 31)).as_matrix()


def look_at_cam_from_world(center, target=(0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0)):
    """cam_from_world (R, t) of an OpenCV camera at ``center`` looking at ``target``."""
    c = np.asarray(center, float)
    z = np.asarray(target, float) - c
    z /= np.linalg.norm(z)
    x = np.cross(z, up)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    R = np.stack([x, y, z])  # rows: camera axes in world
    return R, -R @ c


def ring_of_cameras(n: int = 8, radius: float = 3.0, height: float = 1.0):
    """n cameras on a circle looking at the origin: (R (n,3,3), t (n,3)), cam_from_world."""
    Rs, ts = [], []
    for k in range(n):
        a = 2 * np.pi * k / n
        R, t = look_at_cam_from_world([radius * np.cos(a), radius * np.sin(a), height + 0.1 * k])
        Rs.append(R)
        ts.append(t)
    return np.array(Rs), np.array(ts)


#: Unit square in the z = 0 plane as two triangles.
SQUARE_V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
SQUARE_F = np.array([[0, 1, 2], [0, 2, 3]])


def _num(values) -> str:
    return " ".join(f"{float(v):.17g}" for v in values)


def write_colmap(d, qs, ts):
    d.mkdir()
    (d / "cameras.txt").write_text("# cams\n1 PINHOLE 640 480 500 505 320 240\n")
    lines = ["# images"]
    for k, (q, t) in enumerate(zip(qs, ts), start=1):
        lines.append(f"{k} {_num(q)} {_num(t)} 1 img{k}.png")
        lines.append("" if k % 2 else "100.0 200.0 -1 5.0 6.0 1")
    (d / "images.txt").write_text("\n".join(lines) + "\n")
    # point 1 is observed by image 2's second keypoint (its POINTS2D line references point 1)
    (d / "points3D.txt").write_text("# pts\n1 0.1 0.2 3.0 255 0 0 0.5 2 1\n")


#: A poster and a blob seen from a reference view, the same view rolled about its optical axis
#: (one camera centre: no epipolar geometry, nothing to triangulate) and a view 0.6 m to the side;
#: crossview pairs [ref, rolled] and [ref, side] with labelled match sets.
ZERO_BASELINE_SPEC = """
name: zero_baseline_runs
seed: 5
render: {spp: 4, max_depth: 2}
objects:
  - name: poster
    shape: {type: plane, size: [1.6, 1.2]}
    transform: {translation: [0, 0.6, 0.7], rotation_deg: [90, 0, 0]}
    material: {type: diffuse, texture: {type: natural, params: {size_px: 256}}}
  - name: rock
    shape: {type: blob, radius: 0.2}
    transform: {translation: [0.1, 0.1, 0.5]}
lights:
  - {type: constant, radiance: 1.0}
cameras:
  cam: {size: [120, 90], fx: 100}
views:
  - camera: cam
    look_at:
      - {eye: [0, -1.5, 0.8], target: [0, 0.3, 0.6]}
      - {eye: [0, -1.5, 0.8], target: [0, 0.3, 0.6], up: [0.5, 0, 0.866]}
      - {eye: [0.6, -1.4, 0.9], target: [0, 0.3, 0.6]}
crossview:
  pairs: [[cam_0000, cam_0001], [cam_0000, cam_0002]]
  flow: false
  targets: false
  matches: {count: 200, sigma_px: 0.5, outlier_fraction: 0.2, seed: 3}
"""

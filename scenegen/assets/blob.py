"""The blob: a seeded, radially displaced icosphere with spherical UVs cut along their seam (the
mesh conventions of :mod:`scenegen.assets.shapes`)."""
from __future__ import annotations

import numpy as np
import trimesh

from scenegen.assets.checks import count as _count, positive as _positive
from scenegen.assets.shapes import build_mesh

_ON_PLANE = 1e-12  # |y| below this counts as on the UV seam's plane (icosphere rounding is ~1e-16)
_ON_AXIS = 1e-12  # x^2 + y^2 below this counts as a pole (longitude undefined)


def _smooth_sphere_noise(dirs: np.ndarray, frequency: float, seed: int, waves: int = 24):
    """Smooth, seeded noise on unit directions (N, 3) with values in [-1, 1].

    A sum of ``waves`` plane waves sin(2 pi f_k w_k . p + phase_k), w_k uniform random unit vectors,
    f_k = frequency * U(0.5, 1.5) cycles per unit length, amplitudes 1/sqrt(f_k); divided by the sum
    of amplitudes so |noise| <= 1 always. Infinitely smooth and seam-free on the sphere.
    """
    rng = np.random.default_rng(seed)
    w = rng.normal(size=(waves, 3))
    w /= np.linalg.norm(w, axis=1, keepdims=True)
    f = frequency * rng.uniform(0.5, 1.5, waves)
    phase = rng.uniform(0, 2 * np.pi, waves)
    amp = 1.0 / np.sqrt(f)
    val = np.sin(2 * np.pi * (dirs @ (w * f[:, None]).T) + phase) @ amp  # (N,)
    return val / amp.sum()


def _split_seam_faces(v: np.ndarray, f: np.ndarray):
    """Cut the triangles of a unit sphere mesh that cross the UV seam (the half-plane y = 0, x > 0).

    Each crossing triangle is clipped against y >= 0 and y <= 0 (Sutherland-Hodgman) and the pieces
    fan-triangulated; a new vertex on a cut edge is shared by both triangles of that edge, so the
    mesh stays watertight. Returns (vertices, faces, side) where side (F,) is +1 for a face on the
    y >= 0 side of the seam, -1 on the y <= 0 side and 0 for faces away from the seam.
    """
    y = v[:, 1]
    fy = y[f]
    cross = (fy > _ON_PLANE).any(1) & (fy < -_ON_PLANE).any(1) & (v[f][:, :, 0].mean(1) > 0)
    verts = list(v)
    edge_point: dict[tuple[int, int], int] = {}

    def cut(a: int, b: int) -> int:
        key = (min(a, b), max(a, b))
        if key not in edge_point:
            pa, pb = v[key[0]], v[key[1]]
            t = pa[1] / (pa[1] - pb[1])
            p = pa + t * (pb - pa)
            p[1] = 0.0
            edge_point[key] = len(verts)
            verts.append(p)
        return edge_point[key]

    new_faces, new_side = [], []
    for tri in f[cross]:
        for sign in (+1, -1):
            poly = []
            for k in range(3):
                a, b = int(tri[k]), int(tri[(k + 1) % 3])
                da, db = sign * y[a], sign * y[b]
                if da >= -_ON_PLANE:
                    poly.append(a)
                if (da > _ON_PLANE and db < -_ON_PLANE) or (da < -_ON_PLANE and db > _ON_PLANE):
                    poly.append(cut(a, b))
            for k in range(1, len(poly) - 1):
                new_faces.append((poly[0], poly[k], poly[k + 1]))
                new_side.append(sign)
    faces = np.concatenate([f[~cross], np.asarray(new_faces, dtype=np.int64).reshape(-1, 3)])
    side = np.concatenate([np.zeros((~cross).sum(), int), np.asarray(new_side, int)])
    return np.asarray(verts), faces, side


def _spherical_corner_uv(v: np.ndarray, f: np.ndarray, side: np.ndarray) -> np.ndarray:
    """Per-corner UVs (F, 3, 2): u = (atan2(y, x) + pi) / (2 pi) wrapped to [0, 1), v = theta / pi.

    Corners on the seam (y = 0, x > 0) get u = 0 on faces of the y > 0 side (where u grows from 0)
    and u = 1 on the y < 0 side; pole corners take the mean u of the face's other corners.
    """
    x, y, z = v[:, 0], v[:, 1], v[:, 2]
    u_v = np.mod(np.arctan2(y, x) / (2 * np.pi), 1.0)  # phi in [0, 2 pi) -> [0, 1); seam at +x
    v_v = np.arccos(np.clip(z, -1, 1)) / np.pi
    cu = u_v[f].copy()  # (F, 3)
    cv = v_v[f]
    on_seam = (np.abs(y[f]) <= _ON_PLANE) & (x[f] > 0)
    off_plane_y = np.where(np.abs(y[f]) > _ON_PLANE, y[f], 0.0)
    face_side = np.where(side != 0, side, np.sign(off_plane_y.sum(1)))
    cu = np.where(on_seam & (face_side[:, None] < 0), 1.0, np.where(on_seam, 0.0, cu))
    pole = (x[f] ** 2 + y[f] ** 2) <= _ON_AXIS
    if pole.any():
        others = np.where(pole, np.nan, cu)
        mean_u = np.nanmean(others, axis=1)
        cu = np.where(pole, mean_u[:, None], cu)
    return np.stack([cu, cv], -1)


def blob(radius: float = 1.0, amplitude: float = 0.2, frequency: float = 1.0, seed: int = 0,
         subdivisions: int = 5) -> trimesh.Trimesh:
    """A smooth random blob: an icosphere whose vertices are displaced radially by seeded noise.

    A unit direction p lands at ``radius * (1 + amplitude * noise(p)) * p`` with noise in [-1, 1]
    (a sum of random plane waves of about ``frequency`` cycles per unit length on the unit sphere,
    see :func:`_smooth_sphere_noise`). With 0 <= amplitude < 1 the surface is star-shaped, hence
    closed, non-self-intersecting and outward-wound like the icosphere.

    UVs are spherical coordinates of the direction p, as in :func:`scenegen.assets.shapes.sphere`: u = phi / (2 pi),
    v = theta / pi. Triangles crossing the seam are cut along it (vertices added on the cut edges),
    seam vertices duplicated, and pole corners get their face's mean u, so u, v lie in [0, 1]
    with no triangle spanning the seam. ``subdivisions`` is trimesh's icosphere level
    (20 * 4**k faces before the seam cut).
    """
    r = _positive("radius", radius)
    if not 0 <= amplitude < 1:
        raise ValueError(f"amplitude must be in [0, 1), got {amplitude!r}")
    if not (np.isfinite(frequency) and frequency >= 0):
        raise ValueError(f"frequency must be >= 0, got {frequency!r}")
    k = _count("subdivisions", subdivisions, 1)
    ico = trimesh.creation.icosphere(subdivisions=k)
    v0 = ico.vertices / np.linalg.norm(ico.vertices, axis=1, keepdims=True)
    v_cut, f, side = _split_seam_faces(v0, np.asarray(ico.faces, dtype=np.int64))
    dirs = v_cut / np.linalg.norm(v_cut, axis=1, keepdims=True)
    corner_uv = _spherical_corner_uv(dirs, f, side)  # (F, 3, 2)
    # One output vertex per distinct (vertex, u, v) corner.
    key = np.concatenate([f.reshape(-1, 1).astype(np.float64), corner_uv.reshape(-1, 2)], 1)
    uniq, inverse = np.unique(key, axis=0, return_inverse=True)
    vid = uniq[:, 0].astype(np.int64)
    disp = r * (1.0 + amplitude * _smooth_sphere_noise(dirs, frequency, seed))
    verts = dirs[vid] * disp[vid, None]
    return build_mesh(verts, inverse.reshape(-1, 3), uniq[:, 1:])

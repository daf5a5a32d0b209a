"""An independent analytic scene for the truth-across-time tests (sequence truth, rolling shutter,
stereo scene flow): a floor, a sphere and boxes on keyframed linear paths, intersected here in
float64 with the test's own slerp/lerp (scipy's Slerp) at every ray's own time. No scenegen code:
the datasets' truth is checked against it.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation, Slerp


def look(eye, target):
    """world_from_cam rotation (OpenCV axes: x right, y down, z forward) looking from eye at target, z up."""
    z = np.subtract(target, eye) / np.linalg.norm(np.subtract(target, eye))
    x = np.cross(z, [0, 0, 1.0])
    x /= np.linalg.norm(x)
    return np.stack([x, np.cross(z, x), z], 1)


def euler_deg(*deg):
    return Rotation.from_euler("xyz", deg, degrees=True).as_matrix()


def slerp_lerp(t, t0, t1, Ra, Rb, pa, pb):
    """((N, 3, 3), (N, 3)) at times ``t`` (N,): slerp and lerp between keyframes at t0 and t1,
    held before t0 and after t1."""
    u = np.clip((np.atleast_1d(np.asarray(t, float)) - t0) / (t1 - t0), 0, 1)
    R = Slerp([0, 1], Rotation.from_matrix(np.stack([Ra, Rb])))(u).as_matrix()
    return R, (1 - u)[:, None] * np.asarray(pa, float) + u[:, None] * np.asarray(pb, float)


@dataclass
class AnalyticScene:
    """``paths``: name -> (t0, t1, R0, R1, p0, p1) keyframes of a moving object (slerp_lerp's
    arguments); ``fixed``: name ->
    (R, centre); ``sphere``: (name, radius) (its centre is its pose's translation); ``boxes``: name
    -> half extents (object frame); ``visible``: name -> (first, last) time it exists; ``ids``:
    name -> object id; the floor is z = 0 within |x|, |y| <= ``floor_half``."""

    paths: dict
    ids: dict
    sphere: tuple = ("ball", 0.25)
    boxes: dict = field(default_factory=dict)
    fixed: dict = field(default_factory=dict)
    visible: dict = field(default_factory=dict)
    floor_half: float = 2.0

    def poses(self, name, t):
        """((N, 3, 3) R, (N, 3) centre) of an object at times ``t`` (N,) (a scalar: N = 1)."""
        t = np.atleast_1d(np.asarray(t, float))
        if name in self.paths:
            return slerp_lerp(t, *self.paths[name])
        R, c = self.fixed.get(name, (np.eye(3), np.zeros(3)))
        return np.broadcast_to(R, (len(t), 3, 3)), np.broadcast_to(c, (len(t), 3))

    def pose(self, name, t):
        """(R, centre) of an object at one time."""
        R, c = self.poses(name, t)
        return R[0], c[0]

    def present(self, name, t):
        """(N,) bool: the object exists at times ``t``."""
        lo, hi = self.visible.get(name, (-np.inf, np.inf))
        t = np.atleast_1d(np.asarray(t, float))
        return (lo <= t) & (t <= hi)

    def first_hits(self, o, d, t):
        """((N,) distance, (N,) object id) of the first hit of rays o + s d (d (N, 3) unit, o (3,)
        or (N, 3)) with every object where it is at the ray's time (``t`` scalar or (N,))."""
        n = len(d)
        best, oid = np.full(n, np.inf), np.zeros(n, np.int64)
        o = np.broadcast_to(o, d.shape)
        t = np.broadcast_to(np.atleast_1d(np.asarray(t, float)), (n,)) if np.ndim(t) else np.full(n, float(t))

        def take(s, name):
            better = (s > 1e-9) & (s < best) & self.present(name, t)
            best[better], oid[better] = s[better], self.ids[name]

        with np.errstate(divide="ignore", invalid="ignore"):
            s = -o[:, 2] / d[:, 2]
            p = o + s[:, None] * d
            h = self.floor_half
            take(np.where((np.abs(p[:, 0]) <= h) & (np.abs(p[:, 1]) <= h), s, np.inf), "floor")
            name, r = self.sphere
            _, c = self.poses(name, t)
            oc = o - c
            b = np.sum(oc * d, 1)
            disc = b * b - (np.sum(oc * oc, 1) - r * r)
            take(np.where(disc >= 0, -b - np.sqrt(np.maximum(disc, 0)), np.inf), name)
            for name, half in self.boxes.items():
                R, c = self.poses(name, t)
                ol, dl = np.einsum("nji,nj->ni", R, o - c), np.einsum("nji,nj->ni", R, d)
                t1, t2 = (-np.asarray(half) - ol) / dl, (np.asarray(half) - ol) / dl
                near, far = np.minimum(t1, t2).max(1), np.maximum(t1, t2).min(1)
                take(np.where((near <= far) & (near > 0), near, np.inf), name)
        return best, oid

    def moved(self, P, ids, ta, tb):
        """(N, 3) points P on objects ``ids`` at time(s) ``ta`` carried by their objects to ``tb``."""
        out = np.array(P, float)
        for name, k in self.ids.items():
            sel = ids == k
            if sel.any():
                Ra, ca = self.poses(name, np.broadcast_to(ta, len(P))[sel] if np.ndim(ta) else ta)
                Rb, cb = self.poses(name, np.broadcast_to(tb, len(P))[sel] if np.ndim(tb) else tb)
                X = np.einsum("nji,nj->ni", Ra, P[sel] - ca)
                out[sel] = np.einsum("nij,nj->ni", Rb, X) + cb
        return out


#: The scene of tests/scenegen/pipeline/test_sequence_truth.py and test_sequence_stereo.py (their
#: specs' objects, restated): a ball and a crate on linear paths over 0.2 s, a box from 0.15 s.
SEQUENCE_SCENE = AnalyticScene(
    paths={"ball": (0.0, 0.2, np.eye(3), euler_deg(0, 0, 40), [-0.3, 0.1, 0.25], [0.3, -0.1, 0.35]),
           "crate": (0.0, 0.2, euler_deg(0, 0, 10), euler_deg(20, 0, 80), [0.35, 0.3, 0.125], [-0.2, 0.25, 0.2])},
    fixed={"dice": (np.eye(3), np.array([-0.45, -0.35, 0.075]))},
    boxes={"crate": (0.15, 0.1, 0.125), "dice": (0.075, 0.075, 0.075)},
    visible={"dice": (0.15, 1.0)},
    ids={"floor": 1, "ball": 2, "crate": 3, "dice": 4})


@dataclass
class RollingPinhole:
    """The tests' own rolling-shutter pinhole: W x H pixels, focal ``f`` px, principal point at the
    image centre, rows exposed at ``t_frame + readout_s (v / (H - 1) - 0.5)``, the camera on the
    keyframed path ``path`` (slerp_lerp's arguments: world_from_cam rotations and centres)."""

    W: int
    H: int
    f: float
    readout_s: float
    path: tuple

    def row_time(self, t_frame, v):
        return t_frame + self.readout_s * (np.asarray(v, float) / (self.H - 1) - 0.5)

    def pose(self, t):
        """((N, 3, 3) world_from_cam rotations, (N, 3) centres) at times ``t`` (N,)."""
        return slerp_lerp(t, *self.path)

    def project(self, P, t):
        """((N, 2) pixels, (N,) depth) of points P (N, 3) with the camera at times ``t`` (N,)."""
        R, C = self.pose(t)
        Pc = np.einsum("nji,nj->ni", R, P - C)
        cx, cy = (self.W - 1) / 2, (self.H - 1) / 2
        return np.stack([self.f * Pc[:, 0] / Pc[:, 2] + cx, self.f * Pc[:, 1] / Pc[:, 2] + cy], 1), Pc[:, 2]

    def frame_points(self, scene: AnalyticScene, t_frame):
        """Per pixel of a frame: (N, 3) surface points, (N,) ids, (N,) times of their rows, (N,)
        distances along the rays (each ray cast at its row's time)."""
        u, v = np.meshgrid(np.arange(self.W, dtype=float), np.arange(self.H, dtype=float))
        t = self.row_time(t_frame, v.reshape(-1))
        cx, cy = (self.W - 1) / 2, (self.H - 1) / 2
        d = np.stack([(u - cx) / self.f, (v - cy) / self.f, np.ones_like(u)], -1).reshape(-1, 3)
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        R, C = self.pose(t)
        dw = np.einsum("nij,nj->ni", R, d)
        s, ids = scene.first_hits(C, dw, t)
        return C + s[:, None] * dw, ids, t, s

"""A frame as the truth across views and time sees it, and where it images surface points, also
through a rolling shutter (numpy only; the visibility cast is a function passed in).

A global-shutter frame images everything at its time: its objects' poses, one camera pose. A
rolling-shutter frame in which something moves (:class:`scenegen.geometry.rolling.RollingRows`)
images each point at the time of the row that sees it: the point is carried by its object to that
time, projected from the camera's pose then, and its visibility is cast from the camera centre
then, with the moving objects where they are then
(:func:`scenegen.geometry.rolling.rolling_project`). Points of frame a are taken into object
coordinates at the time their pixel row of a was exposed.
"""
from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from scenegen.crossview.correspondence import correspond, finite_rows, project_points
from scenegen.dataset.crossview import NO_SURFACE, OCCLUDED, OUT_OF_FRAME, VISIBLE, Correspondence
from scenegen.geometry.conventions import in_image
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.rolling import RollingRows, rolling_project

Poses = Mapping[int, tuple[Rigid3, bool]]  # object id -> (world_from_object, present)


@dataclass(frozen=True, eq=False)
class FrameGeometry:
    """What truth across frames needs of one frame: object poses at its time, camera, pose and
    the visibility cast in its scene. ``visible_fn(centre (3,), points (M, 3))`` for a global
    shutter; with ``rolling`` set, ``visible_fn(centres (M, 3), points (M, 3), rows (M,))``: each
    point seen from the camera centre of its row, the moving objects at that row's time."""

    poses: Poses
    camera: object  # scenegen.geometry.camera.Camera
    cam_from_world: Rigid3  # at the frame's time (its middle row)
    visible_fn: Callable
    rolling: RollingRows | None = None
    # (points (H, W, 3) world, camera, cam_from_world) -> Correspondence in this frame's scene, the
    # definition of correspondence.correspond (e.g. in one kernel); None: correspond with visible_fn
    correspond_fn: Callable | None = None

    def correspond(self, points_world) -> Correspondence:
        """Correspondences of world points (H, W, 3) in this frame at its time (global shutter)."""
        if self.correspond_fn is not None:
            return self.correspond_fn(points_world, self.camera, self.cam_from_world)
        return correspond(points_world, self.camera, self.cam_from_world, self.visible_fn)


@dataclass(frozen=True, eq=False)
class Imaged:
    """Surface points imaged by a frame: their :class:`Correspondence` fields (N,), where they
    are then (N, 3) world, whether their object exists then (N,), and the rows whose time they
    are imaged at (N,) (None: a global shutter, the frame's time)."""

    correspondence: Correspondence
    points_world: np.ndarray
    present: np.ndarray
    rows: np.ndarray | None = None


def moving_ids(frames) -> set[int]:
    """Object ids whose pose differs between the frames or within one of them (rolling)."""
    out: set[int] = set()
    first = frames[0].poses
    for fr in frames:
        if fr.rolling is not None:
            out |= set(fr.rolling.objects)
        out |= {oid for oid, (pose, present) in fr.poses.items()
                if oid in first and (not pose.allclose(first[oid][0], 0.0) or present != first[oid][1])}
    return out


def _poses_at(frame: FrameGeometry, oid: int, rows, n: int):
    """((n, 3, 3), (n, 3), (n,) present) world_from_object of ``oid`` at ``rows`` (n,) of
    ``frame`` (None: the frame's time)."""
    if rows is not None and frame.rolling is not None and oid in frame.rolling.objects:
        return frame.rolling.object_pose(oid, rows)
    pose, present = frame.poses[oid]
    return (np.broadcast_to(pose.R, (n, 3, 3)), np.broadcast_to(pose.t, (n, 3)), np.full(n, bool(present)))


def to_object(points_world, object_ids, frame: FrameGeometry, rows, movers) -> np.ndarray:
    """(N, 3) object coordinates of world points (N, 3) on ``object_ids`` (N,) seen by ``frame``
    at ``rows`` (N,) (None: the frame's time); points not on ``movers`` stay in the world."""
    P = np.asarray(points_world, np.float64).reshape(-1, 3)
    ids = np.asarray(object_ids).reshape(-1)
    X = P.copy()
    for oid in movers:
        sel = np.flatnonzero(ids == oid)
        if len(sel):
            R, t, _ = _poses_at(frame, oid, None if rows is None else rows[sel], len(sel))
            X[sel] = np.einsum("nji,nj->ni", R, P[sel] - t)  # R^T (P - t)
    return X


def to_world(X, object_ids, frame: FrameGeometry, rows, movers) -> tuple[np.ndarray, np.ndarray]:
    """((N, 3) world points, (N,) present) of object coordinates ``X`` (N, 3) at ``frame``'s
    ``rows`` (N,) (None: its time); the inverse of :func:`to_object`."""
    ids = np.asarray(object_ids).reshape(-1)
    P = np.array(X, np.float64).reshape(-1, 3)
    present = np.ones(len(P), bool)
    for oid in movers:
        sel = np.flatnonzero(ids == oid)
        if len(sel):
            R, t, pres = _poses_at(frame, oid, None if rows is None else rows[sel], len(sel))
            P[sel] = np.einsum("nij,nj->ni", R, X[sel]) + t
            present[sel] = pres
    return P, present


def image(X, object_ids, frame: FrameGeometry, movers) -> Imaged:
    """Where ``frame`` images points given in object coordinates ``X`` (N, 3) (world for points
    not on ``movers``; NaN = no point), with their state (module docstring)."""
    X = np.asarray(X, np.float64).reshape(-1, 3)
    ids = np.asarray(object_ids).reshape(-1)
    n = len(X)
    uv = np.full((n, 2), np.nan)
    z = np.full(n, np.nan)
    P = np.full((n, 3), np.nan)
    present = np.ones(n, bool)
    state = np.full(n, NO_SURFACE, np.uint8)
    idx = np.flatnonzero(finite_rows(X))
    cam = frame.camera
    if frame.rolling is None:
        P[idx], present[idx] = to_world(X[idx], ids[idx], frame, None, movers)
        uv_h, z_h, valid = project_points(P[idx], cam, frame.cam_from_world)
        rows = None
    else:
        Xi, ids_i = X[idx], ids[idx]
        rp = rolling_project(cam, frame.rolling.cam, lambda k, r: to_world(Xi[k], ids_i[k], frame, r, movers)[0],
                             len(idx))
        uv_h, z_h, valid, rows = rp.uv, rp.z, rp.valid, rp.row
        P[idx] = rp.points_world
        present[idx] = to_world(Xi, ids_i, frame, rows, movers)[1]
    uv[idx], z[idx] = uv_h, z_h
    all_rows = None
    if rows is not None:
        all_rows = np.full(n, np.nan)
        all_rows[idx] = rows
    inside = valid & in_image(uv_h, cam.width, cam.height)
    state[idx] = OUT_OF_FRAME
    cand = idx[inside]
    if frame.rolling is None:
        vis = frame.visible_fn(frame.cam_from_world.inverse().t, P[cand])
    else:
        r = rows[inside]
        vis = frame.visible_fn(camera_centres(frame, r), P[cand], r)
    state[cand] = np.where(np.asarray(vis, bool), VISIBLE, OCCLUDED)
    state[(state == VISIBLE) & ~present] = OCCLUDED  # an object that is gone is not seen
    return Imaged(Correspondence(uv, z, state), P, present, all_rows)


def camera_centres(frame: FrameGeometry, rows) -> np.ndarray:
    """(N, 3) the camera centre (world) at each of ``rows`` (N,) (a global shutter: the frame's
    one centre, repeated)."""
    if frame.rolling is None or rows is None:
        return np.broadcast_to(frame.cam_from_world.inverse().t, (len(rows) if rows is not None else 1, 3))
    return frame.rolling.cam.at(rows)[1]  # world_from_cam's translation

"""Long point tracks over a sequence (TAP-Vid style), from exact truth: each query's surface point
is moved with its object's pose to every frame (:func:`scenegen.crossview.motion.move_points`),
projected by the frame's camera, and its visibility decided by a ray cast in the frame's scene
(numpy only; the casts are functions passed in). The stored form is
:class:`scenegen.dataset.codecs.tracks.TrackSet`.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from scenegen.crossview.correspondence import correspond
from scenegen.crossview.motion import Poses, move_points
from scenegen.dataset.crossview import OUT_OF_FRAME, VISIBLE


@dataclass(frozen=True)
class FrameGeometry:
    """What a track needs of one frame: object poses, camera, pose and the visibility cast."""

    poses: Poses
    camera: object  # scenegen.geometry.camera.Camera
    cam_from_world: object  # Rigid3
    visible_fn: Callable[[np.ndarray, np.ndarray], np.ndarray]  # in this frame's scene


def track_points(groups, frames: list[FrameGeometry]):
    """((N, T, 2) float64 pixels, (N, T) bool occluded, (N, T) bool out of frame) of surface
    points over the frames. ``groups``: [(points (n, 3) world at their query frame, object ids
    (n,), poses at the query frame)], concatenated in order (N = the sum of the n); each frame
    is cast once for all of them. Occluded: not VISIBLE (out of frame, behind another surface,
    or the object absent), as TAP-Vid counts it."""
    groups = [(np.asarray(P, np.float64).reshape(-1, 3), np.asarray(ids).reshape(-1), poses) for P, ids, poses in groups]
    n, t = sum(len(g[0]) for g in groups), len(frames)
    xy = np.full((n, t, 2), np.nan)
    occ = np.ones((n, t), bool)
    oof = np.ones((n, t), bool)
    for k, fr in enumerate(frames):
        moved = [move_points(P, ids, poses, fr.poses) for P, ids, poses in groups]
        Pk = np.concatenate([m[0] for m in moved]) if moved else np.zeros((0, 3))
        present = np.concatenate([m[1] for m in moved]) if moved else np.zeros(0, bool)
        c = correspond(Pk.reshape(n, 1, 3), fr.camera, fr.cam_from_world, fr.visible_fn)
        state = c.state.reshape(n)
        xy[:, k] = c.uv.reshape(n, 2)
        occ[:, k] = (state != VISIBLE) | ~present
        oof[:, k] = state == OUT_OF_FRAME
    return xy, occ, oof

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


def track_points(points_world, object_ids, poses_query: Poses, frames: list[FrameGeometry]):
    """((N, T, 2) float64 pixels, (N, T) bool occluded, (N, T) bool out of frame) of surface points
    (N, 3) (world, at their query frame, on objects (N,)) over the frames. Occluded: not VISIBLE
    (out of frame, behind another surface, or the object absent), as TAP-Vid counts it."""
    P = np.asarray(points_world, np.float64).reshape(-1, 3)
    n, t = len(P), len(frames)
    xy = np.full((n, t, 2), np.nan)
    occ = np.ones((n, t), bool)
    oof = np.ones((n, t), bool)
    for k, fr in enumerate(frames):
        Pk, present = move_points(P, object_ids, poses_query, fr.poses)
        c = correspond(Pk.reshape(n, 1, 3), fr.camera, fr.cam_from_world, fr.visible_fn)
        state = c.state.reshape(n)
        xy[:, k] = c.uv.reshape(n, 2)
        occ[:, k] = (state != VISIBLE) | ~present
        oof[:, k] = state == OUT_OF_FRAME
    return xy, occ, oof

"""Long point tracks over a sequence (TAP-Vid style), from exact truth: each query's surface point
is moved with its object's pose to every frame (:func:`scenegen.crossview.motion.move_points`),
projected by the frame's camera, and its visibility decided by a ray cast in the frame's scene
(numpy only; the casts are functions passed in). The stored form is
:class:`scenegen.dataset.codecs.tracks.TrackSet`.
"""
from __future__ import annotations

import numpy as np

from scenegen.crossview.frames import FrameGeometry, image, moving_ids, to_object
from scenegen.crossview.motion import move_points
from scenegen.dataset.crossview import OUT_OF_FRAME, VISIBLE

__all__ = ["FrameGeometry", "track_points"]


def track_points(groups, frames: list[FrameGeometry]):
    """((N, T, 2) float64 pixels, (N, T) bool occluded, (N, T) bool out of frame) of surface
    points over the frames. ``groups``: [(points (n, 3) world at their query frame, object ids
    (n,), the query frame (:class:`FrameGeometry`), (n,) the points' pixel rows there)],
    concatenated in order (N = the sum of the n); each frame is cast once for all of them.
    Occluded: not VISIBLE (out of frame, behind another surface, or the object absent), as
    TAP-Vid counts it. Through a rolling shutter a point is taken at its query row's time and
    imaged at the time of the row that sees it (:mod:`scenegen.crossview.frames`)."""
    groups = [(np.asarray(P, np.float64).reshape(-1, 3), np.asarray(ids).reshape(-1), q, np.asarray(rows, np.float64))
              for P, ids, q, rows in groups]
    n, t = sum(len(g[0]) for g in groups), len(frames)
    xy = np.full((n, t, 2), np.nan)
    occ = np.ones((n, t), bool)
    oof = np.ones((n, t), bool)
    rolling = any(f.rolling is not None for f in frames) or any(g[2].rolling is not None for g in groups)
    if rolling:
        movers = moving_ids(frames + [g[2] for g in groups])
        X = np.concatenate([to_object(P, ids, q, rows if q.rolling is not None else None, movers)
                            for P, ids, q, rows in groups]) if groups else np.zeros((0, 3))
        ids_all = np.concatenate([g[1] for g in groups]) if groups else np.zeros(0, np.uint32)
    for k, fr in enumerate(frames):
        if rolling:
            im = image(X, ids_all, fr, movers)
            c, present = im.correspondence, im.present
        else:
            moved = [move_points(P, ids, q.poses, fr.poses) for P, ids, q, _ in groups]
            Pk = np.concatenate([m[0] for m in moved]) if moved else np.zeros((0, 3))
            present = np.concatenate([m[1] for m in moved]) if moved else np.zeros(0, bool)
            c = fr.correspond(Pk.reshape(n, 1, 3))
        state = c.state.reshape(n)
        xy[:, k] = c.uv.reshape(n, 2)
        occ[:, k] = (state != VISIBLE) | ~present
        oof[:, k] = state == OUT_OF_FRAME
    return xy, occ, oof

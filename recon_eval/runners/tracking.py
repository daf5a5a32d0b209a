"""Long point tracks with OpenCV's pyramidal Lucas-Kanade, the TAP-Vid baseline of a real method:
each query point is tracked frame to frame from its query frame forwards to the last frame and
backwards to the first (``cv2.calcOpticalFlowPyrLK``, winSize 21, maxLevel 3, as
:mod:`recon_eval.runners.flow`'s pairwise tracks).

Occlusion is predicted the way such a chain can: a point is lost (occluded from then on, its
position held) when LK's status is 0, when it leaves the image, or when tracking the new position
back to the previous frame misses by more than :data:`FB_MAX_PX` (the forward-backward check of
Kalal et al., ICPR 2010). The chain never re-finds a lost point, so re-appearing points stay
occluded: a baseline, not a tracker.
"""
from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np

from recon_eval.metrics.tapvid import TAPVID_EVAL_SIZE
from recon_eval.readers.tracks import read_tracks
from recon_eval.runners.common import RunOutput, out_path
from recon_eval.tasks.headlines import tracks_headline
from recon_eval.tasks.tracks import score_streams
from scenegen.dataset.codecs import encode_npz
from scenegen.dataset.files import atomic_write_bytes
from scenegen.dataset.layout import check_name
from scenegen.geometry.color import to_grey8

#: Forward-backward error above which a point counts as lost (px).
FB_MAX_PX = 1.0
LK_PARAMS = {"winSize": (21, 21), "maxLevel": 3,
             "criteria": (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 30, 0.01)}


def _step(a: np.ndarray, b: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """LK from frame a to b of points p (M, 2) OpenCV px: (new points, kept)."""
    if not len(p):
        return p, np.zeros(0, bool)
    q, st, _ = cv2.calcOpticalFlowPyrLK(a, b, p.astype(np.float32).reshape(-1, 1, 2), None, **LK_PARAMS)
    back, st_b, _ = cv2.calcOpticalFlowPyrLK(b, a, q, None, **LK_PARAMS)
    q, back = q.reshape(-1, 2).astype(np.float64), back.reshape(-1, 2).astype(np.float64)
    h, w = a.shape[:2]
    inside = (q[:, 0] >= -0.5) & (q[:, 1] >= -0.5) & (q[:, 0] <= w - 0.5) & (q[:, 1] <= h - 0.5)
    fb = np.linalg.norm(back - p, axis=1)
    return q, (st.reshape(-1) > 0) & (st_b.reshape(-1) > 0) & inside & (fb <= FB_MAX_PX)


def lk_tracks(frames_grey8: Sequence[np.ndarray], query_points_tyx) -> tuple[np.ndarray, np.ndarray]:
    """Tracks (N, T, 2) px [x, y] and predicted occlusion (N, T) bool of queries (N, 3)
    [frame, y, x] through the (H, W) uint8 frames. At its query frame a point is visible at the
    query position."""
    frames = list(frames_grey8)
    n_t = len(frames)
    q = np.asarray(query_points_tyx, dtype=np.float64).reshape(-1, 3)
    tracks = np.zeros((len(q), n_t, 2))
    occluded = np.ones((len(q), n_t), bool)
    qt = np.rint(q[:, 0]).astype(np.int64)
    for t0 in np.unique(qt):
        sel = np.flatnonzero(qt == t0)
        start = q[sel][:, [2, 1]]
        tracks[sel, t0], occluded[sel, t0] = start, False
        for direction in (1, -1):
            p, alive, t = start.copy(), np.ones(len(sel), bool), t0
            while 0 <= t + direction < n_t and alive.any():
                nxt, kept = _step(frames[t], frames[t + direction], p[alive])
                idx = np.flatnonzero(alive)
                p[idx[kept]] = nxt[kept]
                alive[idx[~kept]] = False
                t += direction
                tracks[sel, t] = p
                occluded[sel[alive], t] = False
            if direction > 0:  # frames the chain did not reach hold the last position
                tracks[sel, t + 1:] = p[:, None]
            else:
                tracks[sel, :t] = p[:, None]
    return tracks, occluded


def lk_tapvid(ds, out_dir, options) -> RunOutput:
    """The LK chain on every stream of a sequence with point tracks, from the truth's query
    points; raw output ``tracks/<stream>.npz`` (``tracks_xy``, ``occluded``), scored from the files
    with TAP-Vid's metrics at 256 x 256, query mode ``first``."""
    streams = ds.track_streams()
    raw = []
    for stream, frames in streams.items():
        truth = ds.tracks_truth(stream)
        tracks, occ = lk_tracks([to_grey8(ds.image(v)) for v in frames], truth.query_points)
        rel = f"tracks/{check_name('stream', stream)}.npz"
        atomic_write_bytes(out_path(out_dir, rel), encode_npz({"tracks_xy": tracks.astype(np.float32),
                                                               "occluded": occ}))
        raw.append(rel)
    res = score_streams(ds, streams, lambda s, n, t: read_tracks(out_path(out_dir, f"tracks/{s}.npz"), n, t),
                        query_mode="first", eval_size=TAPVID_EVAL_SIZE)
    return RunOutput({"tapvid": res}, tracks_headline(res), raw, {"streams": list(streams), "query_mode": "first",
                                                     "eval_size": list(TAPVID_EVAL_SIZE)})

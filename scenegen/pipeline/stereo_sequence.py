"""The rectified stereo part of the sequence stage: for a stereo rig whose rectified frames are
written (``crossview.stereo``), the truth of KITTI 2015 scene flow on the rectified left grid
(docs/crossview.md, "Sequences"), one ``sequence/stereo_motion/<a>/<b>.exr`` per frame pair.

Frame a's rectified left view is the ideal pinhole of :func:`scenegen.geometry.rectify.rectify`
of the rig's two views at a (the camera the stereo stage renders and casts, ``disp_left.pfm``'s
grid); its truth points come from the truth pass in the scene at a's time, are moved with their
objects' poses a -> b, projected into b's rectified pair and cast in b's scene from both
rectified centres (:func:`scenegen.crossview.motion.moved_stereo_correspondence`). Pairs: frames
(k, k + step) of the rig's stream for every ``sequence.flow_steps`` step, both ways, where all
four views are complete.
"""
from __future__ import annotations

from collections import OrderedDict

import numpy as np

from scenegen.crossview.motion import moved_stereo_correspondence
from scenegen.dataset.sequence import StereoMotionTruth
from scenegen.dataset.truth import TruthKind
from scenegen.geometry.rectify import Rectification, rectify
from scenegen.pipeline.pairs import streams
from scenegen.pipeline.view import correspond_fn, view_time


def stereo_pairs(spec, views, complete: set, steps) -> list[tuple[int, tuple, tuple]]:
    """``(step, (left_a, right_a), (left_b, right_b))`` view pairs of every stereo rig stream for
    each step (a the earlier frame), all four views in ``complete``; none without rectified
    stereo frames (``crossview.stereo``)."""
    cfg = getattr(spec, "crossview", None)
    if cfg is None or not cfg.stereo:
        return []
    right = {(v.view_set, v.frame_index): v for v in views
             if v.rig is not None and spec.rigs[v.rig].type == "stereo" and v.rig_member == "right"}
    out = []
    for (_, member), vs in streams(views).items():
        if member != "left" or spec.rigs[vs[0].rig].type != "stereo":
            continue
        frames = [(v, right.get((v.view_set, v.frame_index))) for v in vs]
        for step in steps:
            for fa, fb in zip(frames, frames[step:]):
                if all(v is not None and v.name in complete for v in (*fa, *fb)):
                    out.append((step, fa, fb))
    return out


class StereoSequence:
    """Rectified left truth of a stereo rig's frames (float64 points, ids, rectification), cached
    for the last ``keep_frames`` frames, and their motion truth."""

    def __init__(self, st, keep_frames: int = 8):
        self.st, self.built = st, st.built
        self.keep_frames = max(2, int(keep_frames))
        self._frames: OrderedDict = OrderedDict()

    def rectification(self, frame) -> Rectification:
        left, right = frame
        cams = self.built.cameras
        return rectify(cams[left.camera], left.cam_from_world, cams[right.camera], right.cam_from_world)

    def frame(self, frame) -> tuple[Rectification, np.ndarray, np.ndarray]:
        """(rectification, (H, W, 3) float64 world points of the rectified left view (NaN = no
        surface), (H, W) uint32 object ids): the stereo stage's truth call at the frame's time."""
        left = frame[0]
        if left.name not in self._frames:
            rect = self.rectification(frame)
            t = self.built.truth(rect.camera, rect.cam_left_from_world, time_s=view_time(left))
            P = np.where(t[TruthKind.VALID][..., None], t[TruthKind.POINTS_WORLD], np.nan)
            self._frames[left.name] = (rect, P, t[TruthKind.OBJECT_ID].copy())
            while len(self._frames) > self.keep_frames:
                self._frames.popitem(last=False)
        self._frames.move_to_end(left.name)
        return self._frames[left.name]

    def motion(self, frame_a, frame_b) -> StereoMotionTruth:
        """Where a's rectified left surface points are in b's rectified pair."""
        _, P, ids = self.frame(frame_a)
        rect_b = self.rectification(frame_b)
        return moved_stereo_correspondence(P, ids, self.st.poses(frame_a[0]), self.st.poses(frame_b[0]), rect_b,
                                           correspond_fn(self.built, frame_b[0]))

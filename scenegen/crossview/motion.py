"""Truth across time: where the surface point behind each pixel of frame a is at frame b, with
the objects moved (numpy only; the visibility test at b is a function passed in).

The core, for pixel p of frame a with surface point P_a (world) on object o:
``X = object_from_world_o(a) @ P_a`` (object coordinates), ``P_b = world_from_object_o(b) @ X``,
then b's single camera model projects P_b (:func:`scenegen.crossview.correspondence.correspond`),
and the ray cast of b's scene decides its state: VISIBLE, OCCLUDED, OUT_OF_FRAME, as for the
static correspondences. A point whose object does not exist at b (outside its ``visible_s``) is
OCCLUDED wherever it projects into b's image. Scene flow is ``P_b - P_a`` in the world frame.
Through a rolling shutter (:func:`frame_motion`), P_a is where the point was when a's row saw it
and P_b where it is when the row of b that images it is exposed (:mod:`scenegen.crossview.frames`).

For a stereo rig (:func:`moved_stereo_correspondence`) the same moved points are projected into
b's RECTIFIED pair (the ideal pinholes of :func:`scenegen.geometry.rectify.rectify` at b): the
left view gives flow and depth z_b, the disparity is ``f_b B_b / z_b`` and the right view's ray
cast decides the second state (KITTI 2015 scene flow's flow and disp_1).
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np

from scenegen.crossview.frames import FrameGeometry, Poses, image, moving_ids, to_object
from scenegen.dataset.crossview import OCCLUDED, VISIBLE, Correspondence
from scenegen.dataset.sequence import MotionTruth, StereoMotionTruth
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.rectify import Rectification, disparity_from_depth


def _apply(T: Rigid3, P: np.ndarray) -> np.ndarray:
    """``T.apply(P)`` per component (no BLAS thread pool next to Dr.Jit's: 10x faster here)."""
    out = np.empty_like(P)
    for i in range(3):
        out[:, i] = T.R[i, 0] * P[:, 0] + T.R[i, 1] * P[:, 1] + T.R[i, 2] * P[:, 2] + T.t[i]
    return out


def move_points(points_world, object_ids, poses_a: Poses, poses_b: Poses) -> tuple[np.ndarray, np.ndarray]:
    """((N, 3) float64 points at b, (N,) bool their object exists at b) of points (N, 3) at a on
    objects ``object_ids`` (N,) (0 or unknown: no object, the point stays where it is)."""
    P = np.asarray(points_world, np.float64).reshape(-1, 3)
    ids = np.asarray(object_ids).reshape(-1)
    out = P.copy()
    present = np.ones(len(P), bool)
    for oid, (wa, _) in poses_a.items():
        wb, pb = poses_b[oid]
        still = wa.allclose(wb, 0.0)
        if still and pb:
            continue  # a static object: its points stay, all present (no pass over the pixels)
        sel = np.flatnonzero(ids == oid)
        if not still:
            out[sel] = _apply(wb @ wa.inverse(), P[sel])
        present[sel] = pb
    return out, present


def _present_state(c: Correspondence, present) -> Correspondence:
    """``c`` with a point whose object does not exist at b OCCLUDED wherever it would be seen."""
    state = c.state.copy()
    state[(state == VISIBLE) & ~present] = OCCLUDED
    return Correspondence(c.uv, c.z, state)


def frame_motion(points_world_a, object_ids_a, frame_a: FrameGeometry, frame_b: FrameGeometry,
                 rows_a=None) -> MotionTruth:
    """Motion truth of a's truth points (H, W, 3) (float64, NaN = no surface) on objects (H, W) at
    frame b, either frame through a rolling shutter (a's points at the times of their rows in a:
    ``rows_a`` (H * W,), by default each pixel's own row)."""
    P = np.asarray(points_world_a, np.float64)
    H, W, _ = P.shape
    if frame_a.rolling is None and frame_b.rolling is None:
        Pb, present = move_points(P.reshape(-1, 3), object_ids_a, frame_a.poses, frame_b.poses)
        Pb = Pb.reshape(H, W, 3)
        return MotionTruth(_present_state(frame_b.correspond(Pb), present.reshape(H, W)), Pb - P)
    movers = moving_ids([frame_a, frame_b])
    if frame_a.rolling is None:
        rows_a = None
    elif rows_a is None:
        rows_a = np.repeat(np.arange(H, dtype=np.float64), W)
    X = to_object(P.reshape(-1, 3), object_ids_a, frame_a, rows_a, movers)
    im = image(X, object_ids_a, frame_b, movers)
    c = im.correspondence
    return MotionTruth(Correspondence(c.uv.reshape(H, W, 2), c.z.reshape(H, W), c.state.reshape(H, W)),
                      im.points_world.reshape(H, W, 3) - P)


def moved_stereo_correspondence(points_world_a, object_ids_a, poses_a: Poses, poses_b: Poses,
                                rect_b: Rectification, correspond_b: Callable) -> StereoMotionTruth:
    """Stereo motion truth of a's rectified left truth points (H, W, 3) (float64, NaN = no
    surface) on objects (H, W) in b's rectified pair ``rect_b``: flow and depth in its left view,
    disparity ``f_b B_b / z_b``, the states in both views. ``correspond_b(points (H, W, 3),
    camera, cam_from_world) -> Correspondence`` in b's scene (the rectified centres are the raw
    cameras' centres)."""
    P = np.asarray(points_world_a, np.float64)
    H, W, _ = P.shape
    Pb, present = move_points(P.reshape(-1, 3), object_ids_a, poses_a, poses_b)
    Pb, present = Pb.reshape(H, W, 3), present.reshape(H, W)
    left = _present_state(correspond_b(Pb, rect_b.camera, rect_b.cam_left_from_world), present)
    right = _present_state(correspond_b(Pb, rect_b.camera, rect_b.cam_right_from_world), present)
    return StereoMotionTruth(MotionTruth(left, Pb - P), right.state,
                             disparity_from_depth(left.z, rect_b.f, rect_b.baseline_m))

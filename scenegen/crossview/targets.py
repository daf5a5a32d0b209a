"""Calibration-target truth per view: each board point's world position, its exact projection
through the view's full camera model, and its visibility (numpy; visibility by a passed function).

``state`` uses :mod:`scenegen.crossview.correspondence`'s codes: VISIBLE (1), OCCLUDED (2,
something in front, or the board seen from its back), OUT_OF_FRAME (3). ``facing`` is True when
the camera is on the printed side (boards print on their -z side in the board frame).
"""
from __future__ import annotations

import numpy as np

from scenegen.crossview.correspondence import project_points
from scenegen.crossview.frames import camera_centres, image
from scenegen.dataset.crossview import OCCLUDED, OUT_OF_FRAME, VISIBLE
from scenegen.geometry.conventions import in_image


def board_view_truth(board, world_from_board, camera, cam_from_world, visible_fn, frame=None,
                     board_object=None) -> dict:
    """JSON-ready truth of one board in one view (see the module docstring). ChArUco boards also
    get their markers' corners (``marker_ids``, ``marker_corners`` with the same fields, (M, 4)
    in OpenCV's corner order). ``frame``: the view as a :class:`scenegen.crossview.frames.FrameGeometry`
    with a rolling shutter's rows (then each point is imaged at the time of the row that sees it,
    and ``board_object`` = (object id, world_from_object at the view's time) of the board's object)."""
    truth = lambda pts: _points_truth(pts, world_from_board, camera, cam_from_world, visible_fn)  # noqa: E731
    if frame is not None and frame.rolling is not None:
        truth = lambda pts: _rolling_points_truth(pts, world_from_board, frame, board_object)  # noqa: E731
    out = truth(np.asarray(board.points_board, np.float64))
    out = {"kind": board.kind, "point_ids": np.asarray(board.point_ids).tolist(), **out}
    if board.kind == "charuco" and len(board.marker_ids):
        mc = truth(np.asarray(board.marker_corners_board, np.float64).reshape(-1, 3))
        out["marker_ids"] = np.asarray(board.marker_ids).tolist()
        out["marker_corners"] = {k: [v[i:i + 4] for i in range(0, len(v), 4)] for k, v in mc.items()}
    return out


def _points_truth(points_board, world_from_board, camera, cam_from_world, visible_fn) -> dict:
    P = world_from_board.apply(points_board)
    uv, z, valid = project_points(P, camera, cam_from_world)
    inside = valid & in_image(uv, camera.width, camera.height)
    C = cam_from_world.inverse().t
    n_print = world_from_board.rotate(np.array([0.0, 0.0, -1.0]))  # print side normal, world
    facing = (C - P) @ n_print > 0
    state = np.full(len(P), OUT_OF_FRAME, np.int64)
    cand = np.flatnonzero(inside)
    vis = np.asarray(visible_fn(C, P[cand]), bool) & facing[cand]
    state[cand] = np.where(vis, VISIBLE, OCCLUDED)
    return _document(P, uv, z, state, facing)


def _rolling_points_truth(points_board, world_from_board, frame, board_object) -> dict:
    """:func:`_points_truth` through a rolling shutter: each point where it is (the board moving
    with its object) when the row that images it is exposed, seen from that row's centre."""
    oid, world_from_object = board_object
    moving = oid in frame.rolling.objects
    P0 = world_from_board.apply(points_board)
    object_from_board = world_from_object.inverse() @ world_from_board
    X = object_from_board.apply(points_board) if moving else P0
    ids = np.full(len(P0), oid)
    im = image(X, ids, frame, {oid} if moving else set())
    P = im.points_world
    rows = im.rows
    n_print = np.broadcast_to(world_from_board.rotate(np.array([0.0, 0.0, -1.0])), P.shape)
    if moving:  # the print side turns with the board
        R, _ = frame.rolling.objects[oid].at(np.nan_to_num(rows))
        n_print = R @ object_from_board.rotate(np.array([0.0, 0.0, -1.0]))
    C = camera_centres(frame, np.nan_to_num(rows))
    facing = np.einsum("ni,ni->n", C - P, n_print) > 0
    state = im.correspondence.state.astype(np.int64)
    state[(state == VISIBLE) & ~facing] = OCCLUDED
    return _document(P, im.correspondence.uv, im.correspondence.z, state, facing)


def _document(P, uv, z, state, facing) -> dict:
    return {"points_world": P.tolist(),
            "uv": [[float(a), float(b)] if np.isfinite(a) else None for a, b in uv],
            "depth_z": [float(x) for x in z], "state": state.tolist(), "facing": facing.tolist()}

"""``scene/targets/<object>.json``: a calibration target's exact points, board and world frame.

Keys: ``kind``, ``size_m``, ``world_from_board`` ({R, t}), ``point_ids``, ``points_board`` and
``points_world`` (N x 3, metres), ``frame`` (the board frame in words), and for ChArUco / ArUco
boards ``marker_ids`` and ``marker_corners_board`` (M x 4 x 3, OpenCV's corner order).
"""
from __future__ import annotations

import numpy as np

BOARD_FRAME = ("board: origin at the top-left physical corner, x along the picture's columns,"
               " y along its rows, z = 0 on the surface")


def target_document(board, world_from_board) -> dict:
    """The JSON document of a board (:class:`scenegen.assets.targets.Board`, read by attribute)
    placed by ``world_from_board`` (Rigid3)."""
    pts = np.asarray(board.points_board, dtype=np.float64)
    d = {"kind": board.kind, "size_m": list(map(float, board.size_m)),
         "world_from_board": world_from_board.to_dict(),
         "point_ids": np.asarray(board.point_ids).tolist(),
         "points_board": pts.tolist(), "points_world": world_from_board.apply(pts).tolist(),
         "frame": BOARD_FRAME}
    for extra in ("marker_ids", "marker_corners_board"):
        if getattr(board, extra, None) is not None:
            d[extra] = np.asarray(getattr(board, extra)).tolist()
    return d

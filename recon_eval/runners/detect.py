"""Marker-board detection shared by the runners: ChArUco corners and ArUco-grid marker corners
found by ``cv2.aruco`` in a view, matched by id to the board truth (scene/targets/<board>.json:
ChArUco corner ids, ArUco-grid ``marker_id * 4 + corner``)."""
from __future__ import annotations

import cv2
import numpy as np

from scenegen.geometry.color import to_grey8

#: Board kinds :func:`detect_board_points` finds (checkerboards: runners.calibration).
MARKER_BOARD_KINDS = ("charuco", "aruco_grid", "aruco")


def detect_board_points(image, geo: dict, truth: dict) -> tuple[np.ndarray, np.ndarray]:
    """(image points (N, 2) OpenCV px, world points (N, 3) m) of a ChArUco / ArUco board in an
    image (H, W[, 3]) RGB or grey, uint8/uint16; ``geo`` is the board's spec geometry, ``truth`` its
    target truth (``point_ids``, ``points_world``)."""
    d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, geo["dictionary"]))
    g = to_grey8(image)
    P = np.asarray(truth["points_world"], np.float64)
    ids_truth = {int(k): n for n, k in enumerate(truth["point_ids"])}
    if geo["kind"] == "charuco":
        board = cv2.aruco.CharucoBoard((int(geo["squares_x"]), int(geo["squares_y"])), float(geo["square_m"]),
                                       float(geo["marker_m"]), d)
        board.setLegacyPattern(bool(geo.get("legacy_pattern", False)))  # the spec's ChArUco layout
        corners, ids, _, _ = cv2.aruco.CharucoDetector(board).detectBoard(g)
        if ids is None:
            return np.zeros((0, 2)), np.zeros((0, 3))
        idx = [ids_truth[int(i)] for i in ids.ravel()]
        return np.asarray(corners, np.float64).reshape(-1, 2), P[idx]
    corners, ids, _ = cv2.aruco.ArucoDetector(d).detectMarkers(g)
    if ids is None:
        return np.zeros((0, 2)), np.zeros((0, 3))
    x, X = [], []
    for c, mid in zip(corners, ids.ravel()):
        for k in range(4):  # aruco grid truth: id = marker_id * 4 + corner
            n = ids_truth.get(int(mid) * 4 + k)
            if n is not None:
                x.append(c.reshape(4, 2)[k])
                X.append(P[n])
    return np.asarray(x, np.float64).reshape(-1, 2), np.asarray(X, np.float64).reshape(-1, 3)

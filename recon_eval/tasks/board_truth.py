"""Calibration-board truth points of a dataset addressed by (board name, point id), and the test
that a point set is three-dimensional enough for a DLT or a 15-DoF projective alignment.

Board truth: ``scene/targets/<board>.json`` through the dataset reader
(:meth:`recon_eval.readers.scenegen_dataset.DatasetTruth.boards`: ``point_ids``, ``points_world``,
metres, world frame; ids as scenegen.assets.targets documents: ChArUco corner ids, ArUco-grid
``marker_id * 4 + corner``).
"""
from __future__ import annotations

import numpy as np

from recon_eval.errors import InputError
from scenegen.dataset.layout import TARGETS_DIR, target_path

#: Smallest singular value over the largest of the centred points (N, 3) below which they count
#: as coplanar. One board's points are coplanar to rounding (ratio ~1e-16); boards on two or three
#: faces of a corner give ~0.3-0.6. The DLT and the 15-DoF alignment need 3D points: under 1e-3
#: the out-of-plane direction is fixed by less than 0.1 % of the point spread, and any pixel
#: noise decides it instead of the geometry.
MIN_THICKNESS_RATIO = 1e-3


def thickness_ratio(points) -> float:
    """sigma_min / sigma_max of the centred points (N, 3); 0 for fewer than 4 points."""
    X = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(X) < 4:
        return 0.0
    s = np.linalg.svd(X - X.mean(axis=0), compute_uv=False)
    return float(s[2] / s[0]) if s[0] > 0 else 0.0


def is_three_dimensional(points) -> bool:
    return thickness_ratio(points) >= MIN_THICKNESS_RATIO


def board_points(ds) -> dict:
    """``{(board, point_id): (3,) world point}`` of every ChArUco / ArUco / checkerboard target
    of the dataset (empty if it has none)."""
    out = {}
    for name, (_, truth) in ds.boards().items():
        for pid, X in zip(truth["point_ids"], np.asarray(truth["points_world"], np.float64).reshape(-1, 3)):
            out[(name, int(pid))] = X
    return out


def lookup_board_points(ds, rows, path) -> np.ndarray:
    """Truth points (N, 3) for text rows whose labels are ``(board, id)``
    (:class:`recon_eval.readers.rows.Row`); an unknown board or id, or a repeated one, is an
    error naming ``path:line``."""
    table = board_points(ds)
    names = sorted({b for b, _ in table})
    seen, out = {}, []
    for r in rows:
        board, sid = r.labels
        try:
            pid = int(sid)
        except ValueError:
            raise InputError(f"{path}:{r.line}: point id {sid!r} is not an integer") from None
        if (board, pid) not in table:
            if board not in names:
                raise InputError(f"{path}:{r.line}: no board {board!r} in {ds.root / TARGETS_DIR} "
                                 f"(boards: {', '.join(names) or 'none'})")
            raise InputError(f"{path}:{r.line}: board {board!r} has no point id {pid} "
                             f"({ds.root / target_path(board)}: point_ids)")
        if (board, pid) in seen:
            raise InputError(f"{path}:{r.line}: point {board} {pid} repeats line {seen[(board, pid)]}")
        seen[(board, pid)] = r.line
        out.append(table[(board, pid)])
    return np.asarray(out, np.float64).reshape(-1, 3)

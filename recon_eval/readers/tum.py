"""TUM RGB-D trajectories: ``timestamp tx ty tz qx qy qz qw`` per line (vision.in.tum.de format).

Each line is the pose of the camera in the world (world_from_cam; quaternion *scalar last*). The
reader converts to cam_from_world and assumes OpenCV camera axes. Poses are named by their
timestamp string; :func:`associate` matches two trajectories by nearest timestamps.

OpenVINS's ov_eval writes the same lines followed by the upper triangles of the orientation and
position covariances, 20 numbers (``... qw Pr11 Pr12 Pr13 Pr22 Pr23 Pr33 Pt11 Pt12 Pt13 Pt22 Pt23
Pt33``, ov_eval ``Loader::load_data``); those are kept as ``cov_ori`` (rad^2) and ``cov_pos``
(m^2), for NEES (:mod:`recon_eval.metrics.nees`). Every line of a file has the same count.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from recon_eval.metrics.nees import covariances_from_upper
from recon_eval.metrics.poses import Poses
from recon_eval.readers.text import read_text
from scenegen.geometry.rotation import matrix_from_quat_wxyz


@dataclass(frozen=True)
class TumTrajectory:
    timestamps_s: np.ndarray  # (N,)
    poses: Poses  # cam_from_world, names = "%.6f" % timestamp
    cov_ori: np.ndarray | None = None  # (N, 3, 3) rad^2, ov_eval's 20-number lines only
    cov_pos: np.ndarray | None = None  # (N, 3, 3) m^2


def read_tum(path) -> TumTrajectory:
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such file (expected a TUM trajectory: timestamp tx ty tz qx qy qz qw)")
    rows = []
    for k, ln in enumerate(read_text(p, "a TUM trajectory").splitlines(), start=1):
        ln = ln.split("#", 1)[0].replace(",", " ").strip()
        if not ln:
            continue
        tok = ln.split()
        if len(tok) not in (8, 20) or (rows and len(tok) != len(rows[0])):
            want = (f"{len(rows[0])} numbers as the lines above" if rows
                    else "8 numbers (timestamp tx ty tz qx qy qz qw)")
            raise InputError(f"{p}:{k}: expected {want} (or ov_eval's 20 with covariances), got {len(tok)}")
        try:
            rows.append([float(v) for v in tok])
        except ValueError:
            raise InputError(f"{p}:{k}: not numbers: {ln!r}") from None
    a = np.asarray(rows, dtype=np.float64).reshape(-1, len(rows[0]) if rows else 8)
    if not np.all(np.isfinite(a)) or (len(a) and not np.all(np.linalg.norm(a[:, 4:8], axis=1) > 0)):
        raise InputError(f"{p}: non-finite values or zero quaternions")
    q_wxyz = a[:, [7, 4, 5, 6]]
    R_wc = matrix_from_quat_wxyz(q_wxyz)  # finite and non-zero: checked above
    R_cw = np.swapaxes(R_wc, 1, 2)
    t_cw = -np.einsum("nij,nj->ni", R_cw, a[:, 1:4])
    names = tuple(f"{t:.6f}" for t in a[:, 0])
    if a.shape[1] == 20:
        return TumTrajectory(a[:, 0].copy(), Poses(names, R_cw, t_cw), covariances_from_upper(a[:, 8:14]),
                             covariances_from_upper(a[:, 14:20]))
    return TumTrajectory(a[:, 0].copy(), Poses(names, R_cw, t_cw))


def associate(traj_est: TumTrajectory, traj_gt: TumTrajectory, max_diff_s: float = 0.01) -> Poses:
    """The estimate renamed after the truth: each truth timestamp takes the estimate with the
    nearest timestamp within ``max_diff_s`` (each estimate used once, greedy by time difference,
    as evo/TUM ``associate.py``). Truth poses without a partner stay unregistered."""
    te, tg = np.asarray(traj_est.timestamps_s), np.asarray(traj_gt.timestamps_s)
    order = np.argsort(te)
    ts = te[order]
    cand = []  # (time difference, estimate index, truth index) for the two neighbours of each truth time
    if len(ts):
        pos = np.searchsorted(ts, tg)
        for j, b in enumerate(tg):
            for k in (pos[j] - 1, pos[j]):
                if 0 <= k < len(ts) and abs(ts[k] - b) <= max_diff_s:
                    cand.append((abs(ts[k] - b), int(order[k]), j))
    cand.sort()
    used_e, used_g, pairs = set(), set(), []
    for _, i, j in cand:
        if i not in used_e and j not in used_g:
            used_e.add(i)
            used_g.add(j)
            pairs.append((i, j))
    pairs.sort(key=lambda p: p[1])
    ie = [i for i, _ in pairs]
    return Poses(tuple(traj_gt.poses.names[j] for _, j in pairs),
                 traj_est.poses.R_cam_from_world[ie].reshape(-1, 3, 3),
                 traj_est.poses.t_cam_from_world[ie].reshape(-1, 3))

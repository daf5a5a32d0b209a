"""TUM RGB-D trajectories: ``timestamp tx ty tz qx qy qz qw`` per line (vision.in.tum.de format).

Each line is the pose of the camera in the world (world_from_cam; quaternion *scalar last*). The
reader converts to cam_from_world and assumes OpenCV camera axes. Poses are named by their
timestamp string; :func:`associate` matches two trajectories by nearest timestamps.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from recon_eval.metrics.poses import Poses
from recon_eval.readers.text import read_text
from scenegen.geometry.rotation import matrix_from_quat_wxyz


@dataclass(frozen=True)
class TumTrajectory:
    timestamps_s: np.ndarray  # (N,)
    poses: Poses  # cam_from_world, names = "%.6f" % timestamp


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
        if len(tok) != 8:
            raise InputError(f"{p}:{k}: expected 8 numbers (timestamp tx ty tz qx qy qz qw), got {len(tok)}")
        try:
            rows.append([float(v) for v in tok])
        except ValueError:
            raise InputError(f"{p}:{k}: not numbers: {ln!r}") from None
    a = np.asarray(rows, dtype=np.float64).reshape(-1, 8)
    if not np.all(np.isfinite(a)) or (len(a) and not np.all(np.linalg.norm(a[:, 4:8], axis=1) > 0)):
        raise InputError(f"{p}: non-finite values or zero quaternions")
    q_wxyz = a[:, [7, 4, 5, 6]]
    R_wc = matrix_from_quat_wxyz(q_wxyz)  # finite and non-zero: checked above
    R_cw = np.swapaxes(R_wc, 1, 2)
    t_cw = -np.einsum("nij,nj->ni", R_cw, a[:, 1:4])
    names = tuple(f"{t:.6f}" for t in a[:, 0])
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

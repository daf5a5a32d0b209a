"""EuRoC MAV ground truth (ASL dataset format, ``mav0/state_groundtruth_estimate0/data.csv``; also
what evo reads as ``euroc``): a ``#timestamp, p_RS_R_x [m], ...`` header line, then per row the
timestamp in integer nanoseconds, the body's position ``p_RS_R`` in the world and its orientation
``q_RS`` (world_from_body, **w first**), followed by velocity and biases (not read here).

Read as a stamped trajectory (:class:`recon_eval.readers.tum.TumTrajectory`: seconds = ns / 1e9,
as evo converts them; the body's poses as cam_from_world), so it is associated by time like a TUM
file.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from recon_eval.errors import InputError
from recon_eval.metrics.poses import Poses
from recon_eval.readers.text import read_text
from recon_eval.readers.tum import TumTrajectory
from scenegen.geometry.rotation import matrix_from_quat_wxyz


def is_euroc_groundtruth(path: Path) -> bool:
    """A ``.csv`` whose first line is EuRoC's ground-truth header (names ``p_RS_R_x``)."""
    if not (path.is_file() and path.suffix.lower() == ".csv"):
        return False
    with open(path, "rb") as f:
        head = f.readline(4096)
    return head.startswith(b"#") and b"p_RS_R_x" in head


def read_euroc_groundtruth(path) -> TumTrajectory:
    p = Path(path)
    rows = []
    for k, ln in enumerate(read_text(p, "a EuRoC ground-truth csv").splitlines(), start=1):
        ln = ln.strip()
        if not ln or ln.startswith("#"):
            continue
        tok = [t.strip() for t in ln.split(",")]
        if len(tok) < 8:
            raise InputError(f"{p}:{k}: expected timestamp [ns], p_RS_R xyz, q_RS wxyz (8 or more columns), "
                             f"got {len(tok)}")
        try:
            rows.append((int(tok[0]), [float(v) for v in tok[1:8]]))
        except ValueError:
            raise InputError(f"{p}:{k}: not an integer timestamp and numbers: {ln[:80]!r}") from None
    if not rows:
        raise InputError(f"{p}: no ground-truth rows (expected EuRoC's state_groundtruth_estimate0/data.csv)")
    a = np.array([r for _, r in rows], dtype=np.float64)
    if not np.all(np.isfinite(a)) or not np.all(np.linalg.norm(a[:, 3:7], axis=1) > 0):
        raise InputError(f"{p}: non-finite values or zero quaternions")
    stamps_s = np.array([s for s, _ in rows], dtype=np.float64) / 1e9
    R_wb = matrix_from_quat_wxyz(a[:, 3:7])
    R_bw = np.swapaxes(R_wb, 1, 2)
    names = tuple(str(s) for s, _ in rows)
    if len(set(names)) != len(names):
        raise InputError(f"{p}: repeated timestamps")
    return TumTrajectory(stamps_s, Poses(names, R_bw, -np.einsum("nij,nj->ni", R_bw, a[:, 0:3])))

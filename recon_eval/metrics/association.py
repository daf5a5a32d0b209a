"""Timestamp association of two trajectories as evo does it (evo 1.38 ``core/sync.py``
``matching_time_indices`` and ``associate_trajectories`` with ``SyncMethod.nearest_time``).

evo starts from the trajectory with fewer poses (the truth when both are as long) and gives each
of its stamps the nearest stamp of the other, shifted by the offset, when the difference is at most
``max_diff_s`` (``<=``; a tie goes to the earlier stamp). A pose of the longer trajectory can be
taken twice. The offset is added to the second (estimated) trajectory's stamps: evo's
``--t_offset``. This differs from TUM's ``associate.py`` (unique pairs, greedy by difference),
which :func:`recon_eval.readers.tum.associate` keeps.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.errors import InputError


def matching_time_indices(stamps_1_s, stamps_2_s, max_diff_s: float = 0.01,
                          offset_2_s: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """For each stamp of ``stamps_1_s`` (N1,) seconds, the nearest of ``stamps_2_s + offset_2_s``
    (N2,) within ``max_diff_s``; returns the index arrays (K,), (K,) of the matches, in the order
    of ``stamps_1_s`` (evo ``matching_time_indices``, its sorted and unsorted branches)."""
    s1 = np.asarray(stamps_1_s, dtype=np.float64).reshape(-1)
    s2 = np.asarray(stamps_2_s, dtype=np.float64).reshape(-1) + float(offset_2_s)
    i1, i2 = [], []
    if len(s2) == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    if not np.all(np.diff(s2) >= 0):  # evo's linear search: argmin takes the first of equal differences
        for k, s in enumerate(s1):
            d = np.abs(s2 - s)
            j = int(np.argmin(d))
            if d[j] <= max_diff_s:
                i1.append(k)
                i2.append(j)
        return np.asarray(i1, np.int64), np.asarray(i2, np.int64)
    for k, s in enumerate(s1):
        if s < s2[0] - max_diff_s or s > s2[-1] + max_diff_s:
            continue
        j = min(int(np.searchsorted(s2, s, side="right")), len(s2) - 1)
        diff_ub = s2[j] - s
        diff_lb = s - s2[j - 1] if j > 0 else np.inf
        if diff_ub <= max_diff_s and diff_ub < diff_lb:
            best = j
        elif diff_lb <= max_diff_s and diff_lb <= diff_ub:
            best = j - 1
        else:
            continue
        i1.append(k)
        i2.append(best)
    return np.asarray(i1, np.int64), np.asarray(i2, np.int64)


@dataclass(frozen=True)
class Association:
    """Index pairs of an association: ``ref[k]`` is matched with ``est[k]``, in the order of the
    shorter trajectory's stamps (evo's)."""

    ref: np.ndarray  # (K,) indices into the reference (truth) stamps
    est: np.ndarray  # (K,) indices into the estimated stamps
    max_diff_s: float
    offset_s: float  # added to the estimated stamps before matching (evo --t_offset)


def associate_evo(stamps_ref_s, stamps_est_s, max_diff_s: float = 0.01, offset_s: float = 0.0) -> Association:
    """evo's ``associate_trajectories(traj_ref, traj_est, max_diff, offset_2)``: the estimate's
    stamps shifted by ``offset_s``; matched from the shorter trajectory (the reference when both
    have as many poses). Raises :class:`InputError` when nothing matches, as evo does."""
    if not (np.isfinite(max_diff_s) and max_diff_s >= 0 and np.isfinite(offset_s)):
        raise InputError(f"association: max difference must be >= 0 and the offset finite, got {max_diff_s}, "
                         f"{offset_s}")
    ref = np.asarray(stamps_ref_s, dtype=np.float64).reshape(-1)
    est = np.asarray(stamps_est_s, dtype=np.float64).reshape(-1)
    if len(est) > len(ref):
        i_ref, i_est = matching_time_indices(ref, est, max_diff_s, offset_s)
    else:
        i_est, i_ref = matching_time_indices(est, ref, max_diff_s, -offset_s)
    if len(i_ref) == 0:
        raise InputError(f"found no matching timestamps between the truth and the estimate with max. time diff "
                         f"{max_diff_s} s and time offset {offset_s} s")
    i_ref.setflags(write=False)
    i_est.setflags(write=False)
    return Association(i_ref, i_est, float(max_diff_s), float(offset_s))

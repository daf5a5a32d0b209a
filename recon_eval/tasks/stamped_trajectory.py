"""Scoring a timestamped trajectory (TUM lines, or ov_eval's with covariances) against a timestamped
truth: evo's association (:mod:`recon_eval.metrics.association`), then the VIO benchmarks'
figures on the associated poses: rpg_trajectory_evaluation's aligned absolute errors and relative
errors over sub-trajectory lengths (drift per distance) and durations (drift per time), and
ov_eval's NEES when the estimate carries covariances. Poses are world_from_cam (the TUM lines)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.errors import InputError
from recon_eval.metrics.association import Association, associate_evo
from recon_eval.metrics.nees import NeesResult, nees
from recon_eval.metrics.poses import Poses
from recon_eval.metrics.rpg_trajectory import (RPG_LENGTH_FRACTIONS, RpgAbsoluteError, default_lengths_m,
                                               relative_errors, rpg_absolute_error, rpg_alignment)
from recon_eval.readers.tum import TumTrajectory


def associated_poses(est: TumTrajectory, gt: TumTrajectory, a: Association) -> tuple[Poses, Poses]:
    """``(est, gt)`` as name-matched :class:`Poses` for the APE/RPE of :mod:`recon_eval.metrics.poses`:
    every truth pose in time order (one without a partner stays unregistered, a failure), a truth
    pose evo pairs twice repeated (named ``<stamp>#2``, ...), each paired estimate named after its
    truth pose; the finite statistics are then evo's on its associated pair."""
    partners: dict[int, list[int]] = {}
    for i_ref, i_est in zip(a.ref.tolist(), a.est.tolist()):
        partners.setdefault(i_ref, []).append(i_est)
    g_idx, g_names, e_idx, e_names = [], [], [], []
    for j, name in enumerate(gt.poses.names):
        for k, i in enumerate(partners.get(j, [None])):
            nm = name if k == 0 else f"{name}#{k + 1}"
            g_idx.append(j)
            g_names.append(nm)
            if i is not None:
                e_idx.append(i)
                e_names.append(nm)
    G, E = gt.poses, est.poses
    return (Poses(tuple(e_names), E.R_cam_from_world[e_idx].reshape(-1, 3, 3),
                  E.t_cam_from_world[e_idx].reshape(-1, 3)),
            Poses(tuple(g_names), G.R_cam_from_world[g_idx], G.t_cam_from_world[g_idx]))


def _world_from_cam(poses: Poses, idx) -> tuple[np.ndarray, np.ndarray]:
    return poses.centers_world[idx], np.swapaxes(poses.R_cam_from_world[idx], 1, 2)


@dataclass(frozen=True)
class StampedScores:
    """The VIO benchmarks' figures of one associated trajectory (module docstring)."""

    n_associated: int
    n_truth: int
    n_estimate: int
    max_diff_s: float
    offset_s: float  # added to the estimate's stamps (evo --t_offset)
    absolute: RpgAbsoluteError  # rpg, after its alignment
    relative_per_distance: dict  # "<d> m" -> RelativeErrors or None (too few sub-trajectories)
    drift_per_time: dict  # "<d> s" -> RelativeErrors or None
    nees: NeesResult | None  # ov_eval, when the estimate has covariances


def score_stamped(est: TumTrajectory, gt: TumTrajectory, *, max_diff_s: float = 0.01, offset_s: float = 0.0,
                  alignment: str = "sim3", n_aligned: int = -1, lengths_m=None, durations_s=None,
                  nees_alignment: str = "posyaw") -> StampedScores:
    """Associate (evo), align (rpg ``alignment`` over the first ``n_aligned`` poses, -1 all) and
    score. ``lengths_m``: rpg's sub-trajectory lengths (default 10 .. 50 % of the truth's path);
    ``durations_s``: the same fractions of the associated truth's duration, truncated to ms."""
    a = associate_evo(gt.timestamps_s, est.timestamps_s, max_diff_s, offset_s)
    if len(a.ref) < 3:
        raise InputError(f"only {len(a.ref)} poses associated within {max_diff_s} s; scoring needs >= 3")
    p_e, R_e = _world_from_cam(est.poses, a.est)
    p_g, R_g = _world_from_cam(gt.poses, a.ref)
    stamps = np.asarray(gt.timestamps_s)[a.ref]
    absolute = rpg_absolute_error(p_e, R_e, p_g, R_g, alignment, n_aligned)
    scale = rpg_alignment(p_e, R_e, p_g, R_g, alignment, n_aligned).scale
    lengths = tuple(lengths_m) if lengths_m else default_lengths_m(p_g)
    span = float(stamps[-1] - stamps[0])
    durations = tuple(durations_s) if durations_s else tuple(np.trunc(f * span * 1e3) / 1e3
                                                             for f in RPG_LENGTH_FRACTIONS)
    per_d = {f"{L:g} m": relative_errors(p_e, R_e, p_g, R_g, L, unit="m", scale=scale) for L in lengths if L > 0}
    per_t = {f"{d:g} s": relative_errors(p_e, R_e, p_g, R_g, d, unit="s", scale=scale, stamps_s=stamps)
             for d in durations if d > 0}
    n = None
    if est.cov_ori is not None:
        n = nees(p_e, R_e, est.cov_ori[a.est], est.cov_pos[a.est], p_g, R_g, alignment=nees_alignment)
    return StampedScores(len(a.ref), len(gt.timestamps_s), len(est.timestamps_s), a.max_diff_s, a.offset_s,
                         absolute, per_d, per_t, n)

"""Normalised estimation error squared (NEES) of a trajectory with its covariances, as OpenVINS's
ov_eval defines it (rpng/open_vins ``ov_eval/src/calc/ResultTrajectory.cpp``,
``ResultTrajectory`` and ``calculate_nees``; GPL-3.0: the definition is restated, not its code).

ov_eval aligns the *truth into the estimate's frame* (``align_trajectory(gt, est, method)``,
the alignments of :func:`recon_eval.metrics.rpg_trajectory.rpg_alignment`), then for each
associated pose, with ``R`` world_from_body rotations and the estimate's 3x3 orientation and
position covariances ``P_ori``, ``P_pos``:

* orientation error ``e_R = -Log(R_gt'^T R_est)`` (ov_eval: ``-log_so3(quat_2_Rot(q_gt) *
  quat_2_Rot(q_est)^T)`` with JPL quaternions, global-to-IMU rotations), NEES ``e_R^T P_ori^-1
  e_R`` (rad^2 / rad^2: unitless);
* position error ``e_p = p_gt' - p_est``, NEES ``e_p^T P_pos^-1 e_p``;

a pose whose NEES is NaN is skipped (ov_eval prints a warning and goes on); the run's figure is
the mean over poses (``Statistics::calculate``), which is 3 for a consistent estimator (chi^2 with
3 degrees of freedom). ov_eval's trajectory file: ``t tx ty tz qx qy qz qw`` then the upper
triangles ``Pr11 Pr12 Pr13 Pr22 Pr23 Pr33 Pt11 Pt12 Pt13 Pt22 Pt23 Pt33``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.arrays import as_float_array, frozen
from recon_eval.errors import InputError
from recon_eval.metrics.align import Sim3
from recon_eval.metrics.rpg_trajectory import rpg_alignment
from scenegen.geometry.rotation import rotvec_from_matrix


@dataclass(frozen=True)
class NeesResult:
    """ov_eval's NEES per pose and their means (unitless; 3 = consistent)."""

    nees_ori: np.ndarray  # (K,) over the poses kept (finite NEES)
    nees_pos: np.ndarray  # (K,)
    kept: np.ndarray  # (N,) bool: the poses whose NEES is finite
    mean_ori: float  # NaN when no pose is kept
    mean_pos: float
    alignment: str
    est_from_gt: Sim3


def nees(p_est, R_est, cov_ori, cov_pos, p_gt, R_gt, *, alignment: str = "posyaw", n_aligned: int = -1) -> NeesResult:
    """ov_eval's NEES (module docstring) of associated poses (N,): positions (N, 3) metres,
    world_from_body rotations (N, 3, 3), covariances (N, 3, 3) of the estimate (rad^2, m^2)."""
    p_est = as_float_array(p_est, "p_est", (None, 3))
    n = len(p_est)
    R_est = as_float_array(R_est, "R_est", (n, 3, 3))
    P_ori = as_float_array(cov_ori, "cov_ori", (n, 3, 3))
    P_pos = as_float_array(cov_pos, "cov_pos", (n, 3, 3))
    p_gt = as_float_array(p_gt, "p_gt", (n, 3))
    R_gt = as_float_array(R_gt, "R_gt", (n, 3, 3))
    T = rpg_alignment(p_gt, R_gt, p_est, R_est, alignment, n_aligned)  # est_from_gt, as ov_eval
    p_g = T.apply(p_gt)
    R_g = T.R @ R_gt
    e_ori = -rotvec_from_matrix(np.swapaxes(R_g, 1, 2) @ R_est).reshape(n, 3)
    e_pos = p_g - p_est
    with np.errstate(all="ignore"):
        n_ori = np.array([_quad(e, P) for e, P in zip(e_ori, P_ori)])
        n_pos = np.array([_quad(e, P) for e, P in zip(e_pos, P_pos)])
    kept = ~(np.isnan(n_ori) | np.isnan(n_pos))
    nan = float("nan")
    return NeesResult(frozen(n_ori[kept]), frozen(n_pos[kept]), frozen(kept),
                      float(np.mean(n_ori[kept])) if kept.any() else nan,
                      float(np.mean(n_pos[kept])) if kept.any() else nan, alignment, T)


def _quad(e, P) -> float:
    """e^T P^-1 e; NaN for a singular or non-finite covariance (ov_eval's Eigen inverse gives
    inf/NaN there and the pose is skipped)."""
    try:
        return float(e @ np.linalg.solve(P, e))
    except np.linalg.LinAlgError:
        return float("nan")


def covariances_from_upper(upper6) -> np.ndarray:
    """(N, 3, 3) symmetric covariances from ov_eval's upper triangles (N, 6) ``c11 c12 c13 c22
    c23 c33``, symmetrised as ov_eval does."""
    u = np.asarray(upper6, np.float64).reshape(-1, 6)
    if not np.all(np.isfinite(u)):
        raise InputError("covariance values must be finite")
    C = u[:, [0, 1, 2, 1, 3, 4, 2, 4, 5]].reshape(-1, 3, 3)
    return 0.5 * (C + np.swapaxes(C, 1, 2))

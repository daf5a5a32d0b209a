"""Trajectory errors as rpg_trajectory_evaluation defines them (Zhang and Scaramuzza, "A Tutorial
on Quantitative Trajectory Evaluation for Visual(-Inertial) Odometry", IROS 2018; uzh-rpg/
rpg_trajectory_evaluation ``align_utils.py``, ``align_trajectory.py``,
``compute_trajectory_errors.py``, ``trajectory_utils.py``), on time-associated poses.

Poses are ``world_from_body``: positions ``p_*`` (N, 3) metres and rotations ``R_*`` (N, 3, 3),
index k of the estimate associated with index k of the truth.

* Alignments (:data:`RPG_ALIGNMENTS`), ``gt = s R est + t``: ``sim3`` and ``se3`` (Umeyama on the
  positions, with or without scale), ``posyaw`` (position and yaw about the world z axis, the 4
  DoF a visual-inertial estimator cannot observe: Umeyama with the rotation restricted to yaw,
  ``get_best_yaw``), ``none``; over the first ``n_aligned`` frames (``-1`` all, rpg's
  ``align_num_frames``); ``se3`` and ``posyaw`` with ``n_aligned = 1`` align the first pose alone
  (``alignSE3Single``, ``alignPositionYawSingle``).
* Relative errors over a sub-trajectory length d (``compute_relative_error``): for each start
  index the end index whose truth distance from the start is nearest to d, within
  ``0.2 d`` (strict ``<``); the estimate's relative motion, its translation times the alignment's
  scale, compared with the truth's, the error rotated into the world by the estimate's end
  orientation; translation norm (m and % of d), rotation angle (deg and deg/m), yaw and gravity
  (roll-pitch) parts of its ZYX Euler angles. As in rpg, the i-th found end index is paired
  with start index i (``enumerate(comparisons)``): the ends of starts that find none shift the
  pairing; rpg's numbers need that and it is kept.
* Drift: the same relative errors over a duration in seconds (the truth's stamps in place of the
  distance along it), translation error divided by the duration (m/s), beside the per-distance
  drift (% of d).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from recon_eval.arrays import as_float_array, frozen
from recon_eval.errors import InputError
from recon_eval.metrics.align import Sim3, umeyama
from recon_eval.metrics.stats import ErrorStats, error_stats
from scenegen.geometry.rotation import rotation_angle_rad

RPG_ALIGNMENTS = ("sim3", "se3", "posyaw", "none")
#: rpg's default sub-trajectory lengths: these fractions of the truth's length, truncated to cm.
RPG_LENGTH_FRACTIONS = (0.1, 0.2, 0.3, 0.4, 0.5)


def _check(p_est, R_est, p_gt, R_gt):
    p_est = as_float_array(p_est, "p_est", (None, 3))
    n = p_est.shape[0]
    return (p_est, as_float_array(R_est, "R_est", (n, 3, 3)), as_float_array(p_gt, "p_gt", (n, 3)),
            as_float_array(R_gt, "R_gt", (n, 3, 3)))


def best_yaw_rad(C) -> float:
    """The theta maximising trace(Rz(theta) C) (rpg ``get_best_yaw``)."""
    A = C[0, 1] - C[1, 0]
    B = C[0, 0] + C[1, 1]
    return float(np.pi / 2 - np.arctan2(B, A))


def rot_z(theta_rad: float) -> np.ndarray:
    c, s = np.cos(theta_rad), np.sin(theta_rad)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rpg_alignment(p_est, R_est, p_gt, R_gt, method: str = "sim3", n_aligned: int = -1) -> Sim3:
    """``gt_from_est`` of rpg's ``alignTrajectory`` (module docstring). Umeyama needs >= 3
    frames not all collinear (rpg accepts 2 for sim3, where the rotation is undetermined)."""
    p_est, R_est, p_gt, R_gt = _check(p_est, R_est, p_gt, R_gt)
    if method not in RPG_ALIGNMENTS:
        raise InputError(f"rpg alignment must be one of {', '.join(RPG_ALIGNMENTS)}, got {method!r}")
    n = len(p_est)
    if n == 0:
        raise InputError("rpg alignment: no associated poses")
    if not (n_aligned == -1 or 1 <= n_aligned <= n):
        raise InputError(f"rpg alignment: n_aligned must be -1 (all) or 1..{n}, got {n_aligned}")
    if method == "none":
        return Sim3()
    if method == "sim3" and n_aligned == 1:
        raise InputError("rpg alignment: sim3 uses at least 2 frames (n_aligned -1 or >= 2)")
    if n_aligned == 1:  # the first pose alone
        if method == "se3":
            R = R_gt[0] @ R_est[0].T
        else:
            R = rot_z(best_yaw_rad(R_est[0] @ R_gt[0].T))
        return Sim3(R, p_gt[0] - R @ p_est[0], 1.0)
    k = slice(None) if n_aligned == -1 else slice(0, n_aligned)
    src, tgt = p_est[k], p_gt[k]
    if method == "posyaw":
        if len(src) < 2:
            raise InputError("rpg alignment: posyaw over frames needs at least 2 frames")
        mu_s, mu_t = src.mean(axis=0), tgt.mean(axis=0)
        R = rot_z(best_yaw_rad((src - mu_s).T @ (tgt - mu_t)))
        return Sim3(R, mu_t - R @ mu_s, 1.0)
    return umeyama(src, tgt, with_scale=method == "sim3")


@dataclass(frozen=True)
class RpgAbsoluteError:
    """rpg ``compute_absolute_error`` after the alignment (its scale-drift figure is left out: rpg
    computes it with ``np.diff(p, 0)``, the positions themselves, not their motion)."""

    trans_err_m: np.ndarray  # (N,) |p_gt - p_est_aligned|
    rot_err_deg: np.ndarray  # (N,) angle of R_est_aligned R_gt^T
    trans_stats_m: ErrorStats
    rot_stats_deg: ErrorStats
    alignment: str
    n_aligned: int
    gt_from_est: Sim3


def rpg_absolute_error(p_est, R_est, p_gt, R_gt, method: str = "sim3", n_aligned: int = -1) -> RpgAbsoluteError:
    p_est, R_est, p_gt, R_gt = _check(p_est, R_est, p_gt, R_gt)
    T = rpg_alignment(p_est, R_est, p_gt, R_gt, method, n_aligned)
    p_al = T.apply(p_est)
    R_al = T.R @ R_est
    te = np.linalg.norm(p_gt - p_al, axis=1)
    re = np.degrees(np.atleast_1d(rotation_angle_rad(R_al @ np.swapaxes(R_gt, 1, 2))))
    return RpgAbsoluteError(frozen(te), frozen(re), error_stats(te), error_stats(re), method, int(n_aligned), T)


def distances_from_start(p) -> np.ndarray:
    """(N,) path length from the first position (rpg ``get_distance_from_start``)."""
    step = np.linalg.norm(np.diff(np.asarray(p, np.float64), axis=0), axis=1)
    return np.r_[0.0, np.cumsum(step)]


def comparison_indices(accum, length: float, max_diff: float) -> list[int]:
    """rpg ``compute_comparison_indices_length``: for each start, the index whose ``accum`` is
    nearest to ``accum[start] + length`` within ``max_diff`` (strict), the first on a tie;
    starts with none contribute nothing (so the list is not indexed by start)."""
    out = []
    for idx, d in enumerate(accum):
        err = np.abs(accum[idx:] - (d + length))
        k = int(np.argmin(err))
        if err[k] < max_diff:
            out.append(idx + k)
    return out


@dataclass(frozen=True)
class RelativeErrors:
    """rpg's relative errors over one sub-trajectory ``length`` (``unit`` 'm' of truth path, or
    's' of truth time: drift per time); arrays (K,) per sub-trajectory."""

    length: float
    unit: str  # 'm' or 's'
    trans_err_m: np.ndarray  # rpg rel_trans
    trans_err_pct: np.ndarray  # rel_trans_perc: / length x 100 (unit 'm'), per metre of path
    trans_drift_m_per_s: np.ndarray  # / length (unit 's'); NaN for unit 'm'
    rot_err_deg: np.ndarray  # rel_rot (arccos of the trace, as rpg)
    rot_err_deg_per_m: np.ndarray  # rel_rot_deg_per_m (unit 'm'); deg per s for unit 's'
    yaw_err_deg: np.ndarray  # rel_yaw
    gravity_err_deg: np.ndarray  # rel_gravity: sqrt(pitch^2 + roll^2)
    pairs: tuple  # ((start, end), ...) indices into the associated poses
    trans_stats_m: ErrorStats
    trans_stats_pct: ErrorStats
    rot_stats_deg: ErrorStats
    yaw_stats_deg: ErrorStats
    scale: float  # the alignment's scale applied to the estimate's relative translations


def _homogeneous(R, p):
    T = np.tile(np.eye(4), (len(p), 1, 1))
    T[:, :3, :3], T[:, :3, 3] = R, p
    return T


def relative_errors(p_est, R_est, p_gt, R_gt, length: float, *, unit: str = "m", scale: float = 1.0,
                    stamps_s=None, max_diff: float | None = None) -> RelativeErrors | None:
    """rpg ``compute_relative_error`` (module docstring) over ``length`` metres (``unit='m'``) or
    seconds (``unit='s'``, on ``stamps_s`` (N,) of the truth); ``max_diff`` defaults to rpg's
    ``0.2 * length``. None with fewer than 2 sub-trajectories (rpg: "Too few samples")."""
    p_est, R_est, p_gt, R_gt = _check(p_est, R_est, p_gt, R_gt)
    if not (np.isfinite(length) and length > 0) or unit not in ("m", "s"):
        raise InputError(f"relative errors: length must be > 0 and unit 'm' or 's', got {length} {unit!r}")
    if unit == "s":
        if stamps_s is None:
            raise InputError("relative errors per time need the truth's timestamps")
        accum = np.asarray(stamps_s, np.float64).reshape(-1) - float(np.asarray(stamps_s).reshape(-1)[0])
        if len(accum) != len(p_gt):
            raise InputError("relative errors: one timestamp per associated pose expected")
    else:
        accum = distances_from_start(p_gt)
    tol = 0.2 * length if max_diff is None else float(max_diff)
    comps = comparison_indices(accum, length, tol)
    if len(comps) < 2:
        return None
    T_es, T_gt = _homogeneous(R_est, p_est), _homogeneous(R_gt, p_gt)
    errs = []
    for i, c in enumerate(comps):
        d_es = np.linalg.inv(T_es[i]) @ T_es[c]
        d_es[:3, 3] *= scale
        d_gt = np.linalg.inv(T_gt[i]) @ T_gt[c]
        e = np.linalg.inv(d_gt) @ d_es
        Rc = np.eye(4)
        Rc[:3, :3] = T_es[c][:3, :3]
        errs.append(Rc @ e @ Rc.T)
    E = np.asarray(errs)
    tn = np.linalg.norm(E[:, :3, 3], axis=1)
    ypr = Rotation.from_matrix(E[:, :3, :3]).as_euler("ZYX")  # transformations' 'rzyx': yaw, pitch, roll
    rot = np.degrees(np.arccos(np.clip((np.trace(E[:, :3, :3], axis1=1, axis2=2) - 1) / 2, -1, 1)))
    yaw = np.degrees(np.abs(ypr[:, 0]))
    grav = np.degrees(np.hypot(ypr[:, 1], ypr[:, 2]))
    pct = tn / length * 100 if unit == "m" else np.full(len(tn), np.nan)
    per_s = tn / length if unit == "s" else np.full(len(tn), np.nan)
    return RelativeErrors(
        float(length), unit, frozen(tn), frozen(pct), frozen(per_s), frozen(rot), frozen(rot / length), frozen(yaw),
        frozen(grav), tuple((i, int(c)) for i, c in enumerate(comps)), error_stats(tn), error_stats(pct),
        error_stats(rot), error_stats(yaw), float(scale))


def default_lengths_m(p_gt) -> tuple[float, ...]:
    """rpg's preset sub-trajectory lengths: 10 %, 20 %, ... 50 % of the truth's path length,
    truncated to 2 decimals (``compute_boxplot_distances``)."""
    total = float(distances_from_start(p_gt)[-1])
    return tuple(float(np.trunc(f * total * 100.0) / 100.0) for f in RPG_LENGTH_FRACTIONS)

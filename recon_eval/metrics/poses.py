"""Camera pose metrics: evo-style APE and RPE, registration ratio, relative-pose AUC (SuperGlue)
and mAA (Image Matching Benchmark).

Definitions: shared/notes/metrics.md, "Camera poses". Poses are ``cam_from_world``
(``x_cam = R x_world + t``), OpenCV camera axes, metres. Errors: translation in metres, angles in
degrees in fields named ``*_deg``.

Unlike evo, unmatched poses are never dropped silently: a truth camera with no estimate is
*unregistered*, its per-camera error is ``inf``, the registration ratio is reported, and the summary
statistics (over registered cameras) carry the failure count. Recall-type scores (AUC, mAA) count
failures as misses.
"""
from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations
from typing import Sequence

import numpy as np

from recon_eval.arrays import as_float_array, frozen
from recon_eval.errors import InputError
from recon_eval.metrics.align import Alignment, Sim3, umeyama
from recon_eval.metrics.stats import ErrorStats, error_stats, recall_auc
from scenegen.geometry.rotation import angle_between_vectors_rad, rotation_error_rad


@dataclass(frozen=True)
class Poses:
    """Named camera poses: names (N,) unique strings; R_cam_from_world (N, 3, 3);
    t_cam_from_world (N, 3) metres."""

    names: tuple
    R_cam_from_world: np.ndarray
    t_cam_from_world: np.ndarray

    def __post_init__(self):
        names = tuple(str(n) for n in self.names)
        n = len(names)
        if len(set(names)) != n:
            raise InputError("poses: image names must be unique")
        R = as_float_array(self.R_cam_from_world, "R_cam_from_world", (n, 3, 3))
        t = as_float_array(self.t_cam_from_world, "t_cam_from_world", (n, 3))
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "R_cam_from_world", frozen(R))
        object.__setattr__(self, "t_cam_from_world", frozen(t))

    @property
    def centers_world(self) -> np.ndarray:
        """Camera centres (N, 3) in the world frame: c = -R^T t."""
        return -np.einsum("nji,nj->ni", self.R_cam_from_world, self.t_cam_from_world)


@dataclass(frozen=True)
class _Matched:
    R_est: np.ndarray  # (N, 3, 3), NaN for unregistered
    t_est: np.ndarray  # (N, 3), NaN for unregistered
    registered: np.ndarray  # (N,) bool
    n_extra: int  # estimated poses with no truth counterpart (ignored, reported)


def _match(est: Poses, gt: Poses) -> _Matched:
    index = {n: i for i, n in enumerate(est.names)}
    N = len(gt.names)
    R = np.full((N, 3, 3), np.nan)
    t = np.full((N, 3), np.nan)
    reg = np.zeros(N, bool)
    for k, name in enumerate(gt.names):
        i = index.get(name)
        if i is None:
            continue
        Ri, ti = est.R_cam_from_world[i], est.t_cam_from_world[i]
        if np.all(np.isfinite(Ri)) and np.all(np.isfinite(ti)):  # a NaN pose is unregistered
            R[k], t[k], reg[k] = Ri, ti, True
    return _Matched(R, t, reg, len(set(est.names) - set(gt.names)))


def registration_ratio(est: Poses, gt: Poses) -> float:
    """Fraction of truth cameras with a finite estimated pose of the same name, in [0, 1]."""
    return float(np.mean(_match(est, gt).registered)) if len(gt.names) else 0.0


def _alignment_transform(m: _Matched, gt: Poses, alignment: Alignment) -> Sim3:
    if alignment == Alignment.NONE:
        return Sim3()
    if alignment not in (Alignment.SE3, Alignment.SIM3):
        raise InputError(f"pose alignment must be none, se3 or sim3, got {alignment.value}")
    c_est = -np.einsum("nji,nj->ni", m.R_est[m.registered], m.t_est[m.registered])
    c_gt = gt.centers_world[m.registered]
    if len(c_est) < 3:
        raise InputError(f"{alignment.value} alignment needs >= 3 registered cameras, got {len(c_est)}")
    return umeyama(c_est, c_gt, with_scale=alignment == Alignment.SIM3)


@dataclass(frozen=True)
class ApeResult:
    """Absolute pose error (evo ``evo_ape``, translation and rotation-angle parts)."""

    names: tuple  # truth camera names, order of the per-camera arrays
    trans_err_m: np.ndarray  # (N,) |c_est_aligned - c_gt| (camera centres), inf if unregistered
    rot_err_deg: np.ndarray  # (N,) angle of R_est_aligned^T R_gt, inf if unregistered
    trans_stats_m: ErrorStats  # over registered cameras; n_failed = unregistered
    rot_stats_deg: ErrorStats
    registration_ratio: float  # registered / truth cameras
    n_registered: int
    n_gt: int
    n_extra: int  # estimated poses whose name is not in the truth (ignored)
    alignment: str  # Alignment value
    tgt_from_src: Sim3  # the alignment applied (truth_from_estimate)


def ape(est: Poses, gt: Poses, *, alignment: Alignment = Alignment.SIM3) -> ApeResult:
    """evo APE with the declared alignment (Umeyama SE(3)/Sim(3) on registered camera centres):
    translation error |t_est - t_ref| of camera positions, rotation error |Log(P_est^-1 P_ref)|
    (its angle). Inputs are not modified."""
    alignment = Alignment(alignment)
    m = _match(est, gt)
    T = _alignment_transform(m, gt, alignment)
    N = len(gt.names)
    terr = np.full(N, np.inf)
    rerr = np.full(N, np.inf)
    reg = m.registered
    if np.any(reg):
        R_al, t_al = T.cam_from_tgt(m.R_est[reg], m.t_est[reg])
        c_al = -np.einsum("nji,nj->ni", R_al, t_al)
        terr[reg] = np.linalg.norm(c_al - gt.centers_world[reg], axis=1)
        rerr[reg] = np.degrees(rotation_error_rad(R_al, gt.R_cam_from_world[reg]))
    return ApeResult(
        gt.names, frozen(terr), frozen(rerr), error_stats(terr), error_stats(rerr),
        float(np.mean(reg)) if N else 0.0, int(reg.sum()), N, m.n_extra, alignment.value, T,
    )


@dataclass(frozen=True)
class RpeResult:
    """Relative pose error (evo ``evo_rpe``) over frame pairs (i, i + delta) in truth order."""

    pairs: tuple  # ((name_i, name_j), ...)
    trans_err_m: np.ndarray  # (P,) |translation of (Q_i^-1 Q_j)^-1 (P_i^-1 P_j)|, inf if either unregistered
    rot_err_deg: np.ndarray  # (P,) its rotation angle
    trans_stats_m: ErrorStats
    rot_stats_deg: ErrorStats
    delta_frames: int
    alignment: str
    tgt_from_src: Sim3


def rpe(est: Poses, gt: Poses, *, delta_frames: int = 1, alignment: Alignment = Alignment.SIM3) -> RpeResult:
    """evo RPE: for pairs (i, i + delta) of truth frames, with world_from_cam poses P (estimate,
    aligned) and Q (truth), the error E_ij = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j); translation error |t(E)|
    metres, rotation error angle(R(E)). SE(3) alignment does not change RPE; Sim(3) fixes the
    scale. A pair with an unregistered camera is a failure (inf)."""
    alignment = Alignment(alignment)
    if delta_frames < 1:
        raise InputError(f"delta_frames must be >= 1, got {delta_frames}")
    m = _match(est, gt)
    T = _alignment_transform(m, gt, alignment)
    N = len(gt.names)
    R_e, t_e = m.R_est.copy(), m.t_est.copy()
    if np.any(m.registered):
        R_e[m.registered], t_e[m.registered] = T.cam_from_tgt(m.R_est[m.registered], m.t_est[m.registered])
    i = np.arange(0, max(N - delta_frames, 0))
    j = i + delta_frames

    def rel(R, t):  # cam_j_from_cam_i ... as world_from_cam: P_i^-1 P_j = cam_i_from_cam_j
        Rw, cw = np.swapaxes(R, 1, 2), -np.einsum("nji,nj->ni", R, t)  # world_from_cam
        R_ij = np.swapaxes(Rw[i], 1, 2) @ Rw[j]
        t_ij = np.einsum("nji,nj->ni", Rw[i], cw[j] - cw[i])
        return R_ij, t_ij

    Rq, tq = rel(gt.R_cam_from_world, gt.t_cam_from_world)
    Rp, tp = rel(R_e, t_e)
    # E = Q_ij^-1 P_ij: R_E = Rq^T Rp, t_E = Rq^T (tp - tq)
    RE = np.swapaxes(Rq, 1, 2) @ Rp
    tE = np.einsum("nji,nj->ni", Rq, tp - tq)
    ok = m.registered[i] & m.registered[j]
    terr = np.where(ok, np.linalg.norm(np.where(ok[:, None], tE, 0.0), axis=1), np.inf)
    rerr = np.full(len(i), np.inf)
    if np.any(ok):
        rerr[ok] = np.degrees(rotation_error_rad(np.eye(3), RE[ok]))
    pairs = tuple((gt.names[a], gt.names[b]) for a, b in zip(i, j))
    return RpeResult(pairs, frozen(terr), frozen(rerr), error_stats(terr), error_stats(rerr), delta_frames,
                     alignment.value, T)


# --- relative pose between image pairs -------------------------------------------------------
def relative_pose_errors_deg(R_est, t_est, R_gt, t_gt) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """SuperGlue ``compute_pose_error`` for relative poses cam2_from_cam1, (P, 3, 3) and (P, 3):
    err_R = rotation angle of R_est^T R_gt; err_t = angle between t_est and t_gt folded with
    min(e, 180 - e) (the sign of t is not observable from E); pose error = max(err_R, err_t).
    All in degrees. Non-finite estimate or zero estimated baseline -> inf. Zero truth baseline:
    err_t is undefined (NaN) and the pose error is err_R alone.
    """
    R_est = np.asarray(R_est, float).reshape(-1, 3, 3)
    R_gt = np.asarray(R_gt, float).reshape(-1, 3, 3)
    t_est = np.asarray(t_est, float).reshape(-1, 3)
    t_gt = np.asarray(t_gt, float).reshape(-1, 3)
    bad = ~(np.all(np.isfinite(R_est), axis=(1, 2)) & np.all(np.isfinite(t_est), axis=1))
    with np.errstate(invalid="ignore"):
        eR = np.degrees(np.atleast_1d(rotation_error_rad(np.where(bad[:, None, None], np.eye(3), R_est), R_gt)))
        et = np.degrees(np.atleast_1d(angle_between_vectors_rad(np.where(bad[:, None], 1.0, t_est), t_gt)))
    et = np.minimum(et, 180.0 - et)
    gt_zero = np.linalg.norm(t_gt, axis=1) == 0
    est_zero = np.linalg.norm(np.where(bad[:, None], 1.0, t_est), axis=1) == 0
    et = np.where(est_zero & ~gt_zero, np.inf, et)
    pose = np.where(gt_zero, eR, np.maximum(eR, et))
    eR[bad], et[bad], pose[bad] = np.inf, np.inf, np.inf
    return eR, et, pose


def maa_deg(pose_err_deg, max_threshold_deg: int = 10) -> float:
    """Image Matching Benchmark mean average accuracy: mean over thresholds 1, 2, ..., max deg of
    the fraction of pairs with pose error (max(err_q, err_t)) strictly below the threshold.
    Discrete: not the same number as the AUC. Empty -> 0."""
    e = np.asarray(pose_err_deg, float).reshape(-1)
    if len(e) == 0:
        return 0.0
    ths = np.arange(1, max_threshold_deg + 1, dtype=float)
    return float(np.mean([np.mean(e < th) for th in ths]))


@dataclass(frozen=True)
class RelativePoseResult:
    """Relative pose accuracy over image pairs."""

    pairs: tuple  # ((name_1, name_2), ...): the pose of 2 relative to 1 (cam2_from_cam1)
    rot_err_deg: np.ndarray  # (P,)
    trans_dir_err_deg: np.ndarray  # (P,) folded translation-direction angle
    pose_err_deg: np.ndarray  # (P,) max of the two; inf = failure
    auc_5_deg: float  # SuperGlue AUC@5 deg, in [0, 1]
    auc_10_deg: float
    auc_20_deg: float
    maa_10_deg: float  # IMC mAA@10 deg, in [0, 1]
    n_failed: int
    registration_ratio: float


def relative_pose(est: Poses, gt: Poses, pairs: Sequence[tuple[str, str]] | None = None) -> RelativePoseResult:
    """Relative-pose errors, AUC@5/10/20 deg (SuperGlue/LoFTR) and mAA@10 (IMC) over ``pairs`` of
    truth image names (default: all unordered pairs in truth order). No alignment is needed (the
    relative pose is gauge-free up to scale, and only directions are compared). A pair with an
    unregistered camera is a failure (inf)."""
    m = _match(est, gt)
    idx = {n: k for k, n in enumerate(gt.names)}
    if pairs is None:
        pairs = list(combinations(gt.names, 2))
    try:
        ij = np.array([(idx[a], idx[b]) for a, b in pairs], dtype=np.int64).reshape(-1, 2)
    except KeyError as exc:
        raise InputError(f"relative_pose: pair names an image not in the truth: {exc}") from None
    i, j = ij[:, 0], ij[:, 1]

    def rel(R, t):  # cam_j_from_cam_i = T_j T_i^-1
        Rr = R[j] @ np.swapaxes(R[i], 1, 2)
        return Rr, t[j] - np.einsum("nij,nj->ni", Rr, t[i])

    Rg, tg = rel(np.asarray(gt.R_cam_from_world), np.asarray(gt.t_cam_from_world))
    with np.errstate(invalid="ignore"):
        Re, te = rel(m.R_est, m.t_est)
    eR, et, pe = relative_pose_errors_deg(Re, te, Rg, tg)
    a5, a10, a20 = recall_auc(pe, (5.0, 10.0, 20.0))
    return RelativePoseResult(
        tuple((gt.names[a], gt.names[b]) for a, b in ij), frozen(eR), frozen(et), frozen(pe),
        a5, a10, a20, maa_deg(pe, 10), int(np.sum(~np.isfinite(pe))),
        float(np.mean(m.registered)) if len(gt.names) else 0.0,
    )

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
from recon_eval.metrics.stats import ErrorStats, error_stats, maa_deg, recall_auc
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
class MatchedPoses:
    """Estimated poses put in truth order (``match_poses``)."""

    R_est: np.ndarray  # (N, 3, 3), NaN for unregistered
    t_est: np.ndarray  # (N, 3), NaN for unregistered
    registered: np.ndarray  # (N,) bool
    n_extra: int  # estimated poses with no truth counterpart (ignored, reported)


def match_poses(est: Poses, gt: Poses) -> MatchedPoses:
    """The estimate of each truth camera, matched by name (a NaN pose is unregistered)."""
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
    return MatchedPoses(R, t, reg, len(set(est.names) - set(gt.names)))


def registration_ratio(est: Poses, gt: Poses) -> float:
    """Fraction of truth cameras with a finite estimated pose of the same name, in [0, 1]."""
    return float(np.mean(match_poses(est, gt).registered)) if len(gt.names) else 0.0


#: Pose alignments, as evo names them: ``none``; ``se3`` (``--align``), ``sim3`` (``--align
#: --correct_scale``), ``scale`` (``--correct_scale`` alone: the Sim(3) scale applied to the
#: estimated positions about the origin, orientations unchanged), all Umeyama on camera centres;
#: ``origin`` (``--align_origin``: the estimate's first pose moved onto the truth's first pose).
POSE_ALIGNMENTS = ("none", "se3", "sim3", "scale", "origin")


def _alignment_name(alignment) -> str:
    name = alignment.value if isinstance(alignment, Alignment) else str(alignment)
    if name not in POSE_ALIGNMENTS:
        raise InputError(f"pose alignment must be one of {', '.join(POSE_ALIGNMENTS)}, got {name}")
    return name


def pose_alignment(m: MatchedPoses, gt: Poses, alignment, n_to_align: int = -1) -> Sim3:
    """``truth_from_estimate`` for the declared alignment (:data:`POSE_ALIGNMENTS`), over the
    registered cameras in truth order: Umeyama on their centres (the first ``n_to_align`` of them
    when > 0, evo's ``--n_to_align``; evo ``PosePath3D.align``), or the origin alignment
    ``Q_0 P_0^-1`` of the first registered camera (evo ``align_origin``; world_from_cam poses)."""
    name = _alignment_name(alignment)
    if name == "none":
        return Sim3()
    reg = np.flatnonzero(m.registered)
    if name == "origin":
        if len(reg) == 0:
            raise InputError("origin alignment needs a registered camera")
        k = reg[0]
        Rq, Rp = gt.R_cam_from_world[k].T, m.R_est[k].T  # world_from_cam rotations
        cq, cp = gt.centers_world[k], -Rp @ m.t_est[k]
        R = Rq @ Rp.T
        return Sim3(R, cq - R @ cp, 1.0)
    if n_to_align is not None and n_to_align > 0:
        reg = reg[:n_to_align]
    c_est = -np.einsum("nji,nj->ni", m.R_est[reg], m.t_est[reg])
    c_gt = gt.centers_world[reg]
    if len(c_est) < 3:
        raise InputError(f"{name} alignment needs >= 3 registered cameras, got {len(c_est)}")
    T = umeyama(c_est, c_gt, with_scale=name in ("sim3", "scale"))
    return Sim3(np.eye(3), np.zeros(3), T.scale) if name == "scale" else T


def _aligned(m: MatchedPoses, T: Sim3) -> tuple[np.ndarray, np.ndarray]:
    R, t = m.R_est.copy(), m.t_est.copy()
    if np.any(m.registered):
        R[m.registered], t[m.registered] = T.cam_from_tgt(m.R_est[m.registered], m.t_est[m.registered])
    return R, t


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
    alignment: str  # one of POSE_ALIGNMENTS
    tgt_from_src: Sim3  # the alignment applied (truth_from_estimate)
    n_to_align: int = -1  # cameras the alignment was fitted on (first n registered; -1 = all, evo)


def ape(est: Poses, gt: Poses, *, alignment=Alignment.SIM3, n_to_align: int = -1) -> ApeResult:
    """evo APE with the declared alignment (:func:`pose_alignment`): translation error
    |t_est - t_ref| of camera positions, rotation error |Log(P_est^-1 P_ref)| (its angle).
    Unregistered cameras are inf (evo drops them; its numbers are the statistics here, whose
    ``n_failed`` counts them). Inputs are not modified."""
    name = _alignment_name(alignment)
    m = match_poses(est, gt)
    T = pose_alignment(m, gt, name, n_to_align)
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
        float(np.mean(reg)) if N else 0.0, int(reg.sum()), N, m.n_extra, name, T, n_to_align,
    )


#: evo's ``--delta_unit``: frames, metres of path, degrees or radians of rotation.
DELTA_UNITS = ("f", "m", "d", "r")


def delta_pairs(R_world_from_cam, centers, delta, unit: str = "f", *, all_pairs: bool = False,
                rel_tol: float = 0.1) -> list[tuple[int, int]]:
    """Index pairs of a pose sequence as evo forms them (evo 1.38 ``core/filters.py``
    ``filter_pairs_by_index`` / ``_by_path`` / ``_by_angle`` via ``metrics.id_pairs_from_delta``).

    ``f``: (0, d), (d, 2d), ... or, ``all_pairs``, (i, i + d) for every i. ``m``: consecutive pairs
    close when the travelled path reaches ``delta`` (then restarts), all pairs: for each i the j
    whose path from i is nearest to ``delta`` if within ``rel_tol * delta``. ``d``/``r``: the same
    with the accumulated rotation angle of consecutive poses; all pairs: every (i, j > i) whose
    direct relative angle is within ``delta +- rel_tol * delta``."""
    n = len(centers)
    if unit not in DELTA_UNITS:
        raise InputError(f"delta unit must be one of {', '.join(DELTA_UNITS)}, got {unit!r}")
    if unit == "f":
        d = int(delta)
        if d != delta or d < 1:
            raise InputError(f"delta in frames must be an integer >= 1, got {delta}")
        if all_pairs:
            return [(i, i + d) for i in range(n - d)]
        ids = list(range(0, n, d))
        return list(zip(ids, ids[1:]))
    if not delta > 0:
        raise InputError(f"delta must be > 0, got {delta}")
    tol = delta * rel_tol
    if unit == "m":
        step = np.linalg.norm(np.diff(centers, axis=0), axis=1)
        if all_pairs:
            dist = np.r_[0.0, np.cumsum(step)]
            out = []
            for i in range(n - 1):
                here = dist[i + 1:] - dist[i]
                k = int(np.argmin(np.abs(here - delta)))
                if abs(here[k] - delta) <= tol:
                    out.append((i, i + 1 + k))
            return out
        ids, path = [0], 0.0
        for i in range(1, n):
            path += float(step[i - 1])
            if path >= delta:
                ids.append(i)
                path = 0.0
        return list(zip(ids, ids[1:]))
    bound = 180.0 if unit == "d" else np.pi
    if delta > bound:
        raise InputError(f"delta angle must be within [0, {bound}], got {delta}")
    scale = np.pi / 180.0 if unit == "d" else 1.0
    delta, tol = delta * scale, tol * scale
    R = np.asarray(R_world_from_cam, float)
    if all_pairs:
        out = []
        for i in range(n - 1):
            ang = np.atleast_1d(rotation_error_rad(np.broadcast_to(R[i], R[i + 1:].shape), R[i + 1:]))
            out.extend((i, int(j)) for j in np.flatnonzero((delta - tol <= ang) & (ang <= delta + tol)) + i + 1)
        return out
    step = np.atleast_1d(rotation_error_rad(R[:-1], R[1:])) if n > 1 else np.zeros(0)
    out, acc, start = [], 0.0, 0
    for i, a in enumerate(step):
        acc += float(a)
        if acc >= delta:
            out.append((start, i + 1))
            acc, start = 0.0, i + 1
    return out


@dataclass(frozen=True)
class RpeResult:
    """Relative pose error (evo ``evo_rpe``).

    The pairs are evo's, formed over the registered poses in truth order (a gap is bridged, as
    evo pairs the poses that survive its association), followed in truth order by the pairs of
    truth frames that an unregistered camera breaks (inf: failures). So the statistics' finite
    part is evo's number and their ``n_failed`` the failure count. ``gaps='fail'`` forms the pairs
    over the truth frames only (no bridging)."""

    pairs: tuple  # ((name_i, name_j), ...)
    trans_err_m: np.ndarray  # (P,) |translation of (Q_i^-1 Q_j)^-1 (P_i^-1 P_j)|, inf for a broken pair
    rot_err_deg: np.ndarray  # (P,) its rotation angle
    trans_stats_m: ErrorStats
    rot_stats_deg: ErrorStats
    delta_frames: int | None  # delta when delta_unit is 'f', else None
    alignment: str
    tgt_from_src: Sim3
    delta: float = 1.0
    delta_unit: str = "f"  # evo --delta_unit: f frames, m metres, d degrees, r radians
    all_pairs: bool = False  # evo --all_pairs; default: consecutive pairs (0, d), (d, 2d), ...
    gaps: str = "bridge"  # 'bridge' (evo) or 'fail'
    n_failed_pairs: int = 0  # truth-frame pairs with an unregistered camera
    registration_ratio: float = 1.0
    n_to_align: int = -1
    pairs_from: str = "estimate"  # the poses a non-frame delta is measured on (evo's default)


def rpe(est: Poses, gt: Poses, *, delta_frames: int | None = None, delta: float = 1.0, delta_unit: str = "f",
        all_pairs: bool = False, alignment=Alignment.SIM3, n_to_align: int = -1, gaps: str = "bridge",
        pairs_from_reference: bool = False, rel_delta_tol: float = 0.1) -> RpeResult:
    """evo RPE (``evo_rpe``, evo 1.38 ``core/metrics.py`` ``RPE``): for pose pairs (i, j) with
    world_from_cam poses P (estimate, aligned) and Q (truth), E_ij = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j);
    translation error |t(E)| metres, rotation error angle(R(E)) degrees. Pairs by
    :func:`delta_pairs` (``delta``, ``delta_unit``, ``all_pairs``; ``delta_frames`` is the
    frames delta, kept for callers), measured on the aligned estimate unless
    ``pairs_from_reference``. See :class:`RpeResult` for unregistered cameras."""
    name = _alignment_name(alignment)
    if delta_frames is not None:
        delta, delta_unit = delta_frames, "f"
    if gaps not in ("bridge", "fail"):
        raise InputError(f"gaps must be 'bridge' or 'fail', got {gaps!r}")
    m = match_poses(est, gt)
    T = pose_alignment(m, gt, name, n_to_align)
    N = len(gt.names)
    R_e, t_e = _aligned(m, T)
    Rw_e = np.swapaxes(R_e, 1, 2)
    c_e = -np.einsum("nji,nj->ni", R_e, t_e)
    Rw_g, c_g = np.swapaxes(gt.R_cam_from_world, 1, 2), gt.centers_world

    def pairs_over(idx):  # pairs (truth indices) over the poses idx, measured as evo does
        Rw, c = (Rw_g[idx], c_g[idx]) if pairs_from_reference or not np.all(m.registered[idx]) else (Rw_e[idx], c_e[idx])
        return [(int(idx[a]), int(idx[b])) for a, b in delta_pairs(Rw, c, delta, delta_unit, all_pairs=all_pairs,
                                                                     rel_tol=rel_delta_tol)]

    reg = np.flatnonzero(m.registered)
    truth_pairs = pairs_over(np.arange(N))
    broken = [(i, j) for i, j in truth_pairs if not (m.registered[i] and m.registered[j])]
    scored = pairs_over(reg) if gaps == "bridge" else [p for p in truth_pairs if p not in set(broken)]
    ij = sorted(set(scored) | set(broken))
    i = np.array([a for a, _ in ij], dtype=np.int64)
    j = np.array([b for _, b in ij], dtype=np.int64)
    ok = m.registered[i] & m.registered[j] if len(ij) else np.zeros(0, bool)
    terr = np.full(len(ij), np.inf)
    rerr = np.full(len(ij), np.inf)
    if np.any(ok):
        a, b = i[ok], j[ok]
        Rq = np.swapaxes(Rw_g[a], 1, 2) @ Rw_g[b]  # Q_i^-1 Q_j
        tq = np.einsum("nji,nj->ni", Rw_g[a], c_g[b] - c_g[a])
        Rp = np.swapaxes(Rw_e[a], 1, 2) @ Rw_e[b]
        tp = np.einsum("nji,nj->ni", Rw_e[a], c_e[b] - c_e[a])
        terr[ok] = np.linalg.norm(np.einsum("nji,nj->ni", Rq, tp - tq), axis=1)  # t(Q_ij^-1 P_ij)
        rerr[ok] = np.degrees(rotation_error_rad(Rq, Rp))
    pairs = tuple((gt.names[a], gt.names[b]) for a, b in ij)
    return RpeResult(pairs, frozen(terr), frozen(rerr), error_stats(terr), error_stats(rerr),
                     int(delta) if delta_unit == "f" else None, name, T, float(delta), delta_unit, bool(all_pairs),
                     gaps, len(broken), float(np.mean(m.registered)) if N else 0.0, n_to_align,
                     "reference" if pairs_from_reference else "estimate")


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
    m = match_poses(est, gt)
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

"""PCK for 2D keypoints and per-part pose errors of articulated objects (docs/metrics.md,
"Keypoints" and "Articulated objects")."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from recon_eval.metrics.objects_bop import SymmetryTransforms, add, rot_trans_error
from scenegen.geometry.rotation import rotation_error_rad

#: PCK thresholds reported by default (fractions of the reference size).
PCK_ALPHAS = (0.05, 0.1, 0.2)


@dataclass(frozen=True)
class PckResult:
    alphas: tuple  # fractions of each instance's reference size
    pck: tuple  # per alpha: correct / scored keypoints (NaN when none is scored)
    n_scored: int  # truth keypoints labelled (v > 0), each a correct or a wrong one
    n_missing: int  # of those, without a finite prediction (counted wrong)


def pck(pred_xy, gt_xy, labelled, ref_size_px, alphas=PCK_ALPHAS) -> PckResult:
    """Percentage of correct keypoints (Yang and Ramanan, PAMI 2013): a labelled truth keypoint
    is correct when the prediction lies within ``alpha * ref_size`` of it (``<=``; pixels).
    ``pred_xy``, ``gt_xy`` (N, K, 2); ``labelled`` (N, K) bool; ``ref_size_px`` (N,) per instance
    (Yang and Ramanan: max(w, h) of the truth box). Non-finite predictions are wrong, not dropped."""
    p = np.asarray(pred_xy, dtype=np.float64)
    g = np.asarray(gt_xy, dtype=np.float64)
    lab = np.asarray(labelled, dtype=bool)
    size = np.asarray(ref_size_px, dtype=np.float64).reshape(-1, 1)
    d = np.linalg.norm(p - g, axis=-1)
    d = np.where(np.isfinite(d), d, np.inf)
    n = int(lab.sum())
    vals = tuple(float(np.sum((d <= a * size) & lab) / n) if n else float("nan") for a in alphas)
    return PckResult(tuple(float(a) for a in alphas), vals, n, int(np.sum(lab & ~np.isfinite(p).all(axis=-1))))


@dataclass(frozen=True)
class PartPoseError:
    part: str
    rot_err_deg: float  # symmetry-aware (bop_toolkit re against the nearest symmetric truth)
    trans_err: float  # model units
    add: float  # mean vertex distance, model units


@dataclass(frozen=True)
class ArticulatedPoseResult:
    parts: tuple  # PartPoseError per part, in the truth's order
    joint_err_deg: dict  # joint name -> |angle_est - angle_gt| wrapped to [0, 180] (revolute)
    max_rot_err_deg: float
    max_trans_err: float
    mean_joint_err_deg: float  # NaN without joints


def articulated_pose_errors(est: dict, gt: dict, points: dict, syms: dict | None = None,
                            joints_est_deg: dict | None = None, joints_gt_deg: dict | None = None
                            ) -> ArticulatedPoseResult:
    """Per-part errors of ``est`` against ``gt`` (part name -> ``cam_from_part`` (R (3, 3),
    t (3,))), each part's vertices ``points[name]`` (N, 3) for ADD; a part missing from ``est``
    has infinite errors. Joint angle errors for the joints in ``joints_gt_deg``; a joint missing
    from the estimate is inf."""
    syms = syms or {}
    parts = []
    for name, (Rg, tg) in gt.items():
        if name not in est:
            parts.append(PartPoseError(name, np.inf, np.inf, np.inf))
            continue
        Re, te = est[name]
        rt = rot_trans_error(Re, te, Rg, tg, syms.get(name) if isinstance(syms.get(name), SymmetryTransforms) else None)
        parts.append(PartPoseError(name, rt.rot_err_deg, rt.trans_err, add(Re, te, Rg, tg, points[name])))
    joints = {}
    for j, ag in (joints_gt_deg or {}).items():
        ae = (joints_est_deg or {}).get(j)
        if ae is None or not np.isfinite(ae):
            joints[j] = float("inf")
        else:
            joints[j] = float(abs((ae - ag + 180.0) % 360.0 - 180.0))
    return ArticulatedPoseResult(
        tuple(parts), joints, max((p.rot_err_deg for p in parts), default=float("nan")),
        max((p.trans_err for p in parts), default=float("nan")),
        float(np.mean(list(joints.values()))) if joints else float("nan"))


def joint_rotation_errors(est: dict, gt: dict, parents: dict) -> dict:
    """Per child part, the angle (deg) of ``(R_parent^T R_child)_est^T (R_parent^T R_child)_gt``:
    how far the recovered relative rotation of each joint is from the truth's. For a revolute
    joint whose estimate turns about the joint's axis it is ``|angle_est - angle_gt|``; it needs
    no axis, so it applies to any joint. ``est``, ``gt``: part -> (R (3, 3), t (3,));
    ``parents``: child -> parent. A joint with a part missing from ``est`` is inf."""
    out = {}
    for child, parent in parents.items():
        if parent is None or child not in gt or parent not in gt:
            continue
        if child not in est or parent not in est:
            out[child] = float("inf")
            continue
        rel_e = np.asarray(est[parent][0]).T @ np.asarray(est[child][0])
        rel_g = np.asarray(gt[parent][0]).T @ np.asarray(gt[child][0])
        out[child] = float(np.degrees(rotation_error_rad(rel_e, rel_g)))
    return out


def twist_angle_rad(R, axis) -> float:
    """The signed angle about unit ``axis`` of rotation ``R`` (3, 3): the twist of its
    swing-twist decomposition, ``2 atan2(q_v . axis, q_w)`` wrapped to [-pi, pi)."""
    q = Rotation.from_matrix(np.asarray(R, dtype=np.float64)).as_quat()  # x, y, z, w
    a = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
    ang = 2.0 * np.arctan2(float(q[:3] @ a), float(q[3]))
    return float((ang + np.pi) % (2 * np.pi) - np.pi)


def recovered_joint_angle_rad(R_parent_est, R_child_est, R_parent_gt, R_child_gt, axis, value_gt_rad: float) -> float:
    """A revolute joint's angle recovered from estimated part poses (``cam_from_part``): the truth
    angle plus the twist about the joint ``axis`` (parent frame) of the estimated relative rotation
    against the truth's, ``(R_p^T R_c)_est (R_p^T R_c)_gt^T``: the joint turns the child about the
    axis in the parent's frame, so the rest rotation cancels."""
    rel_e = np.asarray(R_parent_est).T @ np.asarray(R_child_est)
    rel_g = np.asarray(R_parent_gt).T @ np.asarray(R_child_gt)
    return value_gt_rad + twist_angle_rad(rel_e @ rel_g.T, axis)

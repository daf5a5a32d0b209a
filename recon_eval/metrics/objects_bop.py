"""BOP's 6D object pose errors (docs/metrics.md, "Object pose"): VSD, MSSD, MSPD, ADD, ADD-S
(bop_toolkit's ``adi``), rotation and translation errors, each symmetry-aware where BOP's is.

Transliterated from bop_toolkit (thodan/bop_toolkit, commit cea62d6, ``bop_toolkit_lib/
pose_error.py``, ``misc.py``, ``visibility.py``) and checked against a verbatim copy of it
(tests/recon_eval/agreement/bop_toolkit_reference.py). Poses are BOP's ``cam_from_model``:
``R (3, 3)``, ``t (3,)``; lengths are in the model's units (BOP: millimetres), MSPD in pixels of
the image whose ``K`` is given. ``K`` is BOP's: pixel (u, v) centre at ``K^-1 [u, v, 1]``, the
convention ``misc.depth_im_to_dist_im_fast`` assumes.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from scenegen.geometry.rotation import matrix_from_rotvec, rotation_error_rad

#: misc.get_symmetry_transformations's step, as eval_bop19_pose.py sets it: the vertex farthest
#: from a continuous symmetry axis moves at most this fraction of the diameter between samples.
MAX_SYM_DISC_STEP = 0.01


@dataclass(frozen=True)
class SymmetryTransforms:
    """The model's symmetry transforms ``model_from_model`` (identity first), as BOP enumerates
    them: every discrete symmetry (from ``symmetries_discrete``, 4x4 row-major) composed with
    every sample of every continuous one (``symmetries_continuous``: axis, offset)."""

    R: np.ndarray  # (S, 3, 3)
    t: np.ndarray  # (S, 3), model units


def symmetry_transforms(model_info: dict, max_sym_disc_step: float = MAX_SYM_DISC_STEP) -> SymmetryTransforms:
    """``misc.get_symmetry_transformations`` of a ``models_info.json`` entry (same order)."""
    disc_R, disc_t = [np.eye(3)], [np.zeros(3)]
    for sym in model_info.get("symmetries_discrete", []):
        m = np.asarray(sym, dtype=np.float64).reshape(4, 4)
        disc_R.append(m[:3, :3])
        disc_t.append(m[:3, 3])
    cont_R, cont_t = [], []
    for sym in model_info.get("symmetries_continuous", []):
        axis = np.asarray(sym["axis"], dtype=np.float64)
        offset = np.asarray(sym["offset"], dtype=np.float64)
        n = int(np.ceil(np.pi / max_sym_disc_step))
        for i in range(n):
            R = matrix_from_rotvec(axis / np.linalg.norm(axis) * (i * 2.0 * np.pi / n))
            cont_R.append(R)
            cont_t.append(offset - R @ offset)
    if not cont_R:
        return SymmetryTransforms(np.stack(disc_R), np.stack(disc_t))
    Rs = [Rc @ Rd for Rd in disc_R for Rc in cont_R]
    ts = [Rc @ td + tc for td in disc_t for Rc, tc in zip(cont_R, cont_t)]
    return SymmetryTransforms(np.stack(Rs), np.stack(ts))


def identity_symmetry() -> SymmetryTransforms:
    return SymmetryTransforms(np.eye(3)[None], np.zeros((1, 3)))


def _pose(R, t) -> tuple[np.ndarray, np.ndarray]:
    return np.asarray(R, dtype=np.float64).reshape(3, 3), np.asarray(t, dtype=np.float64).reshape(3)


def _gt_sym_poses(R_gt, t_gt, syms: SymmetryTransforms) -> tuple[np.ndarray, np.ndarray]:
    """The truth pose composed with each symmetry: R_gt S_R, R_gt S_t + t_gt (S, 3, 3), (S, 3)."""
    return np.einsum("ij,sjk->sik", R_gt, syms.R), syms.t @ R_gt.T + t_gt


def _project(pts_cam: np.ndarray, K: np.ndarray) -> np.ndarray:
    """misc.project_pts after the transform: (..., N, 3) camera points -> (..., N, 2) pixels."""
    h = pts_cam @ K.T
    return h[..., :2] / h[..., 2:3]


def mssd(R_est, t_est, R_gt, t_gt, pts, syms: SymmetryTransforms) -> float:
    """Maximum symmetry-aware surface distance: min over symmetries of the largest distance
    between model vertex ``pts`` (N, 3) in the estimated and the symmetric truth pose (units of
    ``pts``)."""
    Re, te = _pose(R_est, t_est)
    Rg, tg = _pose(R_gt, t_gt)
    p = np.asarray(pts, dtype=np.float64)
    est = p @ Re.T + te
    Rs, ts = _gt_sym_poses(Rg, tg, syms)
    gt = np.einsum("nj,sij->sni", p, Rs) + ts[:, None, :]
    return float(np.linalg.norm(est[None] - gt, axis=2).max(axis=1).min())


def mspd(R_est, t_est, R_gt, t_gt, K, pts, syms: SymmetryTransforms) -> float:
    """Maximum symmetry-aware projection distance (pixels of ``K`` (3, 3)): as :func:`mssd` on
    the projections of the vertices."""
    Re, te = _pose(R_est, t_est)
    Rg, tg = _pose(R_gt, t_gt)
    K = np.asarray(K, dtype=np.float64)
    p = np.asarray(pts, dtype=np.float64)
    est = _project(p @ Re.T + te, K)
    Rs, ts = _gt_sym_poses(Rg, tg, syms)
    gt = _project(np.einsum("nj,sij->sni", p, Rs) + ts[:, None, :], K)
    return float(np.linalg.norm(est[None] - gt, axis=2).max(axis=1).min())


def add(R_est, t_est, R_gt, t_gt, pts) -> float:
    """ADD (Hinterstoisser et al., ACCV 2012): mean distance between corresponding vertices."""
    Re, te = _pose(R_est, t_est)
    Rg, tg = _pose(R_gt, t_gt)
    p = np.asarray(pts, dtype=np.float64)
    return float(np.linalg.norm((p @ Re.T + te) - (p @ Rg.T + tg), axis=1).mean())


def add_s(R_est, t_est, R_gt, t_gt, pts) -> float:
    """ADD-S (bop_toolkit ``adi``): mean over truth-posed vertices of the distance to the nearest
    estimated-posed vertex."""
    Re, te = _pose(R_est, t_est)
    Rg, tg = _pose(R_gt, t_gt)
    p = np.asarray(pts, dtype=np.float64)
    d, _ = cKDTree(p @ Re.T + te).query(p @ Rg.T + tg, k=1)
    return float(d.mean())


@dataclass(frozen=True)
class RotTransError:
    rot_err_deg: float  # angle of R_est (R_gt S_R)^T, atan2 form (bop_toolkit ``re`` uses arccos)
    trans_err: float  # |t_est - (R_gt S_t + t_gt)|, model units
    symmetry_index: int  # which of the symmetry transforms gave the smallest rotation error (0 = identity)


def rot_trans_error(R_est, t_est, R_gt, t_gt, syms: SymmetryTransforms | None = None) -> RotTransError:
    """bop_toolkit's ``re``/``te`` against the symmetric truth pose with the smallest rotation
    error (ties: the first in :func:`symmetry_transforms`'s order); without ``syms`` the plain
    ``re``/``te``. Continuous symmetries count at their sampled angles (step
    :data:`MAX_SYM_DISC_STEP` of the diameter), as BOP's MSSD/MSPD do."""
    syms = syms or identity_symmetry()
    Re, te = _pose(R_est, t_est)
    Rg, tg = _pose(R_gt, t_gt)
    Rs, ts = _gt_sym_poses(Rg, tg, syms)
    angles = rotation_error_rad(np.broadcast_to(Re, Rs.shape), Rs)
    i = int(np.argmin(angles))
    return RotTransError(float(np.degrees(angles[i])), float(np.linalg.norm(te - ts[i])), i)


def dist_from_depth(depth, K) -> np.ndarray:
    """misc.depth_im_to_dist_im_fast: (H, W) depth (Z) -> distance from the camera centre (0 stays 0)."""
    d = np.asarray(depth, dtype=np.float64)
    K = np.asarray(K, dtype=np.float64)
    xs, ys = np.meshgrid(np.arange(d.shape[1]), np.arange(d.shape[0]))
    return np.sqrt(((xs - K[0, 2]) / K[0, 0] * d) ** 2 + ((ys - K[1, 2]) / K[1, 1] * d) ** 2 + d ** 2)


def visible_mask(dist_test, dist_model, delta) -> np.ndarray:
    """visibility._estimate_visib_mask, ``bop19`` mode: model pixels no farther than the scene
    by more than ``delta``, or where the scene has no depth (float32 difference, as BOP)."""
    diff = dist_model.astype(np.float32) - dist_test.astype(np.float32)
    return ((diff <= delta) | (dist_test == 0)) & (dist_model > 0)


def vsd(depth_est, depth_gt, depth_test, K, *, delta: float, taus, diameter: float | None) -> tuple[float, ...]:
    """Visible surface discrepancy (Hodan et al. 2016/2018; BOP's ``step`` cost, ``bop19``
    visibility), one value per misalignment tolerance in ``taus``.

    ``depth_est``, ``depth_gt`` (H, W): the model rendered alone in the estimated and the truth
    pose (0 = no surface); ``depth_test``: the scene's depth image; ``delta`` and ``taus`` in
    depth units, or ``taus`` as fractions of ``diameter`` when it is given (BOP19:
    ``vsd_normalized_by_diameter``)."""
    dist_test = dist_from_depth(depth_test, K)
    dist_gt = dist_from_depth(depth_gt, K)
    dist_est = dist_from_depth(depth_est, K)
    visib_gt = visible_mask(dist_test, dist_gt, delta)
    visib_est = visible_mask(dist_test, dist_est, delta) | (visib_gt & (dist_est > 0))
    inter = visib_gt & visib_est
    union_count = int((visib_gt | visib_est).sum())
    if union_count == 0:
        return tuple(1.0 for _ in taus)
    comp_count = union_count - int(inter.sum())
    dists = np.abs(dist_gt[inter] - dist_est[inter])
    if diameter is not None:
        dists = dists / diameter
    return tuple(float((np.sum(dists >= tau) + comp_count) / float(union_count)) for tau in taus)


def sphere_projections_overlap(radius: float, t1, t2) -> bool:
    """misc.overlapping_sphere_projections: eval_calc_errors.py sets VSD to 1 for every tau when
    the (approximated) silhouettes of the bounding spheres do not overlap."""
    p1, p2 = np.asarray(t1, dtype=np.float64).reshape(3), np.asarray(t2, dtype=np.float64).reshape(3)
    if p1[2] == 0 or p2[2] == 0:
        return False
    return bool(np.linalg.norm(p1[:2] / p1[2] - p2[:2] / p2[2]) < radius * (1.0 / p1[2] + 1.0 / p2[2]))

"""DLT camera matrices: decomposition of a 3x4 projection matrix P into K, R, t, scoring of an
estimated P against the truth, and the normalised linear DLT estimator from 2D-3D points.

Conventions (Hartley & Zisserman, "Multiple View Geometry", 2nd ed., sec. 6.2.4, "Decomposition of
the camera matrix"): ``P ~ K [R | t]`` with ``M = P[:, :3] = K R`` split by RQ decomposition into an
upper-triangular K and a rotation R. RQ is unique only up to the signs of K's columns / R's rows and
P is defined only up to a (possibly negative) scale, so :func:`decompose_projection` fixes:

* P is first multiplied by ``sign(det M)``: then ``det R = +1`` (a rotation, not a reflection) and
  points in front of the camera have positive depth (H&Z sec. 6.2.3, ``depth = sign(det M) w / T``);
* K has a positive diagonal (fx, fy > 0, K[2, 2] > 0);
* K is scaled so that ``K[2, 2] = 1``; ``t = K^-1 p4`` with the same scale, so ``P = s K [R | t]``
  with ``s > 0`` exactly.

Poses are cam_from_world (``X_cam = R X_world + t``), pixels are OpenCV pixels (pinhole: P has no
distortion, so scoring pixels must be undistorted ones), metres.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.arrays import as_float_array
from recon_eval.errors import InputError
from recon_eval.metrics.align import cameras_to_truth_frame, normalising_transform_3d, projective_align
from scenegen.geometry.rotation import rotation_error_rad


def _finite_P(P, name: str) -> np.ndarray:
    P = as_float_array(P, name, (3, 4))
    if not np.all(np.isfinite(P)):
        raise InputError(f"{name}: projection matrix must be finite")
    return P


def decompose_projection(P):
    """``(K, R, t)`` of a finite camera ``P`` (3, 4) (any non-zero scale, either sign):
    ``P = s K [R | t]``, ``s > 0``, K upper-triangular with positive diagonal and ``K[2, 2] = 1``,
    ``det R = +1`` (module docstring; H&Z sec. 6.2.4). Raises :class:`InputError` if ``M = P[:, :3]``
    is singular (a camera at infinity has no such decomposition).

    RQ from numpy's Householder QR: with the row-reversal permutation ``J``, ``(J M)^T = Q U`` gives
    ``M = (J U^T J)(J Q^T)``, an upper-triangular times an orthogonal matrix.
    """
    P = _finite_P(P, "decompose_projection P")
    M = P[:, :3]
    det = np.linalg.det(M)
    if not np.isfinite(det) or abs(det) <= 1e-14 * np.linalg.norm(M) ** 3:
        raise InputError("decompose_projection P: P[:, :3] is singular (camera at infinity); no K [R | t] form")
    if det < 0:
        P = -P
        M = -M
    Q, U = np.linalg.qr(M[::-1, :].T)
    K = U.T[::-1, ::-1]
    R = Q.T[::-1, :]
    D = np.sign(np.diag(K))  # det M > 0 and det K = prod(diag) > 0 after this => det R = +1
    K = K * D[None, :]
    R = D[:, None] * R
    t = np.linalg.solve(K, P[:, 3])  # uses K before rescaling: P = K_raw [R | t]
    K = K / K[2, 2]
    K[2, 2] = 1.0
    return K, R, t


def _pose_Rt(cam_from_world):
    """(R, t) from a (R, t) pair, a (3, 4) / (4, 4) matrix, or an object with ``.R`` and ``.t``."""
    if hasattr(cam_from_world, "R") and hasattr(cam_from_world, "t"):
        R, t = cam_from_world.R, cam_from_world.t
    elif isinstance(cam_from_world, (tuple, list)) and len(cam_from_world) == 2:
        R, t = cam_from_world
    else:
        T = np.asarray(cam_from_world, dtype=np.float64)
        if T.shape not in ((3, 4), (4, 4)):
            raise InputError(f"cam_from_world: expected (R, t), a (3, 4) or (4, 4) matrix, got shape {T.shape}")
        R, t = T[:3, :3], T[:3, 3]
    return as_float_array(R, "cam_from_world R", (3, 3)), as_float_array(t, "cam_from_world t", (3,))


def project_with_P(P, points_world) -> np.ndarray:
    """Pixels (N, 2) of Euclidean points (N, 3) through P (any scale); inf where the third
    homogeneous coordinate is 0 (points on the principal plane)."""
    P = as_float_array(P, "P", (3, 4))
    X = as_float_array(points_world, "points_world", (None, 3))
    x = X @ P[:, :3].T + P[:, 3]
    with np.errstate(divide="ignore", invalid="ignore"):
        uv = x[:, :2] / x[:, 2:3]
    uv[~np.isfinite(uv)] = np.inf
    return uv


@dataclass(frozen=True)
class ProjectionScore:
    """Errors of an estimated camera matrix against the truth (all from :func:`decompose_projection`)."""

    fx_abs_err_px: float
    fy_abs_err_px: float
    cx_abs_err_px: float
    cy_abs_err_px: float
    skew_abs_err_px: float  # |K[0, 1] est - gt|; no relative form (the truth skew is usually 0)
    fx_rel_err: float
    fy_rel_err: float
    cx_rel_err: float
    cy_rel_err: float
    rot_err_deg: float  # angle of R_est^T R_gt, atan2 form (recon_eval.rotation)
    trans_abs_err_m: float  # |t_est - t_gt|
    trans_rel_err: float  # |t_est - t_gt| / |t_gt| (NaN if t_gt = 0)
    center_err_m: float  # |C_est - C_gt|, C = -R^T t
    reproj_rms_px: float  # RMS over all points of |project(P_est, X) - pixel|; inf if any point fails
    reproj_max_px: float
    n_points: int
    n_invalid: int  # points P_est maps to infinity (counted as failures, never dropped)
    failed: bool  # P_est non-finite or singular: every error is inf


def score_projection(P_est, K_true, cam_from_world_true, points_world=None, pixels=None) -> ProjectionScore:
    """Score an estimated metric-frame camera ``P_est`` (3, 4) against the truth intrinsics
    ``K_true`` (3, 3) and pose ``cam_from_world_true`` ((R, t), a matrix, or a Rigid3).

    P_est is decomposed by :func:`decompose_projection`; K errors are per entry (absolute, and
    relative to the truth value for fx, fy, cx, cy, as OpenCV's calibration test); pose errors as
    PnP (metrics.md, "Calibration and PnP"). The reprojection RMS uses ``P_est`` itself on the truth
    points ``points_world`` (N, 3) against the truth (undistorted) ``pixels`` (N, 2) when given.
    A non-finite or singular ``P_est`` is a failure (every error inf), not an exception.
    """
    Kg = as_float_array(K_true, "K_true", (3, 3))
    Rg, tg = _pose_Rt(cam_from_world_true)
    Kg = Kg / Kg[2, 2]
    n = 0
    if points_world is not None or pixels is not None:
        if points_world is None or pixels is None:
            raise InputError("score_projection: give both points_world and pixels, or neither")
        Xw = as_float_array(points_world, "points_world", (None, 3))
        px = as_float_array(pixels, "pixels", (None, 2))
        if len(Xw) != len(px):
            raise InputError(f"score_projection: {len(Xw)} points but {len(px)} pixels")
        n = len(Xw)
    Pe = np.asarray(P_est, dtype=np.float64)
    inf = float("inf")
    try:
        if Pe.shape != (3, 4) or not np.all(np.isfinite(Pe)):
            raise InputError("non-finite")
        K, R, t = decompose_projection(Pe)
    except InputError:
        return ProjectionScore(*([inf] * 15), n, n, True)

    def rel(e, g):
        return abs(e - g) / abs(g) if g != 0 else float("nan")

    rms = mx = float("nan")
    n_invalid = 0
    if n:
        d = np.linalg.norm(project_with_P(Pe, Xw) - px, axis=1)
        bad = ~np.isfinite(d)
        n_invalid = int(bad.sum())
        rms = inf if n_invalid else float(np.sqrt(np.mean(d**2)))
        mx = inf if n_invalid else float(d.max())
    dt = float(np.linalg.norm(t - tg))
    ng = float(np.linalg.norm(tg))
    errs = [
        abs(K[0, 0] - Kg[0, 0]), abs(K[1, 1] - Kg[1, 1]), abs(K[0, 2] - Kg[0, 2]), abs(K[1, 2] - Kg[1, 2]),
        abs(K[0, 1] - Kg[0, 1]),
        rel(K[0, 0], Kg[0, 0]), rel(K[1, 1], Kg[1, 1]), rel(K[0, 2], Kg[0, 2]), rel(K[1, 2], Kg[1, 2]),
        np.degrees(rotation_error_rad(R, Rg)), dt, dt / ng if ng > 0 else float("nan"),
        np.linalg.norm(-R.T @ t + Rg.T @ tg), rms, mx,
    ]
    return ProjectionScore(*[float(e) for e in errs], n, n_invalid, False)


def score_projection_projective(P_proj, points_proj, points_world_true, K_true, cam_from_world_true,
                                pixels=None) -> ProjectionScore:
    """Score a camera ``P_proj`` (3, 4) of a *projective* reconstruction: its points ``points_proj``
    ((N, 3) or homogeneous (N, 4)) correspond one to one to the truth ``points_world_true`` (N, 3).
    The 15-DoF transform ``H`` (truth_from_proj) is fitted on the points alone
    (:func:`recon_eval.metrics.align.projective_align`, N >= 5 in general position), the camera is moved into
    the truth frame (``P H^-1``) and scored by :func:`score_projection` (reprojection of the truth
    points against ``pixels`` when given). Alignment: ``projective15``.
    """
    H = projective_align(points_proj, points_world_true)
    P_truth = cameras_to_truth_frame(_finite_P(P_proj, "P_proj"), H)
    pts = points_world_true if pixels is not None else None
    return score_projection(P_truth, K_true, cam_from_world_true, pts, pixels)


def _normalise_2d(x: np.ndarray) -> np.ndarray:
    mu = x.mean(axis=0)
    d = np.mean(np.linalg.norm(x - mu, axis=1))
    s = np.sqrt(2.0) / d if d > 0 else 1.0
    return np.array([[s, 0.0, -s * mu[0]], [0.0, s, -s * mu[1]], [0.0, 0.0, 1.0]])


def dlt_projection(points_world, pixels) -> np.ndarray:
    """Camera matrix (3, 4), unit Frobenius norm, from N >= 6 2D-3D correspondences in general
    position (not coplanar): the normalised linear DLT, i.e. the linear steps of H&Z Algorithm 7.1
    (normalise the image points to centroid 0 and mean distance sqrt(2), the world points to
    centroid 0 and mean distance sqrt(3); two equations per point (H&Z eq. 7.2); null vector by
    SVD; denormalise ``P = T^-1 P~ U``). The iterative minimisation of geometric error of the Gold
    Standard algorithm is not done: this is the reference estimator for tests. Exact on noise-free
    points (to rounding)."""
    X = as_float_array(points_world, "dlt points_world", (None, 3))
    x = as_float_array(pixels, "dlt pixels", (None, 2))
    if len(X) != len(x) or len(X) < 6:
        raise InputError(f"dlt_projection: need >= 6 corresponding points, got {len(X)} and {len(x)}")
    if not (np.all(np.isfinite(X)) and np.all(np.isfinite(x))):
        raise InputError("dlt_projection: points must be finite")
    T, U = _normalise_2d(x), normalising_transform_3d(X)
    xn = x @ T[:2, :2].T + T[:2, 2]
    Xn = np.hstack([X @ U[:3, :3].T + U[:3, 3], np.ones((len(X), 1))])
    n = len(X)
    A = np.zeros((2 * n, 12))
    A[0::2, 4:8] = -Xn
    A[0::2, 8:12] = xn[:, 1:2] * Xn
    A[1::2, 0:4] = Xn
    A[1::2, 8:12] = -xn[:, 0:1] * Xn
    _, _, Vt = np.linalg.svd(A)
    P = np.linalg.inv(T) @ Vt[-1].reshape(3, 4) @ U
    return P / np.linalg.norm(P)

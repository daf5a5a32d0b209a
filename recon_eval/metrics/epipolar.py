"""Fundamental / essential matrix and homography metrics.

Definitions: docs/metrics.md, "Fundamental / essential matrices and homographies".
Pixels are OpenCV coordinates (N, 2) float64; F maps image-1 points to image-2 lines
(``x2^T F x1 = 0``). Degenerate estimates (non-finite, zero, rank 3 F; non-finite or singular H)
are scored as failures (errors = inf, ``failed=True`` with the reason), never raised.
"""
from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from recon_eval.arrays import as_float_array
from recon_eval.errors import InputError
from recon_eval.metrics.stats import recall_auc
from scenegen.geometry.conventions import corner_pixel_centers
from scenegen.geometry.rotation import angle_between_vectors_rad, rotation_error_rad
from scenegen.geometry.twoview import apply_homography, homogeneous, sampson_error, symmetric_epipolar_error

#: s3 / s1 of F above this is "rank 3". 1e-6 admits F estimated in float32 or written with ~7
#: significant digits, whose rank-2 enforcement leaves s3/s1 ~ 1e-7; a real rank-3 F is O(1e-2+).
RANK2_REL_TOL = 1e-6


#: s3 / s1 of H below this is "singular": it maps the image onto a line or a point.
SINGULAR_REL_TOL = 1e-12


def _singular_value_ratio(M) -> tuple[float | None, str | None]:
    """(s3 / s1 of a finite, non-zero 3x3 matrix, None) or (None, why it has none)."""
    M = np.asarray(M, dtype=np.float64)
    if M.shape != (3, 3):
        return None, f"shape {M.shape}, expected (3, 3)"
    if not np.all(np.isfinite(M)):
        return None, "non-finite"
    s = np.linalg.svd(M, compute_uv=False)
    if s[0] == 0:
        return None, "zero"
    return float(s[2] / s[0]), None


def fundamental_degeneracy(F) -> str | None:
    """Why an estimated F cannot be scored, or None. Reasons: 'non-finite', 'zero', 'rank 3'."""
    ratio, why = _singular_value_ratio(F)
    return why if why is not None else ("rank 3" if ratio > RANK2_REL_TOL else None)


def sampson_sq_px2(F, x1, x2) -> np.ndarray:
    """Sampson error (N,) in px^2 of correspondences x1 -> x2 (N, 2) pixels, checked; the formula
    is :func:`scenegen.geometry.twoview.sampson_error` (H&Z eq. 11.9, = ``cv2.sampsonDistance``)."""
    return sampson_error(as_float_array(F, "F", (3, 3)), as_float_array(x1, "x1", (None, 2)),
                         as_float_array(x2, "x2", (None, 2)))


def symmetric_epipolar_sq_px2(F, x1, x2) -> np.ndarray:
    """Symmetric epipolar distance (N,) in px^2 (H&Z eq. 11.10) of correspondences x1 -> x2 (N, 2),
    checked; the formula is :func:`scenegen.geometry.twoview.symmetric_epipolar_error`."""
    return symmetric_epipolar_error(as_float_array(F, "F", (3, 3)), as_float_array(x1, "x1", (None, 2)),
                                    as_float_array(x2, "x2", (None, 2)))


@dataclass(frozen=True)
class FundamentalResult:
    """Scores of an estimated F on exact truth correspondences."""

    sampson_rms_px: float  # sqrt(mean Sampson error); inf if failed
    sampson_median_px: float  # median of the per-point Sampson distances sqrt(s) (for even N the mean of the two
    # middle distances, not sqrt of the mean of the two middle squared errors)
    sym_epipolar_rms_px: float  # sqrt(mean over the 2N point-to-line distances squared)
    n_points: int
    failed: bool
    failure_reason: str | None


def fundamental_metrics(F_est, x1, x2) -> FundamentalResult:
    """Sampson and symmetric epipolar RMS of ``F_est`` on truth correspondences x1 <-> x2 (N, 2),
    pixels (exact, dense, visible correspondences from the synthetic truth)."""
    x1 = as_float_array(x1, "x1", (None, 2))
    x2 = as_float_array(x2, "x2", (None, 2))
    if x1.shape != x2.shape or len(x1) == 0:
        raise InputError(f"correspondences: x1 {x1.shape} and x2 {x2.shape} must be equal-length and non-empty")
    why = fundamental_degeneracy(F_est)
    if why is not None:
        return FundamentalResult(np.inf, np.inf, np.inf, len(x1), True, why)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = sampson_sq_px2(F_est, x1, x2)
        sym = symmetric_epipolar_sq_px2(F_est, x1, x2)
    s = np.where(np.isfinite(s), s, np.inf)  # a point on the epipole has no line: worst case
    sym = np.where(np.isfinite(sym), sym, np.inf)
    return FundamentalResult(float(np.sqrt(np.mean(s))), float(np.median(np.sqrt(s))),
                             float(np.sqrt(np.mean(sym) / 2.0)), len(x1), False, None)


def _clip_line_to_image(l: np.ndarray, w: int, h: int):
    """End points (2, 2) of the segment of line l = (a, b, c) inside [0, w-1] x [0, h-1], or None."""
    a, b, c = l
    pts = []
    if abs(b) > 0:
        for u in (0.0, w - 1.0):
            v = -(a * u + c) / b
            if 0 <= v <= h - 1:
                pts.append((u, v))
    if abs(a) > 0:
        for v in (0.0, h - 1.0):
            u = -(b * v + c) / a
            if 0 <= u <= w - 1:
                pts.append((u, v))
    if len(pts) < 2:
        return None
    pts = np.array(pts)
    d = np.linalg.norm(pts[:, None] - pts[None], axis=2)
    i, j = np.unravel_index(np.argmax(d), d.shape)
    return pts[[i, j]]


def _point_line_distance(x: np.ndarray, l: np.ndarray) -> float:
    return abs(l[0] * x[0] + l[1] * x[1] + l[2]) / np.hypot(l[0], l[1])


def _zhang_one_way(F1, F2, size1, size2, n, rng):
    dists = []
    tries = 0
    while len(dists) < n and tries < 50 * n:
        tries += 1
        x1 = np.array([rng.uniform(0, size1[0] - 1), rng.uniform(0, size1[1] - 1), 1.0])
        seg = _clip_line_to_image(F1 @ x1, *size2)
        if seg is None:
            continue
        lam = rng.random()
        x2 = np.r_[seg[0] + lam * (seg[1] - seg[0]), 1.0]
        l1 = F2.T @ x2  # line in image 1 through which x1 should pass under F2
        l2 = F2 @ x1  # line in image 2 through which x2 should pass under F2
        if np.hypot(*l1[:2]) == 0 or np.hypot(*l2[:2]) == 0:
            continue
        dists.append(0.5 * (_point_line_distance(x1, l1) + _point_line_distance(x2, l2)))
    return dists


@dataclass(frozen=True)
class FDistanceResult:
    """Zhang's distance between two fundamental matrices (no correspondences needed)."""

    f_distance_px: float  # mean over samples (both roles) of the point-to-line distances
    n_samples: int
    seed: int
    failed: bool
    failure_reason: str | None


def zhang_f_distance(F_est, F_gt, size1, size2=None, *, n_samples: int = 1000, seed: int = 0) -> FDistanceResult:
    """Zhang's F-distance (Z. Zhang, "Determining the epipolar geometry and its uncertainty: a
    review", IJCV 27(2), 1998, sec. 7): draw x1 uniformly in image 1 (size (W, H)); take its
    epipolar line under F1 and a uniform random point x2 on that line inside image 2; measure the
    distance of x1 to F2's line F2^T x2 and of x2 to F2's line F2 x1, average the two. Then swap the
    roles of F1 and F2 and average everything. Seeded; samples whose line misses the image are
    redrawn."""
    size2 = size1 if size2 is None else size2
    why_gt = fundamental_degeneracy(F_gt)
    if why_gt is not None:
        raise InputError(f"truth F is degenerate ({why_gt})")
    why = fundamental_degeneracy(F_est)
    if why is not None:
        return FDistanceResult(np.inf, 0, seed, True, why)
    Fe, Fg = np.asarray(F_est, float), np.asarray(F_gt, float)
    rng = np.random.default_rng(seed)
    d = _zhang_one_way(Fe, Fg, size1, size2, n_samples, rng) + _zhang_one_way(Fg, Fe, size1, size2, n_samples, rng)
    if not d:
        return FDistanceResult(np.inf, 0, seed, True, "no epipolar line crosses the images")
    return FDistanceResult(float(np.mean(d)), len(d), seed, False, None)


@dataclass(frozen=True)
class EpipolarPoseResult:
    """Relative pose recovered from an estimated F through the truth intrinsics."""

    rot_err_deg: float  # angle of R_est^T R_gt
    trans_dir_err_deg: float  # folded: min(e, 180 - e)
    pose_err_deg: float  # max of the two (SuperGlue); inf if failed
    failed: bool
    failure_reason: str | None


def pose_error_from_fundamental(F_est, K1, K2, x1, x2, R_gt, t_gt) -> EpipolarPoseResult:
    """E = K2^T F K1, decomposed (cheirality on the truth correspondences x1 <-> x2 (N, 2) pixels,
    via ``cv2.recoverPose`` on normalised coordinates); errors against cam2_from_cam1 (R_gt, t_gt)
    as in SuperGlue (:func:`recon_eval.metrics.poses.relative_pose_errors_deg`)."""
    why = fundamental_degeneracy(F_est)
    if why is not None:
        return EpipolarPoseResult(np.inf, np.inf, np.inf, True, why)
    K1 = as_float_array(K1, "K1", (3, 3))
    K2 = as_float_array(K2, "K2", (3, 3))
    E = K2.T @ np.asarray(F_est, float) @ K1
    n1 = (homogeneous(as_float_array(x1, "x1", (None, 2))) @ np.linalg.inv(K1).T)[:, :2]
    n2 = (homogeneous(as_float_array(x2, "x2", (None, 2))) @ np.linalg.inv(K2).T)[:, :2]
    _, R, t, _ = cv2.recoverPose(E, n1, n2, np.eye(3))
    eR = float(np.degrees(rotation_error_rad(R, R_gt)))
    et = float(np.degrees(angle_between_vectors_rad(t.reshape(3), np.asarray(t_gt, float).reshape(3))))
    et = min(et, 180.0 - et)
    return EpipolarPoseResult(eR, et, max(eR, et), False, None)


@dataclass(frozen=True)
class InlierResult:
    """Inlier classification against truth match labels."""

    precision: float  # TP / (TP + FP); 0 when nothing is returned as inlier
    recall: float  # TP / (TP + FN); 0 when there are no true inliers
    n_est_inliers: int
    n_true_inliers: int
    n_true_positive: int


def inlier_precision_recall(est_inliers, true_inliers) -> InlierResult:
    """Precision and recall of an estimator's inlier mask (N,) bool against truth labels (N,)."""
    e = np.asarray(est_inliers, bool).reshape(-1)
    g = np.asarray(true_inliers, bool).reshape(-1)
    if e.shape != g.shape:
        raise InputError(f"inlier masks: estimate {e.shape} and truth {g.shape} differ")
    tp = int(np.sum(e & g))
    ne, ng = int(e.sum()), int(g.sum())
    return InlierResult(tp / ne if ne else 0.0, tp / ng if ng else 0.0, ne, ng, tp)


# --- homographies ------------------------------------------------------------------------------
def homography_degeneracy(H) -> str | None:
    """Why an estimated H cannot be scored, or None. Reasons: 'non-finite', 'zero', 'singular'."""
    ratio, why = _singular_value_ratio(H)
    return why if why is not None else ("singular" if ratio < SINGULAR_REL_TOL else None)


@dataclass(frozen=True)
class HomographyResult:
    mace_px: float  # mean corner error; inf if failed
    corner_err_px: tuple  # the four corner errors
    failed: bool
    failure_reason: str | None


def homography_mace(H_est, H_gt, width: int, height: int) -> HomographyResult:
    """Mean corner error: mean over the corners (0,0), (W-1,0), (0,H-1), (W-1,H-1) of
    |H_est c - H_gt c| in pixels (HPatches / SuperPoint style). A degenerate H_est, or one that
    sends a corner to infinity, is a failure (inf)."""
    why = homography_degeneracy(H_est)
    if homography_degeneracy(H_gt) is not None:
        raise InputError(f"truth H is degenerate ({homography_degeneracy(H_gt)})")
    if why is not None:
        return HomographyResult(np.inf, (np.inf,) * 4, True, why)
    c = corner_pixel_centers(width, height)
    d = np.linalg.norm(apply_homography(H_est, c) - apply_homography(H_gt, c), axis=1)
    if not np.all(np.isfinite(d)):
        return HomographyResult(np.inf, (np.inf,) * 4, True, "corner mapped to infinity")
    return HomographyResult(float(np.mean(d)), tuple(float(v) for v in d), False, None)


@dataclass(frozen=True)
class HomographySummary:
    """Over a set of image pairs."""

    accuracy_1_px: float  # fraction with MACE <= 1 px (SuperPoint "correctness" uses <=)
    accuracy_3_px: float
    accuracy_5_px: float
    auc_3_px: float  # SuperGlue/LoFTR recall-curve area up to 3 px, normalised
    auc_5_px: float
    auc_10_px: float
    n_pairs: int
    n_failed: int
    accuracy_operator: str = "<="


def homography_summary(mace_px) -> HomographySummary:
    """Accuracy@1/3/5 px (MACE <= eps, SuperPoint's ``compute_homography`` correctness) and
    AUC@3/5/10 px (LoFTR ``error_auc`` on corner errors) of MACE values (P,); inf = failure."""
    e = np.asarray(mace_px, float).reshape(-1)
    e = np.where(np.isnan(e), np.inf, e)
    acc = [float(np.mean(e <= t)) if len(e) else 0.0 for t in (1.0, 3.0, 5.0)]
    return HomographySummary(*acc, *recall_auc(e, (3.0, 5.0, 10.0)), len(e), int(np.sum(~np.isfinite(e))))


# --- the survey's measure ------------------------------------------------------------------------
@dataclass(frozen=True)
class EpipolarDistanceResult:
    """Distances of points to their epipolar lines, both images pooled (Armangue and Salvi,
    "Overall view regarding fundamental matrix estimation", IVC 21(2), 2003: the mean and
    standard deviation of the distances between points and epipolar lines)."""

    mean_px: float  # mean of the 2N distances; inf if failed
    std_px: float  # their standard deviation (population, ddof 0); inf if failed
    n_points: int  # N correspondences (2N distances)
    failed: bool
    failure_reason: str | None


def epipolar_line_distances_px(F, x1, x2) -> tuple[np.ndarray, np.ndarray]:
    """(d1, d2) (N,) px: the distance of x1 to its epipolar line F^T x2 in image 1 and of x2 to
    F x1 in image 2, for correspondences x1 -> x2 (N, 2); inf where a line is undefined."""
    F = as_float_array(F, "F", (3, 3))
    a = homogeneous(as_float_array(x1, "x1", (None, 2)))
    b = homogeneous(as_float_array(x2, "x2", (None, 2)))
    Fa, Ftb = a @ F.T, b @ F
    r = np.abs(np.sum(b * Fa, axis=1))
    with np.errstate(divide="ignore", invalid="ignore"):
        d1, d2 = r / np.hypot(Ftb[:, 0], Ftb[:, 1]), r / np.hypot(Fa[:, 0], Fa[:, 1])
    return np.where(np.isfinite(d1), d1, np.inf), np.where(np.isfinite(d2), d2, np.inf)


def epipolar_distance_stats(F_est, x1, x2) -> EpipolarDistanceResult:
    """Mean and standard deviation of the 2N point-to-epipolar-line distances of correspondences
    x1 <-> x2 (N, 2) px under ``F_est`` (:func:`epipolar_line_distances_px`); a degenerate F is a
    failure (inf)."""
    x1 = as_float_array(x1, "x1", (None, 2))
    if len(x1) == 0:
        raise InputError("correspondences: empty")
    why = fundamental_degeneracy(F_est)
    if why is not None:
        return EpipolarDistanceResult(np.inf, np.inf, len(x1), True, why)
    d = np.concatenate(epipolar_line_distances_px(F_est, x1, x2))
    return EpipolarDistanceResult(float(np.mean(d)), float(np.std(d)), len(x1), False, None)

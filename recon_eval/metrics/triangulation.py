"""Two-view triangulation scored against the truth points.

A user's triangulated points (or OpenCV's ``cv2.triangulatePoints``, the reference method, run on
noisy truth correspondences at a chosen sigma) are compared point by point with the truth:
the error in metres ``|X_est - X_true|``, the same relative to the truth depth (z of the truth point
in the first camera), and both binned by the triangulation (baseline) angle: the angle at the truth
point between the rays to the two camera centres, computed in the atan2 form
(:func:`scenegen.geometry.rotation.angle_between_vectors_rad`). A point that was not triangulated
(non-finite) is a failure with error inf; it stays in every count, and mean / RMS over a set that
holds one are inf (metrics.md, "Rules for CI gates" 3).

Poses are cam_from_world (R (3, 3), t (3,) metres), pixels OpenCV pixels of a pinhole camera
(undistorted), projection matrices ``P = K [R | t]``.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass

import cv2
import numpy as np

from recon_eval.arrays import as_float_array, frozen
from recon_eval.errors import InputError
from scenegen.geometry.rotation import angle_between_vectors_rad

#: Default bin edges of the triangulation angle, degrees; bins are [lo, hi), the last one closed.
ANGLE_BINS_DEG = (0.0, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 45.0, 90.0, 180.0)


def projection_matrix(K, R, t) -> np.ndarray:
    """``K [R | t]`` (3, 4) of a pinhole camera with pose cam_from_world (R, t)."""
    K = as_float_array(K, "K", (3, 3))
    R = as_float_array(R, "R", (3, 3))
    t = as_float_array(t, "t", (3,))
    return K @ np.hstack([R, t[:, None]])


def noisy_observations(pixels, sigma_px: float, seed: int = 0) -> np.ndarray:
    """``pixels`` (N, 2) plus independent Gaussian noise of standard deviation ``sigma_px`` per
    coordinate (seeded); a new array."""
    x = as_float_array(pixels, "pixels", (None, 2))
    if not sigma_px >= 0:
        raise InputError(f"sigma_px must be >= 0, got {sigma_px}")
    return x + np.random.default_rng(seed).normal(scale=sigma_px, size=x.shape)


def triangulate_opencv(P1, P2, x1, x2) -> np.ndarray:
    """Reference triangulation: ``cv2.triangulatePoints`` (linear DLT, float64) on pixels x1, x2
    (N, 2) of cameras P1, P2 (3, 4); Euclidean points (N, 3), inf where w = 0."""
    P1 = as_float_array(P1, "P1", (3, 4))
    P2 = as_float_array(P2, "P2", (3, 4))
    x1 = as_float_array(x1, "x1", (None, 2))
    x2 = as_float_array(x2, "x2", (None, 2))
    if len(x1) != len(x2):
        raise InputError(f"triangulate: {len(x1)} pixels in view 1 but {len(x2)} in view 2")
    if len(x1) == 0:
        return np.zeros((0, 3))
    Xh = cv2.triangulatePoints(P1, P2, np.ascontiguousarray(x1.T), np.ascontiguousarray(x2.T)).T
    with np.errstate(divide="ignore", invalid="ignore"):
        X = Xh[:, :3] / Xh[:, 3:4]
    X[~np.all(np.isfinite(X), axis=1)] = np.inf
    return X


def triangulation_angle_deg(points_world, center1, center2) -> np.ndarray:
    """Angle (degrees, [0, 180]) at each point (N, 3) between the rays to the two camera centres."""
    X = as_float_array(points_world, "points_world", (None, 3))
    c1 = as_float_array(center1, "center1", (3,))
    c2 = as_float_array(center2, "center2", (3,))
    return np.degrees(np.atleast_1d(angle_between_vectors_rad(c1 - X, c2 - X)))


@dataclass(frozen=True)
class AngleBin:
    lo_deg: float
    hi_deg: float
    n: int
    n_failed: int
    median_m: float
    mean_m: float
    rms_m: float
    median_rel: float  # median of error / truth depth
    median_angle_deg: float  # median triangulation angle of the bin's points


@dataclass(frozen=True)
class TriangulationScore:
    n_points: int
    n_failed: int  # non-finite estimates (error inf)
    mean_m: float
    median_m: float
    rms_m: float
    max_m: float
    median_rel: float
    mean_rel: float
    bins: tuple  # AngleBin per angle bin (empty bins included, with n = 0 and NaN statistics)
    err_m: np.ndarray  # (N,) per point
    rel_err: np.ndarray  # (N,) err_m / truth depth in camera 1
    angle_deg: np.ndarray  # (N,) triangulation angle at the truth point


def _stats(e: np.ndarray):
    if len(e) == 0:
        return (float("nan"),) * 3
    return float(np.median(e)), float(np.mean(e)), float(np.sqrt(np.mean(e**2)))


def score_triangulation(points_est, points_true, cam1_from_world, cam2_from_world,
                        angle_bins_deg=ANGLE_BINS_DEG) -> TriangulationScore:
    """Score triangulated points ``points_est`` (N, 3) against ``points_true`` (N, 3) (metres,
    world frame, one to one) for the camera pair given as cam_from_world ``(R, t)`` pairs.

    Per point: ``err_m = |X_est - X_true|`` (inf if X_est is not finite), ``rel_err = err_m / z``
    with z the truth depth in camera 1 (must be > 0), and the triangulation angle. Summaries over all
    points and per angle bin (edges ``angle_bins_deg``, [lo, hi), last bin closed; points outside
    every bin count only in the totals)."""
    Xe = as_float_array(points_est, "points_est", (None, 3))
    Xt = as_float_array(points_true, "points_true", (None, 3))
    if Xe.shape != Xt.shape:
        raise InputError(f"score_triangulation: points_est {Xe.shape} and points_true {Xt.shape} must correspond")
    if not np.all(np.isfinite(Xt)):
        raise InputError("score_triangulation: points_true must be finite")
    (R1, t1), (R2, t2) = cam1_from_world, cam2_from_world
    R1 = as_float_array(R1, "cam1 R", (3, 3))
    t1 = as_float_array(t1, "cam1 t", (3,))
    R2 = as_float_array(R2, "cam2 R", (3, 3))
    t2 = as_float_array(t2, "cam2 t", (3,))
    z = Xt @ R1[2] + t1[2]
    if np.any(z <= 0):
        raise InputError(f"score_triangulation: {int(np.sum(z <= 0))} truth points are not in front of camera 1")
    ok = np.all(np.isfinite(Xe), axis=1)
    err = np.full(len(Xt), np.inf)
    err[ok] = np.linalg.norm(Xe[ok] - Xt[ok], axis=1)
    ang = triangulation_angle_deg(Xt, -R1.T @ t1, -R2.T @ t2) if len(Xt) else np.zeros(0)
    return _summarise(err, err / z, ang, angle_bins_deg)


def pool_scores(scores, angle_bins_deg=ANGLE_BINS_DEG) -> TriangulationScore:
    """One :class:`TriangulationScore` over the points of several scores (e.g. the camera pairs of
    a task): their per-point errors, relative errors and angles pooled, then summarised and binned
    exactly as :func:`score_triangulation` does."""
    scores = list(scores)
    cat = [np.concatenate([getattr(s, f) for s in scores]) if scores else np.zeros(0)
           for f in ("err_m", "rel_err", "angle_deg")]
    return _summarise(*cat, angle_bins_deg)


def _summarise(err, rel, ang, angle_bins_deg) -> TriangulationScore:
    """Totals and angle bins of per-point errors (N,) (inf = failure), relative errors and angles."""
    ok = np.isfinite(err)
    edges = np.asarray(angle_bins_deg, dtype=np.float64)
    if edges.ndim != 1 or len(edges) < 2 or np.any(np.diff(edges) <= 0):
        raise InputError(f"angle_bins_deg: expected increasing edges, got {angle_bins_deg}")
    bins = []
    for k, (lo, hi) in enumerate(itertools.pairwise(edges)):
        sel = (ang >= lo) & ((ang < hi) | ((k == len(edges) - 2) & (ang <= hi)))
        med, mean, rms = _stats(err[sel])
        bins.append(AngleBin(float(lo), float(hi), int(sel.sum()), int(np.sum(sel & ~ok)), med, mean, rms,
                             _stats(rel[sel])[0], _stats(ang[sel])[0]))
    med, mean, rms = _stats(err)
    return TriangulationScore(
        len(err), int(np.sum(~ok)), mean, med, rms, float(err.max()) if len(err) else float("nan"),
        _stats(rel)[0], _stats(rel)[1], tuple(bins), frozen(err), frozen(rel), frozen(ang),
    )

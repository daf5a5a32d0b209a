"""The view-pair sweep kinds: homographies (``h``), essential matrices (``e``) and two-view
triangulation (``triangulation``), on :func:`recon_eval.sweep.truth.pair_points`.

A trial is :func:`recon_eval.sweep.draw.draw_trial` on the truth pixels x1 <-> x2 (noise on all
four coordinates, an outlier's image-2 pixel uniform over image 2), in the kind's own seed stream.
Scores are on the trial's inlier rows, against the noise-free truth:

* ``h``: the mean corner error (MACE, px; :func:`recon_eval.metrics.epipolar.homography_mace`)
  against the plane's truth homography ``K2 (R + t n^T / d) K1^-1``
  (:func:`scenegen.geometry.twoview.plane_homography`; n, d the least-squares plane of the truth
  points in camera 1, which must be coplanar to :data:`PLANAR_REL_TOL` of their extent);
* ``e``: the pose error (deg, SuperGlue's max of rotation and translation-direction angles) of E
  through the truth K (:func:`recon_eval.metrics.epipolar.pose_error_from_fundamental` on
  ``F = K2^-T E K1^-1``, cheirality on the inlier truth pixels), and the truth points' distances
  to its epipolar lines (px);
* ``triangulation``: the mean 3D error (m) of the inlier rows' points
  (:func:`recon_eval.metrics.triangulation.score_triangulation`). Each point is triangulated on its
  own, so an outlier spoils only its own point (which is not scored): the outlier axis cannot
  break these methods down, and the sweep shows it.

Methods (OpenCV, with the thresholds of :mod:`recon_eval.runners.twoview`):
``opencv-h-ls`` (``findHomography`` method 0: least squares on every point), ``opencv-h-ransac``,
``opencv-h-lmeds``, ``opencv-h-rho``, ``opencv-h-usac-magsac``; ``opencv-e-ransac``,
``opencv-e-lmeds``, ``opencv-e-usac-magsac`` (``findEssentialMat`` on points normalised by each
truth K, the threshold divided by the mean focal length, as the ``opencv-e-*`` runners);
``opencv-triangulate`` (``triangulatePoints``, linear) and ``opencv-triangulate-corrected``
(``correctMatches`` with the truth F first: Lindstrom's optimal correction, then linear).
"""
from __future__ import annotations

import dataclasses

import cv2
import numpy as np

from recon_eval.metrics.epipolar import epipolar_distance_stats, homography_mace, pose_error_from_fundamental
from recon_eval.metrics.triangulation import score_triangulation, triangulate_opencv
from recon_eval.runners.twoview import CONFIDENCE, MAX_ITERS, THRESH_PX, USAC_THRESH_PX
from recon_eval.sweep.draw import draw_trial
from recon_eval.sweep.kind import SweepKind
from recon_eval.sweep.methods import OPENCV, SweepMethod, builtin_resolver
from recon_eval.sweep.summary import summarise_scores
from recon_eval.sweep.truth import pair_points, plane_of
from scenegen.geometry.twoview import fundamental, plane_homography

#: Largest distance of a truth point from the pair's plane, relative to the points' extent, for
#: ``--kind h`` (float32 storage of the points: about 1e-7).
PLANAR_REL_TOL = 1e-5
NAN3 = np.full((3, 3), np.nan)


def _pair_draw(stream):
    def draw(truth, n, sigma, frac, seed, cell, trial):
        return draw_trial(truth.x[0], truth.x[1], truth.sizes[1], n, sigma, frac, seed, cell, trial, stream=stream)
    return draw


def _fit(m, trial, truth, seed, workdir):
    return m.fit(trial, truth, seed, workdir)


def _notes(extra: dict):
    return lambda truth: {**truth.notes, **extra}


# --- homographies ---------------------------------------------------------------------------------
def h_truth(ds, views, pool, obj=None):
    t = pair_points(ds, *views, pool, obj, baseline=False)
    p1 = t.cam_from_world[0]
    n, d, res = plane_of(p1.apply(t.X), PLANAR_REL_TOL)
    H = plane_homography(t.K[0], t.K[1], t.cam2_from_cam1, n, d)
    return dataclasses.replace(t, notes={**t.notes, "H_gt": H.tolist(), "plane": "least-squares plane of the truth "
                                         f"points in camera 1 (max residual {res:.2e} m)"})


def _h_method(name: str, flag) -> SweepMethod:
    def fit(trial, truth, seed, workdir):
        if flag == 0:
            H, _ = cv2.findHomography(trial.x1, trial.x2, 0)
        else:
            thresh = USAC_THRESH_PX if flag == cv2.USAC_MAGSAC else THRESH_PX["ransac"]
            H, _ = cv2.findHomography(trial.x1, trial.x2, flag, thresh, maxIters=MAX_ITERS, confidence=CONFIDENCE)
        return None if H is None or H.shape != (3, 3) else H

    return SweepMethod(name, OPENCV, f"cv2.findHomography {name.removeprefix('opencv-h-')}", {"method": name}, fit)


H_METHODS = {m.name: m for m in [_h_method("opencv-h-ls", 0), _h_method("opencv-h-ransac", cv2.RANSAC),
                                 _h_method("opencv-h-lmeds", cv2.LMEDS), _h_method("opencv-h-rho", cv2.RHO),
                                 _h_method("opencv-h-usac-magsac", cv2.USAC_MAGSAC)]}


def h_score(H, trial, truth) -> dict:
    H_gt = np.asarray(truth.notes["H_gt"])
    r = homography_mace(NAN3 if H is None else H, H_gt, *truth.sizes[0])
    return {"mace_px": r.mace_px, "failed": r.failed, "failure_reason": r.failure_reason}


# --- essential matrices ---------------------------------------------------------------------------
def _e_method(name: str, flag) -> SweepMethod:
    def fit(trial, truth, seed, workdir):
        K1, K2 = truth.K
        n1 = (trial.x1 - K1[:2, 2]) @ np.linalg.inv(K1[:2, :2]).T
        n2 = (trial.x2 - K2[:2, 2]) @ np.linalg.inv(K2[:2, :2]).T
        f = 0.5 * (K1[0, 0] + K2[0, 0])
        thresh = USAC_THRESH_PX if flag == cv2.USAC_MAGSAC else THRESH_PX["ransac"]
        E, _ = cv2.findEssentialMat(n1, n2, np.eye(3), flag, CONFIDENCE, thresh / f)
        return None if E is None or E.shape[0] < 3 else E[:3]

    return SweepMethod(name, OPENCV, f"cv2.findEssentialMat {name.removeprefix('opencv-e-')}", {"method": name}, fit)


E_METHODS = {m.name: m for m in [_e_method("opencv-e-ransac", cv2.RANSAC), _e_method("opencv-e-lmeds", cv2.LMEDS),
                                 _e_method("opencv-e-usac-magsac", cv2.USAC_MAGSAC)]}


def e_score(E, trial, truth) -> dict:
    K1, K2 = truth.K
    F = NAN3 if E is None else np.linalg.inv(K2).T @ E @ np.linalg.inv(K1)
    t1, t2 = trial.t1[trial.inliers], trial.t2[trial.inliers]
    rel = truth.cam2_from_cam1
    pe = pose_error_from_fundamental(F, K1, K2, t1, t2, rel.R, rel.t)
    epi = epipolar_distance_stats(F, t1, t2)
    return {"pose_err_deg": pe.pose_err_deg, "rot_err_deg": pe.rot_err_deg, "trans_dir_err_deg": pe.trans_dir_err_deg,
            "epi_mean_px": epi.mean_px, "failed": pe.failed, "failure_reason": pe.failure_reason}


# --- triangulation --------------------------------------------------------------------------------
def _tri_method(name: str, corrected: bool) -> SweepMethod:
    def fit(trial, truth, seed, workdir):
        x1, x2 = trial.x1, trial.x2
        if corrected:
            F = fundamental(truth.K[0], truth.K[1], truth.cam2_from_cam1)
            a, b = cv2.correctMatches(F, x1[None], x2[None])
            x1, x2 = a[0].astype(np.float64), b[0].astype(np.float64)
        return triangulate_opencv(truth.P[0], truth.P[1], x1, x2)

    desc = ("cv2.correctMatches (truth F) then cv2.triangulatePoints" if corrected else "cv2.triangulatePoints")
    return SweepMethod(name, OPENCV, desc, {"method": name}, fit)


TRI_METHODS = {m.name: m for m in [_tri_method("opencv-triangulate", False),
                                   _tri_method("opencv-triangulate-corrected", True)]}


def tri_score(X_est, trial, truth) -> dict:
    keep = trial.inliers
    X_est = np.full((len(keep), 3), np.inf) if X_est is None else np.asarray(X_est, np.float64)
    (p1, p2) = truth.cam_from_world
    s = score_triangulation(X_est[keep], truth.X[trial.rows][keep], (p1.R, p1.t), (p2.R, p2.t))
    failed = s.n_failed > 0
    return {"err_m": s.mean_m, "median_err_m": s.median_m, "mean_rel_err": s.mean_rel, "failed": failed,
            "failure_reason": f"{s.n_failed} points not triangulated" if failed else None}


def _with_baseline(ds, views, pool, obj=None):
    return pair_points(ds, *views, pool, obj, baseline=True)


def _kind(name, label, stream, measure, key, unit, extras, min_inl, breakdown, truth, score, methods, notes):
    return SweepKind(
        name, label, stream, measure, key, unit, (f"mean_{key}", f"std_{key}", f"median_trial_{key}"), min_inl,
        breakdown, 2, truth, _pair_draw(stream), _fit, score,
        lambda trials, b: summarise_scores(trials, b, key, extras), builtin_resolver(name, methods),
        lambda: list(methods), _notes(notes))


H_KIND = _kind("h", "homography", "h-sweep", "mean corner error (MACE) of the estimated H against the truth H, px",
               "mace_px", "px", (), 4, 2.0, h_truth, h_score, H_METHODS, {})
E_KIND = _kind("e", "essential matrix", "e-sweep", "pose error through the truth K: max of the rotation and "
               "translation-direction errors, deg", "pose_err_deg", "deg",
               ("rot_err_deg", "trans_dir_err_deg", "epi_mean_px"), 5, 5.0,
               _with_baseline, e_score, E_METHODS, {})
TRI_KIND = _kind("triangulation", "two-view triangulation", "triangulation-sweep",
                 "mean 3D error of the inlier rows' triangulated points against the truth points, m", "err_m", "m",
                 ("median_err_m", "mean_rel_err"), 1, 0.05,
                 _with_baseline, tri_score, TRI_METHODS,
                 {"outliers": "an outlier's image-2 pixel is uniform over image 2; its point is not scored"})

"""The PnP sweep kind (``pnp``), on one view's truth (:func:`recon_eval.sweep.truth.view_points`):
a trial (:func:`recon_eval.sweep.draw.draw_view_trial`) gives the 3D truth points of n rows and
their undistorted pixels with Gaussian noise, an outlier's pixel uniform over the image.

Score (:func:`recon_eval.metrics.pnp.pnp_errors`, on the inlier rows): the reprojection RMS (px)
of the truth points through the truth K at the ESTIMATED pose against their noise-free pixels
(the estimate, not the noise: 0 for the truth pose), with the rotation error (deg) and the
translation error (m). Methods: ``cv2.solvePnP`` ITERATIVE, EPNP and SQPNP, and
``cv2.solvePnPRansac`` with each (reprojection threshold and iterations of the
``opencv-pnp-ransac-*`` runners, :mod:`recon_eval.runners.pnp`), given K and no distortion.
"""
from __future__ import annotations

import cv2
import numpy as np

from recon_eval.metrics.pnp import pnp_errors
from recon_eval.runners.pnp import RANSAC_THRESH_PX
from recon_eval.sweep.draw import draw_view_trial
from recon_eval.sweep.kind import SweepKind
from recon_eval.sweep.methods import OPENCV, SweepMethod, builtin_resolver
from recon_eval.sweep.summary import summarise_scores
from recon_eval.sweep.truth import view_points
from scenegen.geometry.camera import Camera

SOLVERS = {"iterative": cv2.SOLVEPNP_ITERATIVE, "epnp": cv2.SOLVEPNP_EPNP, "sqpnp": cv2.SOLVEPNP_SQPNP}
RANSAC_ITERATIONS, RANSAC_CONFIDENCE = 1000, 0.999
STREAM = "pnp-sweep"


def _method(solver: str, ransac: bool) -> SweepMethod:
    name = f"opencv-pnp-{'ransac-' if ransac else ''}{solver}"

    def fit(trial, truth, seed, workdir):
        X, x, K = truth.X[trial.rows], trial.x, truth.K[0]
        try:
            if ransac:
                ok, rvec, tvec, _ = cv2.solvePnPRansac(X, x, K, None, flags=SOLVERS[solver],
                                                      iterationsCount=RANSAC_ITERATIONS,
                                                      reprojectionError=RANSAC_THRESH_PX,
                                                      confidence=RANSAC_CONFIDENCE)
            else:
                ok, rvec, tvec = cv2.solvePnP(X, x, K, None, flags=SOLVERS[solver])
        except cv2.error:
            return None
        return (cv2.Rodrigues(rvec)[0], tvec.ravel()) if ok else None

    call = "cv2.solvePnPRansac" if ransac else "cv2.solvePnP"
    params = {"solver": solver, **({"threshold_px": RANSAC_THRESH_PX, "iterations": RANSAC_ITERATIONS} if ransac
                                   else {})}
    return SweepMethod(name, OPENCV, f"{call} SOLVEPNP_{solver.upper()}", params, fit)


METHODS = {m.name: m for m in [_method(s, r) for r in (False, True) for s in SOLVERS]}


def score(pose, trial, truth) -> dict:
    p, K = truth.cam_from_world[0], truth.K[0]
    keep = trial.inliers
    cam = Camera("pinhole", *truth.sizes[0], K[0, 0], K[1, 1], K[0, 2], K[1, 2], K[0, 1])
    R, t = (np.full((3, 3), np.nan), np.full(3, np.nan)) if pose is None else pose
    r = pnp_errors(R, t, p.R, p.t, cam=cam, points_world=truth.X[trial.rows][keep], pixels=trial.t[keep])
    rep = np.inf if r.reprojection is None else r.reprojection.rms_px
    return {"reproj_px": rep, "rot_err_deg": r.rot_err_deg, "trans_err_m": r.trans_abs_err_m,
            "failed": r.failed or not np.isfinite(rep),
            "failure_reason": "no pose" if r.failed else (None if np.isfinite(rep) else "a truth point does not "
                                                          "project at the estimated pose (behind the camera)")}


def _draw(truth, n, sigma, frac, seed, cell, trial):
    return draw_view_trial(truth.x[0], truth.sizes[0], n, sigma, frac, seed, cell, trial, STREAM)


KEY = "reproj_px"
PNP_KIND = SweepKind(
    "pnp", "absolute pose (PnP)", STREAM, "reprojection RMS of the inlier truth points at the estimated pose "
    "against their noise-free pixels, px", KEY, "px", (f"mean_{KEY}", f"std_{KEY}", f"median_trial_{KEY}"), 6, 2.0, 1,
    lambda ds, views, pool, obj=None: view_points(ds, views[0], pool, obj), _draw,
    lambda m, trial, truth, seed, wd: m.fit(trial, truth, seed, wd), score,
    lambda trials, b: summarise_scores(trials, b, KEY, ("rot_err_deg", "trans_err_m")),
    builtin_resolver("pnp", METHODS), lambda: list(METHODS), lambda truth: dict(truth.notes))

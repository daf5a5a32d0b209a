"""OpenCV absolute pose: ``solvePnP`` / ``solvePnPRansac`` with a chosen solver, given the truth
intrinsics (K and distortion of the view's camera, OpenCV models only), on two kinds of input:

* ``targets``: ChArUco / ArUco-grid corners detected in each view (``cv2.aruco``), matched by id
  to the board truth (scene/targets/<board>.json, world frame);
* ``points``: held-out truth 2D-3D pairs of each view (``points_at_pixels``, seeded), with
  N(0, POINT_SIGMA_PX^2) pixel noise and a fraction OUTLIER_FRACTION of the pixels replaced by
  uniform draws over the image (seeded).

Raw output: ``poses.json``, per input and view ``{rvec, tvec, R, t}`` (cam_from_world, OpenCV's
convention) or null on failure. Scores (recon_eval.metrics.pnp): rotation angle, translation and
camera-centre errors; a failure counts as inf. Headline: median over views; on ``targets`` also the
median reprojection RMS of the detected corners at the estimated pose (the truth camera model).
"""
from __future__ import annotations

import json

import cv2
import numpy as np

from recon_eval.errors import NotApplicable
from recon_eval.metrics.pnp import pnp_errors
from recon_eval.runners.common import RunOutput, out_path
from recon_eval.runners.detect import MARKER_BOARD_KINDS, detect_board_points
from scenegen.geometry.camera import camera_model

POINTS_PER_VIEW = 200
POINT_SIGMA_PX = 1.0
OUTLIER_FRACTION = 0.3
SEED = 0
#: RANSAC reprojection threshold, px: 3 sigma of the pixel noise.
RANSAC_THRESH_PX = 3.0 * POINT_SIGMA_PX


def _solver(name: str) -> int:
    return {"iterative": cv2.SOLVEPNP_ITERATIVE, "epnp": cv2.SOLVEPNP_EPNP, "sqpnp": cv2.SOLVEPNP_SQPNP,
            "ippe": cv2.SOLVEPNP_IPPE, "ap3p": cv2.SOLVEPNP_AP3P}[name]


def _solve(x, X, K, D, solver: str, ransac: bool):
    if len(x) < 4:
        return None
    try:
        if ransac:
            ok, rvec, tvec, _ = cv2.solvePnPRansac(X, x, K, D, flags=_solver(solver), iterationsCount=1000,
                                                  reprojectionError=RANSAC_THRESH_PX, confidence=0.999)
        else:
            ok, rvec, tvec = cv2.solvePnP(X, x, K, D, flags=_solver(solver))
    except cv2.error:
        return None
    return (rvec.ravel(), tvec.ravel()) if ok else None


def noisy_points(ds, view: str, cam, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """(pixels (N, 2) with N(0, POINT_SIGMA_PX^2) noise and OUTLIER_FRACTION uniform outliers,
    world points (N, 3)) of ``view``: the ``points`` input (module docstring), drawn from ``rng``."""
    uv, Xp = ds.points_at_pixels(view, max_points=POINTS_PER_VIEW, seed=SEED)
    uv = uv + rng.normal(0.0, POINT_SIGMA_PX, uv.shape)
    n_out = int(round(OUTLIER_FRACTION * len(uv)))
    uv[:n_out] = rng.uniform((0, 0), (cam.width - 1, cam.height - 1), (n_out, 2))
    return uv, Xp


def headline(errs: dict, out: RunOutput) -> None:
    """The headline of per-view errors ``errs[kind]`` = [(rot_err_deg, trans_err_m, failed,
    reprojection rms px)]: medians over the views and the failure ratio, ``<kind>.`` in front."""
    for kind, e in errs.items():
        if not e:
            continue
        a = np.asarray([(x[0], x[1]) for x in e], float)
        out.metrics[f"{kind}.median_rot_err_deg"] = float(np.median(a[:, 0]))
        out.metrics[f"{kind}.median_trans_err_m"] = float(np.median(a[:, 1]))
        out.metrics[f"{kind}.failure_ratio"] = float(np.mean([x[2] for x in e]))
        if kind == "targets":  # the detections' fit residual; on ``points`` the outliers would swamp it
            out.metrics[f"{kind}.median_reproj_rms_px"] = float(np.median([x[3] for x in e]))


def run(ds, out_dir, options) -> RunOutput:
    solver, ransac = options["solver"], options["ransac"]
    targets = {n: b for n, b in ds.boards().items() if b[0]["kind"] in MARKER_BOARD_KINDS}
    rng = np.random.default_rng(SEED)
    raw: dict = {"targets": {}, "points": {}}
    errs: dict = {"targets": [], "points": []}
    out = RunOutput()
    for v in ds.views:
        cam, pose = ds.camera(v)
        if camera_model(cam.model).opencv_fisheye:  # solvePnP takes OpenCV's perspective models only
            continue
        K, D = cam.to_opencv()
        inputs = {}
        for name, (geo, truth) in targets.items():
            x, X = detect_board_points(ds.image(v), geo, truth)
            if len(x) >= 4:
                inputs[("targets", f"{v}.{name}")] = (x, X)
        inputs[("points", v)] = noisy_points(ds, v, cam, rng)
        for (kind, key), (x, X) in inputs.items():
            s = _solve(x, X, K, D, solver, ransac)
            if s is None:
                raw[kind][key] = None
                r = pnp_errors(np.full((3, 3), np.nan), np.full(3, np.nan), pose.R, pose.t)
            else:
                R = cv2.Rodrigues(s[0])[0]
                raw[kind][key] = {"rvec": s[0].tolist(), "tvec": s[1].tolist(), "R": R.tolist(), "t": s[1].tolist()}
                r = pnp_errors(R, s[1], pose.R, pose.t, cam=cam, points_world=X, pixels=x)
            out.results[f"{kind}.{key}"] = r
            rep = r.reprojection.rms_px if r.reprojection is not None else float("inf")
            errs[kind].append((r.rot_err_deg, r.trans_abs_err_m, r.failed, rep))
    path = out_path(out_dir, "poses.json")
    path.write_text(json.dumps(raw, indent=1))
    out.raw_files.append("poses.json")
    headline(errs, out)
    out.notes.update({"points_per_view": POINTS_PER_VIEW, "sigma_px": POINT_SIGMA_PX,
                      "outlier_fraction": OUTLIER_FRACTION, "ransac_threshold_px": RANSAC_THRESH_PX if ransac else None,
                      "target_views": len(errs["targets"])})
    if not errs["points"]:
        raise NotApplicable(f"{ds.root}: no view with an OpenCV/pinhole camera")
    return out

"""OpenCV absolute pose: ``solvePnP`` / ``solvePnPRansac`` with a chosen solver, given the truth
intrinsics (K and distortion of the view's camera, OpenCV models only), on two kinds of input:

* ``targets``: ChArUco / ArUco-grid corners detected in each view (``cv2.aruco``), matched by id
  to the board truth (scene/targets/<board>.json, world frame);
* ``points``: held-out truth 2D-3D pairs of each view (``points_at_pixels``, seeded), with
  N(0, POINT_SIGMA_PX^2) pixel noise and a fraction OUTLIER_FRACTION of the pixels replaced by
  uniform draws over the image (seeded).

Raw output: ``poses.json``, per input and view ``{rvec, tvec, R, t}`` (cam_from_world, OpenCV's
convention) or null on failure. Scores (recon_eval.pnp): rotation angle, translation and
camera-centre errors; a failure counts as inf. Headline: median over views; on ``targets`` also the
median reprojection RMS of the detected corners at the estimated pose (the truth camera model).
"""
from __future__ import annotations

import json

import numpy as np

from recon_eval.runners._common import NotApplicable, RunOutput, boards, gray, out_path

POINTS_PER_VIEW = 200
POINT_SIGMA_PX = 1.0
OUTLIER_FRACTION = 0.3
SEED = 0
#: RANSAC reprojection threshold, px: 3 sigma of the pixel noise.
RANSAC_THRESH_PX = 3.0 * POINT_SIGMA_PX


def _solver(name: str) -> int:
    import cv2

    return {"iterative": cv2.SOLVEPNP_ITERATIVE, "epnp": cv2.SOLVEPNP_EPNP, "sqpnp": cv2.SOLVEPNP_SQPNP,
            "ippe": cv2.SOLVEPNP_IPPE, "ap3p": cv2.SOLVEPNP_AP3P}[name]


def _detect(ds, view, geo, truth):
    """(image points (N, 2), world points (N, 3)) of a ChArUco / ArUco board in one view."""
    import cv2

    d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, geo["dictionary"]))
    g = gray(ds.image(view))
    P = np.asarray(truth["points_world"], np.float64)
    ids_truth = {int(k): n for n, k in enumerate(truth["point_ids"])}
    if geo["kind"] == "charuco":
        board = cv2.aruco.CharucoBoard((int(geo["squares_x"]), int(geo["squares_y"])), float(geo["square_m"]),
                                       float(geo["marker_m"]), d)
        corners, ids, _, _ = cv2.aruco.CharucoDetector(board).detectBoard(g)
        if ids is None:
            return np.zeros((0, 2)), np.zeros((0, 3))
        idx = [ids_truth[int(i)] for i in ids.ravel()]
        return np.asarray(corners, np.float64).reshape(-1, 2), P[idx]
    corners, ids, _ = cv2.aruco.ArucoDetector(d).detectMarkers(g)
    if ids is None:
        return np.zeros((0, 2)), np.zeros((0, 3))
    x, X = [], []
    for c, mid in zip(corners, ids.ravel()):
        for k in range(4):  # aruco grid truth: id = marker_id * 4 + corner
            n = ids_truth.get(int(mid) * 4 + k)
            if n is not None:
                x.append(c.reshape(4, 2)[k])
                X.append(P[n])
    return np.asarray(x, np.float64).reshape(-1, 2), np.asarray(X, np.float64).reshape(-1, 3)


def _solve(x, X, K, D, solver: str, ransac: bool):
    import cv2

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


def run(ds, out_dir, options) -> RunOutput:
    import cv2

    from recon_eval.pnp import pnp_errors

    solver, ransac = options["solver"], options["ransac"]
    targets = {n: b for n, b in boards(ds).items() if b[0]["kind"] in ("charuco", "aruco_grid", "aruco")}
    rng = np.random.default_rng(SEED)
    raw: dict = {"targets": {}, "points": {}}
    errs: dict = {"targets": [], "points": []}
    out = RunOutput()
    for v in ds.views:
        cam, pose = ds.camera(v)
        if cam.model == "fisheye":
            continue
        K, D = cam.to_opencv()
        inputs = {}
        for name, (geo, truth) in targets.items():
            x, X = _detect(ds, v, geo, truth)
            if len(x) >= 4:
                inputs[("targets", f"{v}.{name}")] = (x, X)
        uv, Xp = ds.points_at_pixels(v, max_points=POINTS_PER_VIEW, seed=SEED)
        uv = uv + rng.normal(0.0, POINT_SIGMA_PX, uv.shape)
        n_out = int(round(OUTLIER_FRACTION * len(uv)))
        uv[:n_out] = rng.uniform((0, 0), (cam.width - 1, cam.height - 1), (n_out, 2))
        inputs[("points", v)] = (uv, Xp)
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
    for kind, e in errs.items():
        if not e:
            continue
        a = np.asarray([(x[0], x[1]) for x in e], float)
        out.metrics[f"{kind}.median_rot_err_deg"] = float(np.median(a[:, 0]))
        out.metrics[f"{kind}.median_trans_err_m"] = float(np.median(a[:, 1]))
        out.metrics[f"{kind}.failure_ratio"] = float(np.mean([x[2] for x in e]))
        if kind == "targets":  # the detections' fit residual; on ``points`` the outliers would swamp it
            out.metrics[f"{kind}.median_reproj_rms_px"] = float(np.median([x[3] for x in e]))
    out.notes.update({"points_per_view": POINTS_PER_VIEW, "sigma_px": POINT_SIGMA_PX,
                      "outlier_fraction": OUTLIER_FRACTION, "ransac_threshold_px": RANSAC_THRESH_PX if ransac else None,
                      "target_views": len(errs["targets"])})
    if not errs["points"]:
        raise NotApplicable(f"{ds.root}: no view with an OpenCV/pinhole camera")
    return out

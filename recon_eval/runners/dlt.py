"""The normalised linear DLT (:func:`recon_eval.metrics.dlt.dlt_projection`, H&Z Algorithm 7.1 without
the geometric refinement) per view, on two kinds of 2D-3D input:

* ``targets``: the marker / ChArUco corners detected in the view (``cv2.aruco``,
  :func:`recon_eval.runners.detect.detect_board_points`), matched by id to the board truth of
  every board; the DLT needs them on at least two
  planes (a 3D calibration object, scenes/dlt_calibration_object.yaml);
* ``points``: POINTS_PER_VIEW held-out truth 2D-3D pairs of the view (``points_at_pixels``,
  seeded) with N(0, POINT_SIGMA_PX^2) pixel noise per coordinate.

P is a pinhole camera: the pixels of a distorted camera are undistorted with the truth camera
model first (:func:`scenegen.geometry.twoview.undistorted_pixels`), as a user who knows the
distortion would. Raw output: ``P/<kind>/<view>.txt``, 3 rows of 4 numbers (all NaN when the DLT could not
run: fewer than 6 points, or coplanar ones). Scores (:func:`recon_eval.metrics.dlt.score_projection`, read
back from those files): K entries, rotation angle, camera-centre error, and the reprojection RMS of
HELD_OUT_POINTS other truth points (undistorted pixels); a failure counts as inf. Headline: the
median over views. NotApplicable when the dataset's board points are coplanar (or it has none).
"""
from __future__ import annotations

from typing import Callable

import numpy as np

from recon_eval.errors import NotApplicable
from recon_eval.metrics.dlt import dlt_projection, score_projection
from recon_eval.readers.rows import read_projection_matrix
from recon_eval.runners.common import RunOutput, out_path
from recon_eval.runners.detect import MARKER_BOARD_KINDS, detect_board_points
from recon_eval.tasks.board_truth import board_points, is_three_dimensional
from scenegen.geometry.twoview import undistorted_pixels

POINTS_PER_VIEW = 200
POINT_SIGMA_PX = 1.0
HELD_OUT_POINTS = 2000
SEED = 0
#: The DLT's minimum: 11 degrees of freedom, two equations per point.
MIN_POINTS = 6


def _write_P(out_dir, rel: str, P: np.ndarray, what: str) -> np.ndarray:
    """Write P as text, read it back (what is scored is what was written)."""
    p = out_path(out_dir, rel)
    np.savetxt(p, P, fmt="%.17g", header=f"3x4 camera matrix P (DLT on {what}); undistorted OpenCV pixels")
    return read_projection_matrix(p)


def _linear_fit(view: str, kind: str, x: np.ndarray, Xw: np.ndarray, out: RunOutput) -> np.ndarray:
    """The normalised linear DLT, or NaN below its minimum (MIN_POINTS, non-coplanar points)."""
    if len(x) >= MIN_POINTS and is_three_dimensional(Xw):
        return dlt_projection(Xw, x)
    return np.full((3, 4), np.nan)


def linear(ds, out_dir, options, *, estimate: Callable | None = None) -> RunOutput:
    """The DLT on every view's detected corners and noisy truth points (module docstring).
    ``estimate(view, kind, x (N, 2) undistorted px, X (N, 3) world m, out) -> P (3, 4)`` replaces it (an
    external estimator, :mod:`recon_eval.runners.external_views`; NaN: no estimate)."""
    all_points = np.asarray(list(board_points(ds).values())).reshape(-1, 3)
    if not is_three_dimensional(all_points):
        raise NotApplicable(f"{ds.root}: no non-coplanar board points (the DLT needs a 3D calibration object: "
                            f"boards on two or more planes)")
    targets = {n: b for n, b in ds.boards().items() if b[0]["kind"] in MARKER_BOARD_KINDS}
    rng = np.random.default_rng(SEED)
    out = RunOutput()
    per_kind: dict = {"targets": [], "points": []}
    detections = {}
    for v in ds.views:
        cam, pose = ds.camera(v)
        uv, X = ds.points_at_pixels(v, max_points=POINTS_PER_VIEW + HELD_OUT_POINTS, seed=SEED)
        uv = undistorted_pixels(cam, uv)
        split = np.random.default_rng(SEED).permutation(len(X))
        fit, held = split[:POINTS_PER_VIEW], split[POINTS_PER_VIEW:]
        xs, Xs, counts = [], [], {}
        for name, (geo, truth) in targets.items():
            x, Xb = detect_board_points(ds.image(v), geo, truth)
            counts[name] = int(len(x))
            xs.append(undistorted_pixels(cam, x))
            Xs.append(Xb)
        detections[v] = counts
        inputs = {"targets": (np.concatenate(xs or [np.zeros((0, 2))]), np.concatenate(Xs or [np.zeros((0, 3))])),
                  "points": (uv[fit] + rng.normal(0.0, POINT_SIGMA_PX, (len(fit), 2)), X[fit])}
        for kind, (x, Xw) in inputs.items():
            P = (estimate or _linear_fit)(v, kind, x, Xw, out)
            rel = f"P/{kind}/{v}.txt"
            what = "detected corners" if kind == "targets" else "noisy truth points"
            P = _write_P(out_dir, rel, P, f"{len(x)} {what}")
            out.raw_files.append(rel)
            s = score_projection(P, cam.K, pose, X[held], uv[held])
            out.results[f"{kind}.{v}"] = s
            per_kind[kind].append(s)
    for kind, scores in per_kind.items():
        def med(f):
            return float(np.median([getattr(s, f) for s in scores]))

        for f in ("fx_rel_err", "fy_rel_err", "cx_abs_err_px", "cy_abs_err_px", "rot_err_deg", "center_err_m",
                  "reproj_rms_px"):
            out.metrics[f"{kind}.median_{f}"] = med(f)
        out.metrics[f"{kind}.failure_ratio"] = float(np.mean([s.failed for s in scores]))
    out.notes.update({"detected_corners": detections, "points_per_view": POINTS_PER_VIEW,
                      "sigma_px": POINT_SIGMA_PX, "held_out_points": HELD_OUT_POINTS,
                      "undistorted_with_truth_model": sorted({ds.camera(v)[0].model for v in ds.views} - {"pinhole"})})
    return out

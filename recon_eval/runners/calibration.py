"""OpenCV camera calibration on the dataset's board views: ``cv2.calibrateCamera`` on
checkerboard corners (``findChessboardCorners`` + ``cornerSubPix``) or ChArUco corners
(``cv2.aruco.CharucoDetector``), and ``cv2.fisheye.calibrate`` on checkerboard corners.

Raw output: ``calibration_<camera>.yaml`` (cv2.FileStorage, the fields OpenCV's calibration sample
writes: image size, camera_matrix, distortion_coefficients, distortion_model, avg_reprojection_error,
per-view errors, flags). Scores (recon_eval.metrics.calibration, metrics.md "Calibration and PnP"):
fx/fy/cx/cy errors, the projection-difference field (intrinsics only, mrcal's
``intrinsics_only``), and the reprojection RMS of held-out truth points at the truth pose of the
first calibrated view.

Object points are the board truth of ``scene/targets/<board>.json`` (metres, board frame). A
checkerboard detection may come back in reverse order (the pattern is symmetric under a half turn
for the detector); that swaps the per-view extrinsics, never the intrinsics.
"""
from __future__ import annotations

from typing import Callable

import cv2
import numpy as np

from recon_eval.errors import NotApplicable
from recon_eval.metrics.calibration import intrinsics_errors, projection_difference, reprojection_rms
from recon_eval.readers.opencv_calib import read_opencv_calibration
from recon_eval.runners.common import RunOutput, out_path
from recon_eval.tasks.headlines import calibration_headline
from scenegen.geometry.camera import camera_model
from scenegen.geometry.color import to_grey8

#: cornerSubPix half window, px: a quarter of the smallest square the scene library shows
#: (~20 px at 480x360), so the window never reaches the next corner.
SUBPIX_HALF_WINDOW_PX = 5
#: cornerSubPix stop: 100 iterations or a 1e-4 px step (far below the 0.01 px level that matters).
SUBPIX_CRITERIA = (3, 100, 1e-4)  # cv2.TERM_CRITERIA_EPS + MAX_ITER
#: cornerSubPix half window on ChArUco corners, px: smaller than the checkerboard's, since the window
#: must stay inside the white ring between a chessboard corner and the neighbouring markers
#: ((square - marker) / 2 = 4 mm, ~5 px at calib_charuco's closest poses). Measured on calib_charuco
#: (16 views, 8 spp, OpenCV's default minMarkers): the detector's corners 0.082 px RMS against the
#: truth, refined 0.071 px; cy error of the calibration 0.64 px -> 0.39 px.
CHARUCO_SUBPIX_HALF_WINDOW_PX = 3
#: A ChArUco corner is interpolated when this many of its (up to 2) adjacent markers are found.
#: OpenCV's default 2 drops the outermost corners whenever a board runs off the image, which is
#: where the distortion is strongest: on calib_charuco, 1 keeps 47 of 48 corners in the corner views
#: (35 with 2) and takes the projection-difference RMS from 0.63 px to the figure in the tests.
CHARUCO_MIN_MARKERS = 1
#: Held-out truth points per calibration for the reprojection RMS.
HELD_OUT_POINTS = 5000


def _camera_groups(ds) -> dict:
    """spec camera name -> its complete views, in view order."""
    out: dict = {}
    for v in ds.views:
        out.setdefault(ds.view_info(v).get("camera_name"), []).append(v)
    return out


def _checkerboard_detections(ds, views, geo, truth):
    pattern = (int(geo["inner_cols"]), int(geo["inner_rows"]))
    obj = np.asarray(truth["points_board"], np.float64)
    used, objs, imgs = [], [], []
    for v in views:
        g = to_grey8(ds.image(v))
        ok, c = cv2.findChessboardCorners(g, pattern, cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE)
        if not ok:
            continue
        w = SUBPIX_HALF_WINDOW_PX
        c = cv2.cornerSubPix(g, c, (w, w), (-1, -1), SUBPIX_CRITERIA)
        used.append(v)
        objs.append(obj.astype(np.float32).reshape(-1, 1, 3))
        imgs.append(c.astype(np.float32).reshape(-1, 1, 2))
    return used, objs, imgs


def _charuco_detections(ds, views, geo, truth):
    d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, geo["dictionary"]))
    board = cv2.aruco.CharucoBoard((int(geo["squares_x"]), int(geo["squares_y"])), float(geo["square_m"]),
                                   float(geo["marker_m"]), d)
    board.setLegacyPattern(bool(geo.get("legacy_pattern", False)))  # the spec's ChArUco layout
    params = cv2.aruco.CharucoParameters()
    params.minMarkers = CHARUCO_MIN_MARKERS
    det = cv2.aruco.CharucoDetector(board, params)
    pts = np.asarray(truth["points_board"], np.float64)
    ids_truth = list(truth["point_ids"])
    used, objs, imgs = [], [], []
    for v in views:
        g = to_grey8(ds.image(v))
        corners, ids, _, _ = det.detectBoard(g)
        if ids is None or len(ids) < 6:  # calibrateCamera needs >= 4 non-collinear; 6 for a stable view
            continue
        w = CHARUCO_SUBPIX_HALF_WINDOW_PX
        corners = cv2.cornerSubPix(g, np.asarray(corners, np.float32).reshape(-1, 1, 2), (w, w), (-1, -1),
                                   SUBPIX_CRITERIA)
        idx = [ids_truth.index(int(i)) for i in ids.ravel()]
        used.append(v)
        objs.append(pts[idx].astype(np.float32).reshape(-1, 1, 3))
        imgs.append(np.asarray(corners, np.float32).reshape(-1, 1, 2))
    return used, objs, imgs


def _write_yaml(path, width, height, K, D, model, rms, per_view, views, flags, board_name):
    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
    fs.write("image_width", int(width))
    fs.write("image_height", int(height))
    fs.write("camera_matrix", np.asarray(K, np.float64))
    fs.write("distortion_coefficients", np.asarray(D, np.float64).reshape(1, -1))
    fs.write("distortion_model", "equidistant" if camera_model(model).opencv_fisheye else "plumb_bob")
    fs.write("avg_reprojection_error", float(rms))
    fs.write("per_view_reprojection_errors", np.asarray(per_view, np.float64).reshape(-1, 1))
    fs.write("nr_of_frames", len(views))
    fs.write("flags", int(flags))
    fs.write("board", board_name)
    fs.release()


def score_calibration(ds, out: RunOutput, key: str, pre: str, yaml_path, views_used, views_all, rms) -> None:
    """Score the calibration file ``yaml_path`` of the camera whose views are ``views_all`` into
    ``out`` (module docstring; the held-out points of the first of ``views_used``). ``rms``: the
    calibration's own RMS, None when unknown (an external method): then ``calib_rms_px`` and
    ``views_used_ratio`` are not reported."""
    est = read_opencv_calibration(yaml_path)  # score what was written
    gt, pose = ds.camera(views_used[0])
    uv, X = ds.points_at_pixels(views_used[0], max_points=HELD_OUT_POINTS)
    ie = intrinsics_errors(est.K, gt.K)
    pdiff = projection_difference(gt, est)
    rep = reprojection_rms(est, pose.R, pose.t, X, uv)
    out.results[f"{key}.intrinsics"] = ie
    out.results[f"{key}.projection_diff"] = pdiff
    out.results[f"{key}.reprojection_held_out"] = rep
    m = out.metrics
    m.update(calibration_headline(ie, pdiff, rep, pre))
    if rms is not None:
        m[pre + "calib_rms_px"] = float(rms)
        m[pre + "views_used_ratio"] = len(views_used) / len(views_all)


def calibrate(ds, out_dir, *, board_kind: str, fisheye: bool,
              transform_K: Callable[[np.ndarray], np.ndarray] | None = None) -> RunOutput:
    """Calibrate every spec camera of the dataset's ``fisheye`` family (wide-angle models: the
    cv2.fisheye model) on the first ``board_kind`` board (module docstring). ``transform_K`` maps
    the estimated camera matrix before it is written (only :mod:`recon_eval.runners.faults` sets it)."""
    bs = {n: b for n, b in ds.boards().items() if b[0]["kind"] == board_kind}
    if not bs:
        raise NotApplicable(f"{ds.root}: the scene has no {board_kind} board")
    board_name, (geo, truth) = next(iter(bs.items()))
    out = RunOutput()
    out.notes["board"] = board_name
    groups = _camera_groups(ds)
    for cam_name, views in groups.items():
        pre = "" if len(groups) == 1 else f"{cam_name}."  # metric names carry the camera when several
        cam0, _ = ds.camera(views[0])
        if fisheye != camera_model(cam0.model).opencv_fisheye:
            continue
        detect = _checkerboard_detections if board_kind == "checkerboard" else _charuco_detections
        used, objs, imgs = detect(ds, views, geo, truth)
        size = (cam0.width, cam0.height)
        if len(used) < 3:
            out.notes[f"{cam_name}.failed"] = f"board found in {len(used)} of {len(views)} views (< 3)"
            out.metrics[pre + "views_used_ratio"] = len(used) / len(views)
            continue
        if fisheye:
            flags = cv2.fisheye.CALIB_RECOMPUTE_EXTRINSIC | cv2.fisheye.CALIB_FIX_SKEW
            crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 200, 1e-12)
            rms, K, D, rv, tv = cv2.fisheye.calibrate([o.reshape(1, -1, 3).astype(np.float64) for o in objs],
                                                      [i.reshape(1, -1, 2).astype(np.float64) for i in imgs],
                                                      size, None, None, flags=flags, criteria=crit)
            per_view = []
            for o, i, r, t in zip(objs, imgs, rv, tv):
                p, _ = cv2.fisheye.projectPoints(o.reshape(1, -1, 3).astype(np.float64), r, t, K, D)
                per_view.append(float(np.sqrt(np.mean(np.sum((p.reshape(-1, 2) - i.reshape(-1, 2)) ** 2, 1)))))
        else:
            flags = 0
            crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 200, 1e-12)
            rms, K, D, rv, tv, _, _, per_view = cv2.calibrateCameraExtended(objs, imgs, size, None, None,
                                                                           flags=flags, criteria=crit)
        K = np.array(K, np.float64)
        if transform_K is not None:
            K = transform_K(K)
        path = out_path(out_dir, f"calibration_{cam_name}.yaml")
        _write_yaml(path, *size, K, D, "fisheye" if fisheye else "opencv", rms, per_view, used, flags, board_name)
        out.raw_files.append(path.name)
        out.notes[f"{cam_name}.views_used"] = used
        score_calibration(ds, out, cam_name, pre, path, used, views, rms)
    if not out.raw_files and not out.metrics:
        raise NotApplicable(f"{ds.root}: no {'fisheye' if fisheye else 'OpenCV/pinhole'} camera sees the {board_kind} board")
    return out


def checkerboard(ds, out_dir, options=None) -> RunOutput:
    return calibrate(ds, out_dir, board_kind="checkerboard", fisheye=False)


def charuco(ds, out_dir, options=None) -> RunOutput:
    return calibrate(ds, out_dir, board_kind="charuco", fisheye=False)


def fisheye(ds, out_dir, options=None) -> RunOutput:
    return calibrate(ds, out_dir, board_kind="checkerboard", fisheye=True)

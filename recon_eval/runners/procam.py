"""Projector-camera calibration (Moreno and Taubin, 3DIMPVT 2012) on a dataset's projector-lit
views of a checkerboard (``scenes/sl_procam_calibration.yaml``).

Per pose: the checkerboard's corners in the white-lit image (``findChessboardCorners`` +
``cornerSubPix``), the Gray codes decoded as :mod:`recon_eval.runners.structured_light` does, and
each corner carried into the projector by a local homography of the decoded pixels around it
(:mod:`recon_eval.estimators.structured_light.homography`). Then ``cv2.calibrateCamera`` for the
camera and for the projector (k1 k2 p1 p2, k3 fixed), the projector's refined with a skew term
(``fit_skew``, :mod:`recon_eval.estimators.structured_light.skew`: OpenCV fits none), and
``cv2.stereoCalibrate`` with both intrinsics fixed for ``proj_from_cam`` (it projects without the
skew, so its extrinsics carry the skew's small residual).

Raw output: ``calibration_camera.yaml``, ``calibration_projector.yaml`` (cv2.FileStorage, as
OpenCV's calibration sample writes them) and ``stereo.yaml`` (R, T: projector from camera);
read back and scored: intrinsics errors and the projection difference over each image
(:func:`recon_eval.metrics.calibration.projection_difference`, intrinsics only and with the
rotation a principal-point error trades against fitted, as ``recon-eval calibration``), the projector
corners against the truth corners projected through the truth projector, and the stereo
rotation (deg) and translation (mm) errors.
"""
from __future__ import annotations

import cv2
import numpy as np

from recon_eval.errors import NotApplicable
from recon_eval.estimators.structured_light.homography import corners_in_projector
from recon_eval.estimators.structured_light.skew import refine_with_skew
from recon_eval.metrics.calibration import intrinsics_errors, projection_difference
from recon_eval.readers.opencv_calib import read_opencv_calibration, write_opencv_calibration
from recon_eval.readers.structured_light import projector_views
from recon_eval.runners.common import RunOutput, out_path
from recon_eval.runners.structured_light import decode_gray_view
from recon_eval.tasks.headlines import calibration_headline
from scenegen.geometry.camera import Camera
from scenegen.geometry.color import srgb_from_linear
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.rotation import rotation_angle_rad

SUBPIX_CRITERIA = (3, 100, 1e-4)  # cv2.TERM_CRITERIA_EPS + MAX_ITER: 100 iterations or 1e-4 px
#: k1 k2 p1 p2 (k3 fixed at 0: 8 poses of a 9 x 6 board leave it free to swing the image edges by
#: pixels, 2.1 px RMS projection difference with it free on sl_procam_calibration), fx != fy, principal point free
FLAGS = cv2.CALIB_FIX_K3


def _board(ds):
    boards = [(g, t) for g, t in ds.boards().values() if g.get("kind") == "checkerboard"]
    if not boards:
        raise NotApplicable(f"{ds.root}: no checkerboard (projector calibration needs one)")
    return boards[0]


def _detect(image_linear, pattern, half_window_px):
    g = np.round(255.0 * srgb_from_linear(image_linear)).astype(np.uint8)
    ok, c = cv2.findChessboardCorners(g, pattern, cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE)
    if not ok:
        return None
    return cv2.cornerSubPix(g, c, (half_window_px, half_window_px), (-1, -1), SUBPIX_CRITERIA).reshape(-1, 2)


def run(ds, out_dir, options) -> RunOutput:
    geo, truth = _board(ds)
    pattern = (int(geo["inner_cols"]), int(geo["inner_rows"]))
    obj = np.asarray(truth["points_board"], np.float64)
    hw = int(options.get("half_window_px", 14))
    views = projector_views(ds.root, source=str(options.get("source", "png")))
    used, objs, cam_pts, proj_pts, corner_err = [], [], [], [], []
    for pv in views:
        white = next(i for i, f in enumerate(pv.frames) if f.kind == "white")
        c = _detect(pv.images[white], pattern, int(options.get("subpix_half_window_px", 4)))
        if c is None:
            continue
        codes = decode_gray_view(pv, float(options.get("threshold", 0.1)), float(options.get("min_contrast", 0.005)))
        p, ok = corners_in_projector(c, codes, half_window_px=hw)
        if ok.sum() < 6:
            continue
        used.append(pv.view)
        objs.append(obj[ok].astype(np.float32).reshape(-1, 1, 3))
        cam_pts.append(c[ok].astype(np.float32).reshape(-1, 1, 2))
        proj_pts.append(p[ok].astype(np.float32).reshape(-1, 1, 2))
        # the truth: the corners' world points (scene/targets) through the truth projector
        pw = np.asarray(truth["points_world"], np.float64)[ok]
        corner_err.append(np.linalg.norm(pv.projector.project(pv.projector_from_world.apply(pw)) - p[ok], axis=1))
    if len(used) < 3:
        raise NotApplicable(f"{ds.root}: the board was found and decoded in {len(used)} views; calibration needs 3")
    pv0 = views[0]
    cam_size = (pv0.camera.width, pv0.camera.height)
    proj_size = (pv0.projector.width, pv0.projector.height)
    rms_c, Kc, Dc, _, _ = cv2.calibrateCamera(objs, cam_pts, cam_size, None, None, flags=FLAGS)
    rms_p, Kp, Dp, rv, tv = cv2.calibrateCamera(objs, proj_pts, proj_size, None, None, flags=FLAGS)
    if bool(options.get("fit_skew", True)):
        refined = refine_with_skew(objs, proj_pts, Kp, Dp, rv, tv)
        Kp, Dp, rms_p = refined.K, refined.dist.reshape(1, -1), refined.rms_px
    rms_s, _, _, _, _, R, T, _, _ = cv2.stereoCalibrate(objs, cam_pts, proj_pts, Kc, Dc, Kp, Dp, cam_size,
                                                        flags=cv2.CALIB_FIX_INTRINSIC)
    est = {"camera": Camera.from_opencv(Kc, Dc.ravel(), cam_size), "projector": Camera.from_opencv(Kp, Dp.ravel(), proj_size)}
    raw = []
    for name, cam in est.items():
        write_opencv_calibration(out_path(out_dir, f"calibration_{name}.yaml"), cam)
        raw.append(f"calibration_{name}.yaml")
    fs = cv2.FileStorage(str(out_path(out_dir, "stereo.yaml")), cv2.FILE_STORAGE_WRITE)
    fs.write("R", np.asarray(R, np.float64))
    fs.write("T", np.asarray(T, np.float64).reshape(3, 1))
    fs.write("rms", float(rms_s))
    fs.release()
    raw.append("stereo.yaml")
    back = {n: read_opencv_calibration(out_path(out_dir, f"calibration_{n}.yaml")) for n in est}
    fs = cv2.FileStorage(str(out_path(out_dir, "stereo.yaml")), cv2.FILE_STORAGE_READ)
    proj_from_cam = Rigid3(fs.getNode("R").mat(), fs.getNode("T").mat().ravel())
    fs.release()
    truth_cams = {"camera": pv0.camera, "projector": pv0.projector}
    results, metrics = {}, {}
    for n in est:
        ie = intrinsics_errors(back[n].K, truth_cams[n].K)
        pd = projection_difference(truth_cams[n], back[n])
        pdr = projection_difference(truth_cams[n], back[n], fit_rotation=True)
        results[f"{n}.intrinsics"], results[f"{n}.projection_diff"] = ie, pd
        results[f"{n}.projection_diff_rotation_fitted"] = pdr
        metrics.update(calibration_headline(ie, pd, prefix=f"{n}."))
        metrics[f"{n}.proj_diff_rot_rms_px"] = pdr.rms_px
    truth_pc = pv0.projector_from_world @ pv0.cam_from_world.inverse()
    d = proj_from_cam @ truth_pc.inverse()
    err = np.concatenate(corner_err)
    results["stereo"] = {"rot_err_deg": float(np.degrees(rotation_angle_rad(d.R))),
                         "trans_err_mm": 1e3 * float(np.linalg.norm(proj_from_cam.t - truth_pc.t)),
                         "rms_px": float(rms_s)}
    results["projector_corners"] = {"rms_px": float(np.sqrt(np.mean(err ** 2))), "max_px": float(err.max()),
                                    "n": int(err.size)}
    metrics.update({"stereo.rot_err_deg": results["stereo"]["rot_err_deg"],
                    "stereo.trans_err_mm": results["stereo"]["trans_err_mm"],
                    "projector_corner_rms_px": results["projector_corners"]["rms_px"],
                    "camera.calib_rms_px": float(rms_c), "projector.calib_rms_px": float(rms_p)})
    notes = {"views_used": used, "views": [pv.view for pv in views], "half_window_px": hw,
             "fit_skew": bool(options.get("fit_skew", True))}
    return RunOutput(results, metrics, raw, notes)

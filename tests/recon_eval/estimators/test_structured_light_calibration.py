"""Projector calibration from synthetic board corners: each camera pixel's code is the projector
pixel of its ray's hit on the board plane (closed form, the projector's own model), the corners
are carried into the projector by local homographies (Moreno and Taubin), then calibrateCamera."""
import functools

import cv2
import numpy as np

from recon_eval.estimators.structured_light.homography import corners_in_projector
from recon_eval.estimators.structured_light.skew import refine_with_skew
from recon_eval.metrics.calibration import projection_difference
from scenegen.geometry.camera import Camera
from scenegen.geometry.conventions import pixel_centers
from scenegen.geometry.pose import Rigid3, look_at
from scenegen.geometry.sl_codes import pixel_index

CAMERA = Camera("opencv", 320, 240, 420.0, 421.0, 161.3, 118.6, dist=(-0.12, 0.05, 0.0004, -0.0003, 0.0))
PROJECTOR = Camera("opencv", 256, 192, 300.0, 302.0, 129.4, 150.2, skew=0.4, dist=(-0.08, 0.03, 0.0005, -0.0004, 0.0))
# projector from camera: 0.12 m to the right, turned toward the camera's axis
PROJ_FROM_CAM = Rigid3.from_rotvec(np.radians([9.0, 12.0, 0.0]), [-0.12, 0.0, 0.02])
BOARD = np.array([[0.03 * i - 0.12, 0.03 * j - 0.075, 0.0] for j in range(6) for i in range(9)])  # board frame
# The calibration amplifies corner noise ~10x at these 8 poses (the scene's first 8 eyes, all
# looking at the board's centre with one up vector): corner RMS 0.026,
# 0.020, 0.015, 0.011, 0.008 px at half windows 6, 8, 10, 14, 22 px gave intrinsics-only
# projection differences of 0.28, 0.34, 0.13, 0.11, 0.03 px RMS (rotation fitted: 0.07, 0.05,
# 0.10, 0.02, 0.01); a window of 29 x 29 px spans more than a square of the board, still one
# plane, so its homography holds up to the distortion's curvature.
HALF_WINDOW_PX = 14
EYES = [(0.0, 0.0, 0.54), (0.15, 0.06, 0.51), (-0.15, 0.06, 0.51), (0.03, 0.18, 0.49), (0.03, -0.18, 0.49),
        (0.21, -0.12, 0.48), (-0.21, 0.12, 0.48), (-0.08, -0.08, 0.60)]


@functools.cache
def _camera_rays() -> np.ndarray:
    return CAMERA.unproject_unit(pixel_centers(CAMERA.width, CAMERA.height).reshape(-1, 2))


def _pose_codes(cam_from_board: Rigid3):
    """(H, W, 2) integer codes of the board plane (z = 0 of the board frame) and the camera corners."""
    proj_from_board = PROJ_FROM_CAM @ cam_from_board
    d = _camera_rays()
    board_from_cam = cam_from_board.inverse()
    o, db = board_from_cam.t, board_from_cam.rotate(d)
    t = -o[2] / db[:, 2]
    hit = o + t[:, None] * db
    uv = PROJECTOR.project(proj_from_board.apply(hit))
    codes = np.stack([pixel_index(uv[:, 0], PROJECTOR.width), pixel_index(uv[:, 1], PROJECTOR.height)], axis=1)
    codes = np.where(codes >= 0, codes, np.nan).reshape(CAMERA.height, CAMERA.width, 2)
    corners_cam = CAMERA.project(cam_from_board.apply(BOARD))
    corners_proj = PROJECTOR.project(proj_from_board.apply(BOARD))
    return codes, corners_cam, corners_proj


def test_local_homographies_calibrate_the_projector():
    objs, proj_pts, errs = [], [], []
    for eye in EYES:
        cam_from_board = look_at(eye, (0.0, 0.0, 0.0), up=(0.0, -1.0, 0.0)).inverse()
        codes, c_cam, c_proj = _pose_codes(cam_from_board)
        p, ok = corners_in_projector(c_cam, codes, half_window_px=HALF_WINDOW_PX)
        assert ok.all()
        errs.append(np.linalg.norm(p - c_proj, axis=1))
        objs.append(BOARD.astype(np.float32).reshape(-1, 1, 3))
        proj_pts.append(p.astype(np.float32).reshape(-1, 1, 2))
    err = np.concatenate(errs)
    # integer codes (a projector pixel's quantisation, RMS 0.29 px per axis) averaged over ~400
    # pixels: the corners land within a few hundredths of a projector pixel
    assert np.sqrt(np.mean(err ** 2)) < 0.05
    size = (PROJECTOR.width, PROJECTOR.height)
    _, K, D, rv, tv = cv2.calibrateCamera(objs, proj_pts, size, None, None,
                                          flags=cv2.CALIB_FIX_K3)  # 8 poses do not pin k3 down at the edges
    no_skew = projection_difference(PROJECTOR, Camera.from_opencv(K, D.ravel(), size), fit_rotation=True).rms_px
    s = refine_with_skew(objs, proj_pts, K, D, rv, tv)
    est = Camera.from_opencv(s.K, s.dist, size)
    # OpenCV's model has no skew: the projector's 0.4 px costs 0.24 px; refined with one, 0.02 px
    # once the rotation a principal-point error trades against is fitted (mrcal's projection_diff);
    # intrinsics only, 0.11 px (8 poses leave cx and the extrinsics' rotation entangled)
    assert no_skew > 0.15 and projection_difference(PROJECTOR, est, fit_rotation=True).rms_px < 0.05
    assert projection_difference(PROJECTOR, est).rms_px < 0.15 and abs(s.K[0, 1] - 0.4) < 0.05


def test_skew_refinement_is_exact_on_exact_corners():
    objs, pts = [], []
    for eye in EYES:
        cam_from_board = look_at(eye, (0.0, 0.0, 0.0), up=(0.0, -1.0, 0.0)).inverse()
        objs.append(BOARD.astype(np.float32).reshape(-1, 1, 3))
        pts.append(PROJECTOR.project((PROJ_FROM_CAM @ cam_from_board).apply(BOARD)).astype(np.float32).reshape(-1, 1, 2))
    size = (PROJECTOR.width, PROJECTOR.height)
    _, K, D, rv, tv = cv2.calibrateCamera(objs, pts, size, None, None, flags=cv2.CALIB_FIX_K3)
    s = refine_with_skew(objs, pts, K, D, rv, tv)
    # float32 corners (~1e-5 px) bound what the fit can reach
    assert projection_difference(PROJECTOR, Camera.from_opencv(s.K, s.dist, size)).rms_px < 1e-3

"""Bouguet rectification vs cv2.stereoRectify and rectification maps vs
cv2.initUndistortRectifyMap, on planted distorted stereo pairs."""
import cv2
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from scenegen.geometry.camera import Camera
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.rectify import disparity_from_depth, rectification_map, rectify

# R1, R2: the same closed-form arithmetic as OpenCV (Rodrigues in scipy vs OpenCV), ~1e-16.
TOL_ROT = 1e-12
# Principal point of the rectified camera vs OpenCV: OpenCV undistorts the image corners with
# cv2.undistortPoints' fixed-iteration loop, which stops short of the exact inverse we use
# (measured 8e-7 .. 3.4e-6 px on these distortions); 1e-4 px leaves margin for stronger ones.
TOL_PRINCIPAL_PX = 1e-4
# Rectification maps vs cv2.initUndistortRectifyMap: OpenCV stores float32 (half an ulp at
# 320 px is 1.5e-5 px, exactly what is measured).
TOL_MAP_PX = 1e-4
CAM_L = Camera("opencv", 320, 240, 300.0, 301.0, 159.5, 119.2, 0.0, (-0.05, 0.01, 0.0, 0.0, 0.0))
CAM_R = Camera("opencv", 320, 240, 302.0, 300.0, 161.0, 118.0, 0.0, (-0.04, 0.008, 0.0002, -0.0001, 0.0))


def _pair(rotvec, T):
    pose_l = Rigid3(Rotation.from_rotvec([0.1, -0.2, 0.05]).as_matrix(), [0.3, -0.1, 2.0])
    right_from_left = Rigid3(Rotation.from_rotvec(rotvec).as_matrix(), T)
    return pose_l, right_from_left @ pose_l, right_from_left


@pytest.mark.parametrize("rotvec,T", [([0.01, -0.035, 0.004], [-0.12, 0.002, 0.001]),
                                      ([0.0, 0.0349, 0.0], [-0.2, 0.0, 0.0]),
                                      ([-0.02, 0.01, 0.03], [-0.08, -0.01, 0.02])])
def test_rectification_agrees_with_cv2_stereo_rectify(rotvec, T):
    pose_l, pose_r, rfl = _pair(rotvec, T)
    rect = rectify(CAM_L, pose_l, CAM_R, pose_r)
    (K1, D1), (K2, D2) = CAM_L.to_opencv(), CAM_R.to_opencv()
    R1, R2, P1, P2, Q, _, _ = cv2.stereoRectify(K1, D1, K2, D2, (320, 240), rfl.R, rfl.t,
                                                 flags=cv2.CALIB_ZERO_DISPARITY, alpha=-1,
                                                 newImageSize=(320, 240))
    assert np.abs(rect.R1 - R1).max() < TOL_ROT and np.abs(rect.R2 - R2).max() < TOL_ROT
    assert rect.f == pytest.approx(P1[0, 0], abs=1e-9)
    assert np.abs(rect.P1[:2, 2] - P1[:2, 2]).max() < TOL_PRINCIPAL_PX
    assert rect.P2[0, 3] == pytest.approx(P2[0, 3], rel=1e-9, abs=1e-9 * rect.f)
    assert rect.Q[2, 3] == pytest.approx(Q[2, 3], rel=1e-12) and rect.Q[3, 2] == pytest.approx(Q[3, 2], rel=1e-9)
    assert abs(rect.Q[3, 3] - Q[3, 3]) < 1e-9 and np.abs(rect.Q[:2, 3] - Q[:2, 3]).max() < TOL_PRINCIPAL_PX
    # the rectified cameras are parallel: right = left translated by (+B, 0, 0)
    rel = rect.cam_right_from_world @ rect.cam_left_from_world.inverse()
    assert np.allclose(rel.R, np.eye(3), atol=1e-12)
    assert np.allclose(rel.t, [-rect.baseline_m, 0, 0], atol=1e-12)
    # the maps are OpenCV's initUndistortRectifyMap
    for cam, R, P, mine in ((CAM_L, R1, P1, rect.R1), (CAM_R, R2, P2, rect.R2)):
        K, D = cam.to_opencv()
        mx, my = cv2.initUndistortRectifyMap(K, D, R, rect.camera.K, (320, 240), cv2.CV_32FC1)
        ours = rectification_map(cam, mine, rect.camera)
        assert np.abs(ours[..., 0] - mx).max() < TOL_MAP_PX and np.abs(ours[..., 1] - my).max() < TOL_MAP_PX


def test_disparity_from_depth():
    """d = f B / Z; +inf where the depth is not finite or not positive."""
    d = disparity_from_depth(np.array([[2.0, np.inf], [0.0, -1.0]]), 300.0, 0.12)
    assert d[0, 0] == 300.0 * 0.12 / 2.0 and np.isinf(d[0, 1]) and np.isinf(d[1]).all()

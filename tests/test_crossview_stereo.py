"""Rectified stereo truth: Bouguet rectification vs cv2.stereoRectify, rectification maps vs
cv2.initUndistortRectifyMap, exact disparity vs the rectified correspondences, and OpenCV's
StereoSGBM on the rendered rectified pair against the truth."""
import cv2
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from _crossview_data import rendered
from scenegen import io as sio
from scenegen.camera import Camera
from scenegen.crossview import correspondence as cc
from scenegen.crossview.disparity import decode_kitti, decode_pfm
from scenegen.crossview.rectify import rectification_map, rectify
from scenegen.dataset import Dataset
from scenegen.pose import Rigid3

# R1, R2: the same closed-form arithmetic as OpenCV (Rodrigues in scipy vs OpenCV), ~1e-16.
TOL_ROT = 1e-12
# Principal point of the rectified camera vs OpenCV: OpenCV undistorts the image corners with
# cv2.undistortPoints' fixed-iteration loop, which stops short of the exact inverse we use
# (measured 8e-7 .. 3.4e-6 px on these distortions); 1e-4 px leaves margin for stronger ones.
TOL_PRINCIPAL_PX = 1e-4
# Rectification maps vs cv2.initUndistortRectifyMap: OpenCV stores float32 (half an ulp at
# 320 px is 1.5e-5 px, exactly what is measured).
TOL_MAP_PX = 1e-4
# Stored (float32) rectified correspondences vs f B / Z: float32 rounding of u (~1e-5 px).
TOL_DISP_PX = 1e-4
# The bound on StereoSGBM's median (signed) disparity error on non-occluded pixels.
TOL_SGBM_MEDIAN_PX = 0.25

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


@pytest.fixture(scope="module")
def ds(tmp_path_factory):
    return Dataset(rendered(tmp_path_factory)[1])


def frames(ds):
    return sio.read_json(ds.path("crossview/index.json"))["stereo"]


def test_rectified_truth_is_row_aligned_and_exact(ds):
    assert len(frames(ds)) == 2
    for fr in frames(ds):
        base = fr["dir"]
        calib = sio.read_json(ds.path(f"{base}/calib.json"))
        for side, sign in (("left", 1.0), ("right", -1.0)):
            c = cc.decode_correspondence(sio.read_exr(ds.path(f"{base}/corr_{side}.exr")))
            d = decode_pfm(ds.path(f"{base}/disp_{side}.pfm").read_bytes())
            H, W = d.shape
            vv, uu = np.nonzero(c.visible)
            # epipolar lines are rows, and d = u_left - u_right = f B / Z exactly
            assert np.abs(c.uv[vv, uu, 1] - vv).max() < TOL_DISP_PX
            assert np.abs(sign * (uu - c.uv[vv, uu, 0]) - d[vv, uu]).max() < TOL_DISP_PX
            assert (d[np.isfinite(d)] > 0).all()
            noc, noc_ok = decode_kitti(sio.read_png(ds.path(f"{base}/disp_{side}_noc.png")))
            occ, occ_ok = decode_kitti(sio.read_png(ds.path(f"{base}/disp_{side}_occ.png")))
            assert np.array_equal(noc_ok, c.visible) and np.array_equal(occ_ok, np.isfinite(d))
            assert np.abs(occ[occ_ok] - d[occ_ok]).max() <= 0.5 / 256 + 1e-6
            assert (occ_ok & ~noc_ok).sum() > 0  # occluded pixels exist (the sphere, the borders)
        assert calib["baseline_m"] == pytest.approx(0.12, abs=1e-12)


def test_sgbm_agrees_with_truth(ds):
    errs = []
    for fr in frames(ds):
        base = fr["dir"]
        L = cv2.imread(str(ds.path(f"{base}/left.png")), cv2.IMREAD_GRAYSCALE)
        R = cv2.imread(str(ds.path(f"{base}/right.png")), cv2.IMREAD_GRAYSCALE)
        sgbm = cv2.StereoSGBM_create(minDisparity=0, numDisparities=32, blockSize=5, P1=8 * 25, P2=32 * 25,
                                     uniquenessRatio=5, mode=cv2.STEREO_SGBM_MODE_HH)
        est = sgbm.compute(L, R).astype(np.float64) / 16.0
        truth, noc = decode_kitti(sio.read_png(ds.path(f"{base}/disp_left_noc.png")))
        d = decode_pfm(ds.path(f"{base}/disp_left.pfm").read_bytes())
        ok = noc & (est > 0)
        assert ok.sum() > 0.5 * noc.sum()
        errs.append(est[ok] - d[ok])
    e = np.concatenate(errs)
    med = float(np.median(e))
    print(f"StereoSGBM - truth on non-occluded pixels: median {med:+.3f} px, median |e| "
          f"{np.median(np.abs(e)):.3f} px over {e.size} px")
    assert abs(med) < TOL_SGBM_MEDIAN_PX


def test_rectification_maps_resample_raw_to_rectified(ds):
    """Remapping the raw left image with the stored map reproduces the directly rendered
    rectified image (up to resampling blur and render noise)."""
    fr = frames(ds)[0]
    base = fr["dir"]
    raw = ds.linear_image(fr["left_view"])
    m = sio.read_exr(ds.path(f"{base}/map_left.exr"))
    warped = cv2.remap(raw, m["map_x"], m["map_y"], cv2.INTER_LINEAR, borderValue=np.nan)
    rect = sio.unpack_channels(sio.read_exr(ds.path(f"{base}/left_linear.exr")), "", "RGB")
    shifted_img = np.roll(warped, 1, axis=1)
    ok = np.isfinite(warped).all(-1) & np.isfinite(shifted_img).all(-1)
    diff = np.abs(warped - rect)[ok].mean()
    shifted = np.abs(shifted_img - rect)[ok].mean()
    assert diff < 0.5 * shifted, (diff, shifted)

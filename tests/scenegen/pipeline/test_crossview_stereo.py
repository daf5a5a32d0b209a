"""Rectified stereo truth of a rendered dataset: exact disparity vs the rectified
correspondences, maps that resample the raw image, and OpenCV's StereoSGBM against the truth."""
import cv2
import numpy as np
import pytest

from scenegen.dataset import Dataset, codecs as sio
from scenegen.dataset.codecs import decode_pfm, disparity_from_kitti_array as decode_kitti
from scenegen.dataset.crossview import decode_correspondence_channels

# Stored (float32) rectified correspondences vs f B / Z: float32 rounding of u (~1e-5 px).
TOL_DISP_PX = 1e-4
# The bound on StereoSGBM's median (signed) disparity error on non-occluded pixels.
TOL_SGBM_MEDIAN_PX = 0.25

pytestmark = pytest.mark.render


@pytest.fixture(scope="module")
def ds(crossview_render):
    return Dataset(crossview_render[1])


def frames(ds):
    return sio.read_json(ds.path("crossview/index.json"))["stereo"]


def test_rectified_truth_is_row_aligned_and_exact(ds):
    assert len(frames(ds)) == 2
    for fr in frames(ds):
        base = fr["dir"]
        calib = sio.read_json(ds.path(f"{base}/calib.json"))
        for side, sign in (("left", 1.0), ("right", -1.0)):
            c = decode_correspondence_channels(sio.read_exr(ds.path(f"{base}/corr_{side}.exr")))
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
    m = sio.read_exr(ds.path(f"{base}/map_left.exr"))  # R = map_x, G = map_y (OpenCV-readable names)
    warped = cv2.remap(raw, m["R"], m["G"], cv2.INTER_LINEAR, borderValue=np.nan)
    rect = sio.unpack_channels(sio.read_exr(ds.path(f"{base}/left_linear.exr")), "", "RGB")
    shifted_img = np.roll(warped, 1, axis=1)
    ok = np.isfinite(warped).all(-1) & np.isfinite(shifted_img).all(-1)
    diff = np.abs(warped - rect)[ok].mean()
    shifted = np.abs(shifted_img - rect)[ok].mean()
    assert diff < 0.5 * shifted, (diff, shifted)

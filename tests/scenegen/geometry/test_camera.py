"""Camera models against independent implementations (OpenCV, pycolmap, a written-out skew model)."""
import math

import cv2
import numpy as np
import pycolmap
import pytest
from hypothesis import HealthCheck, assume, given, settings, strategies as st

from scenegen.geometry.camera import Camera, unproject_uv
from scenegen.geometry.camera.arith import fisheye_theta_d
from scenegen.geometry.conventions import pixel_centers

# float64 agreement with OpenCV: both evaluate the same polynomial in double precision; 1e-9 px
# leaves three orders of magnitude above the rounding of ~1e3 px values.
TOL_OPENCV_PX = 1e-9
# Round trips go through the iterative undistortion, converged to 1e-10 px by construction.
TOL_ROUNDTRIP_PX = 1e-6
# float32 floor of the same arithmetic (the renderer's precision), measured 4.0e-5 px (opencv,
# k1 = -0.4, k3 = -0.05) and 6.6e-5 px (fisheye to 85 deg) over full 640x480 grids.
TOL_FLOAT32_PX = 1.5e-4

SETTINGS = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])


def strong_opencv() -> Camera:
    K = np.array([[800.0, 0, 319.5], [0, 800.0, 239.5], [0, 0, 1]])
    return Camera.from_opencv(K, [-0.4, 0.0, 0.0, 0.0, -0.05], (640, 480))


def wide_fisheye(max_angle_deg: float = 85.0) -> Camera:
    """Fisheye whose image corners lie exactly at ``max_angle_deg`` off axis."""
    k = (0.02, -0.004, 0.001, -0.0001)
    coeff = type("P", (), dict(zip(("k1", "k2", "k3", "k4"), k)))
    f = 400.0 / fisheye_theta_d(math.radians(max_angle_deg), coeff)  # corner radius 400 px
    K = np.array([[f, 0, 319.5], [0, f, 239.5], [0, 0, 1]])
    return Camera.from_opencv_fisheye(K, k, (640, 480))


def full_grid(cam: Camera) -> np.ndarray:
    return pixel_centers(cam.width, cam.height).reshape(-1, 2)


intrinsics = st.tuples(
    st.floats(200, 2000), st.floats(0.8, 1.25), st.floats(-50, 50), st.floats(-50, 50))
small = st.floats(-0.05, 0.05)


def _points(seed: int, n: int = 200, z_max: float = 10.0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    P = rng.uniform([-1, -1, 0.2], [1, 1, z_max], (n, 3))
    P[:, :2] *= P[:, 2:3] * 0.6  # keep within ~60 degrees
    return P


class TestProjectAgainstOpenCV:
    @SETTINGS
    @given(intrinsics, st.lists(small, min_size=12, max_size=12), st.integers(0, 2**31 - 1),
           st.sampled_from([4, 5, 8, 12]))
    def test_opencv_model(self, intr, coeffs, seed, n):
        f, aspect, dcx, dcy = intr
        K = np.array([[f, 0, 320 + dcx], [0, f * aspect, 240 + dcy], [0, 0, 1]])
        dist = np.array(coeffs[:n])
        dist[:2] *= 4  # radial terms up to +-0.2
        try:
            cam = Camera.from_opencv(K, dist, (640, 480))
        except ValueError:
            assume(False)
        P = _points(seed)
        uv, valid = cam.project(P, return_valid=True)
        assume(valid.sum() > 10)
        ref, _ = cv2.projectPoints(P[valid], np.zeros(3), np.zeros(3), K, dist)
        np.testing.assert_allclose(uv[valid], ref[:, 0], rtol=0, atol=TOL_OPENCV_PX)

    @SETTINGS
    @given(intrinsics, st.lists(small, min_size=4, max_size=4), st.integers(0, 2**31 - 1))
    def test_fisheye_model(self, intr, k, seed):
        f, aspect, dcx, dcy = intr
        K = np.array([[f, 0, 320 + dcx], [0, f * aspect, 240 + dcy], [0, 0, 1]])
        try:
            cam = Camera.from_opencv_fisheye(K, k, (640, 480))
        except ValueError:
            assume(False)
        P = _points(seed)
        uv, valid = cam.project(P, return_valid=True)
        assert valid.all()
        ref, _ = cv2.fisheye.projectPoints(P[None], np.zeros(3), np.zeros(3), K, np.array(k))
        np.testing.assert_allclose(uv, ref[0], rtol=0, atol=TOL_OPENCV_PX)

    def test_fisheye_skew_is_opencv_alpha(self):
        K = np.array([[400.0, 0, 320], [0, 410, 240], [0, 0, 1]])
        alpha = 0.01
        cam = Camera.from_opencv_fisheye(K, [0.01, 0.0, 0.0, 0.0], (640, 480), alpha=alpha)
        P = _points(3)
        ref, _ = cv2.fisheye.projectPoints(P[None], np.zeros(3), np.zeros(3), K, np.array([0.01, 0, 0, 0.0]),
                                           alpha=alpha)
        np.testing.assert_allclose(cam.project(P), ref[0], rtol=0, atol=TOL_OPENCV_PX)

    @SETTINGS
    @given(intrinsics, st.floats(-20, 20), st.lists(small, min_size=5, max_size=5), st.integers(0, 2**31 - 1))
    def test_skew_against_written_out_reference(self, intr, skew, dist, seed):
        """OpenCV's projectPoints ignores skew: distort with K = I there, then apply K by hand."""
        f, aspect, dcx, dcy = intr
        K = np.array([[f, skew, 320 + dcx], [0, f * aspect, 240 + dcy], [0, 0, 1]])
        try:
            cam = Camera.from_opencv(K, dist, (640, 480))
        except ValueError:
            assume(False)
        P = _points(seed)
        uv, valid = cam.project(P, return_valid=True)
        assume(valid.sum() > 10)
        xd, _ = cv2.projectPoints(P[valid], np.zeros(3), np.zeros(3), np.eye(3), np.array(dist))
        hom = np.c_[xd[:, 0], np.ones(valid.sum())] @ K.T
        np.testing.assert_allclose(uv[valid], hom[:, :2], rtol=0, atol=TOL_OPENCV_PX)


class TestModelSpecifics:
    def test_fisheye_reaches_85_degrees(self):
        fov = wide_fisheye().field_of_view_deg()
        assert fov["max_off_axis"] == pytest.approx(85.0, abs=1e-6)

    def test_iteration_count_is_measured(self):
        """The fixed count converges at the worst pixel; one iteration fewer is measurably worse."""
        cam = strong_opencv()
        grid = full_grid(cam)
        p = cam.params()
        for n, ok in ((cam.undistort_iterations, True), (cam.undistort_iterations - 2, False)):
            d = np.stack(unproject_uv(grid[:, 0], grid[:, 1], p, cam.model, n), axis=1)
            err = np.abs(cam.project(d) - grid).max()
            assert (err < 1e-9) == ok, (n, err)

    def test_z1_points(self):
        cam = strong_opencv()
        X = cam.unproject(np.array([[0.0, 0.0], [639.0, 479.0]]))
        np.testing.assert_allclose(X[:, 2], 1.0)


class TestValidity:
    def test_folding_distortion_rejected_with_location(self):
        K = np.array([[500.0, 0, 319.5], [0, 500, 239.5], [0, 0, 1]])
        with pytest.raises(ValueError, match=r"folds over inside the 640x480 image.*pixel \("):
            Camera.from_opencv(K, [-0.4, 0, 0, 0, -0.05], (640, 480))

    def test_fisheye_fold_rejected(self):
        K = np.array([[200.0, 0, 319.5], [0, 200, 239.5], [0, 0, 1]])
        with pytest.raises(ValueError, match="folds over"):
            Camera.from_opencv_fisheye(K, [-0.3, 0, 0, 0], (640, 480))

    def test_image_beyond_field_of_view_rejected(self):
        """A fisheye whose image corners would be more than 180 degrees off axis."""
        K = np.array([[100.0, 0, 319.5], [0, 100, 239.5], [0, 0, 1]])
        with pytest.raises(ValueError, match="field of view"):
            Camera.from_opencv_fisheye(K, [0.0, 0, 0, 0], (640, 480))

    def test_points_beyond_fold_radius_are_nan(self):
        cam = strong_opencv()  # folds at r ~ 0.87 (outside this image), corner at r ~ 0.6
        uv, valid = cam.project(np.array([[0.5, 0.0, 1.0], [3.0, 0.0, 1.0]]), return_valid=True)
        assert valid.tolist() == [True, False]
        assert np.isnan(uv[1]).all() and np.isfinite(uv[0]).all()

    def test_behind_camera_and_nan(self):
        cam = strong_opencv()
        uv, valid = cam.project(np.array([[0.1, 0.1, -1.0], [0, 0, 0.0], [np.nan, 0, 1]]), return_valid=True)
        assert not valid.any() and np.isnan(uv).all()
        assert np.isnan(cam.unproject(np.array([[np.nan, 3.0]]))).all()

    def test_fisheye_projects_behind_90_degrees(self):
        K = np.array([[150.0, 0, 319.5], [0, 150, 239.5], [0, 0, 1]])
        cam = Camera.from_opencv_fisheye(K, [0.0, 0, 0, 0], (640, 480))
        uv, valid = cam.project(np.array([[1.0, 0, -0.2]]), return_valid=True)
        assert valid[0]
        assert uv[0, 0] == pytest.approx(319.5 + 150 * (math.pi / 2 + math.atan(0.2)))
        d = cam.unproject_unit(uv)
        np.testing.assert_allclose(d[0], np.array([1.0, 0, -0.2]) / math.hypot(1, 0.2), atol=1e-12)
        assert np.isnan(cam.unproject(uv)).all()  # no z = 1 point behind the camera

    @pytest.mark.parametrize("kwargs, msg", [
        (dict(fx=0.0), "focal"), (dict(fy=-1.0), "focal"), (dict(width=0), "width"),
        (dict(cx=float("nan")), "finite"), (dict(dist=(0.1, 0.2)), "4, 5, 8, 12"),
    ])
    def test_bad_parameters(self, kwargs, msg):
        base = dict(model="opencv", width=640, height=480, fx=500.0, fy=500.0, cx=319.5, cy=239.5, dist=(0, 0, 0, 0))
        with pytest.raises(ValueError, match=msg):
            Camera(**{**base, **kwargs})

    def test_field_of_view_of_pinhole(self):
        cam = Camera.from_fov(90.0, (640, 480))
        assert cam.field_of_view_deg()["horizontal"] == pytest.approx(90.0, abs=1e-9)
        assert cam.fx == pytest.approx(320.0)


class TestOpenCVAndColmapInterop:
    def test_to_opencv_round_trip(self):
        cam = strong_opencv()
        K, d = cam.to_opencv()
        assert d.shape == (5,)
        assert Camera.from_opencv(K, d, cam.size) == cam

    @pytest.mark.parametrize("cam", [
        Camera.from_fov(70.0, (640, 480)),
        Camera.from_opencv(np.array([[700.0, 0, 330], [0, 705, 235], [0, 0, 1]]), [-0.2, 0.05, 1e-3, -2e-3], (640, 480)),
        Camera.from_opencv(np.array([[700.0, 0, 330], [0, 705, 235], [0, 0, 1]]),
                           [-0.2, 0.05, 1e-3, -2e-3, 0.01, 0.02, 0.01, 0.005], (640, 480)),
        wide_fisheye(80.0),
    ], ids=["PINHOLE", "OPENCV", "FULL_OPENCV", "OPENCV_FISHEYE"])
    def test_colmap_round_trip_and_pycolmap_projection(self, cam):
        name, params = cam.to_colmap()
        assert Camera.from_colmap(name, cam.width, cam.height, params) == cam
        pc = pycolmap.Camera(model=name, width=cam.width, height=cam.height, params=params)
        rays = cam.unproject_unit(full_grid(cam)[::37])
        ours = cam.project(rays)
        theirs = pc.img_from_cam(rays) - 0.5  # COLMAP pixel centres are at +0.5
        np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-6)
        # and pycolmap's unprojection lands on our rays
        back = pc.cam_from_img(ours + 0.5)
        np.testing.assert_allclose(back, rays[:, :2] / rays[:, 2:3], rtol=0, atol=1e-6)

    def test_colmap_rejects_skew(self):
        cam = Camera("pinhole", 64, 48, 50.0, 50.0, 31.5, 23.5, skew=1.0)
        with pytest.raises(ValueError, match="skew"):
            cam.to_colmap()


def test_colmap_simple_radial_and_radial_cameras():
    """COLMAP's one- and two-coefficient radial models (each dict entry used to be evaluated for
    every model, so SIMPLE_RADIAL raised IndexError)."""
    from scenegen.geometry.camera import Camera

    a = Camera.from_colmap("SIMPLE_RADIAL", 640, 480, [500.0, 320.0, 240.0, -0.05])
    b = Camera.from_colmap("RADIAL", 640, 480, [500.0, 320.0, 240.0, -0.05, 0.01])
    assert a.model == b.model == "opencv" and a.dist[:2] == (-0.05, 0.0) and b.dist[:2] == (-0.05, 0.01)
    assert (a.cx, a.cy) == (319.5, 239.5)

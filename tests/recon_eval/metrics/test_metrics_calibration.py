import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from recon_eval.metrics.calibration import intrinsics_errors, projection_difference, reprojection_rms
from recon_eval.errors import InputError
from recon_eval.metrics.pnp import pnp_errors

from scenegen.geometry.camera import Camera  # numpy-only at import (no Mitsuba)

K = np.array([[500.0, 0.0, 319.5], [0.0, 505.0, 239.5], [0.0, 0.0, 1.0]])
SIZE = (640, 480)
DIST = np.array([-0.2, 0.05, 0.001, -0.0005, 0.0])
#: Newton undistortion inside Camera.unproject converges to ~1e-9 px (scenegen UNDISTORT_TOL_PX);
#: projection differences of distorted models are compared at that floor.
UNDISTORT_FLOOR_PX = 1e-6


def shifted(K, dcx):
    K2 = K.copy()
    K2[0, 2] += dcx
    return K2


class TestProjectionDifference:
    def test_camera_against_itself_is_zero(self):
        cam = Camera.from_opencv(K, DIST, SIZE)
        r = projection_difference(cam, cam)
        assert r.max_px < UNDISTORT_FLOOR_PX and r.valid_frac == 1.0

    def test_pinhole_cx_shift_is_one_pixel_everywhere(self):
        r = projection_difference(Camera.from_opencv(K, None, SIZE), Camera.from_opencv(shifted(K, 1.0), None, SIZE))
        assert r.mean_px == pytest.approx(1.0, abs=1e-9)
        assert r.max_px == pytest.approx(1.0, abs=1e-9) and r.rms_px == pytest.approx(1.0, abs=1e-9)

    def test_distorted_cx_shift_is_one_pixel_everywhere(self):
        r = projection_difference(Camera.from_opencv(K, DIST, SIZE), Camera.from_opencv(shifted(K, 1.0), DIST, SIZE))
        assert r.mean_px == pytest.approx(1.0, abs=UNDISTORT_FLOOR_PX)
        assert r.max_px == pytest.approx(1.0, abs=UNDISTORT_FLOOR_PX)

    def test_across_model_families(self):
        pin = Camera.from_opencv(K, None, SIZE)
        fish = Camera.from_opencv_fisheye(K, np.zeros(4), SIZE)
        # An undistorted fisheye is an equidistant camera, not a pinhole: the field grows outwards.
        r = projection_difference(pin, fish, grid_nx=21, grid_ny=15)
        assert r.diff_px[7, 10] < 1e-9  # the principal point maps to itself
        assert r.max_px > 10.0 and r.diff_px[0, 0] == pytest.approx(r.max_px)

    def test_fitted_rotation_absorbs_a_small_principal_point_shift(self):
        a, b = Camera.from_opencv(K, None, SIZE), Camera.from_opencv(shifted(K, 2.0), None, SIZE)
        plain = projection_difference(a, b)
        fitted = projection_difference(a, b, fit_rotation=True)
        assert fitted.rotation_fitted and fitted.fitted_rot_deg > 0.1
        # A rotation cannot absorb a shift exactly (it moves the edges by f sec^2 theta dtheta):
        # over a 65 degree field about 14 % of the rms remains (measured 0.286 px of 2 px).
        assert fitted.rms_px < 0.2 * plain.rms_px
        # and the fit beats the rotation that makes the principal point exact (atan(2 / fx) about y)
        ang = np.arctan2(2.0, K[0, 0])
        uv = np.stack(np.meshgrid(fitted.grid_u_px, fitted.grid_v_px), axis=-1).reshape(-1, 2)
        rays = a.unproject(uv) @ Rotation.from_rotvec([0.0, -ang, 0.0]).as_matrix().T
        centre_exact = np.linalg.norm(b.project(rays) - uv, axis=1)
        assert abs(b.project(a.unproject([[K[0, 2], K[1, 2]]]) @ Rotation.from_rotvec([0.0, -ang, 0.0]).as_matrix().T)[0, 0] - K[0, 2]) < 1e-9
        assert fitted.rms_px < np.sqrt(np.mean(centre_exact**2))

    def test_size_mismatch(self):
        with pytest.raises(InputError, match="image size"):
            projection_difference(Camera.from_opencv(K, None, SIZE), Camera.from_opencv(K, None, (320, 240)))


def test_intrinsics_errors():
    K2 = K.copy()
    K2[0, 0] += 10.0
    K2[1, 2] -= 2.0
    r = intrinsics_errors(K2, K)
    assert (r.fx_abs_err_px, r.fy_abs_err_px, r.cx_abs_err_px, r.cy_abs_err_px) == (10.0, 0.0, 0.0, 2.0)
    assert r.fx_rel_err == pytest.approx(0.02) and r.cy_rel_err == pytest.approx(2.0 / 239.5)


def held_out_points():
    rng = np.random.default_rng(0)
    X = np.c_[rng.uniform(-1, 1, 50), rng.uniform(-1, 1, 50), rng.uniform(3, 6, 50)]
    R = Rotation.from_rotvec([0.1, -0.05, 0.2]).as_matrix()
    t = np.array([0.1, -0.2, 0.3])
    X_world = (X - t) @ R  # so that R X_world + t = X
    return R, t, X_world


class TestReprojection:
    def test_truth_is_zero_and_a_one_pixel_offset_is_one(self):
        cam = Camera.from_opencv(K, DIST, SIZE)
        R, t, X = held_out_points()
        x = cam.project(X @ R.T + t)
        assert reprojection_rms(cam, R, t, X, x).rms_px < 1e-12
        assert reprojection_rms(cam, R, t, X, x + [1.0, 0.0]).rms_px == pytest.approx(1.0, abs=1e-12)

    def test_points_behind_the_camera_are_failures(self):
        cam = Camera.from_opencv(K, None, SIZE)
        R, t, X = np.eye(3), np.zeros(3), np.array([[0.0, 0.0, 2.0], [0.0, 0.0, -2.0]])
        r = reprojection_rms(cam, R, t, X, np.array([[319.5, 239.5], [319.5, 239.5]]))
        assert r.n_invalid == 1 and np.isinf(r.rms_px)


class TestPnp:
    def test_small_rotation_error_is_exact(self):
        R, t, X = held_out_points()
        dR = Rotation.from_rotvec([0.0, 0.0, 1e-8]).as_matrix()
        r = pnp_errors(dR @ R, t, R, t)
        assert r.rot_err_deg == pytest.approx(np.degrees(1e-8), rel=1e-6)
        assert r.trans_abs_err_m == 0.0

    def test_translation_errors(self):
        R, t, X = held_out_points()
        r = pnp_errors(R, t + [0.0, 0.03, 0.04], R, t)
        assert r.trans_abs_err_m == pytest.approx(0.05)
        assert r.trans_rel_err == pytest.approx(0.05 / np.linalg.norm(t))
        assert r.center_err_m == pytest.approx(0.05)

    def test_reprojection_through_the_estimated_pose(self):
        cam = Camera.from_opencv(K, None, SIZE)
        R, t, X = held_out_points()
        x = cam.project(X @ R.T + t)
        r = pnp_errors(R, t, R, t, cam=cam, points_world=X, pixels=x)
        assert r.reprojection.rms_px < 1e-12

    def test_non_finite_estimate_fails(self):
        R, t, _ = held_out_points()
        assert pnp_errors(np.full((3, 3), np.nan), t, R, t).failed

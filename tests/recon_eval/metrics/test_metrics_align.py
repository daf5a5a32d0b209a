import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from recon_eval.metrics.align import (
    Projective3,
    Sim3,
    cameras_to_truth_frame,
    icp_refine,
    projective_align,
    umeyama,
)
from recon_eval.errors import InputError


# Planted transforms are recovered to rounding: 1e-9 leaves ~7 orders of magnitude for the SVD.
TOL = 1e-9


class TestUmeyama:
    @pytest.mark.parametrize("with_scale", [True, False])
    def test_planted_transform_recovered(self, with_scale, random_rotation):
        rng = np.random.default_rng(0)
        T = Sim3(random_rotation(rng), rng.normal(size=3) * 5, 2.5 if with_scale else 1.0)
        src = rng.normal(size=(40, 3))
        tgt = T.apply(src)
        src0, tgt0 = src.copy(), tgt.copy()
        est = umeyama(src, tgt, with_scale=with_scale)
        np.testing.assert_allclose(est.R, T.R, atol=TOL)
        np.testing.assert_allclose(est.t, T.t, atol=TOL)
        assert est.scale == pytest.approx(T.scale, abs=TOL)
        np.testing.assert_array_equal(src, src0)  # never mutates its input
        np.testing.assert_array_equal(tgt, tgt0)

    def test_on_camera_centres(self, ring_of_cameras):
        R, t = ring_of_cameras(8)
        centres = -np.einsum("nji,nj->ni", R, t)
        T = Sim3(Rotation.from_rotvec([0.3, -1.0, 2.0]).as_matrix(), [1.0, -2.0, 0.5], 0.3)
        est = umeyama(centres, T.apply(centres), with_scale=True)
        np.testing.assert_allclose(est.matrix, T.matrix, atol=TOL)

    def test_coplanar_points_give_a_proper_rotation(self, random_rotation):
        rng = np.random.default_rng(1)
        src = np.c_[rng.normal(size=(20, 2)), np.zeros(20)]
        T = Sim3(random_rotation(rng), [0, 0, 1], 1.0)
        est = umeyama(src, T.apply(src), with_scale=False)
        assert np.linalg.det(est.R) == pytest.approx(1.0)
        np.testing.assert_allclose(est.R, T.R, atol=TOL)

    def test_se3_on_scaled_data_keeps_unit_scale(self):
        rng = np.random.default_rng(2)
        src = rng.normal(size=(30, 3))
        est = umeyama(src, 3.0 * src, with_scale=False)
        assert est.scale == 1.0

    def test_bad_input(self):
        with pytest.raises(InputError, match="at least 3"):
            umeyama(np.zeros((2, 3)), np.zeros((2, 3)), with_scale=True)
        with pytest.raises(InputError, match="collinear"):
            umeyama(np.c_[np.arange(5.0), np.zeros(5), np.zeros(5)], np.c_[np.arange(5.0), np.zeros(5), np.zeros(5)], with_scale=True)
        with pytest.raises(InputError, match="shape"):
            umeyama(np.zeros((5, 2)), np.zeros((5, 2)), with_scale=True)


class TestSim3:
    def test_inverse_and_compose(self, random_rotation):
        rng = np.random.default_rng(5)
        A = Sim3(random_rotation(rng), rng.normal(size=3), 1.7)
        x = rng.normal(size=(5, 3))
        np.testing.assert_allclose((A.inverse() @ A).apply(x), x, atol=1e-12)

    def test_frozen_arrays(self):
        A = Sim3()
        with pytest.raises(ValueError):
            A.R[0, 0] = 2.0

    def test_camera_poses_follow_the_world_change(self, random_rotation, ring_of_cameras):
        rng = np.random.default_rng(6)
        R, t = ring_of_cameras(4)
        A = Sim3(random_rotation(rng), rng.normal(size=3), 0.5)
        R2, t2 = A.cam_from_tgt(R, t)
        X = rng.normal(size=(4, 3))  # a world point seen by every camera
        for k in range(4):
            x_cam = R[k] @ X[k] + t[k]
            x_cam2 = R2[k] @ A.apply(X[k]) + t2[k]
            np.testing.assert_allclose(x_cam2, A.scale * x_cam, atol=1e-12)


class TestIcp:
    def test_refines_a_perturbed_start_to_the_planted_transform(self):
        rng = np.random.default_rng(7)
        src = rng.random((400, 3))
        T = Sim3(Rotation.from_rotvec([0.2, 0.1, -0.3]).as_matrix(), [0.5, 0.0, -0.2], 1.3)
        tgt = T.apply(src)
        init = Sim3(Rotation.from_rotvec([0.005, 0.0, 0.0]).as_matrix() @ T.R, T.t + 0.003, T.scale * 1.002)
        res = icp_refine(src, tgt, init, with_scale=True, max_corr_dist_m=0.05)
        assert res.converged
        np.testing.assert_allclose(res.tgt_from_src.matrix, T.matrix, atol=TOL)
        assert res.inlier_fraction == 1.0


class TestProjective:
    def test_planted_homography_recovered_and_cameras_reproject(self):
        rng = np.random.default_rng(8)
        H = np.eye(4) + 0.1 * rng.normal(size=(4, 4))  # tgt_from_src
        X_tgt = rng.normal(size=(30, 3))
        X_src_h = np.c_[X_tgt, np.ones(30)] @ np.linalg.inv(H).T  # homogeneous projective points
        est = projective_align(X_src_h, X_tgt)
        np.testing.assert_allclose(est.H, Projective3(H).H, atol=TOL)
        np.testing.assert_allclose(est.apply(X_src_h), X_tgt, atol=1e-8)
        # A projective camera P_src = P_tgt H sees the same image; mapped back it reprojects exactly.
        K = np.array([[500.0, 0, 320], [0, 500, 240], [0, 0, 1]])
        P_tgt = K @ np.c_[np.eye(3), [0.0, 0.0, 5.0]]
        P_back = cameras_to_truth_frame(P_tgt @ H, est)
        x_true = np.c_[X_tgt, np.ones(30)] @ P_tgt.T
        x_back = np.c_[X_tgt, np.ones(30)] @ P_back.T
        np.testing.assert_allclose(x_back[:, :2] / x_back[:, 2:], x_true[:, :2] / x_true[:, 2:], atol=1e-7)

    @pytest.mark.parametrize("w_ratio", [1.5e-9, 0.0])
    def test_point_near_the_plane_at_infinity_keeps_full_precision(self, w_ratio):
        """One source point with w' at 1.5e-9 of the largest |w'| (or exactly at infinity): the
        camera mapped into the truth frame is exact to rounding. Dividing by w before the Hartley
        normalisation threw that point ~1e9 away and left the rotation off by 3e-7 .. 1.5e-6 deg."""
        from recon_eval.metrics.dlt import score_projection_projective

        worst = 0.0
        for seed in range(5):
            rng = np.random.default_rng(seed)
            K = np.array([[800.0, 0.5, 320], [0, 790, 240], [0, 0, 1]])
            R, t = Rotation.from_rotvec(rng.normal(size=3) * 0.3).as_matrix(), np.array([0.1, -0.2, 4.0])
            X = rng.normal(size=(40, 3))
            Xh = np.c_[X, np.ones(40)]
            proj_from_truth = np.eye(4) + 0.3 * rng.normal(size=(4, 4))
            r4 = proj_from_truth[3]  # move the plane at infinity onto point 0 (up to w_ratio)
            r4 -= (r4 @ Xh[0] - w_ratio * np.abs(Xh @ r4).max()) / (Xh[0] @ Xh[0]) * Xh[0]
            X_proj = Xh @ proj_from_truth.T
            w = np.abs(X_proj[:, 3])
            assert w.min() <= (2 * w_ratio + 1e-15) * w.max()
            P_truth = K @ np.c_[R, t]
            px = Xh @ P_truth.T
            px = px[:, :2] / px[:, 2:]
            s = score_projection_projective(P_truth @ np.linalg.inv(proj_from_truth), X_proj, X, K, (R, t), px)
            worst = max(worst, s.rot_err_deg)
            assert s.reproj_rms_px < 1e-9 and s.fx_rel_err < 1e-12
        assert worst < 1e-11, worst  # measured <= 2.3e-13 deg

    def test_too_few_points(self):
        with pytest.raises(InputError, match=">= 5"):
            projective_align(np.zeros((4, 3)), np.zeros((4, 3)))

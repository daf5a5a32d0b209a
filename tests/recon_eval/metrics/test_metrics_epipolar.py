import cv2
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from recon_eval.metrics.epipolar import (
    epipolar_distance_stats,
    epipolar_line_distances_px,
    fundamental_degeneracy,
    fundamental_metrics,
    homography_mace,
    homography_summary,
    inlier_precision_recall,
    pose_error_from_fundamental,
    sampson_sq_px2,
    symmetric_epipolar_sq_px2,
    zhang_f_distance,
)
from recon_eval.errors import InputError
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.twoview import fundamental

K1 = np.array([[600.0, 0, 320], [0, 610, 240], [0, 0, 1]])
K2 = np.array([[550.0, 0, 300], [0, 555, 250], [0, 0, 1]])
R21 = Rotation.from_rotvec([0.05, -0.2, 0.03]).as_matrix()
T21 = np.array([0.5, 0.05, 0.1])
#: a rectified pair: epipolar lines are the rows, x2^T F x1 = y1 - y2 (up to sign)
F_RECT = np.array([[0.0, 0, 0], [0, 0, 1], [0, -1, 0]])


def scene():
    """Exact correspondences (x1, x2) of random points in front of both cameras."""
    rng = np.random.default_rng(0)
    X = np.c_[rng.uniform(-1, 1, 200), rng.uniform(-1, 1, 200), rng.uniform(4, 8, 200)]
    x1 = X @ K1.T
    X2 = X @ R21.T + T21
    x2 = X2 @ K2.T
    return x1[:, :2] / x1[:, 2:], x2[:, :2] / x2[:, 2:]


class TestSampson:
    def test_zero_for_exact_correspondences(self):
        x1, x2 = scene()
        F = fundamental(K1, K2, Rigid3(R21, T21))
        assert np.max(np.sqrt(sampson_sq_px2(F, x1, x2))) < 1e-9

    def test_hand_computed(self):
        # F x1 = (0, 1, -20), F^T x2 = (0, -1, 23): residual -3, denominator 1 + 1
        assert sampson_sq_px2(F_RECT, [[10.0, 20.0]], [[30.0, 23.0]])[0] == pytest.approx(4.5)
        assert symmetric_epipolar_sq_px2(F_RECT, [[10.0, 20.0]], [[30.0, 23.0]])[0] == pytest.approx(18.0)

    def test_matches_opencv(self):
        rng = np.random.default_rng(1)
        x1, x2 = scene()
        x2 = x2 + rng.normal(scale=2.0, size=x2.shape)
        F = fundamental(K1, K2, Rigid3(R21, T21))
        ours = sampson_sq_px2(F, x1, x2)
        ref = [cv2.sampsonDistance(np.r_[a, 1.0].reshape(3, 1), np.r_[b, 1.0].reshape(3, 1), F) for a, b in zip(x1, x2)]
        np.testing.assert_allclose(ours, ref, rtol=1e-10)


class TestFundamentalMetrics:
    def test_truth_scores_zero(self):
        x1, x2 = scene()
        r = fundamental_metrics(fundamental(K1, K2, Rigid3(R21, T21)), x1, x2)
        assert not r.failed and r.sampson_rms_px < 1e-9 and r.sym_epipolar_rms_px < 1e-9

    def test_known_vertical_offset(self):
        x1 = np.array([[10.0, 20.0], [50.0, 70.0]])
        x2 = x1 + [5.0, 2.0]
        r = fundamental_metrics(F_RECT, x1, x2)
        assert r.sym_epipolar_rms_px == pytest.approx(2.0)  # every point is 2 px from its line
        assert r.sampson_rms_px == pytest.approx(np.sqrt(2.0))  # 4 / (1 + 1)

    @pytest.mark.parametrize("F,reason", [(np.eye(3), "rank 3"), (np.zeros((3, 3)), "zero"),
                                          (np.full((3, 3), np.nan), "non-finite")])
    def test_degenerate_estimates_are_failures(self, F, reason):
        x1, x2 = scene()
        r = fundamental_metrics(F, x1, x2)
        assert r.failed and r.failure_reason == reason and np.isinf(r.sampson_rms_px)
        assert fundamental_degeneracy(F) == reason

    def test_mismatched_correspondences(self):
        with pytest.raises(InputError):
            fundamental_metrics(F_RECT, np.zeros((3, 2)), np.zeros((4, 2)))


class TestZhangDistance:
    def test_zero_against_itself_and_scale_invariant(self):
        F = fundamental(K1, K2, Rigid3(R21, T21))
        assert zhang_f_distance(F, F, (640, 480), n_samples=200).f_distance_px < 1e-9
        assert zhang_f_distance(-3.0 * F, F, (640, 480), n_samples=200).f_distance_px < 1e-9

    def test_known_row_offset(self):
        delta = 2.5
        F_off = np.array([[0.0, 0, 0], [0, 0, 1], [0, -1, -delta]])  # lines y2 = y1 + delta
        r = zhang_f_distance(F_off, F_RECT, (640, 480), n_samples=300, seed=4)
        assert r.f_distance_px == pytest.approx(delta, abs=1e-9)
        assert r.seed == 4 and r.n_samples == 600

    def test_degenerate_estimate_fails(self):
        assert zhang_f_distance(np.eye(3), F_RECT, (640, 480)).failed


class TestPoseFromF:
    def test_truth_F_gives_truth_pose(self):
        x1, x2 = scene()
        F = fundamental(K1, K2, Rigid3(R21, T21))
        r = pose_error_from_fundamental(F, K1, K2, x1, x2, R21, T21)
        assert r.rot_err_deg < 1e-6 and r.trans_dir_err_deg < 1e-6

    def test_degenerate(self):
        x1, x2 = scene()
        assert pose_error_from_fundamental(np.full((3, 3), np.nan), K1, K2, x1, x2, R21, T21).failed


def test_inlier_precision_recall():
    r = inlier_precision_recall([1, 1, 0, 1, 0], [1, 0, 0, 1, 1])
    assert (r.precision, r.recall, r.n_true_positive) == (2 / 3, 2 / 3, 2)
    empty = inlier_precision_recall([0, 0], [1, 0])
    assert (empty.precision, empty.recall) == (0.0, 0.0)


class TestHomography:
    H = np.array([[1.1, 0.05, 3.0], [-0.02, 0.95, -4.0], [1e-4, -2e-4, 1.0]])

    def test_against_itself(self):
        assert homography_mace(self.H, self.H, 640, 480).mace_px == 0.0

    def test_known_pixel_shift(self):
        shift = np.array([[1.0, 0, 2.0], [0, 1, -1.0], [0, 0, 1]])
        r = homography_mace(shift @ self.H, self.H, 640, 480)
        assert r.mace_px == pytest.approx(np.sqrt(5.0), abs=1e-9)
        np.testing.assert_allclose(r.corner_err_px, [np.sqrt(5.0)] * 4, atol=1e-9)

    @pytest.mark.parametrize("H", [np.zeros((3, 3)), np.full((3, 3), np.nan), np.diag([1.0, 1.0, 0.0])])
    def test_degenerate_is_failure(self, H):
        r = homography_mace(H, self.H, 640, 480)
        assert r.failed and np.isinf(r.mace_px)

    def test_summary_hand_computed(self):
        s = homography_summary([0.5, 1.0, 3.0, np.inf])
        assert (s.accuracy_1_px, s.accuracy_3_px, s.accuracy_5_px) == (0.5, 0.75, 0.75)  # <= eps
        assert s.n_failed == 1
        # curve (0,0) (.5,.25) (1,.5) (3,.75) held to 5: .0625+.1875+1.25+1.5 = 3.0 -> /5
        assert s.auc_5_px == pytest.approx(0.6, abs=1e-15)


def test_epipolar_distance_stats_match_opencv_epilines(two_view_points):
    """The survey's measure against cv2.computeCorrespondEpilines (lines with a^2 + b^2 = 1)."""
    x1, x2, F, _, _ = two_view_points(50, 2)
    rng = np.random.default_rng(0)
    y1, y2 = x1 + rng.normal(0, 1.5, x1.shape), x2 + rng.normal(0, 1.5, x2.shape)
    l2 = cv2.computeCorrespondEpilines(y1.reshape(-1, 1, 2), 1, F).reshape(-1, 3)  # lines in image 2
    l1 = cv2.computeCorrespondEpilines(y2.reshape(-1, 1, 2), 2, F).reshape(-1, 3)  # lines in image 1
    ref1 = np.abs(np.sum(l1[:, :2] * y1, axis=1) + l1[:, 2])
    ref2 = np.abs(np.sum(l2[:, :2] * y2, axis=1) + l2[:, 2])
    d1, d2 = epipolar_line_distances_px(F, y1, y2)
    np.testing.assert_allclose(d1, ref1, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(d2, ref2, rtol=1e-9, atol=1e-9)
    r = epipolar_distance_stats(F, y1, y2)
    ref = np.r_[ref1, ref2]
    assert r.n_points == 50 and abs(r.mean_px - ref.mean()) <= 1e-9 and abs(r.std_px - ref.std()) <= 1e-9
    assert epipolar_distance_stats(F, x1, x2).mean_px < 1e-9  # exact points lie on their lines
    bad = epipolar_distance_stats(np.eye(3), y1, y2)
    assert bad.failed and bad.failure_reason == "rank 3" and bad.mean_px == np.inf

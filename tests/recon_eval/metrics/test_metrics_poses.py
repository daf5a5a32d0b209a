import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from recon_eval.metrics.align import Alignment, Sim3
from recon_eval.errors import InputError
from recon_eval.metrics.poses import Poses, ape, registration_ratio, relative_pose, relative_pose_errors_deg, rpe


NAMES = tuple(f"img{k:02d}.png" for k in range(8))
#: world change applied to the truth to make a planted estimate (est_from_gt), scale 0.4
PLANTED = Sim3(Rotation.from_rotvec([0.4, -0.2, 1.1]).as_matrix(), [2.0, -1.0, 0.3], 0.4)


@pytest.fixture
def truth(ring_of_cameras):
    """``truth()``: the 8 ring cameras as Poses named NAMES."""
    def make() -> Poses:
        R, t = ring_of_cameras(8)
        return Poses(NAMES, R, t)
    return make


def planted_estimate(gt: Poses) -> Poses:
    R, t = PLANTED.cam_from_tgt(gt.R_cam_from_world, gt.t_cam_from_world)
    return Poses(gt.names, R, t)


class TestApe:
    def test_truth_against_itself(self, truth):
        gt = truth()
        r = ape(gt, gt, alignment=Alignment.NONE)
        assert r.trans_stats_m.max < 1e-15 and r.rot_stats_deg.max < 1e-6
        assert r.registration_ratio == 1.0

    def test_planted_sim3_recovered_and_scores_perfect(self, truth):
        gt = truth()
        est = planted_estimate(gt)
        r = ape(est, gt, alignment=Alignment.SIM3)
        np.testing.assert_allclose(r.tgt_from_src.matrix, PLANTED.inverse().matrix, atol=1e-9)
        assert r.trans_stats_m.max < 1e-9
        assert r.rot_stats_deg.max < 1e-7
        # without alignment the same estimate is far off
        assert ape(est, gt, alignment=Alignment.NONE).trans_stats_m.min > 0.1

    def test_known_rotation_error_on_one_camera_shows_exactly(self, truth):
        gt = truth()
        est = planted_estimate(gt)
        R, t = np.array(est.R_cam_from_world), np.array(est.t_cam_from_world)
        c = -R[3].T @ t[3]
        R[3] = Rotation.from_rotvec(np.radians(2.0) * np.array([0.6, 0.0, 0.8])).as_matrix() @ R[3]
        t[3] = -R[3] @ c  # same centre: the Sim(3) on centres is unchanged
        r = ape(Poses(NAMES, R, t), gt, alignment=Alignment.SIM3)
        assert r.rot_err_deg[3] == pytest.approx(2.0, abs=1e-9)
        assert np.max(np.delete(r.rot_err_deg, 3)) < 1e-7
        assert r.trans_stats_m.max < 1e-9

    def test_unregistered_cameras_are_failures(self, truth):
        gt = truth()
        est = planted_estimate(gt)
        keep = [0, 1, 2, 4, 5, 6, 7]
        R = np.array(est.R_cam_from_world)
        R[5] = np.nan  # a NaN pose is unregistered too
        partial = Poses(tuple(NAMES[k] for k in keep), R[keep], np.array(est.t_cam_from_world)[keep])
        r = ape(partial, gt, alignment=Alignment.SIM3)
        assert np.isinf(r.trans_err_m[3]) and np.isinf(r.rot_err_deg[3]) and np.isinf(r.trans_err_m[5])
        assert r.registration_ratio == 6 / 8 and r.n_registered == 6
        assert r.trans_stats_m.n_failed == 2 and r.trans_stats_m.max < 1e-9
        assert registration_ratio(partial, gt) == 6 / 8

    def test_extra_estimates_are_counted(self, truth):
        gt = truth()
        est = planted_estimate(gt)
        extra = Poses(est.names + ("other.png",), np.r_[est.R_cam_from_world, np.eye(3)[None]],
                      np.r_[est.t_cam_from_world, np.zeros((1, 3))])
        assert ape(extra, gt).n_extra == 1

    def test_input_not_mutated(self, truth):
        gt = truth()
        est = planted_estimate(gt)
        R0 = est.R_cam_from_world.copy()
        ape(est, gt)
        np.testing.assert_array_equal(est.R_cam_from_world, R0)

    def test_alignment_needs_three_cameras(self, truth):
        gt = truth()
        est = Poses(NAMES[:2], gt.R_cam_from_world[:2], gt.t_cam_from_world[:2])
        with pytest.raises(InputError, match=">= 3 registered"):
            ape(est, gt, alignment=Alignment.SE3)


class TestRpe:
    def test_planted_sim3_gives_zero(self, truth):
        gt = truth()
        r = rpe(planted_estimate(gt), gt, alignment=Alignment.SIM3)
        assert r.trans_stats_m.max < 1e-9 and r.rot_stats_deg.max < 1e-7 and len(r.pairs) == 7

    def test_one_perturbed_camera_affects_its_two_pairs(self, truth):
        gt = truth()
        R, t = np.array(gt.R_cam_from_world), np.array(gt.t_cam_from_world)
        R[4] = Rotation.from_rotvec([0.0, np.radians(1.0), 0.0]).as_matrix() @ R[4]
        r = rpe(Poses(NAMES, R, t), gt, alignment=Alignment.NONE)
        assert r.rot_err_deg[3] == pytest.approx(1.0, abs=1e-9) and r.rot_err_deg[4] == pytest.approx(1.0, abs=1e-9)
        assert np.max(np.delete(r.rot_err_deg, [3, 4])) < 1e-7

    def test_unregistered_pair_is_inf(self, truth):
        gt = truth()
        est = Poses(NAMES[1:], gt.R_cam_from_world[1:], gt.t_cam_from_world[1:])
        r = rpe(est, gt, alignment=Alignment.NONE)
        assert np.isinf(r.trans_err_m[0]) and r.trans_stats_m.n_failed == 1


class TestRelativePose:
    def test_planted_similarity_is_perfect(self, truth):
        gt = truth()
        r = relative_pose(planted_estimate(gt), gt)
        assert len(r.pairs) == 28
        assert np.max(r.pose_err_deg) < 1e-6
        assert r.auc_5_deg > 1 - 1e-6 and r.maa_10_deg == 1.0

    def test_translation_angle_is_folded(self):
        R = np.eye(3)[None].repeat(3, 0)
        t_gt = np.array([[1.0, 0, 0]] * 3)
        t_est = np.array([[-2.0, 0, 0],
                          [np.cos(np.radians(30)), np.sin(np.radians(30)), 0],
                          [np.cos(np.radians(170)), np.sin(np.radians(170)), 0]])
        eR, et, pose = relative_pose_errors_deg(R, t_est, R, t_gt)
        np.testing.assert_allclose(et, [0.0, 30.0, 10.0], atol=1e-12)
        np.testing.assert_allclose(pose, et)

    def test_degenerate_estimates_fail(self):
        R = np.eye(3)[None].repeat(2, 0)
        t_gt = np.array([[1.0, 0, 0]] * 2)
        t_est = np.array([[np.nan, 0, 0], [0.0, 0, 0]])
        _, _, pose = relative_pose_errors_deg(R, t_est, R, t_gt)
        assert np.all(np.isinf(pose))

    def test_unregistered_camera_fails_its_pairs(self, truth):
        gt = truth()
        est = planted_estimate(gt)
        est = Poses(est.names[1:], est.R_cam_from_world[1:], est.t_cam_from_world[1:])
        r = relative_pose(est, gt)
        assert r.n_failed == 7 and r.registration_ratio == 7 / 8
        assert r.auc_20_deg == pytest.approx(21 / 28, abs=1e-6)

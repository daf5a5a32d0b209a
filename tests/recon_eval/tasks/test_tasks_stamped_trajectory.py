"""Stamped trajectories (recon_eval.tasks.stamped_trajectory): evo's association as name-matched
poses, a truth pose evo pairs twice repeated, unpaired truth poses unregistered; evo's APE on the
pairs; a straight truth path leaves rpg's figures unscored but APE scored."""
import json

import numpy as np
from evo.core import metrics, sync
from evo.core.trajectory import PoseTrajectory3D
from scipy.spatial.transform import Rotation

from recon_eval.cli import main
from recon_eval.metrics.association import associate_evo
from recon_eval.metrics.poses import Poses, ape
from recon_eval.readers.tum import TumTrajectory
from recon_eval.tasks.stamped_trajectory import associated_poses


def _traj(t, c, R):
    R_cw = np.swapaxes(R, 1, 2)
    return TumTrajectory(np.asarray(t, float), Poses(tuple(f"{x:.6f}" for x in t), R_cw,
                                                     -np.einsum("nij,nj->ni", R_cw, c)))


def test_a_truth_pose_paired_twice_is_repeated_and_evos_ape_holds():
    rng = np.random.default_rng(2)
    t_gt = np.arange(6.0)
    c_gt = np.c_[t_gt, np.sin(t_gt), 0.1 * t_gt ** 2]
    R_gt = Rotation.from_rotvec(rng.normal(0, 0.3, (6, 3))).as_matrix()
    t_est = np.array([0.98, 1.02, 3.0, 4.01])  # shorter: evo pairs from it; 0.98 and 1.02 both take truth 1.0
    c_est = np.interp(t_est, t_gt, c_gt[:, 0])[:, None] * [1, 0, 0] + rng.normal(0, 0.05, (4, 3))
    R_est = Rotation.from_rotvec(rng.normal(0, 0.3, (4, 3))).as_matrix()
    est, gt = _traj(t_est, c_est, R_est), _traj(t_gt, c_gt, R_gt)
    a = associate_evo(gt.timestamps_s, est.timestamps_s, 0.05)
    assert a.ref.tolist() == [1, 1, 3, 4] and a.est.tolist() == [0, 1, 2, 3]
    e, g = associated_poses(est, gt, a)
    assert g.names == ("0.000000", "1.000000", "1.000000#2", "2.000000", "3.000000", "4.000000", "5.000000")
    assert e.names == ("1.000000", "1.000000#2", "3.000000", "4.000000")
    r = ape(e, g, alignment="se3")
    assert r.n_registered == 4 and r.trans_stats_m.n_failed == 3
    to_evo = lambda T: PoseTrajectory3D(positions_xyz=T.poses.centers_world, timestamps=T.timestamps_s,  # noqa: E731
                                        orientations_quat_wxyz=Rotation.from_matrix(np.swapaxes(
                                            T.poses.R_cam_from_world, 1, 2)).as_quat(scalar_first=True))
    ref, es = sync.associate_trajectories(to_evo(gt), to_evo(est), max_diff=0.05)
    es.align(ref)
    m = metrics.APE(metrics.PoseRelation.translation_part)
    m.process_data((ref, es))
    assert abs(m.get_statistic(metrics.StatisticsType.rmse) - r.trans_stats_m.rmse) < 1e-12


def test_a_straight_truth_path_scores_ape_and_says_why_rpg_is_not_scored(tmp_path, capsys):
    t = np.arange(5.0)
    c = np.c_[t, np.zeros(5), np.zeros(5)]
    R = np.tile(np.eye(3), (5, 1, 1))
    for name, cc in (("gt.txt", c), ("est.txt", c + 0.01)):
        (tmp_path / name).write_text("".join(f"{x} {p[0]} {p[1]} {p[2]} 0 0 0 1\n" for x, p in zip(t, cc)))
    out = tmp_path / "r.json"
    assert main(["poses", str(tmp_path / "est.txt"), str(tmp_path / "gt.txt"), "--alignment", "none", "--json",
                 str(out), "--quiet"]) == 0
    res = json.loads(out.read_text())["results"]
    assert abs(res["ape"]["trans_stats_m"]["rmse"] - 0.01 * np.sqrt(3)) < 1e-12
    assert res["vio"].startswith("not scored: umeyama: points are (nearly) collinear")

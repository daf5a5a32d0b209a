"""Visual-inertial trajectory scoring against the reference tools: evo's timestamp association
(evo installed), rpg_trajectory_evaluation's alignments and relative errors and ov_eval's NEES
(transliterated in rpg_trajectory_evaluation_ref.py and ov_eval_nees_ref.py, sources and licences
in their headers)."""
from __future__ import annotations

import numpy as np
import pytest
from evo.core import sync
from evo.core.trajectory import PoseTrajectory3D
from scipy.spatial.transform import Rotation

import ov_eval_nees_ref as ov
import rpg_trajectory_evaluation_ref as rpg
from recon_eval.metrics.association import associate_evo, matching_time_indices
from recon_eval.metrics.nees import nees
from recon_eval.metrics.rpg_trajectory import default_lengths_m, relative_errors, rpg_absolute_error, rpg_alignment

N = 300


def _quat_xyzw(R):
    return Rotation.from_matrix(R).as_quat()  # scalar last, as rpg and ov_eval read them


@pytest.fixture(scope="module")
def run():
    """A 15 s, 20 Hz hand-held-like path (truth) and a drifting estimate in a Sim(3)-moved frame
    with its covariances."""
    rng = np.random.default_rng(28)
    t = np.arange(N) * 0.05 + 1000.0
    s = t - t[0]
    p_gt = np.stack([2 * np.cos(0.4 * s) + 0.1 * s, 1.5 * np.sin(0.5 * s), 0.3 * np.sin(1.3 * s)], 1)
    R_gt = Rotation.from_euler("ZYX", np.stack([0.4 * s, 0.2 * np.sin(s), 0.15 * np.cos(0.7 * s)], 1)).as_matrix()
    drift = np.cumsum(rng.normal(0, 0.004, (N, 3)), 0)
    p_e = p_gt + drift + rng.normal(0, 0.01, (N, 3))
    wobble = np.cumsum(rng.normal(0, 0.002, (N, 3)), 0) + rng.normal(0, 0.01, (N, 3))
    R_e = Rotation.from_rotvec(wobble).as_matrix() @ R_gt
    S = Rotation.from_euler("xyz", [0.3, -0.2, 1.1]).as_matrix()
    p_e = 0.8 * p_e @ S.T + [1.0, -2.0, 0.5]
    R_e = S @ R_e
    A = rng.normal(0, 1, (N, 3, 3))
    cov_ori = 1e-4 * (A @ np.swapaxes(A, 1, 2) + 0.5 * np.eye(3))
    B = rng.normal(0, 1, (N, 3, 3))
    cov_pos = 1e-3 * (B @ np.swapaxes(B, 1, 2) + 0.5 * np.eye(3))
    return t, p_e, R_e, p_gt, R_gt, cov_ori, cov_pos


CASES = [("sim3", -1), ("sim3", 20), ("se3", -1), ("se3", 1), ("se3", 20), ("posyaw", -1), ("posyaw", 1),
         ("posyaw", 20), ("none", -1)]


@pytest.mark.parametrize("method,n_aligned", CASES)
def test_rpg_alignment_and_absolute_errors(run, agreement, method, n_aligned):
    _, p_e, R_e, p_gt, R_gt, _, _ = run
    (s, R, t), e_trans, e_rot = rpg.aligned_absolute_errors(p_e, _quat_xyzw(R_e), p_gt, _quat_xyzw(R_gt), method,
                                                            n_aligned)
    T = rpg_alignment(p_e, R_e, p_gt, R_gt, method, n_aligned)
    res = rpg_absolute_error(p_e, R_e, p_gt, R_gt, method, n_aligned)
    d = max(abs(T.scale - s), np.abs(T.R - R).max(), np.abs(T.t - t).max(),
            np.abs(res.trans_err_m - e_trans).max(), np.abs(res.rot_err_deg - e_rot).max())
    if method == "posyaw":  # the alignment is a yaw: z stays z
        assert np.allclose(T.R[2], [0, 0, 1], atol=1e-15)
    assert d < 1e-9
    agreement(f"rpg.align.{method}.{n_aligned}", "gt_from_est (s, R, t) and absolute trans (m) / rot (deg) errors",
              "rpg_trajectory_evaluation `alignTrajectory`, `compute_absolute_error` (transcribed)",
              "uzh-rpg 8c8ceec", f"{N} drifting poses in a Sim(3)-moved frame", d)


@pytest.mark.parametrize("method", ["sim3", "se3"])  # posyaw: scale 1, as se3
def test_rpg_relative_errors_per_distance_and_time(run, agreement, method):
    t, p_e, R_e, p_gt, R_gt, _, _ = run
    s = rpg_alignment(p_e, R_e, p_gt, R_gt, method).scale
    q_e, q_g = _quat_xyzw(R_e), _quat_xyzw(R_gt)
    lengths = default_lengths_m(p_gt)
    assert lengths == tuple(rpg.get_distance_from_start(p_gt)[-1] * f // 0.01 / 100 for f in (0.1, 0.2, 0.3, 0.4,
                                                                                                    0.5))
    worst = 0.0
    for L, unit, accum in [(x, "m", rpg.get_distance_from_start(p_gt)) for x in lengths] + [(2.0, "s", t - t[0]),
                                                                                            (5.0, "s", t - t[0])]:
        ref = rpg.compute_relative_error(p_e, q_e, p_gt, q_g, np.eye(4), L, 0.2 * L, accum, s)
        ours = relative_errors(p_e, R_e, p_gt, R_gt, L, unit=unit, scale=s, stamps_s=t)
        tn, tp, yaw, grav, rot, rot_m = ref
        assert len(ours.trans_err_m) == len(tn) > 10
        got = [ours.trans_err_m, ours.yaw_err_deg, ours.gravity_err_deg, ours.rot_err_deg, ours.rot_err_deg_per_m]
        want = [tn, yaw, grav, rot, rot_m]
        if unit == "m":
            got.append(ours.trans_err_pct)
            want.append(tp)
        else:  # drift per time: rpg's translation error over the duration, m/s
            got.append(ours.trans_drift_m_per_s)
            want.append(tn / L)
        worst = max(worst, max(np.abs(a - b).max() for a, b in zip(got, want)))
    assert worst < 1e-9
    agreement(f"rpg.relative.{method}", "relative trans (m, %, m/s), rot, yaw, gravity (deg) over 10-50 % of the "
              "length and 2 s, 5 s", "rpg_trajectory_evaluation `compute_relative_error` (transcribed)",
              "uzh-rpg 8c8ceec", f"{N} drifting poses in a Sim(3)-moved frame", worst)


@pytest.mark.parametrize("method,n_aligned", [("posyaw", -1), ("posyaw", 1), ("se3", -1), ("sim3", -1), ("none", -1)])
def test_nees_equals_ov_eval(run, agreement, method, n_aligned):
    _, p_e, R_e, p_gt, R_gt, cov_ori, cov_pos = run
    est7 = np.c_[p_e, _quat_xyzw(R_e)]
    gt7 = np.c_[p_gt, _quat_xyzw(R_gt)]
    n_o, n_p, m_o, m_p = ov.nees(est7, gt7, cov_ori, cov_pos, method, n_aligned)
    r = nees(p_e, R_e, cov_ori, cov_pos, p_gt, R_gt, alignment=method, n_aligned=n_aligned)
    d = max(np.abs(r.nees_ori - n_o).max() / max(1.0, np.abs(n_o).max()),
            np.abs(r.nees_pos - n_p).max() / max(1.0, np.abs(n_p).max()),
            abs(r.mean_ori - m_o) / max(1.0, abs(m_o)), abs(r.mean_pos - m_p) / max(1.0, abs(m_p)))
    assert r.kept.all() and d < 1e-9
    agreement(f"ov_eval.nees.{method}.{n_aligned}", "NEES orientation and position per pose and mean (relative)",
              "ov_eval `ResultTrajectory::calculate_nees` (transcribed)", "rpng/open_vins 6948812",
              f"{N} drifting poses, random covariances", d)


def test_nees_is_three_for_a_consistent_estimator():
    """Errors drawn from the stated covariances: the mean NEES is chi^2(3)'s mean, 3."""
    rng = np.random.default_rng(3)
    n = 4000
    p_gt = np.c_[np.linspace(0, 40, n), np.sin(np.linspace(0, 9, n)), np.zeros(n)]
    R_gt = Rotation.from_euler("z", np.linspace(0, 3, n)[:, None]).as_matrix()
    C = np.diag([1e-4, 4e-4, 9e-4])
    L = np.linalg.cholesky(C)
    e_ori, e_pos = rng.normal(size=(n, 3)) @ L.T, rng.normal(size=(n, 3)) @ L.T
    R_e = R_gt @ Rotation.from_rotvec(e_ori).as_matrix()  # e = Log(R_gt^T R_est) in the body frame
    r = nees(p_gt + e_pos, R_e, np.broadcast_to(C, (n, 3, 3)), np.broadcast_to(C, (n, 3, 3)), p_gt, R_gt,
             alignment="none")
    # chi^2(3) has variance 6: the mean of 4000 is 3 +- 0.039 (1 sigma); 4 sigma
    assert abs(r.mean_ori - 3) < 0.16 and abs(r.mean_pos - 3) < 0.16


def _evo(stamps):
    n = len(stamps)
    return PoseTrajectory3D(positions_xyz=np.zeros((n, 3)), orientations_quat_wxyz=np.tile([1.0, 0, 0, 0], (n, 1)),
                            timestamps=np.asarray(stamps, float))


@pytest.mark.parametrize("offset", [0.0, 0.013, -0.2])
@pytest.mark.parametrize("n_est", [50, 200])
def test_association_equals_evo(offset, n_est):
    rng = np.random.default_rng(n_est)
    ref = np.sort(rng.uniform(0, 10, 120))
    ref[10] = ref[11]  # a repeated stamp
    est = np.sort(rng.uniform(-0.5, 10.5, n_est))
    est[5] = est[4] + 0.0  # ties
    for max_diff in (0.005, 0.02, 0.1):
        a = associate_evo(ref, est, max_diff, offset)
        r_evo, e_evo = sync.associate_trajectories(_evo(ref), _evo(est), max_diff=max_diff, offset_2=offset)
        assert np.array_equal(ref[a.ref], r_evo.timestamps) and np.array_equal(est[a.est], e_evo.timestamps)
    # evo's linear branch for unsorted stamps
    perm = rng.permutation(n_est)
    i1, i2 = matching_time_indices(ref, est[perm], 0.05, offset)
    j1, j2 = sync.matching_time_indices(ref, est[perm], 0.05, offset)
    assert list(i1) == j1 and list(i2) == j2

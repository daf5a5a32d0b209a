"""APE / RPE against evo itself (evo 1.38, a dev dependency), and mAA against the Image Matching
Benchmark's histogram (transcribed: ubc-vision/image-matching-benchmark utils/pack_helper.py,
``compute_qt_auc``)."""
from __future__ import annotations

import copy

import evo
import numpy as np
import pytest
from evo import main_ape, main_rpe
from evo.core import metrics as evo_metrics, sync, trajectory
from scipy.spatial.transform import Rotation

from recon_eval.metrics.align import Sim3
from recon_eval.metrics.poses import Poses, ape, rpe
from recon_eval.metrics.stats import maa_deg

N = 60
STATS = ("rmse", "mean", "median", "std", "min", "max")


def _trajectory(seed: int = 3):
    """A wandering camera: world_from_cam (N, 4, 4) truth, and a noisy estimate in another frame."""
    rng = np.random.default_rng(seed)
    c = np.cumsum(rng.normal(0.0, 0.3, (N, 3)) + [0.4, 0.1, 0.0], axis=0)
    rot = Rotation.from_rotvec(np.cumsum(rng.normal(0.0, 0.08, (N, 3)), axis=0))
    Q = np.tile(np.eye(4), (N, 1, 1))
    Q[:, :3, :3], Q[:, :3, 3] = rot.as_matrix(), c
    noise_R = Rotation.from_rotvec(rng.normal(0.0, 0.01, (N, 3))).as_matrix()
    P = Q.copy()
    P[:, :3, :3] = Q[:, :3, :3] @ noise_R
    P[:, :3, 3] = c + rng.normal(0.0, 0.05, (N, 3))
    S = Sim3(Rotation.from_rotvec([0.3, -0.5, 0.9]).as_matrix(), [1.0, 2.0, -0.5], 0.7)  # est_from_truth world
    P[:, :3, :3] = S.R @ P[:, :3, :3]
    P[:, :3, 3] = S.apply(P[:, :3, 3])
    return Q, P


def _poses(T, names) -> Poses:
    R = np.swapaxes(T[:, :3, :3], 1, 2)  # cam_from_world
    return Poses(names, R, -np.einsum("nij,nj->ni", R, T[:, :3, 3]))


NAMES = tuple(f"f{k:03d}" for k in range(N))
EVO_ALIGN = {"none": {}, "se3": {"align": True}, "sim3": {"align": True, "correct_scale": True},
             "scale": {"correct_scale": True}, "origin": {"align_origin": True}}


def _evo_rpe(Q, P, relation, **kw):
    ref, est = trajectory.PosePath3D(poses_se3=list(Q)), trajectory.PosePath3D(poses_se3=list(P))
    return main_rpe.rpe(ref, est, relation, **kw).stats


def _diff(ours, stats) -> float:
    return max(abs(getattr(ours, k) - stats[k]) for k in STATS)


CASES = [  # (delta, unit, all_pairs, alignment, n_to_align)
    (1, "f", False, "sim3", -1), (20, "f", False, "sim3", -1), (20, "f", True, "sim3", -1),
    (7, "f", False, "se3", -1), (5, "f", True, "none", -1), (3, "f", False, "scale", -1),
    (3, "f", False, "origin", -1), (4, "f", False, "sim3", 10),
    (2.0, "m", False, "sim3", -1), (2.0, "m", True, "se3", -1),
    (10.0, "d", False, "sim3", -1), (10.0, "d", True, "sim3", -1), (0.2, "r", False, "none", -1),
]


@pytest.mark.parametrize("delta,unit,all_pairs,alignment,n_to_align", CASES)
def test_rpe_equals_evo_rpe(delta, unit, all_pairs, alignment, n_to_align, agreement):
    Q, P = _trajectory()
    ours = rpe(_poses(P, NAMES), _poses(Q, NAMES), delta=delta, delta_unit=unit, all_pairs=all_pairs,
               alignment=alignment, n_to_align=n_to_align)
    kw = dict(delta=delta, delta_unit=evo_metrics.Unit({"f": "frames", "m": "m", "d": "deg", "r": "rad"}[unit]),
              all_pairs=all_pairs, n_to_align=n_to_align, **EVO_ALIGN[alignment])
    et = _evo_rpe(Q.copy(), P.copy(), evo_metrics.PoseRelation.translation_part, **kw)
    er = _evo_rpe(Q.copy(), P.copy(), evo_metrics.PoseRelation.rotation_angle_deg, **kw)
    assert ours.trans_stats_m.n_failed == 0 and ours.trans_stats_m.n > 0
    d = max(_diff(ours.trans_stats_m, et), _diff(ours.rot_stats_deg, er) * np.pi / 180)
    assert d < 1e-9
    mode = "all pairs" if all_pairs else "consecutive"
    agreement(f"rpe.{unit}{delta:g}.{mode.split()[0]}.{alignment}{'' if n_to_align < 0 else f'.n{n_to_align}'}",
              f"RPE stats, delta {delta:g} {unit} {mode}, {alignment} alignment"
              f"{'' if n_to_align < 0 else f' on {n_to_align} poses'} (m; rad for rotation)",
              "evo `evo_rpe`", evo.__version__, "60 noisy poses in a Sim(3)-moved frame", d)


@pytest.mark.parametrize("alignment", ["none", "se3", "sim3", "scale", "origin"])
def test_ape_equals_evo_ape(alignment, agreement):
    Q, P = _trajectory(5)
    ours = ape(_poses(P, NAMES), _poses(Q, NAMES), alignment=alignment)
    d = 0.0
    for rel, field, k in ((evo_metrics.PoseRelation.translation_part, "trans_stats_m", 1.0),
                          (evo_metrics.PoseRelation.rotation_angle_deg, "rot_stats_deg", np.pi / 180)):
        ref, est = trajectory.PosePath3D(poses_se3=list(Q)), trajectory.PosePath3D(poses_se3=list(P))
        st = main_ape.ape(ref, est, rel, **EVO_ALIGN[alignment]).stats
        d = max(d, _diff(getattr(ours, field), st) * k)
    assert d < 1e-9
    agreement(f"ape.{alignment}", f"APE stats, {alignment} alignment (m; rad for rotation)", "evo `evo_ape`",
              evo.__version__, "60 noisy poses in a Sim(3)-moved frame", d)


@pytest.mark.parametrize("delta,all_pairs", [(1, False), (5, False), (5, True)])
def test_rpe_across_unregistered_frames_is_evo_after_association(delta, all_pairs, agreement):
    """evo associates TUM trajectories by timestamp and pairs the poses that survive: its number is
    the finite part of ours; the truth-frame pairs the missing cameras break are our failures."""
    Q, P = _trajectory(7)
    missing = [0, 11, 12, 30, 47]
    keep = [k for k in range(N) if k not in missing]
    ts = np.arange(N, dtype=float)
    ref = trajectory.PoseTrajectory3D(poses_se3=list(Q), timestamps=ts)
    est = trajectory.PoseTrajectory3D(poses_se3=list(P[keep]), timestamps=ts[keep])
    ref, est = sync.associate_trajectories(ref, est, max_diff=0.01)
    kw = dict(delta=delta, delta_unit=evo_metrics.Unit.frames, all_pairs=all_pairs, align=True, correct_scale=True)
    rt = main_rpe.rpe(copy.deepcopy(ref), copy.deepcopy(est), evo_metrics.PoseRelation.translation_part, **kw)
    et = rt.stats
    er = main_rpe.rpe(ref, est, evo_metrics.PoseRelation.rotation_angle_deg, **kw).stats
    ours = rpe(_poses(P[keep], tuple(NAMES[k] for k in keep)), _poses(Q, NAMES), delta=delta, all_pairs=all_pairs)
    d = max(_diff(ours.trans_stats_m, et), _diff(ours.rot_stats_deg, er) * np.pi / 180)
    assert d < 1e-9
    # the failures: truth-frame pairs with a missing camera, counted
    if all_pairs:
        truth_pairs = [(i, i + delta) for i in range(N - delta)]
    else:
        truth_pairs = list(zip(range(0, N, delta), range(delta, N, delta)))
    broken = sum(1 for i, j in truth_pairs if i in missing or j in missing)
    assert ours.n_failed_pairs == broken == ours.trans_stats_m.n_failed > 0
    assert ours.trans_stats_m.n == len(rt.np_arrays["error_array"])
    agreement(f"rpe.gaps.f{delta}.{'all' if all_pairs else 'consecutive'}",
              f"RPE across 5 unregistered frames, delta {delta} f {'all pairs' if all_pairs else 'consecutive'}"
              " (m; rad)", "evo `evo_rpe` after `associate_trajectories`", evo.__version__,
              "60 poses, 5 missing from the estimate", d)


def _imb_compute_qt_auc(err_deg):
    """image-matching-benchmark utils/pack_helper.py compute_qt_auc, lines 'err_qt[err_qt == np.inf] = 1e6'
    .. "res_dict['qt_auc_10{}'.format(label)] = np.mean(qt_acc)", transcribed (the errors given
    in degrees, IMB's 'err_qt * 180.0 / np.pi' already applied): (qt_auc_05, qt_auc_10)."""
    err_qt = np.asarray(err_deg, float).copy()
    if len(err_qt) > 0:
        err_qt[err_qt == np.inf] = 1e6
        bars = np.arange(11)
        qt_hist, _ = np.histogram(err_qt, bars)
        num_pair = float(len(err_qt))
        qt_hist = qt_hist.astype(float) / num_pair
        qt_acc = np.cumsum(qt_hist)
    else:
        qt_acc = [0] * 10
    return float(np.mean(qt_acc[:5])), float(np.mean(qt_acc))


def test_maa_equals_image_matching_benchmark(agreement):
    rng = np.random.default_rng(0)
    e = np.r_[rng.uniform(0, 12, 200), np.arange(11.0), [10.0, 10.0, np.inf, 5.0]]  # exact thresholds included
    auc_05, auc_10 = _imb_compute_qt_auc(e)
    d = max(abs(maa_deg(e) - auc_10), abs(maa_deg(e, 10) - auc_10))
    assert d == 0
    assert maa_deg([10.0]) == 0.1 and maa_deg([1.0]) == 0.9  # the closed last bin, the open others
    agreement("maa10", "mAA@10 deg (errors exactly at the thresholds included)",
              "Image Matching Benchmark `compute_qt_auc` (transcribed)", "ubc-vision master",
              "215 pose errors, 15 on the bin edges", d)
    d5 = abs(maa_deg(e, 5) - auc_05)
    assert d5 == 0
    assert maa_deg([5.0], 5) == 0.0 == _imb_compute_qt_auc([5.0])[0]  # 5 deg falls in [5, 6): not within 5
    assert maa_deg([4.5], 5) == 0.2  # counted at 5 only
    agreement("maa5", "mAA@5 deg (errors exactly at the thresholds included)",
              "Image Matching Benchmark `compute_qt_auc` `qt_auc_05` (transcribed)", "ubc-vision master",
              "215 pose errors, 15 on the bin edges", d5)
    assert maa_deg([], 5) == 0.0 == _imb_compute_qt_auc([])[0]

"""PCK and per-part pose errors against closed forms."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from recon_eval.metrics.objects_bop import symmetry_transforms
from recon_eval.metrics.objects_parts import (
    articulated_pose_errors, joint_rotation_errors, pck, recovered_joint_angle_rad, twist_angle_rad,
)


def test_pck_counts_labelled_keypoints_within_alpha_size():
    gt = np.zeros((2, 3, 2))
    pred = np.array([[[3.0, 4.0], [10.0, 0.0], [0.0, 0.0]],  # distances 5, 10, 0
                     [[np.nan, 0.0], [0.0, 1.0], [0.0, 50.0]]])  # missing, 1, 50 (unlabelled)
    labelled = np.array([[True, True, True], [True, True, False]])
    r = pck(pred, gt, labelled, [50.0, 10.0], alphas=(0.1, 0.2))
    # alpha 0.1: thresholds 5 (<= 5 counts) and 1 -> 5, 0 | 1 correct = 3 of 5
    assert r.pck == (3 / 5, 4 / 5) and r.n_scored == 5 and r.n_missing == 1


def test_part_errors_and_joint_angles():
    pts = np.array([[0.0, 0.0, 0.0], [100.0, 0.0, 0.0], [0.0, 50.0, 0.0]])
    Rg, tg = np.eye(3), np.array([0.0, 0.0, 500.0])
    R10 = Rotation.from_euler("z", 10, degrees=True).as_matrix()
    flip = {"symmetries_discrete": [[-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]]}
    r = articulated_pose_errors(
        {"base": (Rg, tg + [3.0, 4.0, 0.0]), "arm": (R10, tg), "cap": (Rg @ np.diag([-1.0, -1.0, 1.0]), tg)},
        {"base": (Rg, tg), "arm": (Rg, tg), "cap": (Rg, tg), "lost": (Rg, tg)},
        {"base": pts, "arm": pts, "cap": pts, "lost": pts}, {"cap": symmetry_transforms(flip)},
        joints_est_deg={"elbow": 359.0}, joints_gt_deg={"elbow": 1.0, "wrist": 0.0})
    base, arm, cap, lost = r.parts
    assert base.trans_err == pytest.approx(5.0) and base.rot_err_deg == 0 and base.add == pytest.approx(5.0)
    assert arm.rot_err_deg == pytest.approx(10.0) and arm.trans_err == 0
    assert cap.rot_err_deg == pytest.approx(0.0, abs=1e-9)  # the declared 180 deg symmetry
    assert lost.rot_err_deg == np.inf and r.max_rot_err_deg == np.inf
    assert r.joint_err_deg == {"elbow": pytest.approx(2.0), "wrist": np.inf}


def test_joint_rotation_error_is_the_joint_angle_difference():
    axis_angle = lambda deg: Rotation.from_rotvec(np.radians(deg) * np.array([0.0, 1.0, 0.0])).as_matrix()  # noqa: E731
    base = Rotation.from_rotvec([0.2, -0.4, 0.9]).as_matrix()
    t = np.zeros(3)
    gt = {"torso": (base, t), "arm": (base @ axis_angle(30), t), "hand": (base @ axis_angle(30) @ axis_angle(10), t)}
    est = {"torso": (base, t), "arm": (base @ axis_angle(37), t)}
    e = joint_rotation_errors(est, gt, {"arm": "torso", "hand": "arm", "torso": None})
    assert e["arm"] == pytest.approx(7.0) and e["hand"] == np.inf and "torso" not in e


def test_recovered_joint_angle_is_the_twist_about_the_axis():
    axis = np.array([0.0, 0.6, 0.8])
    rest = Rotation.from_rotvec([0.3, 0.1, -0.2]).as_matrix()  # the child's rest rotation in the parent
    turn = lambda rad: Rotation.from_rotvec(rad * axis).as_matrix()  # noqa: E731
    parent_gt = Rotation.from_rotvec([0.5, -0.2, 0.1]).as_matrix()
    parent_est = Rotation.from_rotvec([0.1, 0.4, 0.3]).as_matrix()  # a wrong parent: the joint is relative
    child_gt = parent_gt @ turn(0.7) @ rest
    child_est = parent_est @ turn(0.7 + 0.25) @ rest
    assert recovered_joint_angle_rad(parent_est, child_est, parent_gt, child_gt, axis, 0.7) == pytest.approx(0.95)
    assert twist_angle_rad(turn(-3.0), axis) == pytest.approx(-3.0)
    assert twist_angle_rad(Rotation.from_rotvec([0.4, 0, 0]).as_matrix(), [0, 0, 1]) == pytest.approx(0.0)

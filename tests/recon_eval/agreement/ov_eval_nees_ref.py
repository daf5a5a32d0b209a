"""A transliteration, for the agreement tests only, of OpenVINS ov_eval's NEES: rpng/open_vins
(commit 6948812) ``ov_eval/src/calc/ResultTrajectory.cpp`` (the constructor's alignment of the truth into
the estimate's frame and ``calculate_nees``) and the JPL quaternion helpers it calls from
``ov_core/src/utils/quat_ops.h`` (``quat_2_Rot``, ``rot_2_quat``, ``quat_multiply``, ``Inv``,
``log_so3``, ``skew_x``). The alignment itself (``AlignTrajectory::align_trajectory``, with
``AlignUtils::align_umeyama`` and ``get_best_yaw``) is the same arithmetic as
rpg_trajectory_evaluation's and is taken from that transliteration (rpg_trajectory_evaluation_ref).

Licence of the original: GNU General Public License v3.0 (OpenVINS, Copyright (C) 2018-2023
Patrick Geneva, Guoquan Huang, OpenVINS Contributors). This file is test code that restates the
computation to check ours against; it is not shipped in the package.
"""
import numpy as np

import rpg_trajectory_evaluation_ref as rpg


def skew_x(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def quat_2_Rot(q):  # JPL, [x, y, z, w]
    q_x = skew_x(q[0:3])
    return (2 * q[3] ** 2 - 1) * np.eye(3) - 2 * q[3] * q_x + 2 * np.outer(q[0:3], q[0:3])


def rot_2_quat(rot):
    q = np.zeros(4)
    T = np.trace(rot)
    if rot[0, 0] >= T and rot[0, 0] >= rot[1, 1] and rot[0, 0] >= rot[2, 2]:
        q[0] = np.sqrt((1 + 2 * rot[0, 0] - T) / 4)
        q[1] = (1 / (4 * q[0])) * (rot[0, 1] + rot[1, 0])
        q[2] = (1 / (4 * q[0])) * (rot[0, 2] + rot[2, 0])
        q[3] = (1 / (4 * q[0])) * (rot[1, 2] - rot[2, 1])
    elif rot[1, 1] >= T and rot[1, 1] >= rot[0, 0] and rot[1, 1] >= rot[2, 2]:
        q[1] = np.sqrt((1 + 2 * rot[1, 1] - T) / 4)
        q[0] = (1 / (4 * q[1])) * (rot[0, 1] + rot[1, 0])
        q[2] = (1 / (4 * q[1])) * (rot[1, 2] + rot[2, 1])
        q[3] = (1 / (4 * q[1])) * (rot[2, 0] - rot[0, 2])
    elif rot[2, 2] >= T and rot[2, 2] >= rot[0, 0] and rot[2, 2] >= rot[1, 1]:
        q[2] = np.sqrt((1 + 2 * rot[2, 2] - T) / 4)
        q[0] = (1 / (4 * q[2])) * (rot[0, 2] + rot[2, 0])
        q[1] = (1 / (4 * q[2])) * (rot[1, 2] + rot[2, 1])
        q[3] = (1 / (4 * q[2])) * (rot[0, 1] - rot[1, 0])
    else:
        q[3] = np.sqrt((1 + T) / 4)
        q[0] = (1 / (4 * q[3])) * (rot[1, 2] - rot[2, 1])
        q[1] = (1 / (4 * q[3])) * (rot[2, 0] - rot[0, 2])
        q[2] = (1 / (4 * q[3])) * (rot[0, 1] - rot[1, 0])
    if q[3] < 0:
        q = -q
    return q / np.linalg.norm(q)


def quat_multiply(q, p):
    Qm = np.zeros((4, 4))
    Qm[0:3, 0:3] = q[3] * np.eye(3) - skew_x(q[0:3])
    Qm[0:3, 3] = q[0:3]
    Qm[3, 0:3] = -q[0:3]
    Qm[3, 3] = q[3]
    q_t = Qm @ p
    if q_t[3] < 0:
        q_t *= -1
    return q_t / np.linalg.norm(q_t)


def Inv(q):
    return np.r_[-q[0:3], q[3]]


def log_so3(R):
    R11, R12, R13 = R[0]
    R21, R22, R23 = R[1]
    R31, R32, R33 = R[2]
    tr = np.trace(R)
    if tr + 1.0 < 1e-10:
        if abs(R33 + 1.0) > 1e-5:
            return (np.pi / np.sqrt(2.0 + 2.0 * R33)) * np.array([R13, R23, 1.0 + R33])
        if abs(R22 + 1.0) > 1e-5:
            return (np.pi / np.sqrt(2.0 + 2.0 * R22)) * np.array([R12, 1.0 + R22, R32])
        return (np.pi / np.sqrt(2.0 + 2.0 * R11)) * np.array([1.0 + R11, R21, R31])
    tr_3 = tr - 3.0
    if tr_3 < -1e-7:
        theta = np.arccos((tr - 1.0) / 2.0)
        magnitude = theta / (2.0 * np.sin(theta))
    else:
        magnitude = 0.5 - tr_3 / 12.0
    return magnitude * np.array([R32 - R23, R13 - R31, R21 - R12])


def nees(est_poses, gt_poses, est_covori, est_covpos, alignment_method, n_aligned=-1):
    """Poses (N, 7) ``x y z qx qy qz qw`` as ov_eval's files hold them; returns (nees_ori,
    nees_pos) lists over the poses kept, and their means (Statistics::calculate)."""
    # ResultTrajectory(): align_trajectory(gt_poses, est_poses, R_GTtoEST, t_GTinEST, s_GTtoEST)
    s, R_GTtoEST, t_GTinEST = rpg.alignTrajectory(gt_poses[:, 0:3], est_poses[:, 0:3], gt_poses[:, 3:7],
                                                  est_poses[:, 3:7], alignment_method, n_aligned)
    q_GTtoEST = rot_2_quat(R_GTtoEST)
    gt_aligned = []
    for g in gt_poses:
        gt_aligned.append(np.r_[s * R_GTtoEST @ g[0:3] + t_GTinEST, quat_multiply(g[3:7], Inv(q_GTtoEST))])
    out_ori, out_pos = [], []
    for i in range(len(est_poses)):  # calculate_nees
        e_R = quat_2_Rot(gt_aligned[i][3:7]) @ quat_2_Rot(est_poses[i][3:7]).T
        errori = -log_so3(e_R)
        ori_nees = errori @ np.linalg.inv(est_covori[i]) @ errori
        errpos = gt_aligned[i][0:3] - est_poses[i][0:3]
        pos_nees = errpos @ np.linalg.inv(est_covpos[i]) @ errpos
        if np.isnan(ori_nees) or np.isnan(pos_nees):
            continue
        out_ori.append(ori_nees)
        out_pos.append(pos_nees)
    return np.array(out_ori), np.array(out_pos), float(np.mean(out_ori)), float(np.mean(out_pos))

"""A transliteration, for the agreement tests only, of rpg_trajectory_evaluation's alignment and
relative-error code: uzh-rpg/rpg_trajectory_evaluation (commit 8c8ceec), files
``src/rpg_trajectory_evaluation/align_utils.py``, ``align_trajectory.py``,
``compute_trajectory_errors.py`` (``compute_relative_error``, ``compute_absolute_error``),
``trajectory_utils.py`` and, from its ``transformations.py`` (Christoph Gohlke, BSD-3-Clause),
``quaternion_matrix`` (x, y, z, w order in that copy) and ``euler_from_matrix`` for 'rzyx'.

Licence of the original: MIT License, Copyright (c) 2018 Zichao Zhang (Robotics and Perception
Group, University of Zurich, Switzerland). Python 2 idioms updated (print, np.linalg.svd); the
logic, loops and comparisons are kept as written, on purpose, including the pairing of
``enumerate(comparisons)``.
"""
import math

import numpy as np

_EPS = np.finfo(float).eps * 4.0


def quaternion_matrix(quaternion):  # transformations.py, [x, y, z, w]
    q = np.array(quaternion[:4], dtype=np.float64, copy=True)
    nq = np.dot(q, q)
    if nq < _EPS:
        return np.identity(4)
    q *= math.sqrt(2.0 / nq)
    q = np.outer(q, q)
    return np.array((
        (1.0 - q[1, 1] - q[2, 2], q[0, 1] - q[2, 3], q[0, 2] + q[1, 3], 0.0),
        (q[0, 1] + q[2, 3], 1.0 - q[0, 0] - q[2, 2], q[1, 2] - q[0, 3], 0.0),
        (q[0, 2] - q[1, 3], q[1, 2] + q[0, 3], 1.0 - q[0, 0] - q[1, 1], 0.0),
        (0.0, 0.0, 0.0, 1.0)), dtype=np.float64)


def euler_from_matrix_rzyx(matrix):  # transformations.py euler_from_matrix(M, 'rzyx'): (0, 0, 0, 1)
    i, j, k = 0, 1, 2
    M = np.array(matrix, dtype=np.float64)[:3, :3]
    cy = math.sqrt(M[i, i] * M[i, i] + M[j, i] * M[j, i])
    if cy > _EPS:
        ax = math.atan2(M[k, j], M[k, k])
        ay = math.atan2(-M[k, i], cy)
        az = math.atan2(M[j, i], M[i, i])
    else:
        ax = math.atan2(-M[j, k], M[j, j])
        ay = math.atan2(-M[k, i], cy)
        az = 0.0
    ax, az = az, ax  # frame: rotating
    return ax, ay, az


def rotation_matrix_z(angle):  # transformations.rotation_matrix(angle, [0, 0, 1])[:3, :3]
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


# ---- align_trajectory.py
def get_best_yaw(C):
    A = C[0, 1] - C[1, 0]
    B = C[0, 0] + C[1, 1]
    return np.pi / 2 - np.arctan2(B, A)


def align_umeyama(model, data, known_scale=False, yaw_only=False):
    mu_M = model.mean(0)
    mu_D = data.mean(0)
    model_zerocentered = model - mu_M
    data_zerocentered = data - mu_D
    n = np.shape(model)[0]
    C = 1.0 / n * np.dot(model_zerocentered.transpose(), data_zerocentered)
    sigma2 = 1.0 / n * np.multiply(data_zerocentered, data_zerocentered).sum()
    U_svd, D_svd, V_svd = np.linalg.svd(C)
    D_svd = np.diag(D_svd)
    V_svd = np.transpose(V_svd)
    S = np.eye(3)
    if np.linalg.det(U_svd) * np.linalg.det(V_svd) < 0:
        S[2, 2] = -1
    if yaw_only:
        rot_C = np.dot(data_zerocentered.transpose(), model_zerocentered)
        theta = get_best_yaw(rot_C)
        R = rotation_matrix_z(theta)
    else:
        R = np.dot(U_svd, np.dot(S, np.transpose(V_svd)))
    if known_scale:
        s = 1
    else:
        s = 1.0 / sigma2 * np.trace(np.dot(D_svd, S))
    t = mu_M - s * np.dot(R, mu_D)
    return s, R, t


# ---- align_utils.py
def _getIndices(n_aligned, total_n):
    if n_aligned == -1:
        return np.arange(0, total_n)
    assert total_n >= n_aligned >= 1
    return np.arange(0, n_aligned)


def alignPositionYawSingle(p_es, p_gt, q_es, q_gt):
    g_rot = quaternion_matrix(q_gt[0, :])[0:3, 0:3]
    est_rot = quaternion_matrix(q_es[0, :])[0:3, 0:3]
    C_R = np.dot(est_rot, g_rot.transpose())
    theta = get_best_yaw(C_R)
    R = rotation_matrix_z(theta)
    t = p_gt[0, :] - np.dot(R, p_es[0, :])
    return R, t


def alignPositionYaw(p_es, p_gt, q_es, q_gt, n_aligned=1):
    if n_aligned == 1:
        return alignPositionYawSingle(p_es, p_gt, q_es, q_gt)
    idxs = _getIndices(n_aligned, p_es.shape[0])
    _, R, t = align_umeyama(p_gt[idxs, 0:3], p_es[idxs, 0:3], known_scale=True, yaw_only=True)
    return np.array(R), np.array(t).reshape((3,))


def alignSE3Single(p_es, p_gt, q_es, q_gt):
    g_rot = quaternion_matrix(q_gt[0, :])[0:3, 0:3]
    est_rot = quaternion_matrix(q_es[0, :])[0:3, 0:3]
    R = np.dot(g_rot, np.transpose(est_rot))
    t = p_gt[0, :] - np.dot(R, p_es[0, :])
    return R, t


def alignSE3(p_es, p_gt, q_es, q_gt, n_aligned=-1):
    if n_aligned == 1:
        return alignSE3Single(p_es, p_gt, q_es, q_gt)
    idxs = _getIndices(n_aligned, p_es.shape[0])
    s, R, t = align_umeyama(p_gt[idxs, 0:3], p_es[idxs, 0:3], known_scale=True)
    return np.array(R), np.array(t).reshape((3,))


def alignSIM3(p_es, p_gt, q_es, q_gt, n_aligned=-1):
    idxs = _getIndices(n_aligned, p_es.shape[0])
    return align_umeyama(p_gt[idxs, 0:3], p_es[idxs, 0:3])


def alignTrajectory(p_es, p_gt, q_es, q_gt, method, n_aligned=-1):
    s = 1
    if method == 'sim3':
        assert n_aligned >= 2 or n_aligned == -1, "sim3 uses at least 2 frames"
        s, R, t = alignSIM3(p_es, p_gt, q_es, q_gt, n_aligned)
    elif method == 'se3':
        R, t = alignSE3(p_es, p_gt, q_es, q_gt, n_aligned)
    elif method == 'posyaw':
        R, t = alignPositionYaw(p_es, p_gt, q_es, q_gt, n_aligned)
    elif method == 'none':
        R = np.identity(3)
        t = np.zeros((3,))
    return s, R, t


# ---- trajectory_utils.py
def get_rigid_body_trafo(quat, trans):
    T = quaternion_matrix(quat)
    T[0:3, 3] = trans
    return T


def get_distance_from_start(gt_translation):
    distances = np.diff(gt_translation[:, 0:3], axis=0)
    distances = np.sqrt(np.sum(np.multiply(distances, distances), 1))
    distances = np.cumsum(distances)
    return np.concatenate(([0], distances))


def compute_comparison_indices_length(distances, dist, max_dist_diff):
    max_idx = len(distances)
    comparisons = []
    for idx, d in enumerate(distances):
        best_idx = -1
        error = max_dist_diff
        for i in range(idx, max_idx):
            if np.abs(distances[i] - (d + dist)) < error:
                best_idx = i
                error = np.abs(distances[i] - (d + dist))
        if best_idx != -1:
            comparisons.append(best_idx)
    return comparisons


def compute_angle(transform):
    return np.arccos(min(1, max(-1, (np.trace(transform[0:3, 0:3]) - 1) / 2))) * 180.0 / np.pi


# ---- compute_trajectory_errors.py
def compute_relative_error(p_es, q_es, p_gt, q_gt, T_cm, dist, max_dist_diff, accum_distances=(), scale=1.0):
    if len(accum_distances) == 0:
        accum_distances = get_distance_from_start(p_gt)
    comparisons = compute_comparison_indices_length(accum_distances, dist, max_dist_diff)
    if len(comparisons) < 2:
        return None
    T_mc = np.linalg.inv(T_cm)
    errors = []
    for idx, c in enumerate(comparisons):
        if not c == -1:
            T_c1 = get_rigid_body_trafo(q_es[idx, :], p_es[idx, :])
            T_c2 = get_rigid_body_trafo(q_es[c, :], p_es[c, :])
            T_c1_c2 = np.dot(np.linalg.inv(T_c1), T_c2)
            T_c1_c2[:3, 3] *= scale
            T_m1 = get_rigid_body_trafo(q_gt[idx, :], p_gt[idx, :])
            T_m2 = get_rigid_body_trafo(q_gt[c, :], p_gt[c, :])
            T_m1_m2 = np.dot(np.linalg.inv(T_m1), T_m2)
            T_m1_m2_in_c1 = np.dot(T_cm, np.dot(T_m1_m2, T_mc))
            T_error_in_c2 = np.dot(np.linalg.inv(T_m1_m2_in_c1), T_c1_c2)
            T_c2_rot = np.eye(4)
            T_c2_rot[0:3, 0:3] = T_c2[0:3, 0:3]
            errors.append(np.dot(T_c2_rot, np.dot(T_error_in_c2, np.linalg.inv(T_c2_rot))))
    error_trans_norm, error_trans_perc, error_yaw, error_gravity, e_rot, e_rot_deg_per_m = [], [], [], [], [], []
    for e in errors:
        tn = np.linalg.norm(e[0:3, 3])
        error_trans_norm.append(tn)
        error_trans_perc.append(tn / dist * 100)
        ypr_angles = euler_from_matrix_rzyx(e)
        e_rot.append(compute_angle(e))
        error_yaw.append(abs(ypr_angles[0]) * 180.0 / np.pi)
        error_gravity.append(np.sqrt(ypr_angles[1] ** 2 + ypr_angles[2] ** 2) * 180.0 / np.pi)
        e_rot_deg_per_m.append(e_rot[-1] / dist)
    return (np.array(error_trans_norm), np.array(error_trans_perc), np.array(error_yaw), np.array(error_gravity),
            np.array(e_rot), np.array(e_rot_deg_per_m))


def aligned_absolute_errors(p_es, q_es, p_gt, q_gt, method, n_aligned):
    """trajectory.py ``align_trajectory`` then compute_absolute_error's e_trans and e_rot (deg:
    rpg takes |logmap_so3(R_we R_wg^-1)|; its angle is arccos of the trace's, written here so)."""
    s, R, t = alignTrajectory(p_es, p_gt, q_es, q_gt, method, n_aligned)
    p_al = np.array([s * R.dot(p) + t for p in p_es])
    e_trans = np.sqrt(np.sum((p_gt - p_al) ** 2, 1))
    e_rot = []
    for q_e, q_g in zip(q_es, q_gt):
        R_we = R.dot(quaternion_matrix(q_e)[:3, :3])
        R_wg = quaternion_matrix(q_g)[:3, :3]
        e_rot.append(compute_angle(np.dot(R_we, np.linalg.inv(R_wg))))
    return (s, R, t), e_trans, np.array(e_rot)

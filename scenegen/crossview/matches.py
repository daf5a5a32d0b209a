"""Putative match sets for estimator benchmarks, with labels.

Rows of a match array (N, 8) float64, columns :data:`MATCH_COLUMNS`:
``u_i, v_i`` (observed point in i), ``u_j, v_j`` (observed point in j), ``u_j_true, v_j_true``
(the exact correspondence of the TRUE point of i: its pixel centre for synthetic sets, the keypoint
for SIFT), ``label`` (:data:`LABELS`) and ``error_px`` = |(u_j, v_j) - (u_j_true, v_j_true)|
(+inf where there is no truth). All pixels are OpenCV pixels of the raw (distorted) images.

Synthetic sets (:func:`synthetic_matches`): pixels drawn uniformly without replacement from the
pixels of i that are VISIBLE in j; inliers get independent N(0, sigma_px^2) noise on both
coordinates of both points; outliers replace the j point by either a uniform draw over j's image
(at least ``near_miss_px[0]`` from the truth) or a near miss at a distance uniform in
``near_miss_px`` from the truth, in a uniform direction. Seeded: numpy's default_rng(seed).
"""
from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from scenegen.dataset.crossview import INLIER, MATCH_COLUMNS, NEAR_MISS_OUTLIER, NO_TRUTH, UNIFORM_OUTLIER, WRONG
from scenegen.geometry.color import to_grey8


@dataclass(frozen=True, kw_only=True)
class MatchParams:
    count: int  # matches per pair (fewer if fewer pixels are visible)
    sigma_px: float  # inlier noise, px, per coordinate
    outlier_fraction: float  # in [0, 1)
    near_miss_fraction: float  # share of the outliers that are near misses, in [0, 1]
    near_miss_px: tuple[float, float]  # (min, max) distance of near misses from the truth, px
    seed: int


def synthetic_matches(uv_j, visible, width_j: int, height_j: int, p: MatchParams) -> np.ndarray:
    """(N, 8) labelled matches from a correspondence field: ``uv_j`` (H, W, 2) truth positions in j,
    ``visible`` (H, W) bool; j's image size in pixels."""
    rng = np.random.default_rng(p.seed)
    vv, uu = np.nonzero(np.asarray(visible, bool))
    n = min(int(p.count), len(uu))
    if n == 0:
        return np.zeros((0, len(MATCH_COLUMNS)))
    pick = rng.choice(len(uu), size=n, replace=False)
    xi = np.stack([uu[pick], vv[pick]], 1).astype(np.float64)
    xj_true = np.asarray(uv_j, np.float64)[vv[pick], uu[pick]]
    n_out = int(round(n * p.outlier_fraction))
    n_near = int(round(n_out * p.near_miss_fraction))
    label = np.full(n, INLIER, np.float64)
    label[:n_near] = NEAR_MISS_OUTLIER
    label[n_near:n_out] = UNIFORM_OUTLIER
    obs_i = xi + rng.normal(0.0, p.sigma_px, xi.shape)
    obs_j = xj_true + rng.normal(0.0, p.sigma_px, xi.shape)
    lo, hi = p.near_miss_px
    ang = rng.uniform(0.0, 2 * np.pi, n_near)
    r = rng.uniform(lo, hi, n_near)
    obs_j[:n_near] = xj_true[:n_near] + np.stack([r * np.cos(ang), r * np.sin(ang)], 1)
    for k in range(n_near, n_out):  # uniform over j's image, away from the truth
        while True:
            q = rng.uniform([-0.5, -0.5], [width_j - 0.5, height_j - 0.5])
            if np.hypot(*(q - xj_true[k])) >= lo:
                break
        obs_j[k] = q
    err = np.hypot(*(obs_j - xj_true).T)
    rows = np.column_stack([obs_i, obs_j, xj_true, label, err])
    return rows[rng.permutation(n)]


def sift_matches(image_i, image_j, ratio: float = 0.8) -> tuple[np.ndarray, np.ndarray]:
    """SIFT (OpenCV, default parameters) keypoints matched with Lowe's ratio test ``ratio``
    (brute force, L2): ((N, 2) points of i, (N, 2) points of j), OpenCV pixels."""
    sift = cv2.SIFT_create()
    kp_i, des_i = sift.detectAndCompute(to_grey8(image_i), None)
    kp_j, des_j = sift.detectAndCompute(to_grey8(image_j), None)
    if des_i is None or des_j is None or len(kp_j) < 2:
        return np.zeros((0, 2)), np.zeros((0, 2))
    knn = cv2.BFMatcher(cv2.NORM_L2).knnMatch(des_i, des_j, k=2)
    good = [m[0] for m in knn if len(m) == 2 and m[0].distance < ratio * m[1].distance]
    pi = np.array([kp_i[m.queryIdx].pt for m in good], np.float64).reshape(-1, 2)
    pj = np.array([kp_j[m.trainIdx].pt for m in good], np.float64).reshape(-1, 2)
    return pi, pj


def label_real_matches(pts_i, pts_j, truth_j, truth_visible, inlier_px: float) -> np.ndarray:
    """(N, 8) rows for real matches: ``truth_j`` (N, 2) exact correspondences of ``pts_i`` in j,
    ``truth_visible`` (N,) bool; inlier when visible and within ``inlier_px`` of the truth."""
    pts_i, pts_j = np.asarray(pts_i, float), np.asarray(pts_j, float)
    truth_j = np.asarray(truth_j, float)
    vis = np.asarray(truth_visible, bool)
    err = np.where(vis, np.hypot(*(pts_j - truth_j).T) if len(pts_j) else np.zeros(0), np.inf)
    label = np.where(~vis, NO_TRUTH, np.where(err <= inlier_px, INLIER, WRONG)).astype(np.float64)
    return np.column_stack([pts_i, pts_j, truth_j, label, err]).reshape(-1, len(MATCH_COLUMNS))

"""The nineteen F estimators of recon_eval.estimators.fundamental (issue 34): exact on exact data,
FNS / CFNS at the Sampson minimum a general optimiser finds, equal to OpenCV where OpenCV has the
same method, seeded."""
from __future__ import annotations

import cv2
import numpy as np
import pytest
from scipy.optimize import least_squares

from recon_eval.errors import InputError
from recon_eval.estimators.fundamental import ESTIMATORS, estimate, fns, linear
from scenegen.geometry.twoview import sampson_error

#: Exact data: Sampson distance bound (issue 34), px.
EXACT_SAMPSON_PX = 1e-9
#: OpenCV solves the eight-point eigenproblem on A^T A (squaring its condition number) and the
#: seven-point cubic with its own root finder: measured differences to ours 1.3e-8 and 4e-8 (unit F).
OPENCV_F_TOL = 1e-6


def _up_to_scale(A, B) -> float:
    A, B = A / np.linalg.norm(A), B / np.linalg.norm(B)
    return float(min(np.linalg.norm(A - B), np.linalg.norm(A + B)))


def _sampson_px(F, x1, x2) -> np.ndarray:
    return np.sqrt(sampson_error(F, x1, x2))


def _noisy(two_view_points, n=120, sigma=1.0, seed=3):
    x1, x2, F, K, rel = two_view_points(n, seed)
    rng = np.random.default_rng(seed + 100)
    return x1 + rng.normal(0, sigma, x1.shape), x2 + rng.normal(0, sigma, x2.shape), F


def _far_outliers(two_view_points, n=200, fraction=0.3, seed=6):
    """Exact inliers and outliers drawn uniformly in image 2, kept > 20 px (Sampson) off the truth."""
    x1, x2, F, _, _ = two_view_points(n, seed)
    rng = np.random.default_rng(seed)
    m = int(fraction * n)
    y2 = x2.copy()
    for k in range(m):
        while True:
            y2[k] = rng.uniform([0, 0], [480, 360])
            if _sampson_px(F, x1[k:k + 1], y2[k:k + 1])[0] > 20:
                break
    return x1, y2, F, np.arange(n) >= m


@pytest.mark.parametrize("name", list(ESTIMATORS))
def test_exact_correspondences_give_the_truth_f(name, two_view_points):
    x1, x2, F_gt, _, _ = two_view_points(60, 1)
    e = estimate(name, x1, x2, seed=0)
    assert np.linalg.matrix_rank(e.F, tol=1e-10) == 2
    assert np.max(_sampson_px(e.F, x1, x2)) <= EXACT_SAMPSON_PX
    assert _up_to_scale(e.F, F_gt) <= 1e-9
    assert e.inliers.all()


def _sampson_residuals(f, x1, x2):
    return np.sqrt(sampson_error(f.reshape(3, 3), x1, x2))


def _similarity(x):
    """A similarity taking points to zero mean and unit RMS radius (conditioning for the optimiser)."""
    c, s = x.mean(axis=0), 1.0 / np.sqrt(np.mean(np.sum((x - x.mean(axis=0)) ** 2, axis=1)))
    return np.array([[s, 0, -s * c[0]], [0, s, -s * c[1]], [0, 0, 1.0]])


def test_fns_reaches_the_unconstrained_sampson_minimum(two_view_points):
    """The reference: least_squares over the eight entries but the largest of G = T2^-T F T1^-1
    (a conditioned frame, :func:`_similarity`), residuals the pixel Sampson distances of T2^T G T1,
    started from the truth."""
    y1, y2, F_gt = _noisy(two_view_points)
    F, _, converged, J = fns.fns_theta(y1, y2)
    T1, T2 = _similarity(y1), _similarity(y2)
    g0 = (np.linalg.inv(T2).T @ F_gt @ np.linalg.inv(T1)).ravel()
    g0 /= np.linalg.norm(g0)
    k = int(np.argmax(np.abs(g0)))
    ref = least_squares(lambda p: _sampson_residuals((T2.T @ np.insert(p, k, g0[k]).reshape(3, 3) @ T1).ravel(), y1,
                                                     y2), np.delete(g0, k), method="lm", xtol=1e-15, ftol=1e-15,
                        gtol=1e-15, max_nfev=20000)
    J_ref = float(np.sum(ref.fun ** 2))
    J_fns = float(np.sum(_sampson_residuals(F.ravel(), y1, y2) ** 2))
    assert converged and abs(J_fns - J_ref) <= 1e-6 * J_ref
    assert abs(J - J_fns) <= 1e-9 * J_ref  # FNS's own AML cost is the pixel Sampson cost
    assert J_ref < float(np.sum(_sampson_residuals(F_gt.ravel(), y1, y2) ** 2))  # noise moved the minimum


def _rank2(p, fixed, value):
    """F of seven parameters: the eight of (c1, c2, a, b) but entry ``fixed`` (held at ``value``:
    the scale), third column a c1 + b c2: rank 2 by construction."""
    q = np.insert(p, fixed, value)
    c1, c2 = q[0:3], q[3:6]
    return np.stack([c1, c2, q[6] * c1 + q[7] * c2], axis=1)


def test_cfns_reaches_the_rank2_sampson_minimum(two_view_points):
    """The reference: least_squares over a rank-2 chart of G = T2^-T F T1^-1 (conditioned frame), the
    residuals the pixel Sampson distances of T2^T G T1, started from the truth."""
    y1, y2, F_gt = _noisy(two_view_points)
    e = estimate("cfns", y1, y2)
    T1, T2 = _similarity(y1), _similarity(y2)
    G = np.linalg.inv(T2).T @ F_gt @ np.linalg.inv(T1)
    G /= np.linalg.norm(G)
    ab = np.linalg.lstsq(G[:, :2], G[:, 2], rcond=None)[0]
    q0 = np.r_[G[:, 0], G[:, 1], ab]
    k = int(np.argmax(np.abs(q0[:6])))
    ref = least_squares(lambda p: _sampson_residuals((T2.T @ _rank2(p, k, q0[k]) @ T1).ravel(), y1, y2),
                        np.delete(q0, k), method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=20000)
    J_ref = float(np.sum(ref.fun ** 2))
    J_cfns = float(np.sum(_sampson_px(e.F, y1, y2) ** 2))
    assert e.converged and abs(J_cfns - J_ref) <= 1e-6 * J_ref
    assert e.extra["det_ratio"] < 1e-12
    J_fns_unconstrained = float(np.sum(_sampson_residuals(np.ravel(fns.fns_theta(y1, y2)[0]), y1, y2) ** 2))
    assert J_fns_unconstrained < J_ref  # the constraint costs something: the two minima differ


def test_eight_point_eigen_equals_opencv(two_view_points):
    y1, y2, _ = _noisy(two_view_points, seed=5)
    F_cv, _ = cv2.findFundamentalMat(y1, y2, cv2.FM_8POINT)
    assert _up_to_scale(F_cv, estimate("eight-point-eigen", y1, y2).F) <= OPENCV_F_TOL


def test_seven_point_solutions_equal_opencv(two_view_points):
    y1, y2, _ = _noisy(two_view_points, seed=5)
    F_cv, _ = cv2.findFundamentalMat(y1[:7], y2[:7], cv2.FM_7POINT)
    mine = linear.seven_point_solutions(y1[:7], y2[:7])
    theirs = F_cv.reshape(-1, 3, 3)
    assert len(mine) == len(theirs) >= 1
    assert all(min(_up_to_scale(G, H) for H in mine) <= OPENCV_F_TOL for G in theirs)


@pytest.mark.parametrize("name,flag", [("ransac", cv2.FM_RANSAC), ("lmeds-eigen", cv2.FM_LMEDS)])
def test_sampling_methods_equal_opencv(name, flag, two_view_points):
    """Different random samples, the same answer: OpenCV's inlier mask and F (30 % outliers)."""
    x1, y2, F_gt, labels = _far_outliers(two_view_points)
    F_cv, mask = cv2.findFundamentalMat(x1, y2, flag, 2.0, 0.999, 5000)
    e = estimate(name, x1, y2, seed=0)
    assert np.array_equal(e.inliers, mask.ravel() != 0) and np.array_equal(e.inliers, labels)
    assert _up_to_scale(e.F, F_gt) <= 1e-9
    # OpenCV returns its best sample's seven-point model (RANSAC), solved in unnormalised pixels, or
    # the eight-point refit on A^T A (LMedS): measured 1.2e-6 and 1.3e-8 from the truth
    assert _up_to_scale(F_cv, F_gt) <= 1e-5 and _up_to_scale(e.F, F_cv) <= 1e-5


#: Huber's weights never reach zero and the F33 = 1 form leaves far outliers their pull: the
#: M-estimator with least squares misses the truth at any outlier fraction (measured at 5 %: 149 px
#: Sampson on the inliers); docs/fmatrix_survey.md shows it in the sweep.
WEAK = ("m-estimator-ls",)


@pytest.mark.parametrize("name", [n for n, e in ESTIMATORS.items() if e.family == "robust" and n not in WEAK])
def test_robust_methods_reject_far_outliers(name, two_view_points):
    x1, y2, F_gt, labels = _far_outliers(two_view_points, fraction=0.15 if name.startswith("m-") else 0.4)
    e = estimate(name, x1, y2, seed=2)
    assert np.max(_sampson_px(e.F, x1[labels], y2[labels])) <= 1e-6
    assert not e.inliers[~labels].any()


@pytest.mark.parametrize("name", [n for n, e in ESTIMATORS.items() if e.seeded])
def test_seeded_methods_repeat_bitwise(name, two_view_points):
    x1, y2, _, _ = _far_outliers(two_view_points, n=80, fraction=0.3)
    a, b = estimate(name, x1, y2, seed=9), estimate(name, x1, y2, seed=9)
    assert a.F.tobytes() == b.F.tobytes() and np.array_equal(a.inliers, b.inliers)


def test_too_few_points_is_a_clear_error(two_view_points):
    x1, x2, _, _, _ = two_view_points(7, 0)
    with pytest.raises(InputError, match="at least 8"):
        estimate("eight-point-eigen", x1, x2)
    with pytest.raises(InputError, match="unknown F estimator"):
        estimate("nine-point", x1, x2)

"""The survey's M-estimators (Armangue and Salvi 2003): iteratively reweighted least
squares where each correspondence's row carries its Sampson normalisation 1 / g (H&Z eq. 11.9)
times a robust weight w(d) of its Sampson distance d (px), with the scale sigma re-estimated each
pass as the median absolute deviation about zero, sigma = 1.4826 median(d) (Rousseeuw and Leroy
1987; Zhang, IJCV 27(2), 1998, M-estimators). Started from the normalised eight-point
estimate on every correspondence (outliers included: an M-estimator has no sampling stage).

* :func:`m_ls`, :func:`m_eigen`: Huber's weights, w = 1 for d <= k sigma, k sigma / d above,
  k = :data:`HUBER_K` (95 % efficiency at the Gaussian), solved with F33 = 1 (least squares) or |f| = 1
  (eigen analysis); inliers: d <= 2.5 sigma;
* :func:`m_torr`: Torr and Murray's weights ("The development and comparison of robust methods for
  estimating the fundamental matrix", IJCV 24(3), 1997): w = 1 for d < sigma,
  sigma / d for sigma <= d < 3 sigma, 0 beyond (inliers: w > 0), eigen analysis.
"""
from __future__ import annotations

import numpy as np

from recon_eval.estimators.fundamental.common import (SIGMA_FLOOR_PX, Estimate, check_points, denormalise, design,
                                                     enforce_rank2,
                                                     normalised, sampson_terms, smallest_right_vector, solve_f33,
                                                     tidy)

#: Huber's constant for 95 % efficiency at the Gaussian.
HUBER_K = 1.345
#: MAD to sigma for Gaussian residuals.
MAD_SIGMA = 1.4826
MAX_PASSES = 50
F_TOL = 1e-12


def huber(d, sigma) -> np.ndarray:
    return np.where(d <= HUBER_K * sigma, 1.0, HUBER_K * sigma / np.maximum(d, 1e-300))


def torr(d, sigma) -> np.ndarray:
    return np.where(d < sigma, 1.0, np.where(d < 3 * sigma, sigma / np.maximum(d, 1e-300), 0.0))


def _irls(x1, x2, weight, solve, inlier_sigmas: float | None):
    x1, x2 = check_points(x1, x2, 8)
    x1n, x2n, T1, T2 = normalised(x1, x2)
    A = design(x1n, x2n)
    f = smallest_right_vector(A)
    sigma, step, k = 0.0, np.inf, 0
    for k in range(1, MAX_PASSES + 1):
        r, g = sampson_terms(denormalise(f.reshape(3, 3), T1, T2), x1, x2)
        d = np.abs(r) / np.sqrt(g)
        sigma = max(MAD_SIGMA * float(np.median(d)), SIGMA_FLOOR_PX)
        w = weight(d, sigma) / g
        if np.count_nonzero(w) < 8:
            break
        new = solve(A, np.sqrt(w))
        if new is None:
            break
        new = new / np.linalg.norm(new)
        new = new if new @ f >= 0 else -new
        step = float(np.linalg.norm(new - f))
        f = new
        if step < F_TOL:
            break
    F = tidy(denormalise(enforce_rank2(f.reshape(3, 3)), T1, T2))
    r, g = sampson_terms(F, x1, x2)
    d = np.abs(r) / np.sqrt(g)
    inl = d <= inlier_sigmas * sigma if inlier_sigmas is not None else weight(d, sigma) > 0
    return Estimate(F, inl, k, step < F_TOL, {"sigma_px": sigma})


def _eigen(A, w):
    return smallest_right_vector(A * w[:, None])


def m_ls(x1, x2) -> Estimate:
    """Huber M-estimator, F33 = 1 (least squares)."""
    return _irls(x1, x2, huber, solve_f33, 2.5)


def m_eigen(x1, x2) -> Estimate:
    """Huber M-estimator, |f| = 1 (eigen analysis)."""
    return _irls(x1, x2, huber, _eigen, 2.5)


def m_torr(x1, x2) -> Estimate:
    """Torr and Murray's M-estimator, eigen analysis."""
    return _irls(x1, x2, torr, _eigen, None)

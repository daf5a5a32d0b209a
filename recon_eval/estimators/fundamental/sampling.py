"""The survey's random-sampling estimators (Armangue and Salvi 2003, sec. 3.3.2-3.3.3): hypotheses
from minimal samples of seven correspondences (:func:`.linear.cubic_solutions`, up to three
each), each scored on every correspondence by its Sampson distance d (px, H&Z eq. 11.9); the best
hypothesis's inliers are refitted with the normalised eight-point algorithm (H&Z Alg. 11.1, eigen
analysis unless the method says least squares). Seeded: ``numpy.random.default_rng(seed)``.

* :func:`lmeds_ls`, :func:`lmeds_eigen`: least median of squares (Rousseeuw 1984; Zhang, IJCV
  27(2), 1998, sec. 5.2, eq. 26): the hypothesis of least median d^2, inliers
  d <= 2.5 sigma with sigma = 1.4826 (1 + 5 / (n - 7)) sqrt(median d^2); as many samples as give
  a clean one with probability ``confidence`` at 50 % outliers;
* :func:`ransac`: Fischler and Bolles (CACM 24(6), 1981), H&Z Alg. 4.4: the most inliers
  d < ``threshold_px``; samples adapted to the inlier ratio found (H&Z eq. 4.18);
* :func:`mlesac`: Torr and Zisserman ("MLESAC", CVIU 78(1), 2000, sec. 3): the least negative
  log-likelihood of the mixture gamma N(d; 0, sigma^2) + (1 - gamma) / v, gamma by EM (eq. 8-9),
  v the diagonal of image 2 (the range of d); inliers: posterior inlier probability > 0.5;
* :func:`mapsac`: Torr ("Bayesian model estimation and selection for epipolar geometry and
  generic manifold fitting", IJCV 50(1), 2002, sec. 5): the least sum of min(d^2 / sigma^2, T),
  T = 2 log(gamma v / ((1 - gamma) sqrt(2 pi) sigma)) with gamma = 0.5 (the mixture's two terms
  at their crossing; F's model prior is the same for every hypothesis and drops out).
"""
from __future__ import annotations

import math

import numpy as np

from recon_eval.estimators.fundamental.common import (SIGMA_FLOOR_PX, Estimate, check_points, failed, homog, normalised,
                                                     sampson_distance, tidy)
from recon_eval.estimators.fundamental.linear import cubic_solutions, eight_point_eigen, eight_point_ls

SAMPLE = 7
#: EM passes for MLESAC's mixing parameter.
EM_PASSES = 5


def _iterations_for(inlier_ratio: float, confidence: float, max_iter: int) -> int:
    """Samples for one all-inlier sample with probability ``confidence`` (H&Z eq. 4.18)."""
    p = inlier_ratio ** SAMPLE
    if p >= 1.0:
        return 1
    if p <= 0.0:
        return max_iter
    return min(max_iter, max(1, math.ceil(math.log(1 - confidence) / math.log(1 - p))))


def _search(x1, x2, score, seed: int, confidence: float, max_iter: int, adaptive) -> tuple:
    """(best F or None, its score, samples drawn): the hypothesis of least ``score(d)``;
    ``adaptive(d)`` the inlier ratio that sets the number of samples, or None (fixed count).
    The points are normalised once (the seven-point solutions do not depend on the frame)."""
    rng = np.random.default_rng(seed)
    n = len(x1)
    x1n, x2n, T1, T2 = normalised(x1, x2)
    a, b = homog(x1), homog(x2)
    best, best_score, needed, k = None, np.inf, max_iter if adaptive else _iterations_for(0.5, confidence, max_iter), 0
    while k < needed:
        k += 1
        pick = rng.choice(n, SAMPLE, replace=False)
        for Fn in cubic_solutions(x1n[pick], x2n[pick]):
            F = T2.T @ Fn @ T1
            Fa, Ftb = a @ F.T, b @ F
            with np.errstate(divide="ignore", invalid="ignore"):
                d = np.abs(np.sum(b * Fa, axis=1)) / np.sqrt(Fa[:, 0] ** 2 + Fa[:, 1] ** 2 + Ftb[:, 0] ** 2
                                                             + Ftb[:, 1] ** 2)
            d = np.where(np.isfinite(d), d, np.inf)
            s = score(d)
            if s < best_score:
                best, best_score = tidy(F), s
                if adaptive:
                    needed = min(needed, _iterations_for(adaptive(d), confidence, max_iter))
    return best, best_score, k


def _refit(x1, x2, inl, fit, extra) -> Estimate:
    if inl.sum() < 8:
        return failed(len(x1), f"{int(inl.sum())} inliers, the refit needs 8")
    est = fit(x1[inl], x2[inl])
    return Estimate(est.F, inl, extra.pop("samples"), True, extra)


def _lmeds(x1, x2, seed, confidence, max_iter, fit):
    x1, x2 = check_points(x1, x2, 8)
    F, med, k = _search(x1, x2, lambda d: float(np.median(d ** 2)), seed, confidence, max_iter, None)
    if F is None:
        return failed(len(x1), "no hypothesis")
    sigma = max(1.4826 * (1 + 5.0 / (len(x1) - SAMPLE)) * math.sqrt(med), SIGMA_FLOOR_PX)
    inl = sampson_distance(F, x1, x2) <= 2.5 * sigma
    return _refit(x1, x2, inl, fit, {"samples": k, "sigma_px": sigma, "median_d2_px2": med})


def lmeds_ls(x1, x2, *, seed: int = 0, confidence: float = 0.999, max_iter: int = 5000) -> Estimate:
    """LMedS, inliers refitted with least squares (F33 = 1)."""
    return _lmeds(x1, x2, seed, confidence, max_iter, eight_point_ls)


def lmeds_eigen(x1, x2, *, seed: int = 0, confidence: float = 0.999, max_iter: int = 5000) -> Estimate:
    """LMedS, inliers refitted with eigen analysis (|f| = 1)."""
    return _lmeds(x1, x2, seed, confidence, max_iter, eight_point_eigen)


def ransac(x1, x2, *, seed: int = 0, threshold_px: float = 1.0, confidence: float = 0.999,
           max_iter: int = 5000) -> Estimate:
    """RANSAC: most Sampson distances below ``threshold_px``."""
    x1, x2 = check_points(x1, x2, 8)
    F, s, k = _search(x1, x2, lambda d: -float(np.count_nonzero(d < threshold_px)), seed, confidence, max_iter,
                      lambda d: np.count_nonzero(d < threshold_px) / len(d))
    if F is None:
        return failed(len(x1), "no hypothesis")
    inl = sampson_distance(F, x1, x2) < threshold_px
    return _refit(x1, x2, inl, eight_point_eigen, {"samples": k, "support": int(-s)})


def _diagonal(x2) -> float:
    span = x2.max(axis=0) - x2.min(axis=0)
    return float(max(np.hypot(*span), 1.0))


def mixture_nll(d, sigma: float, v: float) -> tuple[float, float, np.ndarray]:
    """(negative log-likelihood, gamma, inlier posteriors (N,)) of distances d under
    gamma N(0, sigma^2) + (1 - gamma) / v, gamma by EM from 0.5 (Torr and Zisserman 2000, eq. 8-9)."""
    g_in = np.exp(-0.5 * (d / sigma) ** 2) / (math.sqrt(2 * math.pi) * sigma)
    gamma = 0.5
    for _ in range(EM_PASSES):
        p_in = gamma * g_in
        post = p_in / (p_in + (1 - gamma) / v)
        gamma = float(np.mean(post))
    like = gamma * g_in + (1 - gamma) / v
    return float(-np.sum(np.log(like))), gamma, gamma * g_in / like


def mlesac(x1, x2, *, seed: int = 0, sigma_px: float = 1.0, confidence: float = 0.999,
           max_iter: int = 5000) -> Estimate:
    """MLESAC: the least mixture negative log-likelihood (module docstring)."""
    x1, x2 = check_points(x1, x2, 8)
    v = _diagonal(x2)
    F, nll, k = _search(x1, x2, lambda d: mixture_nll(d, sigma_px, v)[0], seed, confidence, max_iter,
                        lambda d: mixture_nll(d, sigma_px, v)[1])
    if F is None:
        return failed(len(x1), "no hypothesis")
    _, gamma, post = mixture_nll(sampson_distance(F, x1, x2), sigma_px, v)
    return _refit(x1, x2, post > 0.5, eight_point_eigen, {"samples": k, "gamma": gamma, "nll": nll, "v_px": v})


def mapsac_threshold(sigma_px: float, v: float, gamma: float = 0.5) -> float:
    """T of MAPSAC's score min(d^2 / sigma^2, T) (module docstring)."""
    return 2.0 * math.log(gamma * v / ((1 - gamma) * math.sqrt(2 * math.pi) * sigma_px))


def mapsac(x1, x2, *, seed: int = 0, sigma_px: float = 1.0, confidence: float = 0.999,
           max_iter: int = 5000) -> Estimate:
    """MAPSAC: the least sum of min(d^2 / sigma^2, T) (module docstring)."""
    x1, x2 = check_points(x1, x2, 8)
    T = mapsac_threshold(sigma_px, _diagonal(x2))
    F, s, k = _search(x1, x2, lambda d: float(np.sum(np.minimum((d / sigma_px) ** 2, T))), seed, confidence,
                      max_iter, lambda d: float(np.mean((d / sigma_px) ** 2 < T)))
    if F is None:
        return failed(len(x1), "no hypothesis")
    inl = (sampson_distance(F, x1, x2) / sigma_px) ** 2 < T
    return _refit(x1, x2, inl, eight_point_eigen, {"samples": k, "score": s, "T": T})

"""The survey's random-sampling estimators (Armangue and Salvi 2003): hypotheses
from minimal samples of seven correspondences (:func:`.linear.cubic_solutions`, up to three
each), each scored on every correspondence by its Sampson distance d (px, H&Z eq. 11.9); the best
hypothesis's inliers are refitted with the normalised eight-point algorithm (H&Z Alg. 11.1, eigen
analysis unless the method says least squares). Seeded: ``numpy.random.default_rng(seed)``.

* :func:`lmeds_ls`, :func:`lmeds_eigen`: least median of squares (Rousseeuw 1984; Zhang, IJCV
  27(2), 1998, LMedS): the hypothesis of least median d^2, inliers
  d <= 2.5 sigma with sigma = 1.4826 (1 + 5 / (n - 7)) sqrt(median d^2); as many samples as give
  a clean one with probability ``confidence`` at 50 % outliers;
* :func:`ransac`: Fischler and Bolles (CACM 24(6), 1981), H&Z sec. 4.7: the most inliers
  d < ``threshold_px``; samples adapted to the inlier ratio found (H&Z sec. 4.7.1);
* :func:`mlesac`: Torr and Zisserman ("MLESAC", CVIU 78(1), 2000): the least negative
  log-likelihood of the mixture gamma N(d; 0, sigma^2) + (1 - gamma) / v, gamma by EM,
  v the diagonal of image 2 (the range of d); inliers: posterior inlier probability > 0.5;
* :func:`mapsac`: Torr ("Bayesian model estimation and selection for epipolar geometry and
  generic manifold fitting", IJCV 50(1), 2002): the least sum of min(d^2 / sigma^2, T),
  T = 2 log(gamma v / ((1 - gamma) sqrt(2 pi) sigma)) with gamma = 0.5 (the mixture's two terms
  at their crossing; F's model prior is the same for every hypothesis and drops out).
"""
from __future__ import annotations

import math

import numpy as np

from recon_eval.estimators.fundamental.common import (SIGMA_FLOOR_PX, Estimate, check_points, design_rows, failed,
                                                     homog,
                                                     normalised,
                                                     sampson_distance, tidy)
from recon_eval.estimators.fundamental.linear import cubic_solutions, eight_point_eigen, eight_point_ls

SAMPLE = 7
#: Minimal samples solved together (vectorised); the result does not depend on it.
BATCH = 64
#: (c3, c2, c1, c0) of a cubic from its values at 0, 1, -1, 2.
_INV_VANDER = np.linalg.inv(np.vander(np.array([0.0, 1.0, -1.0, 2.0]), 4))
#: EM passes for MLESAC's mixing parameter.
EM_PASSES = 5


def _iterations_for(inlier_ratio: float, confidence: float, max_iter: int) -> int:
    """Samples for one all-inlier sample with probability ``confidence`` (H&Z sec. 4.7.1)."""
    p = inlier_ratio ** SAMPLE
    if p >= 1.0:
        return 1
    if p <= 0.0:
        return max_iter
    return min(max_iter, max(1, math.ceil(math.log(1 - confidence) / math.log(1 - p))))


def _batch_hypotheses(x1n, x2n, picks) -> list[tuple[int, np.ndarray]]:
    """(sample index, normalised F) of every real root of a batch of minimal samples (B, 7), in
    sample order: :func:`.linear.cubic_solutions` vectorised (batched SVD, the cubic's four
    determinants, its companion matrix's eigenvalues as ``numpy.roots`` computes them); a sample
    whose cubic has no cubic term goes through :func:`.linear.cubic_solutions` itself."""
    Vt = np.linalg.svd(design_rows(x1n[picks], x2n[picks]), full_matrices=True)[2]  # (B, 9, 9)
    F1, F2 = Vt[:, -1].reshape(-1, 3, 3), Vt[:, -2].reshape(-1, 3, 3)
    t = np.array([0.0, 1.0, -1.0, 2.0])[None, :, None, None]
    dets = np.linalg.det(t * F1[:, None] + (1 - t) * F2[:, None])  # (B, 4)
    c = dets @ _INV_VANDER.T  # (B, 4): c3, c2, c1, c0
    out = []
    degenerate = np.abs(c[:, 0]) <= 1e-12 * np.max(np.abs(c), axis=1)
    comp = np.zeros((len(c), 3, 3))
    comp[:, 0, :] = -c[:, 1:] / np.where(degenerate, 1.0, c[:, 0])[:, None]
    comp[:, 1, 0] = comp[:, 2, 1] = 1.0
    roots = np.linalg.eigvals(comp)
    for b in range(len(c)):
        if degenerate[b]:
            out += [(b, F) for F in cubic_solutions(x1n[picks[b]], x2n[picks[b]])]
            continue
        for r in roots[b]:
            if abs(r.imag) <= 1e-8 * max(1.0, abs(r.real)):
                out.append((b, r.real * F1[b] + (1 - r.real) * F2[b]))
    return out


def _search(x1, x2, score, seed: int, confidence: float, max_iter: int, adaptive) -> tuple:
    """(best F or None, its score, samples drawn): the hypothesis of least ``score(d2)`` (d2: (H, N)
    squared Sampson distances of H hypotheses, scores (H,)), the first of equals; ``adaptive(d2)``
    the inlier ratios (H,) that set the number of samples, or None (a fixed count). Samples are
    drawn one by one (``rng.choice``) and solved in batches of :data:`BATCH`, taken in order up to
    the count needed. The points are normalised once (the seven-point solutions do not depend on
    the frame)."""
    rng = np.random.default_rng(seed)
    n = len(x1)
    x1n, x2n, T1, T2 = normalised(x1, x2)
    a, b = homog(x1), homog(x2)
    best, best_score, k = None, np.inf, 0
    needed = max_iter if adaptive else _iterations_for(0.5, confidence, max_iter)
    while k < needed:
        picks = np.array([rng.choice(n, SAMPLE, replace=False) for _ in range(min(BATCH, needed - k))])
        hyps = _batch_hypotheses(x1n, x2n, picks)
        if hyps:
            Fs = np.einsum("ji,bjk,kl->bil", T2, np.array([F for _, F in hyps]), T1)  # T2^T Fn T1
            Fa, Ftb = np.einsum("bij,nj->bni", Fs, a), np.einsum("bji,nj->bni", Fs, b)
            r = np.einsum("ni,bni->bn", b, Fa)
            with np.errstate(divide="ignore", invalid="ignore"):
                d2 = r ** 2 / (Fa[..., 0] ** 2 + Fa[..., 1] ** 2 + Ftb[..., 0] ** 2 + Ftb[..., 1] ** 2)
            d2 = np.where(np.isfinite(d2), d2, np.inf)
            scores = score(d2)
            ratios = adaptive(d2) if adaptive else None
        done, current = len(picks), -1
        for h, (s_idx, _) in enumerate(hyps):
            if s_idx != current:  # a new sample: drawn only if the count so far still needed it
                current = s_idx
                if k + s_idx >= needed:
                    done = s_idx
                    break
            if scores[h] < best_score:
                best, best_score = tidy(Fs[h]), float(scores[h])
                if adaptive:
                    needed = min(needed, _iterations_for(float(ratios[h]), confidence, max_iter))
        k += done
    return best, best_score, k


def _refit(x1, x2, inl, fit, extra) -> Estimate:
    if inl.sum() < 8:
        return failed(len(x1), f"{int(inl.sum())} inliers, the refit needs 8")
    est = fit(x1[inl], x2[inl])
    return Estimate(est.F, inl, extra.pop("samples"), True, extra)


def _lmeds(x1, x2, seed, confidence, max_iter, fit):
    x1, x2 = check_points(x1, x2, 8)
    F, med, k = _search(x1, x2, lambda d2: np.median(d2, axis=1), seed, confidence, max_iter, None)
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
    t2 = threshold_px ** 2
    F, s, k = _search(x1, x2, lambda d2: -np.count_nonzero(d2 < t2, axis=1).astype(float), seed, confidence,
                      max_iter, lambda d2: np.count_nonzero(d2 < t2, axis=1) / d2.shape[1])
    if F is None:
        return failed(len(x1), "no hypothesis")
    inl = sampson_distance(F, x1, x2) < threshold_px
    return _refit(x1, x2, inl, eight_point_eigen, {"samples": k, "support": int(-s)})


def _diagonal(x2) -> float:
    span = x2.max(axis=0) - x2.min(axis=0)
    return float(max(np.hypot(*span), 1.0))


def mixture_nll(d2, sigma: float, v: float):
    """(negative log-likelihood, gamma, inlier posteriors) of squared distances d2 (N,) or (H, N)
    under gamma N(0, sigma^2) + (1 - gamma) / v, gamma by EM from 0.5 (Torr and Zisserman
    2000); per row for (H, N)."""
    g_in = np.exp(-0.5 * d2 / sigma ** 2) / (math.sqrt(2 * math.pi) * sigma)
    gamma = np.full(g_in.shape[:-1] + (1,), 0.5)
    for _ in range(EM_PASSES):
        p_in = gamma * g_in
        gamma = np.mean(p_in / (p_in + (1 - gamma) / v), axis=-1, keepdims=True)
    like = gamma * g_in + (1 - gamma) / v
    return -np.sum(np.log(like), axis=-1), gamma[..., 0], gamma * g_in / like


def mlesac(x1, x2, *, seed: int = 0, sigma_px: float = 1.0, confidence: float = 0.999,
           max_iter: int = 5000) -> Estimate:
    """MLESAC: the least mixture negative log-likelihood (module docstring)."""
    x1, x2 = check_points(x1, x2, 8)
    v = _diagonal(x2)
    F, nll, k = _search(x1, x2, lambda d2: mixture_nll(d2, sigma_px, v)[0], seed, confidence, max_iter,
                        lambda d2: mixture_nll(d2, sigma_px, v)[1])
    if F is None:
        return failed(len(x1), "no hypothesis")
    _, gamma, post = mixture_nll(sampson_distance(F, x1, x2) ** 2, sigma_px, v)
    return _refit(x1, x2, post > 0.5, eight_point_eigen, {"samples": k, "gamma": float(gamma), "nll": nll, "v_px": v})


def mapsac_threshold(sigma_px: float, v: float, gamma: float = 0.5) -> float:
    """T of MAPSAC's score min(d^2 / sigma^2, T) (module docstring)."""
    return 2.0 * math.log(gamma * v / ((1 - gamma) * math.sqrt(2 * math.pi) * sigma_px))


def mapsac(x1, x2, *, seed: int = 0, sigma_px: float = 1.0, confidence: float = 0.999,
           max_iter: int = 5000) -> Estimate:
    """MAPSAC: the least sum of min(d^2 / sigma^2, T) (module docstring)."""
    x1, x2 = check_points(x1, x2, 8)
    T = mapsac_threshold(sigma_px, _diagonal(x2))
    F, s, k = _search(x1, x2, lambda d2: np.sum(np.minimum(d2 / sigma_px ** 2, T), axis=1), seed, confidence,
                      max_iter, lambda d2: np.mean(d2 / sigma_px ** 2 < T, axis=1))
    if F is None:
        return failed(len(x1), "no hypothesis")
    inl = (sampson_distance(F, x1, x2) / sigma_px) ** 2 < T
    return _refit(x1, x2, inl, eight_point_eigen, {"samples": k, "score": s, "T": T})

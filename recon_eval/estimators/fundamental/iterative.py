"""The survey's iterative methods (Armangue and Salvi 2003) but FNS / CFNS
(:mod:`.fns`), on Hartley-normalised points with every cost measured in pixels:

* :func:`iterative_linear`: reweighted linear least squares whose weights make the algebraic
  residual r = x2^T F x1 the distances of the points to their epipolar lines in both images,
  w^2 = 1 / |(F x1)_12|^2 + 1 / |(F^T x2)_12|^2 (Luong and Faugeras, IJCV 17(1), 1996;
  Zhang, IJCV 27(2), 1998: the distances to the epipolar lines), eigen solution, F of the last pass projected to rank 2;
* :func:`gradient_ls`, :func:`gradient_eigen`: reweighted by the gradient of r, w^2 = 1 / (|(F x1)_12|^2
  + |(F^T x2)_12|^2), so that w^2 r^2 is the Sampson error (H&Z eq. 11.9; Zhang 1998: the gradient-weighted
  criterion), solved with F33 = 1 (least squares) or |f| = 1 (eigen analysis);
* :func:`newton_raphson`: the Sampson residuals e_i = r_i / sqrt(g_i) linearised at the current F
  (first-order Taylor expansion, the survey's Newton-Raphson, in its Gauss-Newton form with step
  halving) over the eight entries of f but its largest;
* :func:`parameter_space`: minimisation over Luong and Faugeras's seven parameters (the two
  epipoles and three entries of the epipolar homography, so that F has rank 2 by construction;
  Luong and Faugeras 1996; Zhang 1998, the parameterisation of F by its epipoles; the map chosen by the largest
  epipole coordinates) of the distances to the epipolar lines in both images, by
  ``scipy.optimize.least_squares`` (Levenberg-Marquardt).
"""
from __future__ import annotations

import numpy as np

from recon_eval.estimators.fundamental.common import (Estimate, check_points, denormalise, design, enforce_rank2,
                                                     homog, line_distances, normalised, smallest_right_vector,
                                                     solve_f33, tidy)

#: Reweighting passes at most, and the change of unit f (sign aligned) that stops them.
MAX_PASSES = 50
F_TOL = 1e-12


def _scales(T1, T2) -> tuple[float, float]:
    return T1[0, 0], T2[0, 0]


def _gradient_terms(Fn, x1n, x2n, s1, s2):
    """(|(F x1)_12|^2, |(F^T x2)_12|^2) in pixel units of the pixel F = T2^T Fn T1: the first two
    entries of F x1 are s2 (Fn x1n)_12 and those of F^T x2 are s1 (Fn^T x2n)_12."""
    Fa, Ftb = homog(x1n) @ Fn.T, homog(x2n) @ Fn
    return s2 ** 2 * (Fa[:, 0] ** 2 + Fa[:, 1] ** 2), s1 ** 2 * (Ftb[:, 0] ** 2 + Ftb[:, 1] ** 2)


def _unit(f, ref=None):
    f = f / np.linalg.norm(f)
    if ref is not None and f @ ref < 0:
        f = -f
    return f


def _reweighted(x1, x2, weights, solve, name):
    x1, x2 = check_points(x1, x2, 8)
    x1n, x2n, T1, T2 = normalised(x1, x2)
    s1, s2 = _scales(T1, T2)
    A = design(x1n, x2n)
    f = _unit(smallest_right_vector(A))
    for k in range(1, MAX_PASSES + 1):
        g1, g2 = _gradient_terms(f.reshape(3, 3), x1n, x2n, s1, s2)
        with np.errstate(divide="ignore"):
            w = np.sqrt(weights(g1, g2))
        w = np.where(np.isfinite(w), w, 0.0)
        new = solve(A, w)
        if new is None:
            return Estimate(np.full((3, 3), np.nan), np.zeros(len(x1), bool), k, False, {"failed": f"{name}: singular"})
        new = _unit(new, f)
        step = np.linalg.norm(new - f)
        f = new
        if step < F_TOL:
            break
    F = tidy(denormalise(enforce_rank2(f.reshape(3, 3)), T1, T2))
    return Estimate(F, np.ones(len(x1), bool), k, step < F_TOL, {"last_step": float(step)})


def _eigen(A, w):
    return smallest_right_vector(A * w[:, None])


def iterative_linear(x1, x2) -> Estimate:
    """Weights 1/|(F x1)_12|^2 + 1/|(F^T x2)_12|^2: the squared distances to both epipolar lines."""
    return _reweighted(x1, x2, lambda g1, g2: 1.0 / g1 + 1.0 / g2, _eigen, "iterative linear")


def gradient_ls(x1, x2) -> Estimate:
    """Sampson weights 1 / g, F33 = 1 (least squares)."""
    return _reweighted(x1, x2, lambda g1, g2: 1.0 / (g1 + g2), solve_f33, "gradient LS")


def gradient_eigen(x1, x2) -> Estimate:
    """Sampson weights 1 / g, |f| = 1 (eigen analysis)."""
    return _reweighted(x1, x2, lambda g1, g2: 1.0 / (g1 + g2), _eigen, "gradient eigen")


def sampson_residuals_jacobian(f, x1n, x2n, s1, s2):
    """(e (N,), de/df (N, 9)): Sampson residuals e = r / sqrt(g) in pixels of the normalised f."""
    a, b = homog(x1n), homog(x2n)
    F = f.reshape(3, 3)
    Fa, Ftb = a @ F.T, b @ F
    r = np.sum(b * Fa, axis=1)
    g = s2 ** 2 * (Fa[:, 0] ** 2 + Fa[:, 1] ** 2) + s1 ** 2 * (Ftb[:, 0] ** 2 + Ftb[:, 1] ** 2)
    u = (b[:, :, None] * a[:, None, :]).reshape(len(a), 9)
    Fa0 = Fa.copy()
    Fa0[:, 2] = 0.0
    Ftb0 = Ftb.copy()
    Ftb0[:, 2] = 0.0
    # dg/dF: 2 s2^2 (F a)_i a_j for rows i < 2, plus 2 s1^2 b_i (F^T b)_j for columns j < 2
    dg = 2 * s2 ** 2 * (Fa0[:, :, None] * a[:, None, :]) + 2 * s1 ** 2 * (b[:, :, None] * Ftb0[:, None, :])
    sg = np.sqrt(g)
    e = r / sg
    J = u / sg[:, None] - (r / (2 * g * sg))[:, None] * dg.reshape(len(a), 9)
    return e, J


def newton_raphson(x1, x2) -> Estimate:
    """Gauss-Newton on the Sampson residuals from the normalised eight-point F (module docstring)."""
    x1, x2 = check_points(x1, x2, 8)
    x1n, x2n, T1, T2 = normalised(x1, x2)
    s1, s2 = _scales(T1, T2)
    f = _unit(smallest_right_vector(design(x1n, x2n)))
    fixed = int(np.argmax(np.abs(f)))
    free = [k for k in range(9) if k != fixed]
    e, J = sampson_residuals_jacobian(f, x1n, x2n, s1, s2)
    cost = float(e @ e)
    converged = cost == 0.0
    k = 0
    for k in range(1, MAX_PASSES + 1):
        if converged:
            break
        step = np.linalg.lstsq(J[:, free], -e, rcond=None)[0]
        t = 1.0
        while t > 1e-6:
            trial = f.copy()
            trial[free] += t * step
            e_t, J_t = sampson_residuals_jacobian(trial, x1n, x2n, s1, s2)
            c_t = float(e_t @ e_t)
            if np.isfinite(c_t) and c_t <= cost:
                break
            t /= 2
        else:
            converged = True  # no decrease along the Gauss-Newton direction: at the minimum
            break
        converged = cost - c_t <= 1e-15 * cost or np.linalg.norm(t * step) <= F_TOL * np.linalg.norm(f)
        f, e, J, cost = trial, e_t, J_t, c_t
    F = tidy(denormalise(enforce_rank2(f.reshape(3, 3)), T1, T2))
    return Estimate(F, np.ones(len(x1), bool), k, converged, {"sampson_cost_px2": cost})


def _luong_map(Fn):
    """The parameterisation chart of rank-2 Fn: (k, kp, i, j) with k (kp) the largest coordinate of
    the right (left) epipole and (i, j) the largest entry of the 2x2 block F[R, C]."""
    U, _, Vt = np.linalg.svd(Fn)
    e, ep = Vt[-1], U[:, -1]
    k, kp = int(np.argmax(np.abs(e))), int(np.argmax(np.abs(ep)))
    C, R = [c for c in range(3) if c != k], [r for r in range(3) if r != kp]
    block = Fn[np.ix_(R, C)]
    i, j = np.unravel_index(np.argmax(np.abs(block)), (2, 2))
    return k, kp, C, R, (int(i), int(j)), e / e[k], ep / ep[kp], block / block[i, j]


def _luong_f(p, chart):
    """F (3, 3) of the seven parameters p: three block entries, e_C (2), e'_R (2)."""
    k, kp, C, R, (i, j), _, _, _ = chart
    block = np.ones(4)
    block[[q for q in range(4) if q != 2 * i + j]] = p[:3]
    block = block.reshape(2, 2)
    eC, epR = p[3:5], p[5:7]
    F = np.zeros((3, 3))
    F[np.ix_(R, C)] = block
    F[R, k] = -block @ eC  # F e = 0 with e_k = 1
    F[kp, :] = -epR @ F[R, :]  # e'^T F = 0 with e'_kp = 1
    return F


def parameter_space(x1, x2) -> Estimate:
    """Luong-Faugeras parameterisation, symmetric epipolar distances (module docstring)."""
    from scipy.optimize import least_squares  # heavy: only this method needs it

    x1, x2 = check_points(x1, x2, 8)
    x1n, x2n, T1, T2 = normalised(x1, x2)
    Fn = enforce_rank2(smallest_right_vector(design(x1n, x2n)).reshape(3, 3))
    chart = _luong_map(Fn)
    k, kp, C, R, (i, j), e, ep, block = chart
    p0 = np.r_[np.delete(block.ravel(), 2 * i + j), e[C], ep[R]]

    def residuals(p):
        d1, d2 = line_distances(denormalise(_luong_f(p, chart), T1, T2), x1, x2)
        return np.r_[d1, d2]

    sol = least_squares(residuals, p0, method="lm", xtol=1e-14, ftol=1e-14, gtol=1e-14, max_nfev=500)
    F = tidy(denormalise(_luong_f(sol.x, chart), T1, T2))
    return Estimate(F, np.ones(len(x1), bool), int(sol.nfev), bool(sol.success),
                    {"chart": [k, kp], "cost_px2": float(2 * sol.cost)})

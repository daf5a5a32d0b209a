"""The survey's linear methods (Armangue and Salvi 2003), each on Hartley-normalised
points (Hartley, "In defense of the eight-point algorithm", PAMI 19(6), 1997; H&Z Alg. 11.1):

* :func:`seven_point`: the two-dimensional null space of the design matrix and the cubic
  ``det(a F1 + (1 - a) F2) = 0`` (H&Z sec. 11.1.2); with more than seven points the null
  space is the two smallest right singular vectors, and of the up to three real roots the one with
  the least Sampson error on the points is kept;
* :func:`eight_point_ls`: "least squares": F33 = 1 and the other eight entries by linear least
  squares, then the rank-2 projection (H&Z sec. 11.1.1);
* :func:`eight_point_eigen`: "eigen analysis": |f| = 1, f the eigenvector of A^T A of the
  smallest eigenvalue (the last right singular vector of A, H&Z Alg. 11.1), then rank 2; the
  same method as OpenCV's ``FM_8POINT``;
* :func:`rank2_algebraic`: the rank-2 constraint imposed inside the linear estimate: F = M [e]_x
  with the epipole e of the eight-point estimate, f = E m minimising |A E m| on |E m| = 1 (H&Z
  Alg. 11.2 without the epipole iteration, sec. 11.3).
"""
from __future__ import annotations

import numpy as np

from recon_eval.estimators.fundamental.common import (Estimate, check_points, denormalise, design,
                                                     enforce_rank2, failed, normalised, sampson_terms,
                                                     smallest_right_vector, solve_f33, tidy)
from scenegen.geometry.twoview import skew


def _det_cubic(F1, F2) -> np.ndarray:
    """Coefficients (c3, c2, c1, c0) of det(a F1 + (1 - a) F2), exact from four evaluations."""
    a = np.array([0.0, 1.0, -1.0, 2.0])
    d = [np.linalg.det(t * F1 + (1 - t) * F2) for t in a]
    return np.linalg.solve(np.vander(a, 4), d)


def cubic_solutions(x1n, x2n) -> list[np.ndarray]:
    """The real roots' F (3, 3) of seven or more (normalised) correspondences, unscaled: the
    cubic of the two-dimensional null space (module docstring)."""
    Vt = np.linalg.svd(design(x1n, x2n), full_matrices=True)[2]
    F1, F2 = Vt[-1].reshape(3, 3), Vt[-2].reshape(3, 3)
    c = _det_cubic(F1, F2)
    at_infinity = abs(c[0]) <= 1e-12 * np.max(np.abs(c))
    roots = np.roots(c[1:] if at_infinity else c)
    out = [r.real * F1 + (1 - r.real) * F2 for r in roots if abs(r.imag) <= 1e-8 * max(1.0, abs(r.real))]
    return out + [F1 - F2] if at_infinity else out  # the root at infinity: F1 - F2 itself


def seven_point_solutions(x1, x2) -> list[np.ndarray]:
    """The up to three real rank-2 solutions (each (3, 3), unit norm) through seven or more
    correspondences (module docstring); an empty list when the cubic has no usable root."""
    x1, x2 = check_points(x1, x2, 7)
    x1n, x2n, T1, T2 = normalised(x1, x2)
    out = [tidy(denormalise(Fn, T1, T2)) for Fn in cubic_solutions(x1n, x2n)]
    return [F for F in out if np.all(np.isfinite(F))]


def seven_point(x1, x2) -> Estimate:
    """7-point (module docstring); of several roots the least total Sampson error on the points."""
    x1, x2 = check_points(x1, x2, 7)
    sols = seven_point_solutions(x1, x2)
    if not sols:
        return failed(len(x1), "no real root of the cubic")

    def cost(F):
        r, g = sampson_terms(F, x1, x2)
        return float(np.sum(r ** 2 / g))

    F = min(sols, key=cost)
    return Estimate(F, np.ones(len(x1), bool), extra={"real_roots": len(sols)})


def eight_point_ls(x1, x2, w=None) -> Estimate:
    """8-point with least squares (F33 = 1), rank 2; ``w`` (N,) optional row weights."""
    x1, x2 = check_points(x1, x2, 8)
    x1n, x2n, T1, T2 = normalised(x1, x2)
    f = solve_f33(design(x1n, x2n), w)
    if f is None:
        return failed(len(x1), "singular least-squares system (F33 = 0)")
    return Estimate(tidy(denormalise(enforce_rank2(f.reshape(3, 3)), T1, T2)), np.ones(len(x1), bool))


def eight_point_eigen(x1, x2, w=None) -> Estimate:
    """8-point with eigen analysis (|f| = 1), rank 2 (H&Z Alg. 11.1); ``w`` optional row weights."""
    x1, x2 = check_points(x1, x2, 8)
    x1n, x2n, T1, T2 = normalised(x1, x2)
    A = design(x1n, x2n)
    f = smallest_right_vector(A if w is None else A * w[:, None])
    return Estimate(tidy(denormalise(enforce_rank2(f.reshape(3, 3)), T1, T2)), np.ones(len(x1), bool))


def rank2_algebraic(x1, x2) -> Estimate:
    """Linear estimate under the rank-2 constraint (H&Z Alg. 11.2 (i)-(iii), one pass): the
    epipole e of image 1 from the normalised eight-point F, then F = M [e]_x with f = E m,
    E = kron(I, [e]_x^T), and m minimising |A E m| subject to |E m| = 1 (H&Z appendix 5, constrained least squares)."""
    x1, x2 = check_points(x1, x2, 8)
    x1n, x2n, T1, T2 = normalised(x1, x2)
    A = design(x1n, x2n)
    F0 = enforce_rank2(smallest_right_vector(A).reshape(3, 3))
    e = np.linalg.svd(F0)[2][-1]  # F0 e = 0
    E = np.kron(np.eye(3), skew(e).T)  # f = E m for F = M [e]_x (rows of F are [e]_x^T rows of M)
    U, s, _ = np.linalg.svd(E)
    Up = U[:, s > 1e-12 * s[0]]  # its range (rank 6)
    f = Up @ smallest_right_vector(A @ Up)
    return Estimate(tidy(denormalise(f.reshape(3, 3), T1, T2)), np.ones(len(x1), bool),
                    extra={"epipole_normalised": e.tolist()})

"""FNS and CFNS: Chojnacki, Brooks, van den Hengel and Gawley's schemes for the approximated
maximum likelihood (AML) cost, which for point data with identity covariance in pixels is the
Sampson cost sum_i r_i^2 / g_i (H&Z eq. 11.9).

With theta = f (9,), u_i = kron(x2h, x1h) the design row (A_i = u_i u_i^T) and B_i the
covariance of u_i propagated from the points' covariance Lambda (theta^T B_i theta = g_i):

    J_AML(theta) = sum_i theta^T A_i theta / theta^T B_i theta,
    X_theta      = sum_i A_i / (theta^T B_i theta) - sum_i (theta^T A_i theta) / (theta^T B_i theta)^2 B_i,

and the gradient of J_AML is 2 X_theta theta ("On the fitting of surfaces to data with
covariances", PAMI 22(11), 2000).

* :func:`fns`: the fundamental numerical scheme: theta_{k+1} = the eigenvector of X_{theta_k}
  whose eigenvalue is closest to zero, from the normalised eight-point estimate, until theta
  stops moving; the unconstrained minimiser is then projected to rank 2 (H&Z sec. 11.1.1), as the
  survey does (the unconstrained F is kept in ``extra``).
* :func:`cfns`: the constrained scheme ("A new approach to constrained parameter estimation
  applicable to some computer vision problems", Chojnacki et al. 2002, and IVC 22(2), 2004):
  the minimiser of J_AML on the cubic det F = phi(theta) = 0 satisfies P_theta X_theta theta = 0
  and phi(theta) = 0, with a_theta = grad phi and P_theta = I - a a^T / |a|^2. Both are the null
  vector condition of the symmetric Z_theta = P_b X P_b + c b b^T / |b|^2 with b = a - 2 phi theta
  (the constraint linearised at unit theta: phi being cubic, a^T theta = 3 phi, so phi(v) ~ 0 reads
  b^T v = 0; b = a on the constraint): a null vector v of Z has b^T v = 0, so P_b v = v and
  P_b X v = 0. theta_{k+1} is the eigenvector of Z_{theta_k} closest to zero, from the
  rank-2-projected FNS estimate; c is the largest |eigenvalue| of X, so that the constraint's
  direction is never the one taken. (With b = a the determinant doubles and flips sign each step.)

Computed on Hartley-normalised points with Lambda = diag(s1^2, s1^2, s2^2, s2^2) (the
normalisation's scales), so that J_AML is the pixel Sampson cost of the pixel F.
"""
from __future__ import annotations

import numpy as np

from recon_eval.estimators.fundamental.common import (Estimate, check_points, denormalise, design, enforce_rank2,
                                                     homog, normalised, smallest_right_vector, tidy)

#: Iterations at most, and the change of unit theta (sign aligned) that stops them.
MAX_ITER = 200
THETA_TOL = 1e-13
#: theta^T B_i theta is floored here (normalised units; ~1e-2 for a usable F): a point on an epipole
#: of a passing iterate would otherwise divide by zero.
G_FLOOR = 1e-30


def _covariances(x1n, x2n, s1, s2) -> np.ndarray:
    """B_i (N, 9, 9): d u_i / d(x1, y1, x2, y2) Lambda (d u_i / d(...))^T."""
    a, b = homog(x1n), homog(x2n)
    n = len(a)
    eye = np.eye(3)
    vs = []
    for k in (0, 1):  # (F x1)_k = kron(e_k, a) . f: derivative of r by x2_k, scale s2
        vs.append((s2, (eye[k][None, :, None] * a[:, None, :]).reshape(n, 9)))
        vs.append((s1, (b[:, :, None] * eye[k][None, None, :]).reshape(n, 9)))  # (F^T x2)_k: by x1_k
    return sum(s ** 2 * v[:, :, None] * v[:, None, :] for s, v in vs)


def x_matrix(theta, U, B) -> tuple[np.ndarray, float]:
    """(X_theta (9, 9), J_AML(theta)) of design rows U (N, 9) and covariances B (N, 9, 9)."""
    r = U @ theta
    g = np.maximum(np.einsum("i,nij,j->n", theta, B, theta), G_FLOOR)
    with np.errstate(over="ignore", invalid="ignore"):
        X = (U / g[:, None]).T @ U - np.einsum("n,nij->ij", r ** 2 / g ** 2, B)
        return X, float(np.sum(r ** 2 / g))


def _closest_to_zero(M) -> np.ndarray:
    w, V = np.linalg.eigh(M)
    return V[:, int(np.argmin(np.abs(w)))]


def _setup(x1, x2):
    x1, x2 = check_points(x1, x2, 8)
    x1n, x2n, T1, T2 = normalised(x1, x2)
    U = design(x1n, x2n)
    return x1, U, _covariances(x1n, x2n, T1[0, 0], T2[0, 0]), T1, T2


def _iterate(theta, step_matrix, cost):
    """(theta, iterations, converged): the fixed point of theta -> the eigenvector of
    ``step_matrix(theta)`` closest to zero; if the iteration does not settle within MAX_ITER (or
    diverges to a non-finite matrix: outliers), the iterate of least ``cost`` met, the start
    included (the schemes minimise that cost; the estimate is never worse than where it began)."""
    best, best_cost = theta, cost(theta)
    for k in range(1, MAX_ITER + 1):
        M = step_matrix(theta)
        if not np.all(np.isfinite(M)):
            return best, k, False
        new = _closest_to_zero(M)
        new = new if new @ theta >= 0 else -new
        moved = np.linalg.norm(new - theta)
        theta = new
        if moved < THETA_TOL:
            return theta, k, True
        c = cost(theta)
        if c < best_cost:
            best, best_cost = theta, c
    return best, MAX_ITER, False


def fns_theta(x1, x2) -> tuple[np.ndarray, int, bool, float]:
    """(unconstrained pixel F (3, 3) unit norm, iterations, converged, J_AML px^2) of FNS."""
    x1, U, B, T1, T2 = _setup(x1, x2)
    theta, k, ok = _iterate(smallest_right_vector(U), lambda t: x_matrix(t, U, B)[0], lambda t: x_matrix(t, U, B)[1])
    J = x_matrix(theta, U, B)[1]
    return tidy(denormalise(theta.reshape(3, 3), T1, T2)), k, ok, J


def fns(x1, x2) -> Estimate:
    """FNS (module docstring), then the rank-2 projection."""
    x1, U, B, T1, T2 = _setup(x1, x2)
    theta, k, ok = _iterate(smallest_right_vector(U), lambda t: x_matrix(t, U, B)[0], lambda t: x_matrix(t, U, B)[1])
    J = x_matrix(theta, U, B)[1]
    F = tidy(denormalise(enforce_rank2(theta.reshape(3, 3)), T1, T2))
    return Estimate(F, np.ones(len(x1), bool), k, ok,
                    {"aml_cost_px2": J, "unconstrained_F": tidy(denormalise(theta.reshape(3, 3), T1, T2)).tolist()})


def det_gradient(theta) -> np.ndarray:
    """grad of det(F) by f (9,): the cofactor matrix of F, row-major."""
    F = theta.reshape(3, 3)
    return np.array([[np.linalg.det(np.delete(np.delete(F, i, 0), j, 1)) * (-1) ** (i + j) for j in range(3)]
                     for i in range(3)]).ravel()


def _z_matrix(theta, U, B):
    X, _ = x_matrix(theta, U, B)
    if not np.all(np.isfinite(X)):
        return X  # diverged: _iterate stops
    # the constraint linearised at theta on the unit sphere: phi(v) ~ phi(theta) + a^T (v - theta) = 0
    # with theta^T v ~ 1 and a^T theta = 3 phi(theta) (phi is cubic) reads (a - 2 phi theta)^T v = 0
    a = det_gradient(theta) - 2.0 * np.linalg.det(theta.reshape(3, 3)) * theta
    a = a / np.linalg.norm(a)
    P = np.eye(9) - np.outer(a, a)
    c = np.max(np.abs(np.linalg.eigvalsh(X)))
    return P @ X @ P + c * np.outer(a, a)


def cfns(x1, x2) -> Estimate:
    """CFNS (module docstring): F of rank 2 minimising the Sampson cost."""
    x1, U, B, T1, T2 = _setup(x1, x2)
    J_of = lambda t: x_matrix(t, U, B)[1]  # noqa: E731
    theta, _, _ = _iterate(smallest_right_vector(U), lambda t: x_matrix(t, U, B)[0], J_of)
    rank2 = lambda t: enforce_rank2(t.reshape(3, 3)).ravel() / np.linalg.norm(t)  # noqa: E731
    theta, k, ok = _iterate(rank2(theta), lambda t: _z_matrix(t, U, B), lambda t: J_of(rank2(t)))
    J = x_matrix(theta, U, B)[1]
    # at convergence det F ~ 1e-17 |F|^3 and the projection changes nothing; otherwise it keeps F of rank 2
    F = tidy(denormalise(enforce_rank2(theta.reshape(3, 3)), T1, T2))
    sv = np.linalg.svd(theta.reshape(3, 3), compute_uv=False)
    return Estimate(F, np.ones(len(x1), bool), k, ok, {"aml_cost_px2": J, "det_ratio": float(sv[2] / sv[0])})

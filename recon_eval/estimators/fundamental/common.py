"""What every fundamental-matrix estimator shares: Hartley's normalisation, the design matrix,
rank-2 enforcement, the Sampson terms, the result record.

Convention (scenegen.geometry.twoview): ``x2^T F x1 = 0`` for (N, 2) undistorted pixels x1 of
image 1 and x2 of image 2; F is returned with unit Frobenius norm and ``F[2, 2] >= 0``.
The vector ``f`` is F row-major, so the design row of a correspondence is
``kron(x2h, x1h) = (x2 x1, x2 y1, x2, y2 x1, y2 y1, y2, x1, y1, 1)`` (Hartley and Zisserman, 2nd
ed., sec. 11.1).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from recon_eval.errors import InputError


#: A robust scale below this (px) is exact data at float64 rounding: scales are floored here so that
#: weights and inlier thresholds stay finite and admit rounding-level residuals (~1e-13 px).
SIGMA_FLOOR_PX = 1e-9


@dataclass(frozen=True)
class Estimate:
    """An estimator's answer: ``F`` (3, 3) rank 2, unit norm (NaN when it failed), the inlier
    mask it claims (N,) bool (all True for non-robust methods), and what it did."""

    F: np.ndarray
    inliers: np.ndarray
    iterations: int = 0
    converged: bool = True
    extra: dict = field(default_factory=dict)  # method-specific figures (scale, support, ...)


def check_points(x1, x2, minimum: int) -> tuple[np.ndarray, np.ndarray]:
    """x1, x2 as (N, 2) float64, equal N >= ``minimum``, finite; InputError otherwise."""
    x1 = np.asarray(x1, np.float64)
    x2 = np.asarray(x2, np.float64)
    if x1.ndim != 2 or x1.shape[1:] != (2,) or x1.shape != x2.shape:
        raise InputError(f"correspondences: x1 {x1.shape} and x2 {x2.shape}: expected two (N, 2) arrays")
    if len(x1) < minimum:
        raise InputError(f"correspondences: {len(x1)} given, the method needs at least {minimum}")
    if not (np.all(np.isfinite(x1)) and np.all(np.isfinite(x2))):
        raise InputError("correspondences: non-finite coordinates")
    return x1, x2


def normalising_transform(x) -> np.ndarray:
    """Hartley's normalisation T (3, 3) of (N, 2) points: centroid to the origin, mean distance
    sqrt(2) (H&Z sec. 4.4.4; the same as OpenCV's ``run8Point``)."""
    c = x.mean(axis=0)
    d = np.mean(np.linalg.norm(x - c, axis=1))
    s = np.sqrt(2.0) / d if d > 0 else 1.0
    return np.array([[s, 0.0, -s * c[0]], [0.0, s, -s * c[1]], [0.0, 0.0, 1.0]])


def homog(x) -> np.ndarray:
    return np.concatenate([x, np.ones((len(x), 1))], axis=1)


def apply_t(T, x) -> np.ndarray:
    """(N, 2) points T x (T affine)."""
    return x @ T[:2, :2].T + T[:2, 2]


def design(x1, x2) -> np.ndarray:
    """(N, 9) rows kron(x2h, x1h) (H&Z sec. 11.1), f row-major."""
    return design_rows(x1, x2)


def design_rows(x1, x2) -> np.ndarray:
    """(..., N, 9) design rows of (..., N, 2) points (batches of samples too)."""
    ones = np.ones(x1.shape[:-1] + (1,))
    a, b = np.concatenate([x1, ones], axis=-1), np.concatenate([x2, ones], axis=-1)
    return (b[..., :, None] * a[..., None, :]).reshape(x1.shape[:-1] + (9,))


def normalised(x1, x2):
    """(x1n, x2n, T1, T2): Hartley-normalised points and their transforms."""
    T1, T2 = normalising_transform(x1), normalising_transform(x2)
    return apply_t(T1, x1), apply_t(T2, x2), T1, T2


def denormalise(Fn, T1, T2) -> np.ndarray:
    """F of pixels from Fn of normalised points: F = T2^T Fn T1 (H&Z Alg. 11.1 (iii))."""
    return T2.T @ Fn @ T1


def smallest_right_vector(A) -> np.ndarray:
    """Unit f minimising |A f| (the last right singular vector; H&Z appendix 5). The thin SVD when A has
    at least as many rows as columns (the full one of a tall A builds an N x N U)."""
    return np.linalg.svd(A, full_matrices=A.shape[0] < A.shape[1])[2][-1]


def solve_f33(A, w=None) -> np.ndarray | None:
    """The survey's "least squares" form: f with F33 = 1, minimising |A f| over the other eight
    (weighted rows when ``w`` is given); None when the system is singular (F33 = 0 truly)."""
    Aw = A if w is None else A * w[:, None]
    sol, _, rank, _ = np.linalg.lstsq(Aw[:, :8], -Aw[:, 8], rcond=None)
    if rank < 8:
        return None
    return np.r_[sol, 1.0]


def enforce_rank2(F) -> np.ndarray:
    """The closest rank-2 matrix in Frobenius norm: smallest singular value set to 0 (H&Z sec.
    11.1.1, Alg. 11.1 (ii))."""
    U, s, Vt = np.linalg.svd(F)
    return U @ np.diag([s[0], s[1], 0.0]) @ Vt


def tidy(F) -> np.ndarray:
    """F scaled to unit Frobenius norm with F[2, 2] >= 0 (or the largest entry positive)."""
    F = np.asarray(F, np.float64)
    n = np.linalg.norm(F)
    if not np.isfinite(n) or n == 0:
        return np.full((3, 3), np.nan)
    F = F / n
    ref = F[2, 2] if abs(F[2, 2]) > 1e-12 else F.flat[np.argmax(np.abs(F))]
    return -F if ref < 0 else F


def failed(n: int, why: str) -> Estimate:
    return Estimate(np.full((3, 3), np.nan), np.zeros(n, bool), 0, False, {"failed": why})


def sampson_terms(F, x1, x2):
    """(r (N,), g (N,)): the algebraic residual x2^T F x1 and the squared gradient norm
    |(F x1)_12|^2 + |(F^T x2)_12|^2; r^2 / g is the Sampson error (H&Z eq. 11.9), px^2."""
    a, b = homog(x1), homog(x2)
    Fa, Ftb = a @ F.T, b @ F
    return np.sum(b * Fa, axis=1), Fa[:, 0] ** 2 + Fa[:, 1] ** 2 + Ftb[:, 0] ** 2 + Ftb[:, 1] ** 2


def sampson_distance(F, x1, x2) -> np.ndarray:
    """(N,) sqrt of the Sampson error, px (inf where the gradient vanishes)."""
    r, g = sampson_terms(F, x1, x2)
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.abs(r) / np.sqrt(g)
    return np.where(np.isfinite(d), d, np.inf)


def line_distances(F, x1, x2) -> tuple[np.ndarray, np.ndarray]:
    """(d1, d2) (N,) px: distance of x1 to the line F^T x2 and of x2 to the line F x1."""
    a, b = homog(x1), homog(x2)
    Fa, Ftb = a @ F.T, b @ F
    r = np.abs(np.sum(b * Fa, axis=1))
    with np.errstate(divide="ignore", invalid="ignore"):
        d1 = r / np.hypot(Ftb[:, 0], Ftb[:, 1])
        d2 = r / np.hypot(Fa[:, 0], Fa[:, 1])
    return np.where(np.isfinite(d1), d1, np.inf), np.where(np.isfinite(d2), d2, np.inf)

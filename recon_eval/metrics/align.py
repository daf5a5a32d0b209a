"""Alignment of an estimate to the truth frame. Every function returns a transform and never
mutates its input; results record which alignment was used (metrics.md, "Camera poses").

* :func:`umeyama` -- closed-form least-squares SE(3) or Sim(3) between corresponding points
  (Umeyama, "Least-squares estimation of transformation parameters between two point patterns",
  IEEE TPAMI 13(4), 1991, eqs. 34-42), as used by evo on camera centres.
* :func:`icp_refine` -- point-to-point ICP (Besl & McKay 1992) with optional scale, nearest
  neighbours by ``scipy.spatial.cKDTree``; the Tanks and Temples protocol refines its camera-centre
  Sim(3) by ICP with scale.
* :func:`projective_align` -- 15-DoF projective transform (4x4 up to scale) between homogeneous
  points by normalised DLT (Hartley & Zisserman, 2nd ed., sec. 4.4 normalisation applied in P^3;
  the source rows scaled to unit norm first, so points near the plane at infinity keep precision).
  A projective reconstruction has no metric error: compare reprojection errors of the truth points
  through the estimated cameras mapped into the truth frame (:func:`cameras_to_truth_frame`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum

import numpy as np
from scipy.spatial import cKDTree

from recon_eval.arrays import as_float_array, frozen
from recon_eval.errors import InputError


class Alignment(str, Enum):
    """Which alignment was applied before scoring (declared in every result)."""

    NONE = "none"
    SE3 = "se3"  # Umeyama without scale
    SIM3 = "sim3"  # Umeyama with scale
    SE3_ICP = "se3+icp"
    SIM3_ICP = "sim3+icp"
    PROJECTIVE = "projective15"


@dataclass(frozen=True)
class Sim3:
    """``tgt_from_src``: ``y = scale * R @ x + t``. R (3, 3) rotation, t (3,) metres, scale > 0."""

    R: np.ndarray = field(default_factory=lambda: np.eye(3))
    t: np.ndarray = field(default_factory=lambda: np.zeros(3))
    scale: float = 1.0

    def __post_init__(self):
        object.__setattr__(self, "R", frozen(as_float_array(self.R, "Sim3.R", (3, 3))))
        object.__setattr__(self, "t", frozen(as_float_array(self.t, "Sim3.t", (3,))))
        object.__setattr__(self, "scale", float(self.scale))

    @property
    def matrix(self) -> np.ndarray:
        """(4, 4) homogeneous matrix [sR | t; 0 1]."""
        T = np.eye(4)
        T[:3, :3] = self.scale * self.R
        T[:3, 3] = self.t
        return T

    def apply(self, points) -> np.ndarray:
        """Map points (..., 3) from the source to the target frame; returns a new array."""
        p = np.asarray(points, dtype=np.float64)
        return self.scale * (p @ self.R.T) + self.t

    def inverse(self) -> "Sim3":
        Rt = self.R.T
        return Sim3(Rt, -(Rt @ self.t) / self.scale, 1.0 / self.scale)

    def __matmul__(self, other: "Sim3") -> "Sim3":
        return Sim3(self.R @ other.R, self.scale * (self.R @ other.t) + self.t, self.scale * other.scale)

    def cam_from_tgt(self, R_cam_from_src, t_cam_from_src):
        """Camera poses ``cam_from_src`` (R (..., 3, 3), t (..., 3)) re-expressed as ``cam_from_tgt``
        (``self`` is ``tgt_from_src``); returns new arrays ``(R, t)``.

        With ``x_tgt = s R_a x_src + t_a`` a camera's centre maps like a point and its orientation
        rotates by R_a; the camera frame keeps metric units of the target:
        ``R' = R_c R_a^T``, ``t' = s t_c - R' t_a``.
        """
        Rc = np.asarray(R_cam_from_src, dtype=np.float64)
        tc = np.asarray(t_cam_from_src, dtype=np.float64)
        R_new = Rc @ self.R.T
        t_new = self.scale * tc - np.einsum("...ij,j->...i", R_new, self.t)
        return R_new, t_new


def umeyama(src, tgt, *, with_scale: bool) -> Sim3:
    """Least-squares ``tgt_from_src`` mapping ``src`` (N, 3) onto ``tgt`` (N, 3) (metres).

    Minimises ``sum_i |tgt_i - (s R src_i + t)|^2`` (Umeyama 1991, eqs. 34-42): covariance
    ``Sigma = (1/N) sum (tgt_i - mu_t)(src_i - mu_s)^T`` (eq. 38), ``U D V^T = svd(Sigma)``,
    ``S = diag(1, 1, det(U) det(V))`` (eq. 39-40), ``R = U S V^T`` (eq. 40),
    ``s = tr(D S) / sigma_src^2`` (eq. 42), ``t = mu_t - s R mu_s`` (eq. 41). ``s = 1`` when
    ``with_scale`` is False (SE(3)). Needs N >= 3 points not all collinear.
    """
    src = as_float_array(src, "umeyama src", (None, 3))
    tgt = as_float_array(tgt, "umeyama tgt", (None, 3))
    if src.shape != tgt.shape:
        raise InputError(f"umeyama: src {src.shape} and tgt {tgt.shape} must correspond one to one")
    if src.shape[0] < 3:
        raise InputError(f"umeyama: need at least 3 corresponding points, got {src.shape[0]}")
    if not (np.all(np.isfinite(src)) and np.all(np.isfinite(tgt))):
        raise InputError("umeyama: points must be finite")
    mu_s, mu_t = src.mean(axis=0), tgt.mean(axis=0)
    xs, xt = src - mu_s, tgt - mu_t
    sigma = xt.T @ xs / src.shape[0]  # (3, 3), eq. 38
    U, D, Vt = np.linalg.svd(sigma)
    if D[1] <= 1e-12 * max(D[0], 1e-300):  # rank < 2: rotation undetermined (collinear points)
        raise InputError("umeyama: points are (nearly) collinear; the rotation is undetermined")
    S = np.eye(3)
    if np.linalg.det(U) * np.linalg.det(Vt) < 0:
        S[2, 2] = -1.0
    R = U @ S @ Vt
    scale = 1.0
    if with_scale:
        var_s = np.mean(np.sum(xs**2, axis=1))
        scale = float(np.sum(D * np.diag(S)) / var_s)
    t = mu_t - scale * R @ mu_s
    return Sim3(R, t, scale)


@dataclass(frozen=True)
class IcpResult:
    """Outcome of :func:`icp_refine`."""

    tgt_from_src: Sim3
    iterations: int
    converged: bool
    rms_m: float  # RMS of the matched nearest-neighbour distances at the last iteration, metres
    inlier_fraction: float  # fraction of source points matched within max_corr_dist_m


def icp_refine(
    src,
    tgt,
    init: Sim3 | None = None,
    *,
    with_scale: bool,
    max_corr_dist_m: float,
    max_iterations: int = 50,
    tol_m: float = 1e-12,
) -> IcpResult:
    """Refine ``init`` (tgt_from_src) by point-to-point ICP between clouds ``src`` (N, 3), ``tgt``
    (M, 3), metres. Pairs farther apart than ``max_corr_dist_m`` (strict ``<`` keeps a pair) are
    ignored; each step is a :func:`umeyama` on the kept pairs. Stops when the RMS changes by less
    than ``tol_m``. The inputs are not modified.
    """
    src = as_float_array(src, "icp src", (None, 3))
    tgt = as_float_array(tgt, "icp tgt", (None, 3))
    T = init if init is not None else Sim3()
    tree = cKDTree(tgt)
    prev = np.inf
    rms, frac, it, converged = np.inf, 0.0, 0, False
    for it in range(1, max_iterations + 1):
        moved = T.apply(src)
        d, idx = tree.query(moved, k=1)
        keep = d < max_corr_dist_m
        frac = float(np.mean(keep))
        if keep.sum() < 3:
            break
        rms = float(np.sqrt(np.mean(d[keep] ** 2)))
        T = umeyama(src[keep], tgt[idx[keep]], with_scale=with_scale)
        if abs(prev - rms) < tol_m:
            converged = True
            break
        prev = rms
    return IcpResult(T, it, converged, rms, frac)


@dataclass(frozen=True)
class Projective3:
    """``tgt_from_src`` 4x4 projective transform, normalised to unit Frobenius norm, sign chosen so
    that the largest-magnitude entry is positive (it is defined up to scale; 15 DoF)."""

    H: np.ndarray

    def __post_init__(self):
        H = as_float_array(self.H, "Projective3.H", (4, 4))
        H = H / np.linalg.norm(H)
        if H.flat[np.argmax(np.abs(H))] < 0:
            H = -H
        object.__setattr__(self, "H", frozen(H))

    def apply(self, points) -> np.ndarray:
        """Map Euclidean (N, 3) or homogeneous (N, 4) points; returns Euclidean (N, 3) (NaN/inf at
        infinity)."""
        X = _homogeneous(np.asarray(points, dtype=np.float64))
        Y = X @ self.H.T
        with np.errstate(divide="ignore", invalid="ignore"):
            return Y[:, :3] / Y[:, 3:4]


def _homogeneous(X: np.ndarray) -> np.ndarray:
    if X.ndim == 2 and X.shape[1] == 3:
        return np.hstack([X, np.ones((X.shape[0], 1))])
    if X.ndim == 2 and X.shape[1] == 4:
        return X
    raise InputError(f"points: expected shape (N, 3) or (N, 4), got {X.shape}")


def normalising_transform_3d(X: np.ndarray) -> np.ndarray:
    """(4, 4) similarity moving the centroid of Euclidean points (N, 3) to 0 and their mean distance
    to the origin to sqrt(3) (Hartley normalisation in P^3)."""
    mu = X.mean(axis=0)
    d = np.mean(np.linalg.norm(X - mu, axis=1))
    s = np.sqrt(3.0) / d if d > 0 else 1.0
    T = np.eye(4)
    T[:3, :3] *= s
    T[:3, 3] = -s * mu
    return T


def normalising_transform_homogeneous(X: np.ndarray) -> np.ndarray:
    """(4, 4) Hartley normalisation of homogeneous points (N, 4) given as unit-norm rows (x, w):
    the similarity ``x -> s (x - mu w)`` with the centroid ``mu = sum w x / sum w^2`` (the least-
    squares centre ``min sum |x - mu w|^2``) and ``s`` making the mean of ``|x - mu w|`` equal
    ``sqrt(3)`` times the RMS of ``w``. For rows of finite points this is the centroid and mean
    distance of their Euclidean points, each weighted by its row's w^2; a point near the plane at
    infinity (w ~ 0) weighs nothing instead of dominating. Identity when every w is 0."""
    x, w = X[:, :3], X[:, 3]
    ww = float(w @ w)
    T = np.eye(4)
    if ww <= 0.0:
        return T
    mu = (w @ x) / ww
    d = np.mean(np.linalg.norm(x - np.outer(w, mu), axis=1))
    s = np.sqrt(3.0) * np.sqrt(ww / len(w)) / d if d > 0 else 1.0
    T[:3, :3] *= s
    T[:3, 3] = -s * mu
    return T


def projective_align(points_src, points_tgt) -> Projective3:
    """15-DoF ``tgt_from_src`` with ``X_tgt ~ H X_src`` for N >= 5 correspondences in general
    position: points_src (N, 3) or (N, 4) homogeneous (a projective reconstruction), points_tgt
    (N, 3) Euclidean truth in metres.

    Normalised DLT: each pair gives 3 equations ``h_i . X - x_i (h_4 . X) = 0`` (i = 1..3) for the
    rows h_i of H, after Hartley normalisation of both sets; the null vector of the 3N x 16 system
    by SVD. Exact for noise-free data (to rounding). The source rows are first scaled to unit norm
    (the equations are homogeneous in X, so H absorbs the scale) and normalised by
    :func:`normalising_transform_homogeneous`; dividing by w instead would throw a point near the
    plane at infinity (w ~ 0) to a huge Euclidean distance that swamps the Hartley normalisation of
    all the others (w at 1.5e-9 of the largest: camera rotations off by ~1e-6 deg instead of
    ~1e-13). Source points at infinity (w = 0) are allowed.
    """
    Xs = _homogeneous(np.asarray(points_src, dtype=np.float64))
    Xt = as_float_array(points_tgt, "projective_align points_tgt", (None, 3))
    if Xs.shape[0] != Xt.shape[0] or Xs.shape[0] < 5:
        raise InputError(f"projective_align: need >= 5 corresponding points, got {Xs.shape[0]} and {Xt.shape[0]}")
    if not (np.all(np.isfinite(Xs)) and np.all(np.isfinite(Xt))):
        raise InputError("projective_align: points must be finite")
    norms = np.linalg.norm(Xs, axis=1, keepdims=True)
    if np.any(norms == 0):
        raise InputError("projective_align: a source point is (0, 0, 0, 0), not a homogeneous point")
    Xs_u = Xs / norms  # unit rows: each homogeneous point rescaled, which the projective H absorbs
    Ts, Tt = normalising_transform_homogeneous(Xs_u), normalising_transform_3d(Xt)
    xs = Xs_u @ Ts.T  # (N, 4)
    xt = Xt @ Tt[:3, :3].T + Tt[:3, 3]  # (N, 3)
    n = xs.shape[0]
    A = np.zeros((3 * n, 16))
    for i in range(3):
        A[i::3, 4 * i : 4 * i + 4] = xs
        A[i::3, 12:16] = -xt[:, i : i + 1] * xs
    _, _, Vt = np.linalg.svd(A)
    Hn = Vt[-1].reshape(4, 4)
    return Projective3(np.linalg.inv(Tt) @ Hn @ Ts)


def cameras_to_truth_frame(P_src, tgt_from_src: Projective3) -> np.ndarray:
    """Projection matrices P_src (..., 3, 4) of a projective reconstruction expressed in the truth
    frame: ``P_tgt = P_src H^-1`` so that ``P_tgt X_tgt ~ P_src X_src``. Each normalised to unit
    Frobenius norm. Input is not modified."""
    P = np.asarray(P_src, dtype=np.float64)
    Pt = P @ np.linalg.inv(tgt_from_src.H)
    return Pt / np.linalg.norm(Pt, axis=(-2, -1), keepdims=True)

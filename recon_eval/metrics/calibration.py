"""Calibration metrics: intrinsic parameter errors, the mrcal-style projection difference field,
and reprojection RMS on held-out truth points.

Definitions: shared/notes/metrics.md, "Calibration and PnP". Distortion coefficients are not
compared one by one (they are correlated; OpenCV's own test leaves that check commented out):
the projection difference field compares what the models *do*, across model families.

Camera objects are duck-typed (``scenegen.geometry.camera.Camera`` satisfies it): ``width``, ``height``,
``K`` (3, 3), ``project(points_cam (N, 3)) -> (N, 2)`` pixels (NaN where invalid), and
``unproject(pixels (N, 2)) -> (N, 3)`` points on z = 1 (NaN where invalid); ``unproject_unit``
(unit rays) is used when present so rays beyond 90 degrees (fisheye) are compared too.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.arrays import as_float_array, frozen
from recon_eval.errors import InputError
from scenegen.geometry.rotation import matrix_from_rotvec, rotation_angle_rad


@dataclass(frozen=True)
class IntrinsicsResult:
    """Errors of fx, fy, cx, cy: absolute in pixels, relative to the truth value (OpenCV's
    calibration test compares relative errors to eps 1e-2)."""

    fx_abs_err_px: float
    fy_abs_err_px: float
    cx_abs_err_px: float
    cy_abs_err_px: float
    fx_rel_err: float  # |fx_est - fx_gt| / |fx_gt|
    fy_rel_err: float
    cx_rel_err: float
    cy_rel_err: float


def intrinsics_errors(K_est, K_gt) -> IntrinsicsResult:
    """fx, fy, cx, cy errors from (3, 3) camera matrices (OpenCV pixel convention)."""
    Ke = as_float_array(K_est, "K_est", (3, 3))
    Kg = as_float_array(K_gt, "K_gt", (3, 3))
    idx = ((0, 0), (1, 1), (0, 2), (1, 2))
    ab = [abs(Ke[i] - Kg[i]) for i in idx]
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = [float(a / abs(Kg[i])) for a, i in zip(ab, idx)]
    return IntrinsicsResult(*(float(a) for a in ab), *rel)


@dataclass(frozen=True)
class ProjectionDiffResult:
    """Projection difference field of two camera models over a pixel grid (mrcal
    ``projection_diff``)."""

    mean_px: float  # over valid grid points
    max_px: float
    rms_px: float
    diff_px: np.ndarray  # (ny, nx) per-grid-point difference, NaN where invalid
    grid_u_px: np.ndarray  # (nx,) column coordinates of the grid (OpenCV pixels)
    grid_v_px: np.ndarray  # (ny,)
    valid_frac: float  # grid points where both unprojection and projection are defined
    rotation_fitted: bool  # False: intrinsics only (identity transform, mrcal intrinsics_only)
    fitted_rot_deg: float  # angle of the fitted rotation (0 when not fitted)


def _rays(cam, uv: np.ndarray) -> np.ndarray:
    if hasattr(cam, "unproject_unit"):
        return np.asarray(cam.unproject_unit(uv), dtype=np.float64)
    return np.asarray(cam.unproject(uv), dtype=np.float64)


def _mean_max_rms(d: np.ndarray) -> tuple[float, float, float]:
    """(mean, max, RMS) of the finite differences d (px); NaN each when there are none."""
    if not len(d):
        return float("nan"), float("nan"), float("nan")
    return float(np.mean(d)), float(np.max(d)), float(np.sqrt(np.mean(d**2)))


def projection_difference(cam_gt, cam_est, *, grid_nx: int = 60, grid_ny: int = 40,
                          fit_rotation: bool = False) -> ProjectionDiffResult:
    """mrcal-style projection difference (mrcal ``projection_diff``): grid the image (pixel
    centres spanning [0, W-1] x [0, H-1], ``grid_nx`` x ``grid_ny``), unproject every grid pixel
    with the truth camera, project the ray with the estimated camera, and take the pixel distance
    to the grid pixel. ``fit_rotation=False`` is mrcal's ``intrinsics_only`` (identity transform).
    With ``fit_rotation=True`` the rotation R minimising the sum of squared differences of
    ``project_est(R ray)`` is fitted first (scipy least squares; a rotation is what an intrinsics
    difference can trade against at infinity), and the residual field reported.
    Valid for any pair of model families. Grid points where either model is undefined are NaN in
    the field and excluded from the statistics (``valid_frac`` says how many remain).
    """
    if (cam_gt.width, cam_gt.height) != (cam_est.width, cam_est.height):
        raise InputError(f"cameras differ in image size: {(cam_gt.width, cam_gt.height)} vs {(cam_est.width, cam_est.height)}")
    gu = np.linspace(0.0, cam_gt.width - 1.0, grid_nx)
    gv = np.linspace(0.0, cam_gt.height - 1.0, grid_ny)
    U, V = np.meshgrid(gu, gv)
    uv = np.stack([U.ravel(), V.ravel()], axis=1)  # (ny*nx, 2)
    rays = _rays(cam_gt, uv)  # (M, 3)
    ok = np.all(np.isfinite(rays), axis=1)
    R = np.eye(3)
    if fit_rotation:
        from scipy.optimize import least_squares  # heavy, and only the rotation-fitted variant needs it

        def resid(w):
            p = np.asarray(cam_est.project(rays[ok] @ matrix_from_rotvec(w).T), float)
            r = p - uv[ok]
            return np.where(np.isfinite(r), r, 0.0).ravel()

        w = least_squares(resid, np.zeros(3), x_scale=1e-3).x
        R = matrix_from_rotvec(w)
    proj = np.full_like(uv, np.nan)
    proj[ok] = np.asarray(cam_est.project(rays[ok] @ R.T), dtype=np.float64)
    d = np.linalg.norm(proj - uv, axis=1)
    valid = np.isfinite(d)
    return ProjectionDiffResult(
        *_mean_max_rms(d[valid]),
        frozen(d.reshape(grid_ny, grid_nx)), frozen(gu), frozen(gv), float(np.mean(valid)),
        fit_rotation, float(np.degrees(rotation_angle_rad(R))),
    )


@dataclass(frozen=True)
class MrcalProjectionDiffResult:
    """mrcal ``projection_diff`` of two models at infinity (mrcal 2.5 ``model_analysis.py``)."""

    mean_px: float  # over valid grid points
    max_px: float
    rms_px: float
    diff_px: np.ndarray  # (ny, nx) |project_b(R unproject_a(q)) - q|, NaN where invalid
    grid_u_px: np.ndarray  # (nx,)
    grid_v_px: np.ndarray  # (ny,)
    valid_frac: float
    intrinsics_only: bool  # True: R = identity (mrcal intrinsics_only)
    fitted_rot_deg: float  # angle of mrcal's implied rotation (0 for intrinsics_only)
    focus_center_px: tuple  # (u, v) of the focus region (default the imager centre)
    focus_radius_px: float  # default min(W, H) / 6, mrcal's region-based logic without uncertainties
    n_focus: int  # grid points the rotation was fitted on
    definition: str = "mrcal projection_diff: rotation fitted on unprojected rays in the focus region"


def _dRp_dr(r: np.ndarray, p: np.ndarray) -> np.ndarray:
    """(N, 3, 3) derivative of R(r) p with respect to the rotation vector r (rotation by
    exp([r]x)): -R [p]x J_r(r), J_r the right Jacobian of SO(3)."""
    th = float(np.linalg.norm(r))
    K = np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
    if th < 1e-8:
        Jr = np.eye(3) - 0.5 * K
    else:
        Jr = np.eye(3) - (1 - np.cos(th)) / th**2 * K + (th - np.sin(th)) / th**3 * (K @ K)
    px = np.zeros((len(p), 3, 3))
    px[:, 0, 1], px[:, 0, 2], px[:, 1, 2] = -p[:, 2], p[:, 1], -p[:, 0]
    px[:, 1, 0], px[:, 2, 0], px[:, 2, 1] = p[:, 2], -p[:, 1], p[:, 0]
    return -matrix_from_rotvec(r) @ px @ Jr


def mrcal_implied_rotation(q0, v0, v1, focus_center, focus_radius) -> np.ndarray:
    """mrcal ``implied_Rt10__from_unprojections`` at infinity without weights: the rotation R
    minimising the huber loss (f_scale (5 deg)^2) of ``th2 = 2 (1 - <R v0, v1>)`` over the grid
    points within ``focus_radius`` (strict ``<``) of ``focus_center``; unit rays v0 (model a), v1
    (model b), non-finite ones carry zero weight. scipy ``least_squares`` with mrcal's settings
    (dogbox, gtol = eps), run to convergence (ftol = xtol = 1e-15: mrcal keeps scipy's 1e-8 and
    starts at a random 1e-5 vector, so its own runs differ by up to ~1e-4 px at the grid corners;
    we start at 5e-6 (1, 1, 1))."""
    from scipy.optimize import least_squares  # heavy, and only the rotation fit needs it

    q0, v0, v1 = (np.asarray(a, float) for a in (q0, v0, v1))
    w = (np.all(np.isfinite(v0), axis=1) & np.all(np.isfinite(v1), axis=1)).astype(float)
    v0, v1 = np.where(np.isfinite(v0), v0, 0.0), np.where(np.isfinite(v1), v1, 0.0)
    i = np.sum((q0 - np.asarray(focus_center, float)) ** 2, axis=1) < focus_radius * focus_radius
    if np.count_nonzero(i) < 3:
        raise InputError("mrcal projection_diff: the focus region contained too few points")
    p0, v1, w = v0[i], v1[i], w[i]

    def resid(r):
        return 2.0 * (1.0 - np.sum((p0 @ matrix_from_rotvec(r).T) * v1, axis=1)) * w

    def jac(r):
        return -2.0 * np.einsum("nj,nji->ni", v1, _dRp_dr(r, p0)) * w[:, None]

    res = least_squares(resid, np.full(3, 5e-6), jac=jac, method="dogbox", loss="huber",
                        f_scale=(5.0 * np.pi / 180.0) ** 2, gtol=np.finfo(float).eps, ftol=1e-15, xtol=1e-15)
    return matrix_from_rotvec(res.x)


def mrcal_projection_diff(cam_a, cam_b, *, gridn_width: int = 60, gridn_height: int | None = None,
                          intrinsics_only: bool = False, focus_center=None,
                          focus_radius: float = -1.0) -> MrcalProjectionDiffResult:
    """mrcal ``projection_diff((a, b))`` at infinity (distance None), without uncertainties, as
    mrcal 2.5 computes it (``model_analysis.py``): the grid ``sample_imager`` (``gridn_height``
    default ``round(H / W * gridn_width)``, pixel centres over [0, W-1] x [0, H-1]), unit rays of
    both models (``sample_imager_unproject``), the implied rotation fitted on the rays of the focus
    region (default centre ((W-1)/2, (H-1)/2), radius min(W, H)/6: mrcal's fallback when no
    uncertainties are available) unless ``intrinsics_only``, then ``|project_b(R v_a) - q|`` over
    the whole grid. Differs from :func:`projection_difference` with ``fit_rotation=True`` (a pixel
    fit over the whole grid): that one is ours."""
    if (cam_a.width, cam_a.height) != (cam_b.width, cam_b.height):
        raise InputError(f"cameras differ in image size: {(cam_a.width, cam_a.height)} vs {(cam_b.width, cam_b.height)}")
    W, H = cam_a.width, cam_a.height
    if gridn_height is None:
        gridn_height = int(round(H / W * gridn_width))
    gu, gv = np.linspace(0, W - 1, gridn_width), np.linspace(0, H - 1, gridn_height)
    U, V = np.meshgrid(gu, gv)
    q0 = np.stack([U.ravel(), V.ravel()], axis=1)
    v0 = _unit(_rays(cam_a, q0))
    center = ((W - 1.0) / 2.0, (H - 1.0) / 2.0) if focus_center is None else tuple(float(x) for x in focus_center)
    radius = float(min(W, H) / 6.0) if focus_radius < 0 else float(focus_radius)
    n_focus = int(np.count_nonzero(np.sum((q0 - center) ** 2, axis=1) < radius * radius))
    R = np.eye(3)
    if not intrinsics_only:
        R = mrcal_implied_rotation(q0, v0, _unit(_rays(cam_b, q0)), center, radius)
    ok = np.all(np.isfinite(v0), axis=1)
    q1 = np.full_like(q0, np.nan)
    q1[ok] = np.asarray(cam_b.project(v0[ok] @ R.T), float)
    d = np.linalg.norm(q1 - q0, axis=1)
    valid = np.isfinite(d)
    return MrcalProjectionDiffResult(
        *_mean_max_rms(d[valid]), frozen(d.reshape(gridn_height, gridn_width)),
        frozen(gu), frozen(gv), float(np.mean(valid)), bool(intrinsics_only),
        float(np.degrees(rotation_angle_rad(R))), center, radius, n_focus,
    )


def _unit(v: np.ndarray) -> np.ndarray:
    with np.errstate(invalid="ignore", divide="ignore"):
        return v / np.linalg.norm(v, axis=1, keepdims=True)


@dataclass(frozen=True)
class ReprojectionResult:
    rms_px: float  # sqrt(mean |project(R X + t) - x|^2) over the points; inf if any is unprojectable
    median_px: float
    max_px: float
    n_points: int
    n_invalid: int  # points the camera could not project (behind it, outside its model): failures


def reprojection_rms(cam, R_cam_from_world, t_cam_from_world, points_world, pixels) -> ReprojectionResult:
    """Reprojection error of held-out truth points (N, 3) metres observed at ``pixels`` (N, 2)
    through ``cam`` at pose cam_from_world (R (3, 3), t (3,)). Points that do not project are
    failures: they make rms/max inf and are counted."""
    X = as_float_array(points_world, "points_world", (None, 3))
    x = as_float_array(pixels, "pixels", (len(X), 2))
    R = as_float_array(R_cam_from_world, "R_cam_from_world", (3, 3))
    t = as_float_array(t_cam_from_world, "t_cam_from_world", (3,))
    if len(X) == 0:
        raise InputError("reprojection_rms: no points")
    p = np.asarray(cam.project(X @ R.T + t), dtype=np.float64)
    e = np.linalg.norm(p - x, axis=1)
    bad = ~np.isfinite(e)
    e[bad] = np.inf
    return ReprojectionResult(float(np.sqrt(np.mean(e**2))), float(np.median(e)), float(np.max(e)), len(X), int(bad.sum()))

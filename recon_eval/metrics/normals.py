"""Photometric stereo metrics, as DiLiGenT defines them (Shi et al., "A Benchmark Dataset and
Evaluation for Non-Lambertian and Uncalibrated Photometric Stereo", CVPR 2016 / TPAMI 2019).

DiLiGenT's release scripts (Boxin Shi, 2016-03-15: the calibrated and uncalibrated box-plot
scripts) score a normal map as::

    m = find(mask == 1);                         % mask = im2bw(imread('mask.png'))
    N_gt = normal_img2vec(Normal_gt, m);         % the masked pixels' normals, (p, 3)
    N_est = normal_img2vec(Normal_est, m);
    angErr = real(acos(dot(N_gt, N_est, 2))) * 180 / pi;
    mean(angErr)

No normalisation: the estimate is taken as it is (the methods write unit normals and 0 where they
found none, ``N(isnan(N)) = 0``, which scores 90 degrees); ``real(acos(x))`` is 0 for x > 1 and 180
for x < -1. :func:`angular_errors_deg` is that line (test: equal to a transliteration of the
MATLAB on the same maps). The median and the fractions under 10, 20 and 30 degrees (strict ``<``)
are the later photometric stereo papers' summaries of the same errors. A non-finite estimate is
scored as DiLiGenT's methods store it, as 0 (90 degrees), and counted in ``missing_ratio``.

Frames: both maps in one camera frame (DiLiGenT's: x right, y up, z toward the camera; ours is
OpenCV's, :data:`scenegen.geometry.conventions.DILIGENT_FROM_OPENCV_CAM` converts).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.arrays import as_float_array
from recon_eval.errors import InputError

#: The angular thresholds of the fractions reported, degrees (``error < threshold``).
ANGLE_THRESHOLDS_DEG = (10.0, 20.0, 30.0)


def angular_errors_deg(normals_gt, normals_est) -> np.ndarray:
    """(N,) DiLiGenT's ``real(acos(dot(N_gt, N_est, 2))) * 180 / pi`` of (N, 3) normals (not
    normalised; non-finite estimates taken as 0)."""
    g = as_float_array(normals_gt, "normals_gt", (None, 3))
    e = as_float_array(normals_est, "normals_est", (g.shape[0], 3))
    e = np.where(np.isfinite(e).all(axis=1, keepdims=True), e, 0.0)
    dot = np.sum(g * e, axis=1)
    return np.degrees(np.arccos(np.clip(dot, -1.0, 1.0)))


@dataclass(frozen=True)
class NormalResult:
    """Angular errors of a normal map over the truth mask (DiLiGenT)."""

    mean_ae_deg: float  # DiLiGenT's number: mean angular error, degrees
    median_ae_deg: float
    within_10deg: float  # fraction of pixels with error < 10 degrees
    within_20deg: float
    within_30deg: float
    missing_ratio: float  # pixels whose estimate is non-finite (scored as 0: 90 degrees)
    n_pixels: int


def normal_metrics(normals_gt, normals_est, mask) -> NormalResult:
    """DiLiGenT's angular errors of (H, W, 3) maps over the (H, W) bool ``mask`` (module docstring)."""
    g = as_float_array(normals_gt, "normals_gt", (None, None, 3))
    e = as_float_array(normals_est, "normals_est", g.shape)
    m = np.asarray(mask, dtype=bool)
    if m.shape != g.shape[:2]:
        raise InputError(f"mask: expected shape {g.shape[:2]}, got {m.shape}")
    if not m.any():
        raise InputError("mask: no pixel to score")
    err = angular_errors_deg(g[m], e[m])
    return NormalResult(mean_ae_deg=float(err.mean()), median_ae_deg=float(np.median(err)),
                        within_10deg=float(np.mean(err < 10.0)), within_20deg=float(np.mean(err < 20.0)),
                        within_30deg=float(np.mean(err < 30.0)),
                        missing_ratio=float(np.mean(~np.isfinite(e[m]).all(axis=1))), n_pixels=int(m.sum()))


@dataclass(frozen=True)
class AlbedoResult:
    """Albedo error up to the one global scale photometric stereo cannot recover (the light
    intensities' unit): ``s = argmin sum (s a_est - a_gt)^2`` over the masked pixels and channels."""

    scale: float  # s applied to the estimate
    rel_mae: float  # mean |s a_est - a_gt| / mean a_gt
    rel_rmse: float  # sqrt(mean (s a_est - a_gt)^2) / mean a_gt
    missing_ratio: float  # masked pixels with a non-finite estimate (scored as 0)
    n_pixels: int


def albedo_metrics(albedo_gt, albedo_est, mask) -> AlbedoResult:
    """Albedo error of (H, W) or (H, W, C) maps over the (H, W) ``mask``, after the global scale."""
    g = np.asarray(albedo_gt, dtype=np.float64)
    e = np.asarray(albedo_est, dtype=np.float64)
    if g.shape != e.shape or g.ndim not in (2, 3):
        raise InputError(f"albedo: expected two (H, W) or (H, W, C) maps of one shape, got {g.shape} and {e.shape}")
    m = np.asarray(mask, dtype=bool)
    if m.shape != g.shape[:2] or not m.any():
        raise InputError(f"mask: expected a non-empty {g.shape[:2]} mask, got {m.shape}")
    gm, em = g[m].reshape(-1), e[m].reshape(-1)
    missing = ~np.isfinite(em)
    em = np.where(missing, 0.0, em)
    denom = float(em @ em)
    s = float(em @ gm) / denom if denom > 0 else 0.0
    r = s * em - gm
    mean_gt = float(gm.mean())
    px_missing = ~np.isfinite(e[m].reshape(int(m.sum()), -1)).all(axis=1)
    return AlbedoResult(scale=s, rel_mae=float(np.abs(r).mean()) / mean_gt,
                        rel_rmse=float(np.sqrt(np.mean(r * r))) / mean_gt,
                        missing_ratio=float(px_missing.mean()), n_pixels=int(m.sum()))


@dataclass(frozen=True)
class LightResult:
    """Light direction errors of an (uncalibrated) estimate, one light per image: the angle
    between the estimated and the true direction toward the light (both normalised)."""

    mean_deg: float
    max_deg: float
    per_light_deg: tuple[float, ...]
    intensity_rel_err: float  # mean |s e_est - e_gt| / mean e_gt after the global scale; NaN without


def light_metrics(directions_gt, directions_est, intensities_gt=None, intensities_est=None) -> LightResult:
    """(K, 3) directions toward the lights (one frame), optional (K,) or (K, 3) intensities."""
    g = as_float_array(directions_gt, "light directions (truth)", (None, 3))
    e = as_float_array(directions_est, "light directions (estimate)", (g.shape[0], 3))
    norms = np.linalg.norm(e, axis=1)
    if not (np.isfinite(e).all() and (norms > 0).all()):
        raise InputError("light directions (estimate): every direction must be finite and non-zero")
    err = angular_errors_deg(g / np.linalg.norm(g, axis=1, keepdims=True), e / norms[:, None])
    rel = float("nan")
    if intensities_gt is not None and intensities_est is not None:
        ig = np.asarray(intensities_gt, np.float64).reshape(-1)
        ie = np.asarray(intensities_est, np.float64).reshape(-1)
        if ig.shape != ie.shape or not np.isfinite(ie).all():
            raise InputError(f"light intensities: expected {ig.shape} finite values, got {ie.shape}")
        s = float(ie @ ig) / float(ie @ ie) if float(ie @ ie) > 0 else 0.0
        rel = float(np.abs(s * ie - ig).mean() / ig.mean())
    return LightResult(mean_deg=float(err.mean()), max_deg=float(err.max()),
                       per_light_deg=tuple(float(x) for x in err), intensity_rel_err=rel)


@dataclass(frozen=True)
class DepthFromNormalsResult:
    """A depth map integrated from normals, against the truth, after the one constant that
    integration cannot recover (the least-squares offset over the mask)."""

    offset_m: float  # added to the estimate
    rmse_m: float
    mean_abs_m: float
    rel_rmse: float  # rmse / (max - min of the truth depth over the mask): relative to the relief
    n_pixels: int


def depth_up_to_offset(depth_gt, depth_est, mask) -> DepthFromNormalsResult:
    """Depth error of (H, W) maps (metres) over ``mask`` after the least-squares constant offset."""
    g = as_float_array(depth_gt, "depth_gt", (None, None))
    e = as_float_array(depth_est, "depth_est", g.shape)
    m = np.asarray(mask, dtype=bool) & np.isfinite(g)
    if m.shape != g.shape or not m.any():
        raise InputError(f"mask: expected a non-empty {g.shape} mask")
    em = np.where(np.isfinite(e[m]), e[m], np.nan)
    if np.isnan(em).any():
        raise InputError("depth_est: non-finite values inside the mask")
    off = float(np.mean(g[m] - em))
    r = em + off - g[m]
    relief = float(g[m].max() - g[m].min())
    rmse = float(np.sqrt(np.mean(r * r)))
    return DepthFromNormalsResult(offset_m=off, rmse_m=rmse, mean_abs_m=float(np.abs(r).mean()),
                                  rel_rmse=rmse / relief if relief > 0 else float("nan"), n_pixels=int(m.sum()))


@dataclass(frozen=True)
class PlaneOrientationResult:
    """A plane's estimated orientation against the truth (shape from texture): slant = angle
    between the plane's normal and the optical axis, tilt = image direction (degrees from +u toward
    +v) in which depth increases fastest."""

    angle_err_deg: float  # between the estimated and true normals (both toward the camera)
    angle_err_folded_deg: float  # the smaller error of the estimate and its mirror (-n_x, -n_y, n_z):
    # orthographic foreshortening alone cannot tell tilt t from t + 180 deg
    slant_err_deg: float  # |slant_est - slant_gt|
    tilt_err_deg: float  # |tilt_est - tilt_gt| folded to [0, 180]; NaN when the truth's slant < 5 deg
    slant_gt_deg: float
    tilt_gt_deg: float


def slant_tilt_deg(normal_cam) -> tuple[float, float]:
    """(slant, tilt) in degrees of a plane normal in the OpenCV camera frame, turned toward the camera."""
    n = np.asarray(normal_cam, np.float64) / np.linalg.norm(normal_cam)
    n = -n if n[2] > 0 else n
    return float(np.degrees(np.arccos(np.clip(-n[2], -1.0, 1.0)))), float(np.degrees(np.arctan2(n[1], n[0])))


def plane_orientation_metrics(normal_gt_cam, normal_est_cam) -> PlaneOrientationResult:
    """Orientation errors of a plane's normal (3,), OpenCV camera frame, either sign."""
    g = as_float_array(normal_gt_cam, "plane normal (truth)", (3,))
    e = as_float_array(normal_est_cam, "plane normal (estimate)", (3,))
    if not (np.isfinite(e).all() and np.linalg.norm(e) > 0):
        raise InputError("plane normal (estimate): expected a finite non-zero vector")
    (sg, tg), (se, te) = slant_tilt_deg(g), slant_tilt_deg(e)
    g, e = g / np.linalg.norm(g), e / np.linalg.norm(e)
    g, e = (g if g[2] < 0 else -g), (e if e[2] < 0 else -e)
    angle, mirrored = angular_errors_deg(np.stack([g, g]), np.stack([e, e * [-1.0, -1.0, 1.0]]))
    dt = abs((te - tg + 180.0) % 360.0 - 180.0)
    return PlaneOrientationResult(angle_err_deg=float(angle), angle_err_folded_deg=float(min(angle, mirrored)),
                                  slant_err_deg=abs(se - sg),
                                  tilt_err_deg=dt if sg >= 5.0 else float("nan"), slant_gt_deg=sg, tilt_gt_deg=tg)

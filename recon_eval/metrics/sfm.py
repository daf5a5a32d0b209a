"""A structure-from-motion reconstruction against its own images, as COLMAP reports it
(colmap/src/colmap/scene/reconstruction.cc): ``UpdatePoint3DErrors`` (each 3D point's error is the
mean over its track of the reprojection distance of the point through that image's camera and
pose), ``ComputeMeanReprojectionError`` (the mean of those point errors), ``ComputeMeanTrackLength``
(observations / points) and ``ComputeMeanObservationsPerRegImage`` (observations / images).
A point behind a camera, or one the model cannot project, makes its error inf (COLMAP: a
``std::numeric_limits<double>::max()`` squared error) and is counted.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.arrays import as_float_array, frozen
from recon_eval.errors import InputError


@dataclass(frozen=True)
class ReconstructionStats:
    """COLMAP's summary statistics of a reconstruction, recomputed from its files."""

    mean_reprojection_error_px: float  # mean over points of the per-point mean reprojection error
    per_point_error_px: np.ndarray  # (P,) mean reprojection error of each point's track (inf: a bad projection)
    mean_track_length: float  # observations / points
    mean_observations_per_image: float  # observations / registered images
    n_points: int
    n_observations: int
    n_images: int
    n_bad_projections: int  # observations behind the camera or outside its model


def reconstruction_stats(cameras, R_cam_from_world, t_cam_from_world, points_world, track_point, track_image,
                         track_xy_px) -> ReconstructionStats:
    """``cameras``: per image a camera object with ``project(points_cam (N, 3)) -> (N, 2)`` px (NaN
    where it cannot), in the pixel convention of ``track_xy_px`` (K, 2); poses (n, 3, 3), (n, 3)
    cam_from_world; ``points_world`` (P, 3); ``track_point`` (K,) row of the observed point and
    ``track_image`` (K,) its image."""
    X = as_float_array(points_world, "points_world", (None, 3))
    R = as_float_array(R_cam_from_world, "R_cam_from_world", (None, 3, 3))
    t = as_float_array(t_cam_from_world, "t_cam_from_world", (len(R), 3))
    xy = as_float_array(track_xy_px, "track points", (None, 2))
    tp, ti = np.asarray(track_point, np.int64), np.asarray(track_image, np.int64)
    if tp.shape != (len(xy),) or ti.shape != (len(xy),) or len(cameras) != len(R):
        raise InputError("reconstruction_stats: one camera per image, one point and image index per observation")
    err = np.full(len(xy), np.inf)
    for k in np.unique(ti):
        sel = np.flatnonzero(ti == k)
        pc = X[tp[sel]] @ R[k].T + t[k]
        front = pc[:, 2] > np.finfo(float).eps
        proj = np.full((len(sel), 2), np.nan)
        if np.any(front):
            proj[front] = np.asarray(cameras[k].project(pc[front]), np.float64)
        e = np.linalg.norm(proj - xy[sel], axis=1)
        err[sel] = np.where(np.isfinite(e), e, np.inf)
    n_obs = np.bincount(tp, minlength=len(X))
    per_point = np.where(n_obs > 0, np.bincount(tp, weights=np.where(np.isfinite(err), err, 0.0), minlength=len(X))
                         / np.maximum(n_obs, 1), 0.0)
    bad = np.bincount(tp, weights=(~np.isfinite(err)).astype(float), minlength=len(X)) > 0
    per_point[bad] = np.inf
    has = n_obs > 0  # COLMAP: a point with an empty track has error 0 and no HasError()
    nan = float("nan")
    return ReconstructionStats(
        float(np.mean(per_point[has])) if np.any(has) else nan, frozen(per_point),
        float(len(xy) / len(X)) if len(X) else nan, float(len(xy) / len(R)) if len(R) else nan,
        len(X), len(xy), len(R), int(np.sum(~np.isfinite(err))),
    )

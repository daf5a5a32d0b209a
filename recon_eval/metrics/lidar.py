"""LiDAR metrics (docs/metrics.md, "LiDAR"): de-skewing against the per-beam truth, and range
error against range and incidence angle. Pure functions of arrays returning frozen results.

De-skewing: a spinning LiDAR's raw cloud has every point in the sensor frame at its own beam's
time; a de-skewed cloud has them all in the sensor frame at one reference time ``t_ref``. The
truth of beam ``i`` is its true hit, where it was when the beam met it (world frame), in the
LiDAR frame at ``t_ref``: ``p_ref_i = R_ref^T (p_world_i - t_ref)`` (:func:`deskew_truth`). A
moving object is left where the beam met it: de-skewing removes the sensor's own motion, which
is what ego-motion compensation (e.g. KISS-ICP's, LIO-SAM's) does. The error is the Euclidean
distance per point, in metres; the raw cloud scored the same way is the error de-skewing faces.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.errors import InputError
from recon_eval.metrics.stats import ErrorStats, error_stats


def deskew_truth(points_world, world_from_lidar_ref_R, world_from_lidar_ref_t) -> np.ndarray:
    """(N, 3) float64 the true hits ``points_world`` (N, 3) in the LiDAR frame at the reference
    time, given ``world_from_lidar`` there as (3, 3) R and (3,) t (module docstring)."""
    p = np.asarray(points_world, np.float64)
    R = np.asarray(world_from_lidar_ref_R, np.float64)
    return (p - np.asarray(world_from_lidar_ref_t, np.float64)) @ R


@dataclass(frozen=True)
class DeskewResult:
    """A de-skewed cloud against the truth at the reference time: ``error_m`` per-point
    distances (m), ``raw_error_m`` the raw (skewed) cloud's against the same truth,
    ``rmse_ratio`` = error rmse / raw rmse (below 1: the de-skewing helped), ``p95_m`` the 95th
    percentile of the distances."""

    error_m: ErrorStats
    raw_error_m: ErrorStats
    rmse_ratio: float
    p95_m: float
    n_points: int


def deskew_error(est_points, truth_ref_points, raw_points) -> DeskewResult:
    """Score ``est_points`` (N, 3) (a user's de-skewed cloud, in beam order) against
    ``truth_ref_points`` (N, 3) (:func:`deskew_truth`), beside the raw cloud ``raw_points`` (N, 3)."""
    est, truth, raw = (np.asarray(a, np.float64) for a in (est_points, truth_ref_points, raw_points))
    if est.shape != truth.shape or est.ndim != 2 or est.shape[1] != 3:
        raise InputError(f"a de-skewed cloud must have one point per returned beam, {truth.shape[0]} x 3, got "
                         f"{'x'.join(map(str, est.shape))}")
    err = np.linalg.norm(est - truth, axis=1)
    raw_err = np.linalg.norm(raw - truth, axis=1)
    e, r = error_stats(err), error_stats(raw_err)
    finite = err[np.isfinite(err)]
    return DeskewResult(e, r, float(e.rmse / r.rmse) if r.rmse > 0 else float("nan"),
                        float(np.percentile(finite, 95)) if len(finite) else float("nan"), int(len(err)))


@dataclass(frozen=True)
class ErrorBin:
    """Range errors (measured - true, m) of the beams whose binned quantity lies in [lo, hi)."""

    lo: float
    hi: float
    n: int
    bias_m: float
    std_m: float
    rmse_m: float


@dataclass(frozen=True)
class RangeErrorResult:
    """Range error (measured - true, m) overall and binned by true range (m) and incidence (deg)."""

    error_m: ErrorStats
    by_range_m: tuple[ErrorBin, ...]
    by_incidence_deg: tuple[ErrorBin, ...]


def _bins(err, x, edges) -> tuple[ErrorBin, ...]:
    out = []
    for lo, hi in zip(edges[:-1], edges[1:]):
        e = err[(x >= lo) & (x < hi)]
        nan = float("nan")
        out.append(ErrorBin(float(lo), float(hi), int(len(e)), float(e.mean()) if len(e) else nan,
                            float(e.std()) if len(e) else nan, float(np.sqrt(np.mean(e**2))) if len(e) else nan))
    return tuple(out)


def range_error(measured_m, true_m, incidence_rad, range_edges_m=(0, 5, 10, 20, 40, 80, 160),
                incidence_edges_deg=(0, 15, 30, 45, 60, 75, 90.001)) -> RangeErrorResult:
    """Range errors of beams with a measured and a true range (both finite; others ignored),
    binned by the true range and the incidence angle."""
    m, t, inc = (np.asarray(a, np.float64).reshape(-1) for a in (measured_m, true_m, incidence_rad))
    if not (m.shape == t.shape == inc.shape):
        raise InputError(f"measured ranges ({len(m)}), true ranges ({len(t)}) and incidence angles ({len(inc)}) "
                         "must match")
    ok = np.isfinite(m) & np.isfinite(t)
    err = m[ok] - t[ok]
    return RangeErrorResult(error_stats(err), _bins(err, t[ok], np.asarray(range_edges_m, np.float64)),
                            _bins(err, np.degrees(inc[ok]), np.asarray(incidence_edges_deg, np.float64)))

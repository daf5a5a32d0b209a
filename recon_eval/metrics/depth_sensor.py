"""Depth-sensor characterisation: a range (or depth) sensor's per-pixel error against its truth,
binned by true range and by incidence angle, its completeness (per frame and as a per-pixel map
over frames), its returns where the truth has no surface, and its behaviour at depth edges
(pixels a label marks as edges, e.g. a ToF stream's ``flying`` truth).

The terms are those of depth-camera evaluations (e.g. the range-dependent error and incidence
studies of Kinect v1/v2 characterisations: bias = mean signed error, precision as RMSE and
median absolute error per range bin; completeness = measured / truth pixels). Definitions, with
``m`` the measurement and ``g`` the truth, each (N, H, W) in metres:

* a truth pixel: ``g`` finite and > 0; a measured pixel: ``m`` finite;
* ``completeness`` = measured truth pixels / truth pixels; ``completeness_map`` (H, W) the same per
  pixel over the N frames (NaN where a pixel never has truth);
* ``phantom_fraction`` = measured pixels without truth / measured pixels;
* error ``e = m - g`` over measured truth pixels: ``bias_m`` mean e, ``mae_m`` mean |e|,
  ``rmse_m`` sqrt(mean e^2), ``median_abs_m`` median |e|; the same per bin of g (``by_range``) and
  of the incidence angle (``by_incidence``), bins [lo, hi);
* edges: ``edge_outlier_rate`` / ``interior_outlier_rate`` = fraction of the measured truth pixels
  on / off the edge mask with |e| > ``outlier_m``; ``edge_mae_m`` / ``interior_mae_m``;
  ``edge_fraction`` = edge pixels among the measured pixels (with or without truth).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.arrays import frozen
from recon_eval.errors import InputError


@dataclass(frozen=True)
class BinnedError:
    """Error statistics of the measured truth pixels per bin [edges[k], edges[k+1]) (NaN: empty)."""

    edges: np.ndarray  # (K + 1,) bin edges, the binned quantity's unit
    count: np.ndarray  # (K,) pixels
    bias_m: np.ndarray  # (K,) mean signed error
    mae_m: np.ndarray  # (K,) mean absolute error
    rmse_m: np.ndarray  # (K,)
    median_abs_m: np.ndarray  # (K,)


@dataclass(frozen=True)
class DepthSensorResult:
    completeness: float
    completeness_map: np.ndarray  # (H, W), NaN where never truth
    phantom_fraction: float
    bias_m: float
    mae_m: float
    rmse_m: float
    median_abs_m: float
    by_range: BinnedError  # bins of the true range, metres
    by_incidence: BinnedError | None  # bins of the incidence angle, degrees (None: no angles given)
    edge_fraction: float
    edge_outlier_rate: float
    interior_outlier_rate: float
    edge_mae_m: float
    interior_mae_m: float
    outlier_m: float
    n_frames: int
    n_measured: int
    n_truth: int


def _stack(a, name) -> np.ndarray:
    a = np.asarray(a, dtype=np.float64)
    if a.ndim == 2:
        a = a[None]
    if a.ndim != 3:
        raise InputError(f"{name}: expected (H, W) or (N, H, W) maps, got shape {a.shape}")
    return a


def _mean(x) -> float:
    return float(np.mean(x)) if x.size else float("nan")


def _binned(values, err, edges) -> BinnedError:
    edges = np.asarray(edges, np.float64)
    k = np.searchsorted(edges, values, side="right") - 1
    inside = (k >= 0) & (k < len(edges) - 1)
    stats = np.full((4, len(edges) - 1), np.nan)
    count = np.zeros(len(edges) - 1, np.int64)
    for b in range(len(edges) - 1):
        e = err[inside & (k == b)]
        count[b] = e.size
        if e.size:
            stats[:, b] = (e.mean(), np.abs(e).mean(), np.sqrt(np.mean(e * e)), np.median(np.abs(e)))
    return BinnedError(edges=frozen(edges), count=frozen(count), bias_m=frozen(stats[0]), mae_m=frozen(stats[1]),
                       rmse_m=frozen(stats[2]), median_abs_m=frozen(stats[3]))


def depth_sensor_metrics(measured_m, truth_m, *, range_bins_m, incidence_deg=None, incidence_bins_deg=None,
                         edge_mask=None, outlier_m: float = 0.05) -> DepthSensorResult:
    """The module docstring's statistics of measurements against truth, each (N, H, W) or (H, W)
    (NaN / inf = no measurement, no truth); ``incidence_deg`` and ``edge_mask`` of the same shape."""
    m, g = _stack(measured_m, "measured"), _stack(truth_m, "truth")
    if m.shape != g.shape:
        raise InputError(f"measured maps {m.shape} and truth maps {g.shape} differ in shape")
    if not np.isfinite(outlier_m) or outlier_m <= 0:
        raise InputError(f"outlier threshold must be a positive number of metres, got {outlier_m}")
    has_truth = np.isfinite(g) & (g > 0)
    measured = np.isfinite(m)
    both = has_truth & measured
    err = (m - np.where(has_truth, g, 0.0))[both]
    with np.errstate(invalid="ignore", divide="ignore"):
        cmap = np.where(has_truth.sum(0) > 0, both.sum(0) / has_truth.sum(0), np.nan)
    by_inc = None
    if incidence_deg is not None:
        inc = _stack(incidence_deg, "incidence")
        if inc.shape != g.shape:
            raise InputError(f"incidence maps {inc.shape} and truth maps {g.shape} differ in shape")
        by_inc = _binned(inc[both], err, incidence_bins_deg if incidence_bins_deg is not None
                         else np.arange(0.0, 91.0, 15.0))
    edge = np.zeros(g.shape, bool) if edge_mask is None else np.asarray(edge_mask, bool).reshape(g.shape)
    on_edge = edge[both]
    big = np.abs(err) > outlier_m
    return DepthSensorResult(
        completeness=float(both.sum() / has_truth.sum()) if has_truth.any() else float("nan"),
        completeness_map=frozen(cmap),
        phantom_fraction=float((measured & ~has_truth).sum() / measured.sum()) if measured.any() else float("nan"),
        bias_m=_mean(err), mae_m=_mean(np.abs(err)), rmse_m=float(np.sqrt(_mean(err * err))),
        median_abs_m=float(np.median(np.abs(err))) if err.size else float("nan"),
        by_range=_binned(g[both], err, range_bins_m), by_incidence=by_inc,
        edge_fraction=float((edge & measured).sum() / measured.sum()) if measured.any() else float("nan"),
        edge_outlier_rate=_mean(big[on_edge]), interior_outlier_rate=_mean(big[~on_edge]),
        edge_mae_m=_mean(np.abs(err[on_edge])), interior_mae_m=_mean(np.abs(err[~on_edge])),
        outlier_m=float(outlier_m), n_frames=int(g.shape[0]), n_measured=int(measured.sum()),
        n_truth=int(has_truth.sum()))

"""The Tanks and Temples toolbox's other pieces: the crop volume and the precision / recall curves
(isl-org/TanksAndTemples, python_toolbox/evaluation).

* Crop: the toolbox crops both clouds with its per-scene ``<scene>.json``, an Open3D
  ``SelectionPolygonVolume`` (a polygon in the plane orthogonal to ``orthogonal_axis``, extruded
  from ``axis_min`` to ``axis_max``). :func:`crop_mask` is Open3D's
  ``SelectionPolygonVolume::CropInPolygon`` (cpp/open3d/visualization/utility/
  SelectionPolygonVolume.cpp): a point is kept when ``axis_min <= w <= axis_max`` and the number
  of polygon-edge crossings (edges with ``v_i < v <= v_j`` or ``v_j < v <= v_i``, crossing at
  ``u_i + (v - v_i) / (v_j - v_i) (u_j - u_i)``) strictly left of ``u`` is odd.
* Curves: ``get_f1_score_histo2`` (evaluation.py): ``np.histogram`` of each side's distances over
  ``np.arange(0, tau * plot_stretch, tau / 100)`` (plot_stretch 5), cumulated and divided by the
  side's point count: precision (rec -> GT) and recall (GT -> rec) against the bin edges.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from recon_eval.arrays import as_float_array, frozen
from recon_eval.errors import InputError

AXES = {"x": (1, 2, 0), "y": (0, 2, 1), "z": (0, 1, 2)}  # (u, v, w) of each orthogonal axis


@dataclass(frozen=True)
class CropVolume:
    """A Tanks and Temples / Open3D ``SelectionPolygonVolume``."""

    bounding_polygon: np.ndarray  # (K, 3) metres; only the two coordinates other than the axis are used
    orthogonal_axis: str  # 'X', 'Y' or 'Z'
    axis_min: float
    axis_max: float

    def __post_init__(self):
        poly = as_float_array(self.bounding_polygon, "bounding_polygon", (None, 3))
        if len(poly) < 3:
            raise InputError(f"bounding_polygon: needs >= 3 vertices, got {len(poly)}")
        if str(self.orthogonal_axis).lower() not in AXES:
            raise InputError(f"orthogonal_axis: expected X, Y or Z, got {self.orthogonal_axis!r}")
        object.__setattr__(self, "bounding_polygon", frozen(poly))
        object.__setattr__(self, "axis_min", float(self.axis_min))
        object.__setattr__(self, "axis_max", float(self.axis_max))


def crop_mask(points, volume: CropVolume, *, chunk: int = 262_144) -> np.ndarray:
    """(N,) bool: the points (N, 3) Open3D's ``CropInPolygon`` keeps (see the module docstring)."""
    p = as_float_array(points, "points", (None, 3))
    u, v, w = AXES[volume.orthogonal_axis.lower()]
    poly = volume.bounding_polygon
    pi, pj = poly, np.roll(poly, -1, axis=0)  # edge i -> j = (i + 1) % K
    out = np.zeros(len(p), bool)
    for s in range(0, len(p), chunk):
        q = p[s:s + chunk]
        inside_w = (q[:, w] >= volume.axis_min) & (q[:, w] <= volume.axis_max)
        qv, qu = q[:, v][:, None], q[:, u][:, None]
        cross = ((pi[:, v] < qv) & (pj[:, v] >= qv)) | ((pj[:, v] < qv) & (pi[:, v] >= qv))
        with np.errstate(divide="ignore", invalid="ignore"):
            node = pi[:, u] + (qv - pi[:, v]) / (pj[:, v] - pi[:, v]) * (pj[:, u] - pi[:, u])
        left = np.count_nonzero(cross & (node < qu), axis=1)  # lower_bound: nodes strictly below u
        out[s:s + chunk] = inside_w & (left % 2 == 1)
    return out


@dataclass(frozen=True)
class TanksAndTemplesCurves:
    """The toolbox's precision and recall curves at one threshold (its plots, as tables)."""

    tau_m: float
    edges_m: np.ndarray  # (B+1,) np.arange(0, tau * plot_stretch, tau / 100)
    precision: np.ndarray  # (B,) fraction of rec points with d(rec->gt) in [0, edges_m[k+1]) (last bin closed)
    recall: np.ndarray  # (B,) the same for GT points, d(gt->rec)
    plot_stretch: float = 5.0


def tanks_and_temples_curves(d_rec_to_gt, d_gt_to_rec, tau_m: float, *, plot_stretch: float = 5.0) -> TanksAndTemplesCurves:
    """``get_f1_score_histo2``'s cumulative histograms of the two distance sets (the distances
    :func:`recon_eval.metrics.pointcloud.tanks_and_temples_distances` returns). Empty -> zeros."""
    if not tau_m > 0:
        raise InputError(f"tau must be > 0 metres, got {tau_m}")
    bins = np.arange(0, tau_m * plot_stretch, tau_m / 100)

    def cum(d):
        d = np.asarray(d, float).reshape(-1)
        if len(d) == 0:
            return np.zeros(len(bins) - 1)
        hist, _ = np.histogram(d, bins)
        return np.cumsum(hist).astype(float) / len(d)

    return TanksAndTemplesCurves(float(tau_m), frozen(bins), frozen(cum(d_rec_to_gt)), frozen(cum(d_gt_to_rec)),
                                 float(plot_stretch))

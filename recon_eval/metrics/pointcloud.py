"""Point cloud / mesh reconstruction metrics: Tanks and Temples, ETH3D, DTU, Chamfer.

Definitions: shared/notes/metrics.md, "Point clouds and meshes" (reproduced in docs/metrics.md).
All clouds are (N, 3) float64 in metres, already in the truth frame (align first with
:mod:`recon_eval.metrics.align`; the result's ``alignment`` field is whatever the caller declares).

Distances rec -> GT go to the GT mesh surface when ``gt_mesh=(vertices, faces)`` (or a
:class:`recon_eval.metrics.distances.MeshSurface`, built once for several metrics) is given (exact
point-to-triangle) and to the nearest GT point otherwise; distances GT -> rec always go to the
nearest reconstructed point (a reconstruction is a cloud). ``distance_rec_to_gt`` says which.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from recon_eval.arrays import as_float_array
from recon_eval.errors import InputError
from recon_eval.metrics.distances import DistanceTo, nearest_point_distances, surface_distances


def voxel_downsample(points, voxel_m: float) -> np.ndarray:
    """Open3D ``VoxelDownSample``: one point per occupied voxel, the centroid of its points.

    The grid starts at ``min(points) - voxel_m / 2`` (Open3D's ``voxel_min_bound``); voxel index
    ``floor((p - origin) / voxel_m)``. Output order: sorted voxel keys. points (N, 3) metres.
    """
    p = as_float_array(points, "points", (None, 3))
    if len(p) == 0:
        return p.copy()
    if not voxel_m > 0:
        raise InputError(f"voxel size must be > 0, got {voxel_m}")
    ijk = np.floor((p - (p.min(axis=0) - 0.5 * voxel_m)) / voxel_m).astype(np.int64)
    inv, counts = _group_voxels(ijk)
    out = np.zeros((len(counts), 3))
    for k in range(3):
        out[:, k] = np.bincount(inv, weights=p[:, k], minlength=len(counts)) / counts
    return out


def _group_voxels(ijk: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Group integer voxel indices (N, 3): (inverse (N,) into sorted unique voxels, counts)."""
    lo = ijk.min(axis=0)
    ext = ijk.max(axis=0) - lo + 1
    if np.prod(ext.astype(np.float64)) < 2.0**62:  # one int64 key per voxel (sorts ~10x faster)
        key = np.ravel_multi_index(tuple((ijk - lo).T), tuple(int(e) for e in ext))
        _, inv, counts = np.unique(key, return_inverse=True, return_counts=True)
    else:
        _, inv, counts = np.unique(ijk, axis=0, return_inverse=True, return_counts=True)
    return inv.reshape(-1), counts


def _check_cloud(points, name: str) -> np.ndarray:
    p = as_float_array(points, name, (None, 3))
    if not np.all(np.isfinite(p)):
        raise InputError(f"{name}: {int(np.sum(~np.all(np.isfinite(p), axis=1)))} non-finite points")
    return p


def _rec_to_gt(rec: np.ndarray, gt: np.ndarray, gt_mesh) -> tuple[np.ndarray, DistanceTo]:
    if gt_mesh is not None:
        return surface_distances(rec, gt_mesh), DistanceTo.MESH
    return nearest_point_distances(rec, gt), DistanceTo.POINTS


def _fscore(p: float, r: float) -> float:
    return 0.0 if p + r == 0 else 2.0 * p * r / (p + r)


# --- Tanks and Temples -------------------------------------------------------------------------
@dataclass(frozen=True)
class TanksAndTemplesResult:
    """Tanks and Temples precision / recall / F-score at one threshold."""

    tau_m: float  # distance threshold, metres
    precision: float  # |{rec: d(rec->gt) < tau}| / |rec|, in [0, 1]
    recall: float  # |{gt: d(gt->rec) < tau}| / |gt|, in [0, 1]
    fscore: float  # 2PR/(P+R); 0 when P = R = 0
    n_rec: int  # reconstructed points scored (after downsampling)
    n_gt: int  # GT points scored (after downsampling)
    voxel_m: float | None  # voxel size of the downsampling of both clouds; None = not downsampled
    distance_rec_to_gt: str  # DistanceTo value: 'mesh_surface' or 'nearest_point'
    operator: str = "<"  # a point counts when its distance is strictly below tau
    alignment: str = "none"  # declared by the caller
    benchmark: str = "tanks_and_temples"


def tanks_and_temples(
    points_rec,
    points_gt,
    tau_m: float,
    *,
    gt_mesh=None,
    downsample: bool = True,
    alignment: str = "none",
) -> TanksAndTemplesResult:
    """Tanks and Temples F-score (Knapitsch et al., SIGGRAPH 2017; isl-org/TanksAndTemples
    python_toolbox/evaluation ``EvaluateHisto``).

    Both clouds are voxel-downsampled at tau/2 (``downsample=True``, as the toolbox does; cropping
    is the caller's job). precision = |{d(rec->gt) < tau}| / |rec|,
    recall = |{d(gt->rec) < tau}| / |gt|, strict ``<``; F = 2PR/(P+R). Empty cloud(s): P = R = F = 0
    (the toolbox divides by zero when P = R = 0; we return F = 0).

    points_rec (N, 3), points_gt (M, 3) float64 metres; gt_mesh optional (vertices (V, 3), faces
    (F, 3)) for exact rec -> GT surface distances.
    """
    d_rg, d_gr, voxel, to = tanks_and_temples_distances(points_rec, points_gt, tau_m, gt_mesh=gt_mesh,
                                                        downsample=downsample,
                                                        upper_bound_m=tau_m * (1.0 + _BOUND_SLACK))
    if len(d_rg) == 0 or len(d_gr) == 0:
        return TanksAndTemplesResult(tau_m, 0.0, 0.0, 0.0, len(d_rg), len(d_gr), voxel, to, alignment=alignment)
    p = float(np.count_nonzero(d_rg < tau_m) / len(d_rg))
    r = float(np.count_nonzero(d_gr < tau_m) / len(d_gr))
    return TanksAndTemplesResult(tau_m, p, r, _fscore(p, r), len(d_rg), len(d_gr), voxel, to, alignment=alignment)


#: Relative slack of the search bound used for thresholded nearest-point distances: the bound
#: tau (1 + 1e-6) lies far above float64 rounding of tau, so every distance below tau is exact and
#: ``d < tau`` is decided exactly as without a bound.
_BOUND_SLACK = 1e-6


def tanks_and_temples_distances(points_rec, points_gt, tau_m: float, *, gt_mesh=None, downsample: bool = True,
                                upper_bound_m: float = np.inf):
    """The distances Tanks and Temples thresholds: ``(d_rec_to_gt (N,), d_gt_to_rec (M,), voxel_m,
    distance_rec_to_gt)`` after voxel downsampling both clouds at tau/2 (``voxel_m`` None when not
    downsampled). Its precision/recall curves over thresholds (the toolbox's plots) use these same
    distances. An empty side gives empty arrays (of inf). Nearest-point distances at or beyond
    ``upper_bound_m`` may be inf (see :func:`recon_eval.metrics.distances.nearest_point_distances`)."""
    rec = _check_cloud(points_rec, "reconstructed points")
    gt = _check_cloud(points_gt, "GT points")
    if not tau_m > 0:
        raise InputError(f"tau must be > 0 metres, got {tau_m}")
    voxel = tau_m / 2.0 if downsample else None
    if voxel is not None:
        rec, gt = voxel_downsample(rec, voxel), voxel_downsample(gt, voxel)
    if len(rec) == 0 or len(gt) == 0:
        to = DistanceTo.MESH if gt_mesh is not None else DistanceTo.POINTS
        return np.full(len(rec), np.inf), np.full(len(gt), np.inf), voxel, to.value
    if gt_mesh is not None:
        d_rg, to = surface_distances(rec, gt_mesh), DistanceTo.MESH
    else:
        d_rg, to = nearest_point_distances(rec, gt, upper_bound_m=upper_bound_m), DistanceTo.POINTS
    d_gr = nearest_point_distances(gt, rec, upper_bound_m=upper_bound_m)
    return d_rg, d_gr, voxel, to.value


# --- ETH3D -------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Eth3dResult:
    """ETH3D multi-view accuracy / completeness / F1 at one tolerance."""

    tolerance_m: float
    accuracy: float  # per-cell-averaged fraction of rec points within tolerance of GT, [0, 1] (float32 value)
    completeness: float  # per-cell-averaged fraction of GT points within tolerance of rec, [0, 1] (float32 value)
    f1: float  # 2 A C / (A + C) in float32; 0 when both are 0
    voxel_m: float  # voxel size for the per-voxel averaging (ETH3D --voxel_size, default 0.01)
    n_rec_scored: int  # reconstructed points scored (observed space only)
    n_rec_unobserved: int  # reconstructed points excluded as lying in unobserved space
    n_gt: int
    distance_rec_to_gt: str
    operator: str = "<="  # within tolerance: distance <= tolerance
    alignment: str = "none"  # ETH3D does no alignment: the result must be in the GT frame
    benchmark: str = "eth3d_multiview"


#: ETH3D's voxel grids (multi-view-evaluation src/accuracy.cc, completeness.cc ``kGridShifts``):
#: the cell of a point is floor(p / voxel + shift) on each axis, for the shifts 0 and 0.5 voxel;
#: the cells of both grids are pooled into one average.
ETH3D_GRID_SHIFTS = (0.0, 0.5)


def _eth3d_cells(points: np.ndarray, voxel_m: float, shift: float) -> np.ndarray:
    """(N, 3) int64 cell indices as ETH3D's ``CalcCellCoordinates`` computes them, in its float32
    arithmetic: ``float(p) * voxel_size_inv + shift`` rounded to float32 at each step, floored;
    ``voxel_size_inv = (float)(1.0 / voxel_size)`` with ``voxel_size`` a float (main.cc)."""
    inv = np.float32(1.0 / np.float64(np.float32(voxel_m)))
    return np.floor(points.astype(np.float32) * inv + np.float32(shift)).astype(np.int64)


def _eth3d_voxel_average(points: np.ndarray, good: np.ndarray, voxel_m: float, *, float_cells: bool) -> np.float32:
    """ETH3D's density-cancelling average: over the occupied cells of both grids
    (:data:`ETH3D_GRID_SHIFTS`), pooled, the fraction of ``good`` points in the cell; the
    fractions summed in double and the mean stored as a float. The cell fraction is a float
    division for accuracy (``accurate / (1.0f * valid)``, ``float_cells``) and a double one for
    completeness (``complete / (1.0 * count)``), as in accuracy.cc and completeness.cc."""
    if len(points) == 0:
        return np.float32(0.0)
    fractions = []
    for shift in ETH3D_GRID_SHIFTS:
        inv, counts = _group_voxels(_eth3d_cells(points, voxel_m, shift))
        n_good = np.bincount(inv, weights=good.astype(np.float64), minlength=len(counts))
        if float_cells:
            fractions.append((n_good.astype(np.float32) / counts.astype(np.float32)).astype(np.float64))
        else:
            fractions.append(n_good / counts)
    f = np.concatenate(fractions)
    return np.float32(math.fsum(f) / len(f))


def _eth3d_f1(accuracy: np.float32, completeness: np.float32) -> np.float32:
    """main.cc's F1 in float: 0 when both are <= 0, else 2 (P R) / (P + R)."""
    if accuracy <= 0 and completeness <= 0:
        return np.float32(0.0)
    return np.float32(2) * (accuracy * completeness) / (accuracy + completeness)


def eth3d(
    points_rec,
    points_gt,
    tolerance_m: float,
    *,
    gt_mesh=None,
    rec_observed=None,
    voxel_m: float = 0.01,
) -> Eth3dResult:
    """ETH3D multi-view metrics (Schoeps et al., CVPR 2017; ETH3D/multi-view-evaluation).

    Completeness: a GT point is complete if a reconstructed point is within the tolerance
    (``<=``). Accuracy: a reconstructed point is accurate if within the tolerance of the GT
    (``<=``); points in unobserved space (``rec_observed`` False, (N,) bool; default all observed)
    are excluded. Both are averaged per voxel of size ``voxel_m`` (ETH3D's ``--voxel_size``,
    default 0.01 m) to cancel density: the score is the mean, over the occupied cells of two
    grids shifted by 0 and 0.5 voxel and pooled, of the fraction of good points in the cell
    (:func:`_eth3d_voxel_average`). F1 = 2AC/(A+C), 0 when both are 0. Empty cloud -> 0. The cell
    indices, fractions, means and F1 follow ETH3D's float32 arithmetic, so the three scores are
    float32 values, equal to the evaluator's for the same per-point classification.
    ETH3D tolerances: 0.01, 0.02, 0.05, 0.1, 0.2, 0.5 m. (:func:`eth3d_table` at one tolerance.)
    """
    return eth3d_table(points_rec, points_gt, (tolerance_m,), gt_mesh=gt_mesh, rec_observed=rec_observed,
                       voxel_m=voxel_m)[0]


#: ETH3D's tolerance table (multi-view-evaluation: 0.01, 0.02, 0.05, 0.1, 0.2, 0.5 m).
ETH3D_TOLERANCES_M = (0.01, 0.02, 0.05, 0.1, 0.2, 0.5)


def eth3d_table(points_rec, points_gt, tolerances_m=ETH3D_TOLERANCES_M, *, gt_mesh=None, rec_observed=None,
                voxel_m: float = 0.01) -> tuple[Eth3dResult, ...]:
    """:func:`eth3d` at every tolerance (ETH3D evaluates its whole table at once), the distances
    computed once. Identical to calling :func:`eth3d` per tolerance."""
    rec = _check_cloud(points_rec, "reconstructed points")
    gt = _check_cloud(points_gt, "GT points")
    tols = tuple(float(t) for t in tolerances_m)
    if not tols or not all(t > 0 for t in tols) or not voxel_m > 0:
        raise InputError("tolerances and voxel size must be > 0 metres")
    observed = np.ones(len(rec), bool) if rec_observed is None else np.asarray(rec_observed, bool).reshape(-1)
    if observed.shape != (len(rec),):
        raise InputError(f"rec_observed: expected shape ({len(rec)},), got {observed.shape}")
    rec_s = rec[observed]
    to = DistanceTo.MESH if gt_mesh is not None else DistanceTo.POINTS
    n_un = int((~observed).sum())
    if len(rec_s) == 0 or len(gt) == 0:
        return tuple(Eth3dResult(t, 0.0, 0.0, 0.0, voxel_m, len(rec_s), n_un, len(gt), to.value) for t in tols)
    d_rg, to = _rec_to_gt(rec_s, gt, gt_mesh)
    d_gr = nearest_point_distances(gt, rec_s, upper_bound_m=max(tols) * (1.0 + _BOUND_SLACK))
    out = []
    for t in tols:
        acc = _eth3d_voxel_average(rec_s, d_rg <= t, voxel_m, float_cells=True)
        comp = _eth3d_voxel_average(gt, d_gr <= t, voxel_m, float_cells=False)
        out.append(Eth3dResult(t, float(acc), float(comp), float(_eth3d_f1(acc, comp)), voxel_m, len(rec_s), n_un,
                               len(gt), to.value))
    return tuple(out)


# --- DTU ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class DtuResult:
    """DTU accuracy / completeness / overall (mean and median), outliers dropped."""

    acc_mean_m: float  # mean of kept d(rec->gt), metres
    acc_median_m: float
    comp_mean_m: float  # mean of kept d(gt->rec), metres
    comp_median_m: float
    overall_mean_m: float  # (acc_mean + comp_mean) / 2 (MVSNet convention)
    overall_median_m: float  # (acc_median + comp_median) / 2
    acc_dropped_frac: float  # fraction of rec points dropped as outliers (d >= max_dist)
    comp_dropped_frac: float  # fraction of GT points dropped (d >= max_dist)
    max_dist_m: float  # outlier cut; DTU uses 20 mm
    n_rec: int
    n_gt: int
    distance_rec_to_gt: str
    operator: str = "<"  # a distance is kept when d < max_dist
    alignment: str = "none"
    benchmark: str = "dtu"


def _kept_stats(d: np.ndarray, max_dist_m: float) -> tuple[float, float, float]:
    if len(d) == 0:
        return np.nan, np.nan, np.nan
    kept = d[d < max_dist_m]
    dropped = 1.0 - len(kept) / len(d)
    if len(kept) == 0:
        return np.nan, np.nan, dropped
    return float(np.mean(kept)), float(np.median(kept)), dropped


def dtu(points_rec, points_gt, *, max_dist_m: float = 0.020, gt_mesh=None) -> DtuResult:
    """DTU MVS metrics (Aanaes et al., IJCV 2016; MATLAB eval ``BaseEvalMain``; MVSNet's
    overall = (acc + comp)/2). Distances at or beyond ``max_dist_m`` (20 mm) are dropped, not
    penalised (``d < max_dist`` kept); the dropped fractions are reported. Observation masks and the
    0.2 mm downsampling of the original are the caller's job. Empty cloud or nothing kept -> NaN
    with the counts reported. points (N, 3), (M, 3) metres.
    """
    rec = _check_cloud(points_rec, "reconstructed points")
    gt = _check_cloud(points_gt, "GT points")
    to = DistanceTo.MESH if gt_mesh is not None else DistanceTo.POINTS
    if len(rec) and len(gt):
        d_rg, to = _rec_to_gt(rec, gt, gt_mesh)
        d_gr = nearest_point_distances(gt, rec)
    else:
        d_rg = np.full(len(rec), np.inf)
        d_gr = np.full(len(gt), np.inf)
    am, amed, adrop = _kept_stats(d_rg, max_dist_m)
    cm, cmed, cdrop = _kept_stats(d_gr, max_dist_m)
    return DtuResult(am, amed, cm, cmed, 0.5 * (am + cm), 0.5 * (amed + cmed), adrop, cdrop, max_dist_m,
                     len(rec), len(gt), to.value)


# --- Chamfer -----------------------------------------------------------------------------------
@dataclass(frozen=True)
class ChamferResult:
    """Chamfer distance, both common conventions, with the one-sided terms."""

    rec_to_gt_mean_m: float  # mean d(rec->gt)
    gt_to_rec_mean_m: float  # mean d(gt->rec)
    chamfer_l1_m: float  # (mean d(rec->gt) + mean d(gt->rec)) / 2 ("Chamfer-L1", occupancy nets)
    chamfer_l2_sq_m2: float  # mean d(rec->gt)^2 + mean d(gt->rec)^2 (squared, summed; Fan et al. 2017)
    n_rec: int
    n_gt: int
    distance_rec_to_gt: str
    alignment: str = "none"


def chamfer(points_rec, points_gt, *, gt_mesh=None) -> ChamferResult:
    """Chamfer distance between clouds (N, 3) and (M, 3), metres. No outlier cut. Empty -> inf."""
    rec = _check_cloud(points_rec, "reconstructed points")
    gt = _check_cloud(points_gt, "GT points")
    to = DistanceTo.MESH if gt_mesh is not None else DistanceTo.POINTS
    if len(rec) == 0 or len(gt) == 0:
        return ChamferResult(np.inf, np.inf, np.inf, np.inf, len(rec), len(gt), to.value)
    d_rg, to = _rec_to_gt(rec, gt, gt_mesh)
    d_gr = nearest_point_distances(gt, rec)
    a, b = float(np.mean(d_rg)), float(np.mean(d_gr))
    return ChamferResult(a, b, 0.5 * (a + b), float(np.mean(d_rg**2) + np.mean(d_gr**2)), len(rec), len(gt), to.value)

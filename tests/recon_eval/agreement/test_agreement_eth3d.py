"""ETH3D multi-view accuracy / completeness / F1 against a transliteration of the official
evaluator's aggregation (ETH3D/multi-view-evaluation, master: src/util.h ``CalcCellCoordinates``;
src/accuracy.cc ``kGridShifts``, ``ComputeAccuracy``; src/completeness.cc ``ComputeCompleteness``;
src/main.cc ``voxel_size_inv`` and the F1 line), float32 where the C++ uses float.

Both sides are given the same per-point classification (``d <= t``): ETH3D classifies its
reconstruction points against laser-scan beams, we against the truth mesh or cloud (docs/metrics.md);
what is compared is the density-cancelling average over the two shifted voxel grids, where the
two used to differ (issue 25: one grid, ``floor(p / voxel)``, float64)."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from recon_eval.metrics.pointcloud import eth3d_table

F = np.float32
kGridShifts = ((F(0), F(0), F(0)), (F(0.5), F(0.5), F(0.5)))  # accuracy.cc, completeness.cc


def CalcCellCoordinates(point, voxel_size_inv, shift):
    """util.h: float voxel = p * voxel_size_inv + shift; int x = (int) voxel, minus 1 when voxel
    is negative and not whole."""
    out = []
    for c in range(3):
        voxel = F(F(point[c] * voxel_size_inv) + shift[c])
        x = int(voxel)  # static_cast<int> truncates toward zero
        if F(voxel - F(x)) != 0 and voxel < 0:
            x -= 1
        out.append(x)
    return tuple(out)


def compute_accuracy(reconstruction, accurate, voxel_size_inv):
    """ComputeAccuracy's cells and average for one tolerance (every point observed)."""
    cell_maps = [{}, {}]
    for point, ok in zip(reconstruction, accurate):
        for grid_index in range(2):
            cell = cell_maps[grid_index].setdefault(CalcCellCoordinates(point, voxel_size_inv,
                                                                        kGridShifts[grid_index]), [0, 0])
            cell[0 if ok else 1] += 1  # accurate_count, inaccurate_count
    accuracy_sum, valid_cell_count = 0.0, 0  # std::vector<double>, size_t
    for grid_index in range(2):
        for accurate_count, inaccurate_count in cell_maps[grid_index].values():
            valid_point_count = accurate_count + inaccurate_count
            if valid_point_count > 0:
                accuracy_sum += float(F(accurate_count) / (F(1.0) * F(valid_point_count)))  # float division
                valid_cell_count += 1
    return F(0) if valid_cell_count == 0 else F(accuracy_sum / valid_cell_count)


def compute_completeness(scan, complete, voxel_size_inv):
    """ComputeCompleteness's cells and average for one tolerance."""
    cell_maps = [{}, {}]
    for point, ok in zip(scan, complete):
        for grid_index in range(2):
            cell = cell_maps[grid_index].setdefault(CalcCellCoordinates(point, voxel_size_inv,
                                                                        kGridShifts[grid_index]), [0, 0])
            cell[0] += 1  # point_count
            cell[1] += int(ok)  # complete_count
    completeness_sum, cell_count = 0.0, 0
    for grid_index in range(2):
        cell_count += len(cell_maps[grid_index])
        for point_count, complete_count in cell_maps[grid_index].values():
            completeness_sum += complete_count / (1.0 * point_count)  # double division
    return F(completeness_sum / cell_count)


def f1_score(precision, recall):
    """main.cc, in float."""
    return F(0) if (precision <= 0 and recall <= 0) else F(F(2) * F(precision * recall) / F(precision + recall))


def clouds(seed: int, offset_m: float):
    """A truth cloud in [-0.3, 0.3]^3 (coordinates snapped to 1/8 of a 5 cm voxel on some points, so
    that cell boundaries are met exactly) and a noisy, offset, partial reconstruction of it."""
    rng = np.random.default_rng(seed)
    gt = rng.uniform(-0.3, 0.3, (1500, 3))
    gt[:300] = np.round(gt[:300] / 0.00625) * 0.00625
    rec = gt[200:1400] + offset_m + rng.normal(0, 0.01, (1200, 3))
    return rec, gt


@pytest.mark.parametrize("seed,offset_m", [(0, 0.0), (1, 0.013), (2, -0.021)])
def test_eth3d_equals_the_official_evaluators_aggregation(agreement, seed, offset_m):
    rec, gt = clouds(seed, offset_m)
    voxel = 0.05
    table = eth3d_table(rec, gt, voxel_m=voxel)
    d_rg = cKDTree(gt).query(rec)[0]
    d_gr = cKDTree(rec).query(gt)[0]
    voxel_size_inv = F(1.0 / float(F(voxel)))  # main.cc: float voxel_size_inv = 1.0 / voxel_size
    worst = 0.0
    for r in table:
        acc = compute_accuracy(rec.astype(F), d_rg <= r.tolerance_m, voxel_size_inv)
        comp = compute_completeness(gt.astype(F), d_gr <= r.tolerance_m, voxel_size_inv)
        ref = (float(acc), float(comp), float(f1_score(acc, comp)))
        worst = max(worst, *(abs(a - b) for a, b in zip((r.accuracy, r.completeness, r.f1), ref)))
    assert 0.1 < table[1].accuracy < 0.9 and 0.1 < table[1].completeness < 0.9  # 2 cm: a scale that separates
    agreement(f"eth3d.{seed}", "ETH3D accuracy, completeness, F1 at 0.01-0.5 m (two shifted voxel grids, float)",
              "ETH3D multi-view-evaluation `ComputeAccuracy`, `ComputeCompleteness` (transcribed)", "master",
              f"1200 / 1500 points, 5 cm voxels, offset {offset_m * 100:g} cm", worst)

"""ETH3D's table against a from-scratch computation at every tolerance; the crop-volume reader's errors."""
import json

import numpy as np
import pytest

from recon_eval.errors import InputError
from recon_eval.metrics.pointcloud import ETH3D_TOLERANCES_M, eth3d, eth3d_table
from recon_eval.readers.crop_volume import read_crop_volume


def _voxel_average_from_scratch(points, good, voxel_m):
    """Mean over the occupied cells of ETH3D's two grids (shifted by 0 and 0.5 voxel, pooled) of
    the fraction of good points in the cell, by a dict (float64; the metric's float32 arithmetic
    is checked against ETH3D's in tests/recon_eval/agreement/test_agreement_eth3d.py)."""
    cells = {}
    for p, g in zip(points, good):
        for shift in (0.0, 0.5):
            key = (shift, *np.floor(p / voxel_m + shift).astype(int))
            n, k = cells.get(key, (0, 0))
            cells[key] = (n + 1, k + int(g))
    return float(np.mean([k / n for n, k in cells.values()]))


def test_table_equals_a_from_scratch_computation_at_every_tolerance():
    rng = np.random.default_rng(0)
    gt = rng.uniform(0, 1, (800, 3))
    rec = gt[:500] + rng.normal(0, 0.008, (500, 3))
    d_rg = np.linalg.norm(rec[:, None] - gt[None], axis=2).min(axis=1)  # brute-force nearest neighbours
    d_gr = np.linalg.norm(gt[:, None] - rec[None], axis=2).min(axis=1)
    table = eth3d_table(rec, gt, voxel_m=0.05)
    assert [r.tolerance_m for r in table] == list(ETH3D_TOLERANCES_M)
    for r in table:
        acc = _voxel_average_from_scratch(rec, d_rg <= r.tolerance_m, 0.05)
        comp = _voxel_average_from_scratch(gt, d_gr <= r.tolerance_m, 0.05)
        assert r.accuracy == pytest.approx(acc, abs=1e-7) and r.completeness == pytest.approx(comp, abs=1e-7)  # float32
        assert r == eth3d(rec, gt, r.tolerance_m, voxel_m=0.05)
    assert 0.1 < table[0].accuracy < 0.9  # the smallest tolerance separates good from bad points


def test_crop_volume_reader(tmp_path):
    ok = {"class_name": "SelectionPolygonVolume", "orthogonal_axis": "Y", "axis_min": 0, "axis_max": 1,
          "bounding_polygon": [[0, 0, 0], [1, 0, 0], [1, 0, 1]]}
    (tmp_path / "c.json").write_text(json.dumps(ok))
    assert read_crop_volume(tmp_path / "c.json").orthogonal_axis == "Y"
    for bad, match in (({**ok, "orthogonal_axis": "W"}, "orthogonal_axis"), ({**ok, "bounding_polygon": [[0, 0, 0]]},
                                                                              "bounding_polygon"),
                       ({k: v for k, v in ok.items() if k != "axis_min"}, "axis_min")):
        (tmp_path / "b.json").write_text(json.dumps(bad))
        with pytest.raises(InputError, match=match):
            read_crop_volume(tmp_path / "b.json")
    (tmp_path / "n.json").write_text("{")
    with pytest.raises(InputError, match="not JSON"):
        read_crop_volume(tmp_path / "n.json")

"""ETH3D's table in one pass equals the per-tolerance metric; the crop-volume reader's errors."""
import json

import numpy as np
import pytest

from recon_eval.errors import InputError
from recon_eval.metrics.pointcloud import ETH3D_TOLERANCES_M, eth3d, eth3d_table
from recon_eval.readers.crop_volume import read_crop_volume


def test_table_equals_one_tolerance_at_a_time():
    rng = np.random.default_rng(0)
    gt = rng.uniform(0, 1, (3000, 3))
    rec = gt[:2000] + rng.normal(0, 0.03, (2000, 3))
    table = eth3d_table(rec, gt)
    assert [r.tolerance_m for r in table] == list(ETH3D_TOLERANCES_M)
    for r in table:
        assert r == eth3d(rec, gt, r.tolerance_m)


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

"""LiDAR metrics (recon_eval.metrics.lidar): de-skewing truth is the hit in the LiDAR frame at the
reference time (a planted pose), a perfect de-skew scores 0 and the raw cloud its skew; range
errors binned by range and incidence recover planted biases."""
from __future__ import annotations

import numpy as np
import pytest

from recon_eval.errors import InputError
from recon_eval.metrics.lidar import deskew_error, deskew_truth, range_error
from scenegen.geometry.rotation import rotation_from_euler_deg


def test_deskew_truth_undoes_a_planted_pose_and_scores_the_skew():
    rng = np.random.default_rng(30)
    R = rotation_from_euler_deg([3, -5, 40], "xyz")
    t = np.array([4.0, -2.0, 1.5])
    local = rng.uniform(-20, 20, (500, 3))
    world = local @ R.T + t
    assert np.allclose(deskew_truth(world, R, t), local, atol=1e-12)
    skew = np.column_stack([np.linspace(0, 1.0, 500), np.zeros(500), np.zeros(500)])  # 0 .. 1 m of ego motion
    res = deskew_error(local, local, local + skew)
    assert res.error_m.rmse == 0 and res.rmse_ratio == 0 and res.n_points == 500
    assert res.raw_error_m.max == pytest.approx(1.0) and res.raw_error_m.mean == pytest.approx(0.5)
    half = deskew_error(local + skew / 2, local, local + skew)
    assert half.rmse_ratio == pytest.approx(0.5) and half.p95_m == pytest.approx(0.475, abs=1e-3)
    with pytest.raises(InputError, match="one point per returned beam, 500 x 3"):
        deskew_error(local[:10], local, local)


def test_range_error_bins_recover_planted_biases():
    true = np.repeat([3.0, 15.0, 50.0], 100)
    inc = np.radians(np.tile(np.linspace(0, 80, 100), 3))
    measured = true + np.where(true > 10, 0.05, -0.02)
    measured[0] = np.nan  # a beam without a return is not scored
    res = range_error(measured, true, inc, range_edges_m=(0, 10, 100), incidence_edges_deg=(0, 45, 90))
    assert [b.n for b in res.by_range_m] == [99, 200]
    assert res.by_range_m[0].bias_m == pytest.approx(-0.02) and res.by_range_m[1].bias_m == pytest.approx(0.05)
    assert res.by_range_m[1].std_m == pytest.approx(0, abs=1e-12) and res.error_m.n == 299
    assert sum(b.n for b in res.by_incidence_deg) == 299

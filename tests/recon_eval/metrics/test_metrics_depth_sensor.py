"""Depth-sensor statistics (recon_eval.metrics.depth_sensor) against scipy's binned_statistic and
planted errors: per-range and per-incidence bias / MAE / RMSE / median, completeness and its map,
phantom returns, edge outlier rates."""
from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from recon_eval.errors import InputError
from recon_eval.metrics.depth_sensor import depth_sensor_metrics


def _planted(seed=0):
    rng = np.random.default_rng(seed)
    g = rng.uniform(0.5, 5.0, (3, 40, 50))
    inc = rng.uniform(0, 89, g.shape)
    err = 0.01 * g + rng.normal(0, 0.005, g.shape)  # a bias growing with range, 1 % of it
    m = g + err
    m[0, :10] = np.nan  # 10 missing rows in frame 0
    g[1, :, :5] = np.inf  # no truth in 5 columns of frame 1, but measured there: phantom returns
    edge = np.zeros(g.shape, bool)
    edge[:, 20] = True
    m[:, 20] += 0.3  # the edge column is off by 30 cm
    return m, g, inc, edge


def test_binned_errors_equal_scipy_binned_statistic():
    m, g, inc, edge = _planted()
    bins = np.array([0.5, 1.0, 2.0, 3.5, 5.0])
    r = depth_sensor_metrics(m, g, range_bins_m=bins, incidence_deg=inc, incidence_bins_deg=[0, 30, 60, 90],
                             edge_mask=edge)
    ok = np.isfinite(m) & np.isfinite(g)
    e, gv, iv = (m - g)[ok], g[ok], inc[ok]
    for binned, x, edges in ((r.by_range, gv, bins), (r.by_incidence, iv, [0, 30, 60, 90])):
        for name, fn in (("bias_m", np.mean), ("mae_m", lambda a: np.mean(np.abs(a))),
                         ("rmse_m", lambda a: np.sqrt(np.mean(a * a))), ("median_abs_m", lambda a: np.median(np.abs(a)))):
            ref = stats.binned_statistic(x, e, statistic=fn, bins=edges).statistic
            np.testing.assert_allclose(getattr(binned, name), ref, rtol=1e-12)
        np.testing.assert_array_equal(binned.count, stats.binned_statistic(x, e, "count", bins=edges).statistic)
    assert r.bias_m == pytest.approx(e.mean()) and r.rmse_m == pytest.approx(np.sqrt(np.mean(e ** 2)))


def test_completeness_phantoms_and_edges_count_what_was_planted():
    m, g, inc, edge = _planted()
    r = depth_sensor_metrics(m, g, range_bins_m=[0, 10], edge_mask=edge, outlier_m=0.1)
    truth = 3 * 40 * 50 - 40 * 5
    assert r.n_truth == truth and r.completeness == pytest.approx((truth - 10 * 50) / truth)
    assert r.phantom_fraction == pytest.approx(40 * 5 / (3 * 40 * 50 - 500))
    want = np.ones((40, 50))
    want[:10] = 2 / 3  # frame 0 misses them
    want[:10, :5] = 1 / 2  # ... and frame 1 has no truth there
    np.testing.assert_allclose(r.completeness_map, want, rtol=1e-15)
    # the edge column is all outliers (30 cm > 10 cm), the interior none (1 % of <= 5 m + 5 mm noise)
    assert r.edge_outlier_rate == 1.0 and r.interior_outlier_rate == 0.0
    assert r.edge_mae_m > 0.3 > 0.06 > r.interior_mae_m
    assert r.by_incidence is None


def test_bad_shapes_are_input_errors():
    with pytest.raises(InputError, match="differ in shape"):
        depth_sensor_metrics(np.zeros((2, 3)), np.zeros((3, 3)), range_bins_m=[0, 1])
    with pytest.raises(InputError, match="outlier threshold"):
        depth_sensor_metrics(np.zeros((2, 3)), np.zeros((2, 3)), range_bins_m=[0, 1], outlier_m=0)

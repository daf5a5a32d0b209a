import numpy as np
import pytest

from recon_eval.metrics.depth import DepthAlignment, eigen_depth_metrics
from recon_eval.errors import InputError

GT = np.array([[1.0, 2.0], [4.0, 0.0]])  # 0: no truth
PRED = np.array([[2.0, 2.0], [2.0, 5.0]])


def test_hand_computed_single_image():
    r = eigen_depth_metrics([PRED], [GT])
    assert r.abs_rel == pytest.approx((1 + 0 + 0.5) / 3)
    assert r.sq_rel_m == pytest.approx((1 + 0 + 1) / 3)
    assert r.rmse_m == pytest.approx(np.sqrt(5 / 3))
    assert r.rmse_log == pytest.approx(np.sqrt(2 * np.log(2) ** 2 / 3))
    assert (r.a1, r.a2, r.a3) == pytest.approx((1 / 3, 1 / 3, 1 / 3))  # ratio 2 is not < 1.25^3
    assert r.coverage == 1.0


def test_averaged_per_image_not_pooled():
    r = eigen_depth_metrics([PRED, np.ones((1, 1))], [GT, np.ones((1, 1))])
    assert r.abs_rel == pytest.approx(0.25)  # (0.5 + 0) / 2; pooled pixels would give 1.5 / 4
    np.testing.assert_allclose(r.per_image_abs_rel, [0.5, 0.0])


def test_threshold_operator_is_strict():
    g = np.array([[1.0]])
    r = eigen_depth_metrics([np.array([[1.25]])], [g])
    assert r.a1 == 0.0 and r.a2 == 1.0


def test_median_alignment():
    g = np.array([[1.0, 2.0, 3.0]])
    r = eigen_depth_metrics([3.0 * g], [g], alignment=DepthAlignment.MEDIAN)
    assert r.abs_rel == pytest.approx(0.0, abs=1e-15) and r.per_image_scale[0] == pytest.approx(1 / 3)
    assert r.alignment == "median"


def test_scale_and_shift_alignment():
    g = np.array([[1.0, 2.0, 3.0, 7.0]])
    r = eigen_depth_metrics([2.0 * g + 1.0], [g], alignment="scale_shift")
    assert r.abs_rel == pytest.approx(0.0, abs=1e-12)
    assert r.per_image_scale[0] == pytest.approx(0.5) and r.per_image_shift_m[0] == pytest.approx(-0.5)


def test_missing_predictions_lower_coverage():
    p = PRED.copy()
    p[0, 0] = np.nan
    r = eigen_depth_metrics([p], [GT])
    assert r.coverage == pytest.approx(2 / 3)
    assert r.abs_rel == pytest.approx(0.25)


def test_image_without_valid_pixels_is_counted():
    r = eigen_depth_metrics([PRED, np.full((1, 1), np.nan)], [GT, np.ones((1, 1))])
    assert r.n_images_failed == 1 and r.abs_rel == pytest.approx(0.5) and r.coverage == pytest.approx(0.5)


def test_shape_mismatch():
    with pytest.raises(InputError, match="differ in shape"):
        eigen_depth_metrics([np.ones((2, 3))], [GT])


def test_depth_range_is_open():
    g = np.array([[1.0, 2.0, 3.0]])
    p = np.array([[1.0, 4.0, 3.0]])  # only the middle pixel is wrong
    r = eigen_depth_metrics([p], [g], min_depth_m=1.0, max_depth_m=3.0, clamp=False)
    assert r.abs_rel == 1.0  # 1 and 3 are outside (1, 3): only g = 2 is scored
    # by default the prediction is clamped to [1, 3] first, as monodepth2 does: 4 -> 3
    assert eigen_depth_metrics([p], [g], min_depth_m=1.0, max_depth_m=3.0).abs_rel == 0.5

import numpy as np
import pytest

from recon_eval.errors import InputError
from recon_eval.metrics.stereo import eth3d_two_view, kitti_d1, kitti_interpolate_background, middlebury

nan = np.nan


class TestKittiD1:
    # truth (occ): (1, 1) invalid; estimate: (1, 2) missing -> interpolated from its row (7)
    GT = np.array([[10.0, 10.0, 100.0], [100.0, 0.0, 50.0]])
    EST = np.array([[13.5, 12.0, 104.0], [106.0, 7.0, nan]])
    # errors: 3.5 (35 % -> bad), 2 (<= 3 px -> ok), 4 (4 % -> ok), 6 (6 % -> bad), 43 (bad)
    FG = np.array([[True, False, False], [False, False, True]])

    def test_hand_computed(self):
        noc = self.GT.copy()
        noc[1, 2] = 0.0  # the interpolated pixel is "occluded"
        r = kitti_d1([self.EST], [self.GT], [noc], [self.FG])
        assert r.d1_all_occ_pct == pytest.approx(60.0)
        assert r.d1_fg_occ_pct == pytest.approx(100.0)
        assert r.d1_bg_occ_pct == pytest.approx(100 / 3)
        assert r.d1_all_noc_pct == pytest.approx(50.0)
        assert r.d1_fg_noc_pct == pytest.approx(100.0)
        assert r.density_pct == pytest.approx(80.0)
        assert (r.n_px_occ, r.n_px_noc) == (5, 4)

    def test_both_conditions_are_strict_in_the_devkits_float_arithmetic(self):
        gt = np.array([[60.0, 100.0]])
        est = np.array([[63.0, 105.0]])  # 3 px exactly (5 %); 5 px at exactly 5 %
        # 3 > 3 is false; the float quotient 5 / 100 = 0.0500000007 > 0.05: the devkit's outlier
        assert kitti_d1([est], [gt]).d1_all_occ_pct == 50.0
        est2 = np.array([[np.nextafter(np.float32(63), np.float32(64)), 105.0]])  # one float above 3 px
        assert kitti_d1([est2], [gt]).d1_all_occ_pct == 100.0
        est3 = np.array([[63.0, np.nextafter(np.float32(105), np.float32(0))]])  # one float below 5 px
        assert kitti_d1([est3], [gt]).d1_all_occ_pct == 0.0

    def test_pooled_over_images_not_averaged(self):
        gt1, est1 = np.full((1, 1), 10.0), np.full((1, 1), 20.0)  # 1 of 1 bad
        gt2, est2 = np.full((1, 3), 10.0), np.full((1, 3), 10.0)  # 0 of 3 bad
        r = kitti_d1([est1, est2], [gt1, gt2])
        assert r.d1_all_occ_pct == pytest.approx(25.0)  # pooled: 1/4 (per-image mean would be 50)

    def test_truth_against_itself(self):
        assert kitti_d1([self.GT], [self.GT]).d1_all_occ_pct == 0.0

    def test_all_missing_is_all_bad(self):
        r = kitti_d1([np.full((2, 3), nan)], [self.GT])
        assert r.d1_all_occ_pct == 100.0 and r.density_pct == 0.0

    def test_shape_mismatch_is_input_error(self):
        with pytest.raises(InputError, match="differ in shape"):
            kitti_d1([np.zeros((2, 2))], [self.GT])


def test_kitti_interpolation_rules():
    d = np.array([[5.0, nan, nan, 3.0], [nan, 4.0, nan, nan], [nan, nan, nan, nan], [1.0, 2.0, 3.0, 4.0]])
    out = kitti_interpolate_background(d)
    np.testing.assert_array_equal(out[0], [5, 3, 3, 3])  # interior gap: min of neighbours
    np.testing.assert_array_equal(out[1], [4, 4, 4, 4])  # row ends: nearest valid
    assert np.all(np.isnan(out[2]))  # an interior empty row stays invalid (only top/bottom extrapolated)
    top = kitti_interpolate_background(np.array([[nan, nan], [1.0, 2.0]]))
    np.testing.assert_array_equal(top, [[1, 2], [1, 2]])
    assert np.isnan(d[0, 1])  # input untouched


class TestTwoView:
    GT = np.array([[1.0, 2.0, 3.0, 4.0, np.inf]])  # inf: unknown truth
    EST = np.array([[1.5, 2.0, 6.0, nan, 7.0]])

    def test_middlebury_hand_computed(self):
        r = middlebury(self.EST, self.GT)
        # 4 truth pixels; valid estimates 1.5, 2, 6 -> errors .5, 0, 3; one invalid
        assert (r.bad_0_5_pct, r.bad_1_0_pct, r.bad_2_0_pct, r.bad_4_0_pct) == (25.0, 25.0, 25.0, 0.0)
        assert r.invalid_pct == 25.0 and r.totbad_2_0_pct == 50.0
        assert r.avgerr_px == pytest.approx(3.5 / 3)
        assert r.rms_px == pytest.approx(np.sqrt(9.25 / 3))
        assert r.a50_px == 0.5 and r.a99_px == 3.0

    def test_eth3d_hand_computed(self):
        r = eth3d_two_view(self.EST, self.GT)
        # width 5: the estimate 6 > 5 is missing; covered errors .5, 0 -> strict > 0.5 gives 0 %
        assert r.coverage_pct == 50.0 and r.bad_0_5_pct == 0.0
        assert r.a50_px == 0.5  # sorted [0, .5] at floor(2 * .5) = 1
        assert r.avgerr_px == 0.25

    def test_mask(self):
        r = middlebury(self.EST, self.GT, nonocc_mask=np.array([[True, True, False, False, False]]))
        assert r.n_px == 2 and r.bad_0_5_pct == 0.0 and r.avgerr_px == 0.25

import numpy as np
import pytest

from recon_eval.errors import InputError
from recon_eval.metrics.stats import error_stats, maa_deg, recall_auc


class TestRecallAuc:
    def test_hand_computed(self):
        # sorted errors 1, 2, 3, 100 -> curve (0,0) (1,.25) (2,.5) (3,.75), held at .75 to 5:
        # area = .125 + .375 + .625 + 1.5 = 2.625 -> / 5 = 0.525
        assert recall_auc([3.0, 1.0, 100.0, 2.0], [5.0])[0] == pytest.approx(0.525, abs=1e-15)
        # up to 2: .125 + .25 (held at .25 from 1 to 2) = .375 -> / 2
        assert recall_auc([3.0, 1.0, 100.0, 2.0], [2.0])[0] == pytest.approx(0.1875, abs=1e-15)

    def test_matches_superglue_reference_code(self):
        # magicleap/SuperGluePretrainedNetwork models/utils.py pose_auc, verbatim logic
        def pose_auc(errors, thresholds):
            sort_idx = np.argsort(errors)
            errors = np.array(errors.copy())[sort_idx]
            recall = (np.arange(len(errors)) + 1) / len(errors)
            errors = np.r_[0.0, errors]
            recall = np.r_[0.0, recall]
            aucs = []
            for t in thresholds:
                last_index = np.searchsorted(errors, t)
                r = np.r_[recall[:last_index], recall[last_index - 1]]
                e = np.r_[errors[:last_index], t]
                aucs.append(np.trapezoid(r, x=e) / t)
            return aucs

        errs = np.random.default_rng(0).exponential(8.0, size=200)
        errs[::17] = np.inf  # failures
        np.testing.assert_allclose(recall_auc(errs, (5, 10, 20)), pose_auc(errs, (5, 10, 20)), atol=1e-15)

    def test_perfect_and_failed(self):
        assert recall_auc([0.0, 0.0], [5.0]) == (1.0,)
        assert recall_auc([np.inf, np.nan], [5.0]) == (0.0,)
        assert recall_auc([], [5.0]) == (0.0,)


def test_maa_hand_computed():
    # th = 1: only 0.5 < 1 (1.0 is not < 1); th = 2..5: 2/4; th = 6..10: 3/4
    assert maa_deg([0.5, 1.0, 5.5, np.inf]) == pytest.approx((0.25 + 4 * 0.5 + 5 * 0.75) / 10, abs=1e-15)
    # mAA@5 takes the first 5 bins of the 10: an error of exactly 5 is in [5, 6), counted from th = 6
    assert maa_deg([0.5, 1.0, 5.0, np.inf], 5) == pytest.approx((0.25 + 4 * 0.5) / 5, abs=1e-15)


@pytest.mark.parametrize("bad", [0, 11, 2.5, -1])
def test_maa_thresholds_are_those_of_the_benchmarks_histogram(bad):
    with pytest.raises(InputError, match="expected an integer 1 .. 10"):
        maa_deg([1.0], bad)


def test_error_stats_reports_failures():
    s = error_stats([3.0, 4.0, np.inf])
    assert (s.n, s.n_failed, s.mean, s.max) == (2, 1, 3.5, 4.0)
    assert s.rmse == pytest.approx(np.sqrt(12.5))
    assert s.std == pytest.approx(0.5)

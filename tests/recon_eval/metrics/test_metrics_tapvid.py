"""TAP-Vid metrics against a from-scratch, per-point reading of the paper's definitions, and on
cases worked by hand."""
import math

import numpy as np
import pytest

from recon_eval.errors import InputError
from recon_eval.metrics.tapvid import evaluation_mask, mean_over_videos, tapvid_metrics


def _by_the_paper(q, gt, gt_occ, pred, pred_occ, size, mode, eval_size):
    """Loop over every (track, frame): which frames count, then TP/FP/visible per threshold."""
    sx, sy = (1.0, 1.0) if eval_size is None else (eval_size[0] / size[0], eval_size[1] / size[1])
    counts = {d: [0, 0, 0] for d in (1, 2, 4, 8, 16)}  # correct, true positives, false positives
    n_ev = n_vis = agree = 0
    for i in range(gt.shape[0]):
        qf = int(np.rint(q[i, 0]))
        for t in range(gt.shape[1]):
            if (mode == "first" and t <= qf) or (mode == "strided" and t == qf):
                continue
            n_ev += 1
            agree += bool(pred_occ[i, t]) == bool(gt_occ[i, t])
            vis = not gt_occ[i, t]
            n_vis += vis
            dist = math.hypot((pred[i, t, 0] - gt[i, t, 0]) * sx, (pred[i, t, 1] - gt[i, t, 1]) * sy) if vis else math.inf
            for d, c in counts.items():
                near = dist < d
                c[0] += vis and near
                c[1] += vis and near and not pred_occ[i, t]
                c[2] += (not pred_occ[i, t]) and not (vis and near)
    within = {d: c[0] / n_vis for d, c in counts.items()}
    jac = {d: c[1] / (n_vis + c[2]) for d, c in counts.items()}
    return np.mean(list(jac.values())), np.mean(list(within.values())), agree / n_ev, jac, within


@pytest.mark.parametrize("mode", ["first", "strided"])
@pytest.mark.parametrize("eval_size", [(256, 256), None])
def test_equals_the_definitions_on_random_videos(mode, eval_size):
    rng = np.random.default_rng(7)
    n, t, size = 60, 24, (640, 480)
    gt = rng.uniform(0, 1, (n, t, 2)) * size
    gt_occ = rng.random((n, t)) < 0.3
    q = np.stack([rng.integers(0, t - 1, n), gt[np.arange(n), 0, 1], gt[np.arange(n), 0, 0]], 1).astype(float)
    pred = gt + rng.normal(0, 6.0, gt.shape)
    pred_occ = np.where(rng.random((n, t)) < 0.2, ~gt_occ, gt_occ)
    gt_nan = np.where(gt_occ[..., None], np.nan, gt)  # occluded truth may be NaN
    r = tapvid_metrics(q, gt_nan, gt_occ, pred, pred_occ, image_size=size, query_mode=mode, eval_size=eval_size)
    aj, avg, oa, jac, within = _by_the_paper(q, gt, gt_occ, pred, pred_occ, size, mode, eval_size)
    assert r.average_jaccard == pytest.approx(aj, abs=1e-15)
    assert r.average_pts_within == pytest.approx(avg, abs=1e-15)
    assert r.occlusion_accuracy == pytest.approx(oa, abs=1e-15)
    for d in (1, 2, 4, 8, 16):
        assert r.jaccard[d] == pytest.approx(jac[d], abs=1e-15)
        assert r.pts_within[d] == pytest.approx(within[d], abs=1e-15)
    assert 0 < r.average_jaccard < 1 and 0 < r.occlusion_accuracy < 1  # the case is not degenerate


def test_hand_worked_case():
    # one track over 4 frames, query at frame 0 ("first": frames 1..3 count), at 256 x 256
    gt = np.array([[[10, 10], [20, 10], [30, 10], [40, 10]]], float)
    gt_occ = np.array([[False, False, False, True]])
    pred = gt + np.array([[[0, 0], [1.5, 0], [5, 0], [0, 0]]])
    pred_occ = np.array([[False, False, False, False]])  # frame 3 predicted visible: a false positive
    r = tapvid_metrics([[0, 10, 10]], gt, gt_occ, pred, pred_occ, image_size=(256, 256))
    # frame 1: error 1.5 (within 2..16); frame 2: error 5 (within 8, 16); frame 3: FP everywhere
    assert r.pts_within == {1: 0.0, 2: 0.5, 4: 0.5, 8: 1.0, 16: 1.0}
    assert r.jaccard == {1: 0 / 5, 2: 1 / 4, 4: 1 / 4, 8: 2 / 3, 16: 2 / 3}
    assert r.occlusion_accuracy == pytest.approx(2 / 3)
    assert (r.n_evaluated, r.n_visible) == (3, 2)


def test_scaling_to_256_and_strict_threshold():
    gt = np.zeros((1, 2, 2)) + 100
    pred = gt.copy()
    pred[0, 1, 0] += 5.0  # 5 px at 1280 wide = exactly 1 px at 256: not within 1 (strict <)
    occ = np.zeros((1, 2), bool)
    r = tapvid_metrics([[0, 100, 100]], gt, occ, pred, occ, image_size=(1280, 720))
    assert r.pts_within[1] == 0.0 and r.pts_within[2] == 1.0
    r_native = tapvid_metrics([[0, 100, 100]], gt, occ, pred, occ, image_size=(1280, 720), eval_size=None)
    assert r_native.pts_within[4] == 0.0 and r_native.pts_within[8] == 1.0


def test_perfect_prediction_scores_one_and_lost_points_score_zero():
    rng = np.random.default_rng(1)
    gt = rng.uniform(0, 200, (5, 6, 2))
    occ = rng.random((5, 6)) < 0.3
    occ[:, 1] = False
    q = np.zeros((5, 3))
    r = tapvid_metrics(q, gt, occ, gt, occ, image_size=(200, 200))
    assert (r.average_jaccard, r.average_pts_within, r.occlusion_accuracy) == (1.0, 1.0, 1.0)
    lost = np.full_like(gt, np.nan)
    r = tapvid_metrics(q, gt, occ, lost, occ, image_size=(200, 200))
    assert r.average_pts_within == 0.0 and r.average_jaccard == 0.0 and r.occlusion_accuracy == 1.0


def test_evaluation_mask_modes():
    assert evaluation_mask([1], 4, "first").tolist() == [[False, False, True, True]]
    assert evaluation_mask([1], 4, "strided").tolist() == [[True, False, True, True]]
    with pytest.raises(InputError, match="query mode"):
        evaluation_mask([0], 4, "last")
    with pytest.raises(InputError, match="query frames"):
        evaluation_mask([4], 4, "first")


def test_shape_errors_name_the_input():
    gt = np.zeros((2, 3, 2))
    occ = np.zeros((2, 3), bool)
    with pytest.raises(InputError, match="predicted tracks"):
        tapvid_metrics(np.zeros((2, 3)), gt, occ, gt[:, :2], occ, image_size=(10, 10))
    with pytest.raises(InputError, match="predicted occlusion"):
        tapvid_metrics(np.zeros((2, 3)), gt, occ, gt, occ[:, :2], image_size=(10, 10))
    with pytest.raises(InputError, match="visible truth point"):
        tapvid_metrics(np.zeros((2, 3)), np.full_like(gt, np.nan), occ, gt, occ, image_size=(10, 10))


def test_mean_over_videos_skips_videos_without_anything_to_score():
    gt = np.zeros((1, 2, 2))
    occ = np.zeros((1, 2), bool)
    all_occ = np.ones((1, 2), bool)
    good = tapvid_metrics([[0, 0, 0]], gt, occ, gt, occ, image_size=(10, 10))
    false_pos = tapvid_metrics([[0, 0, 0]], gt, all_occ, gt, occ, image_size=(10, 10))  # AJ 0 (FPs only)
    nothing = tapvid_metrics([[0, 0, 0]], gt, all_occ, gt, all_occ, image_size=(10, 10))  # AJ 0 / 0
    assert false_pos.average_jaccard == 0.0 and math.isnan(nothing.average_jaccard)
    m = mean_over_videos([good, false_pos, nothing])
    assert m["average_jaccard"] == pytest.approx(0.5)
    assert (m["n_videos"], m["n_videos_without_points"]) == (3, 1)

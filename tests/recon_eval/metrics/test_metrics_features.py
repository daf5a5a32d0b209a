import math

import numpy as np
import pytest

from recon_eval.errors import InputError
from recon_eval.metrics.features import (
    CorrespondenceMap,
    map_keypoints,
    match_accuracy,
    match_precision_recall,
    matching_score,
    mean_over_pairs,
    repeatability,
)
from scenegen.dataset.crossview import NO_SURFACE, OCCLUDED, OUT_OF_FRAME, VISIBLE

W, H = 80, 60
# Bilinear interpolation of a smooth homography between pixel centres: the error is bounded by
# |d2 H| / 8 ~ 1e-3 px for this mild H, so mapping j -> i -> j stays far inside eps = 1 px.
EPS_PX = 1.0
# Translations by exact binary fractions keep every coordinate exact in float64: the known shifts
# must come back to rounding (1e-12 px).
EXACT_TOL = 1e-12


def grid():
    u, v = np.meshgrid(np.arange(W, dtype=np.float64), np.arange(H, dtype=np.float64))
    return np.stack([u, v], axis=-1)


def map_from(fn, occluded_box=None):
    uv = fn(grid().reshape(-1, 2)).reshape(H, W, 2)
    inside = (uv[..., 0] > -0.5) & (uv[..., 0] < W - 0.5) & (uv[..., 1] > -0.5) & (uv[..., 1] < H - 0.5)
    state = np.where(inside, VISIBLE, OUT_OF_FRAME)
    if occluded_box is not None:
        x0, y0, x1, y1 = occluded_box
        state[y0:y1, x0:x1] = OCCLUDED
    return CorrespondenceMap(uv, state)


def homography_maps():
    Hm = np.array([[1.05, 0.04, -2.0], [-0.03, 0.98, 1.5], [2e-4, -1e-4, 1.0]])

    def apply(M):
        def f(x):
            y = np.hstack([x, np.ones((len(x), 1))]) @ M.T
            return y[:, :2] / y[:, 2:3]
        return f

    return map_from(apply(Hm), occluded_box=(50, 10, 65, 30)), map_from(apply(np.linalg.inv(Hm)))


def translation_maps(d=(7.0, 3.0)):
    d = np.asarray(d)
    return map_from(lambda x: x + d), map_from(lambda x: x - d)


def random_keypoints(n, seed):
    rng = np.random.default_rng(seed)
    return np.stack([rng.uniform(0, W - 1, n), rng.uniform(0, H - 1, n)], axis=1)


def test_truth_keypoints_mapped_to_themselves_repeat_fully():
    map_ij, map_ji = homography_maps()
    kp_i = random_keypoints(400, 0)
    m, ok = map_keypoints(kp_i, map_ij)
    assert 0 < (~ok).sum() < 400  # some fall in the occluded box or out of frame: excluded
    kp_j = m[ok]
    r = repeatability(kp_i, kp_j, map_ij, map_ji, eps_px=EPS_PX)
    assert r.repeatability == 1.0
    assert r.n_i == ok.sum() and r.repeated_i == r.n_i and r.repeated_j == r.n_j
    # a view against itself: identity maps, every keypoint repeats at distance 0
    ident = map_from(lambda x: x)
    r0 = repeatability(kp_i, kp_i, ident, ident, eps_px=EPS_PX)
    assert r0.repeatability == 1.0 and r0.localisation_err_px < EXACT_TOL  # weights sum to 1 to rounding


def test_occluded_keypoints_are_not_counted():
    map_ij, _ = homography_maps()
    kp = np.array([[55.25, 15.5], [60.0, 20.0], [10.5, 10.5]])  # two inside the occluded box
    _, ok = map_keypoints(kp, map_ij)
    np.testing.assert_array_equal(ok, [False, False, True])
    # on a pixel centre only that centre is needed; next to an occluded one both are
    st = np.full((H, W), VISIBLE)
    st[5, 6] = OCCLUDED
    cm = CorrespondenceMap(grid(), st)
    np.testing.assert_array_equal(map_keypoints([[5.0, 5.0], [5.5, 5.0], [6.0, 5.0]], cm)[1], [True, False, False])
    np.testing.assert_array_equal(map_keypoints([[-0.2, 3.0], [W - 1.0, H - 1.0]], cm)[1], [False, True])


def test_subpixel_shift_shows_up_exactly_in_localisation_error():
    map_ij, map_ji = translation_maps()
    # a 4 px lattice (every other keypoint is farther than eps) with binary-fraction offsets, inside
    # the frame after the shift: exact arithmetic
    gx, gy = np.meshgrid(np.arange(2.0, 68.0, 4.0), np.arange(2.0, 52.0, 4.0))
    off = np.round(np.random.default_rng(1).uniform(-1, 1, size=(gx.size, 2)) * 64) / 64
    kp_i = np.stack([gx.ravel(), gy.ravel()], axis=1) + off
    shift = np.array([0.3, -0.4])  # |shift| = 0.5
    kp_j = kp_i + [7.0, 3.0] + shift
    r = repeatability(kp_i, kp_j, map_ij, map_ji, eps_px=EPS_PX)
    assert r.repeatability == 1.0
    assert abs(r.localisation_err_px - 0.5) < EXACT_TOL
    assert repeatability(kp_i, kp_j, map_ij, map_ji, eps_px=0.49).repeatability == 0.0


def superpoint_reference(true_warped, warped, thresh):
    """rpautrat/SuperPoint superpoint/evaluations/detector_evaluation.py, compute_repeatability's
    counting, on keypoints already restricted to the shared region (x, y order); plus the mean of
    the nearest distances within the threshold (both counts)."""
    N1, N2 = len(true_warped), len(warped)
    norm = np.linalg.norm(true_warped[:, None, :] - warped[None, :, :], axis=2)
    count1 = count2 = 0
    if N2 != 0:
        min1 = np.min(norm, axis=1)
        count1 = np.sum(min1 <= thresh)
    if N1 != 0:
        min2 = np.min(norm, axis=0)
        count2 = np.sum(min2 <= thresh)
    d = np.r_[min1[min1 <= thresh], min2[min2 <= thresh]]
    return (count1 + count2) / (N1 + N2), np.mean(d)


def test_superpoint_definition_is_the_reference_code():
    """Both sets restricted to the shared region, distances in j: the reference's numbers exactly,
    on a homography pair with an occluded box (keypoints of both views there have no truth)."""
    map_ij, map_ji = homography_maps()
    kp_i = random_keypoints(300, 3)
    m, ok = map_keypoints(kp_i, map_ij)
    rng = np.random.default_rng(4)
    kp_j = np.vstack([m[ok][::2] + rng.normal(0, 0.6, size=(len(m[ok][::2]), 2)), random_keypoints(120, 5)])
    r = repeatability(kp_i, kp_j, map_ij, map_ji, eps_px=3.0, definition="superpoint")
    okj = map_keypoints(kp_j, map_ji)[1]
    rep, loc = superpoint_reference(m[ok], kp_j[okj], 3.0)
    assert r.definition == "superpoint" and (r.n_i, r.n_j) == (ok.sum(), okj.sum())
    assert r.repeatability == pytest.approx(rep, abs=1e-15) and r.localisation_err_px == pytest.approx(loc, abs=1e-12)
    assert repeatability(kp_i, kp_j, map_ij, map_ji, eps_px=3.0).definition == "all_keypoints"  # the default
    with pytest.raises(InputError, match="definition must be one of"):
        repeatability(kp_i, kp_j, map_ij, map_ji, definition="hpatches")


def test_the_definitions_differ_on_a_keypoint_outside_the_shared_region():
    """A keypoint of j without truth in i (outside i's frame) next to a mapped keypoint of i: the
    default finds it, SuperPoint's restriction to the shared region does not."""
    map_ij, map_ji = translation_maps()  # j = i + (7, 3): j's columns < 7 are outside i
    kp_i = np.array([[0.5, 20.0], [30.0, 30.0]])  # map to (7.5, 23) and (37, 33) in j
    kp_j = np.array([[6.2, 23.0], [37.0, 33.0]])  # (6.2, 23) maps to (-0.8, 20): no truth in i
    a = repeatability(kp_i, kp_j, map_ij, map_ji, eps_px=3.0)
    b = repeatability(kp_i, kp_j, map_ij, map_ji, eps_px=3.0, definition="superpoint")
    assert (a.n_i, a.n_j) == (b.n_i, b.n_j) == (2, 1)
    assert a.repeated_i == 2 and a.repeatability == 1.0  # (2 + 1) / 3
    assert b.repeated_i == 1 and b.repeatability == pytest.approx(2 / 3)
    assert b.localisation_err_px == 0.0 and a.localisation_err_px == pytest.approx(1.3 / 3)


def test_the_reference_measures_j_keypoints_in_j():
    """A zoom by 2 (j = 2 i): a keypoint of j 4 px (in j) from the mapped keypoint of i is 2 px from
    it in i. The default measures j's keypoints in i (repeated at eps 3), the reference in j (not)."""
    map_ij, map_ji = map_from(lambda x: 2 * x), map_from(lambda x: x / 2)
    kp_i, kp_j = np.array([[10.0, 10.0]]), np.array([[24.0, 20.0]])  # i -> (20, 20); j -> (12, 10)
    a = repeatability(kp_i, kp_j, map_ij, map_ji, eps_px=3.0)
    b = repeatability(kp_i, kp_j, map_ij, map_ji, eps_px=3.0, definition="superpoint")
    assert (a.repeated_i, a.repeated_j) == (0, 1) and (b.repeated_i, b.repeated_j) == (0, 0)


def test_mma_on_hand_built_matches():
    map_ij, _ = translation_maps()
    occ = map_ij.state.copy()
    occ[40, 40] = OCCLUDED
    map_ij = CorrespondenceMap(map_ij.uv, occ)
    err = np.array([0.0, 0.5, 1.0, 1.5, 2.5, 9.875, 10.0, 10.5])
    x_i = np.array([[10.0 + k, 20.0] for k in range(len(err))] + [[40.0, 40.0]])
    x_j = x_i + [7.0, 3.0]
    x_j[:-1, 0] += err
    a = match_accuracy(x_i, x_j, map_ij)
    assert a.n_matches == 9 and a.n_no_truth == 1 and a.dist_px[-1] == np.inf
    np.testing.assert_array_equal(a.dist_px[:-1], err)
    expect = np.array([3, 4, 5, 5, 5, 5, 5, 5, 5, 7]) / 9  # <= t for t = 1..10
    np.testing.assert_array_equal(a.mma, expect)
    empty = match_accuracy(np.zeros((0, 2)), np.zeros((0, 2)), map_ij)
    np.testing.assert_array_equal(empty.mma, np.zeros(10))
    np.testing.assert_array_equal(mean_over_pairs([a, empty]), expect / 2)


def test_matching_score():
    map_ij, map_ji = translation_maps()
    kp_i = np.array([[10.0, 10.0], [20.0, 10.0], [30.0, 10.0], [40.0, 10.0], [50.0, 10.0], [70.0, 10.0]])
    kp_j = kp_i[:5] + [7.0, 3.0]  # kp_i[5] maps to (77, 13): has truth, no partner
    kp_j = np.vstack([kp_j, [[1.0, 1.0]]])  # j's keypoint at (1, 1) maps to (-6, -2): no truth in i
    matches = np.array([[0, 0], [1, 1], [2, 2], [3, 4], [4, 3]])  # three right, two wrong
    s = matching_score(kp_i, kp_j, matches, map_ij, map_ji, eps_px=3.0)
    assert (s.n_correct, s.n_i, s.n_j) == (3, 6, 5)
    assert s.score == 3 / 5
    with pytest.raises(InputError):
        matching_score(kp_i, kp_j, np.array([[0, 9]]), map_ij, map_ji)


def test_only_the_dataset_visible_state_gives_truth():
    """A keypoint on a pixel centre has truth exactly when the dataset's state there is VISIBLE."""
    uv = np.zeros((1, 4, 2))
    uv[0, :, 0] = np.arange(4)
    cm = CorrespondenceMap(uv, np.array([[NO_SURFACE, VISIBLE, OCCLUDED, OUT_OF_FRAME]]))
    _, ok = map_keypoints(np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]]), cm)
    assert ok.tolist() == [False, True, False, False]


def test_precision_recall_counts_by_hand():
    W, H = 40, 30
    u, v = np.meshgrid(np.arange(W, dtype=float), np.arange(H, dtype=float))
    m = CorrespondenceMap(np.stack([u + 5.0, v], -1), np.full((H, W), VISIBLE))  # j = i + (5, 0)
    kp_i = np.array([[1.0, 1.0], [10.0, 10.0], [20.0, 5.0], [30.0, 20.0]])
    # truth in j: (6,1) (15,10) (25,5) (35,20); j has keypoints near the first three only
    kp_j = np.array([[6.0, 1.0], [15.0, 12.0], [25.0, 8.5], [0.0, 0.0]])
    # i0 -> j0 correct (0 px) and again (duplicate); i1 -> j1 correct (2 px <= 3); i2 -> j2 wrong (3.5 px);
    # i3 -> j3 wrong
    mt = np.array([[0, 0], [0, 0], [1, 1], [2, 2], [3, 3]])
    r = match_precision_recall(kp_i, kp_j, mt, m, eps_px=3.0)
    assert (r.n_putative, r.n_correct) == (5, 3) and r.precision == 3 / 5
    # matchable: i0 (0 px), i1 (2 px); i2's nearest j is 3.5 px away, i3's far: recall = 2 distinct / 2
    assert (r.n_i_recalled, r.n_i_matchable) == (2, 2) and r.recall == 1.0
    r = match_precision_recall(kp_i, kp_j, mt, m, eps_px=3.5)  # <=: 3.5 px now counts
    assert (r.n_correct, r.n_i_recalled, r.n_i_matchable) == (4, 3, 3)
    r = match_precision_recall(kp_i, kp_j, np.zeros((0, 2), int), m)
    assert r.precision == 0.0 and r.recall == 0.0 and r.n_i_matchable == 2
    r = match_precision_recall(kp_i, np.zeros((0, 2)), np.zeros((0, 2), int), m)
    assert math.isnan(r.recall) and r.precision == 0.0

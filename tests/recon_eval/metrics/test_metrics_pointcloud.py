import numpy as np
import pytest

from recon_eval.errors import InputError
from recon_eval.metrics.pointcloud import chamfer, dtu, eth3d, tanks_and_temples, voxel_downsample



def lattice(n=10):
    """Integer lattice in the z = 0 plane: spacing 1 m, so a z-shift d is every NN distance."""
    u, v = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float))
    return np.c_[u.ravel(), v.ravel(), np.zeros(n * n)]


D = 0.25  # exact in binary: every nearest-neighbour distance is exactly D


class TestTanksAndTemples:
    @pytest.mark.parametrize("downsample", [False, True])
    def test_strict_operator_at_the_tie(self, downsample):
        gt = lattice()
        rec = gt + [0.0, 0.0, D]
        at = tanks_and_temples(rec, gt, D, downsample=downsample)
        assert (at.precision, at.recall, at.fscore) == (0.0, 0.0, 0.0)  # d < tau is false at d == tau
        above = tanks_and_temples(rec, gt, np.nextafter(D, 1.0), downsample=downsample)
        assert (above.precision, above.recall, above.fscore) == (1.0, 1.0, 1.0)
        assert at.operator == "<"
        assert at.voxel_m == (D / 2 if downsample else None)

    def test_known_partial_scores(self):
        gt = lattice()
        rec = np.r_[gt[:50], gt[:25] + [0, 0, 5.0]]  # half the truth, plus 25 far outliers
        r = tanks_and_temples(rec, gt, 0.1, downsample=False)
        assert r.precision == pytest.approx(50 / 75)
        assert r.recall == pytest.approx(50 / 100)
        assert r.fscore == pytest.approx(2 * (2 / 3) * 0.5 / (2 / 3 + 0.5))

    def test_truth_against_itself_is_perfect(self):
        gt = lattice()
        r = tanks_and_temples(gt, gt, 0.01)
        assert (r.precision, r.recall, r.fscore) == (1.0, 1.0, 1.0)

    def test_empty_cloud_scores_zero(self):
        r = tanks_and_temples(np.zeros((0, 3)), lattice(), 0.1)
        assert (r.precision, r.recall, r.fscore, r.n_rec) == (0.0, 0.0, 0.0, 0)

    def test_disjoint_clouds_give_zero_not_nan(self):
        r = tanks_and_temples(lattice() + 100.0, lattice(), 0.1)
        assert r.fscore == 0.0

    def test_mesh_distances_are_declared(self, unit_square):
        rec = np.array([[0.5, 0.5, 0.05], [0.2, 0.3, 0.2]])
        gt_pts = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 0.0]])  # sparse sample: too far for precision
        r_pts = tanks_and_temples(rec, gt_pts, 0.1, downsample=False)
        r_mesh = tanks_and_temples(rec, gt_pts, 0.1, gt_mesh=(unit_square[0], unit_square[1]), downsample=False)
        assert r_pts.precision == 0.0 and r_pts.distance_rec_to_gt == "nearest_point"
        assert r_mesh.precision == 0.5 and r_mesh.distance_rec_to_gt == "mesh_surface"

    def test_non_finite_points_are_an_input_error(self):
        with pytest.raises(InputError, match="non-finite"):
            tanks_and_temples([[np.nan, 0, 0]], lattice(), 0.1)


def test_voxel_downsample_hand_computed():
    p = np.array([[0.0, 0, 0], [0.1, 0, 0], [1.0, 0, 0]])
    out = voxel_downsample(p, 0.5)  # origin at min - 0.25: x = 0, 0.1 share voxel 0; x = 1 is voxel 2
    np.testing.assert_allclose(out, [[0.05, 0, 0], [1.0, 0, 0]])


@pytest.mark.parametrize("span_m", [10.0, 1e6])  # 1e6 m at 1 um voxels takes the wide-grid path
def test_voxel_downsample_matches_a_dictionary_grouping(span_m):
    rng = np.random.default_rng(1)
    p = rng.integers(0, 5, size=(300, 3)) * (span_m / 5) + rng.random((300, 3)) * 1e-7
    voxel = 1e-6 if span_m > 100 else 0.5
    origin = p.min(axis=0) - voxel / 2
    groups = {}
    for q in p:
        groups.setdefault(tuple(np.floor((q - origin) / voxel).astype(np.int64)), []).append(q)
    expected = np.array([np.mean(groups[k], axis=0) for k in sorted(groups)])
    np.testing.assert_allclose(voxel_downsample(p, voxel), expected, rtol=0, atol=1e-9)


class TestEth3d:
    def test_inclusive_operator_at_the_tie(self):
        gt = lattice()
        rec = gt + [0.0, 0.0, D]
        at = eth3d(rec, gt, D, voxel_m=1.0)
        assert (at.accuracy, at.completeness, at.f1) == (1.0, 1.0, 1.0)  # d <= t holds at d == t
        below = eth3d(rec, gt, np.nextafter(D, 0.0), voxel_m=1.0)
        assert (below.accuracy, below.completeness, below.f1) == (0.0, 0.0, 0.0)

    def test_per_voxel_averaging_cancels_density(self):
        gt = np.array([[0.25, 0.25, 0.25]])  # in one cell of either grid (shifted by 0 and 0.5 voxel)
        dense_good = gt + np.random.default_rng(0).uniform(-0.01, 0.01, size=(100, 3))
        bad = np.array([[5.25, 0.25, 0.25]])
        r = eth3d(np.r_[dense_good, bad], gt, 0.05, voxel_m=1.0)
        assert r.accuracy == 0.5  # (1 + 0 + 1 + 0) / 4 cells of the two grids, not 100 / 101 points
        assert r.completeness == 1.0

    def test_the_two_grids_are_pooled(self):
        """ETH3D's kGridShifts: a cell boundary of one grid is a cell centre of the other. Points at
        x = 0.1, 0.4 (good) and 0.6 (bad), voxel 1: one cell [0, 1) of the unshifted grid (2/3
        good); x + 0.5 = 0.6, 0.9 and 1.1 fill two cells of the shifted grid (1 and 0). The mean
        over the three cells, 0.556, not the one grid's 0.667; cell fractions in float as ETH3D."""
        gt = np.array([[0.1, 0.25, 0.25], [0.4, 0.25, 0.25]])
        r = eth3d(np.r_[gt, [[0.6, 0.25, 0.25]]], gt, 0.1, voxel_m=1.0)
        assert r.accuracy == np.float32((float(np.float32(2) / np.float32(3)) + 1.0 + 0.0) / 3)

    def test_unobserved_points_are_excluded_and_counted(self):
        gt = lattice()
        rec = np.r_[gt, [[50.0, 50.0, 50.0]]]
        observed = np.r_[np.ones(len(gt), bool), False]
        r = eth3d(rec, gt, 0.01, rec_observed=observed)
        assert r.accuracy == 1.0 and r.n_rec_unobserved == 1 and r.n_rec_scored == len(gt)

    def test_empty_gives_zero(self):
        assert eth3d(np.zeros((0, 3)), lattice(), 0.1).f1 == 0.0


class TestDtu:
    def test_shift_and_outlier(self):
        gt = lattice()
        rec = np.r_[gt + [0, 0, 0.005], [[0.0, 0.0, 1.0]]]
        r = dtu(rec, gt, max_dist_m=0.02)
        assert r.acc_mean_m == pytest.approx(0.005, abs=1e-15)
        assert r.acc_median_m == pytest.approx(0.005, abs=1e-15)
        assert r.comp_mean_m == pytest.approx(0.005, abs=1e-15)
        assert r.overall_mean_m == pytest.approx(0.005, abs=1e-15)
        assert r.acc_dropped_frac == pytest.approx(1 / 101)
        assert r.comp_dropped_frac == 0.0

    def test_cut_is_strict(self):
        gt = lattice()
        r = dtu(gt + [0, 0, D], gt, max_dist_m=D)
        assert r.acc_dropped_frac == 1.0 and np.isnan(r.acc_mean_m)

    def test_empty_reports_nan_with_counts(self):
        r = dtu(np.zeros((0, 3)), lattice())
        assert np.isnan(r.acc_mean_m) and r.n_rec == 0 and r.comp_dropped_frac == 1.0


class TestChamfer:
    def test_known_values(self):
        gt = lattice()
        r = chamfer(gt + [0, 0, D], gt)
        assert r.chamfer_l1_m == D
        assert r.chamfer_l2_sq_m2 == 2 * D**2

    def test_asymmetric(self):
        gt = np.array([[0.0, 0, 0], [1.0, 0, 0]])
        rec = np.array([[0.0, 0, 0]])
        r = chamfer(rec, gt)
        assert (r.rec_to_gt_mean_m, r.gt_to_rec_mean_m, r.chamfer_l1_m) == (0.0, 0.5, 0.25)

    def test_empty_is_inf(self):
        assert np.isinf(chamfer(np.zeros((0, 3)), lattice()).chamfer_l1_m)

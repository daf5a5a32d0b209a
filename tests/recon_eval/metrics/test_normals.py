"""Photometric stereo metrics (recon_eval.metrics.normals) against DiLiGenT's evaluation code,
transliterated from its MATLAB release (Boxin Shi, 2016-03-15: the box-plot evaluation scripts
and normal_img2vec.m):

    mask = im2bw(imread([dataDir, ..., 'mask.png']));
    m = find(mask == 1);
    N_gt = normal_img2vec(Normal_gt, m);
    N_est = normal_img2vec(Normal_est, m);
    angErr = real(acos(dot(N_gt, N_est, 2))) * 180 / pi;
    mean(angErr)

with ``normal_img2vec``: ``S(:, 1) = Nx(m); S(:, 2) = Ny(m); S(:, 3) = Nz(m)``.
"""
import numpy as np
import pytest

from recon_eval.errors import InputError
from recon_eval.metrics.normals import albedo_metrics, angular_errors_deg, depth_up_to_offset, light_metrics, normal_metrics


def diligent_ang_err(Normal_gt, Normal_est, mask_image):
    """The MATLAB above, line by line: im2bw (level 0.5 of a [0, 1] image), find (column-major
    linear indices), normal_img2vec, real(acos(dot)) in degrees."""
    mask = mask_image > 0.5
    m = np.flatnonzero(mask.ravel(order="F"))

    def normal_img2vec(N_est, m):
        S = np.zeros((len(m), 3))
        for i in range(3):
            S[:, i] = N_est[:, :, i].ravel(order="F")[m]
        return S

    N_gt, N_est = normal_img2vec(Normal_gt, m), normal_img2vec(Normal_est, m)
    return np.real(np.arccos(np.sum(N_gt * N_est, axis=1).astype(complex))) * 180 / np.pi


def _maps(seed=0, H=23, W=31):
    rng = np.random.default_rng(seed)
    gt = rng.normal(size=(H, W, 3))
    gt[..., 2] = np.abs(gt[..., 2]) + 0.2
    gt /= np.linalg.norm(gt, axis=2, keepdims=True)
    est = gt + rng.normal(scale=0.3, size=gt.shape)
    est /= np.linalg.norm(est, axis=2, keepdims=True)
    est[0, :5] = 0.0  # no normal: DiLiGenT's methods store 0
    est[1, :3] = gt[1, :3] * 1.5  # not unit: dot > 1 (real(acos) = 0)
    est[2, :3] = -gt[2, :3] * 1.5  # dot < -1 (real(acos) = 180)
    est[3, :4] = gt[3, :4] * 0.5  # shorter than unit: DiLiGenT does not normalise
    mask_image = rng.uniform(size=(H, W))  # im2bw's 0.5 threshold decides
    return gt, est, mask_image


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_angular_errors_equal_diligent_code(seed):
    gt, est, mask_image = _maps(seed)
    ref = diligent_ang_err(gt, est, mask_image)
    r = normal_metrics(gt, est, mask_image > 0.5)
    ours = angular_errors_deg(gt[mask_image > 0.5], est[mask_image > 0.5])
    np.testing.assert_allclose(np.sort(ours), np.sort(ref), rtol=0, atol=1e-12)
    assert r.mean_ae_deg == pytest.approx(ref.mean(), rel=1e-14)
    assert r.median_ae_deg == pytest.approx(np.median(ref), rel=1e-14)
    for t, frac in ((10, r.within_10deg), (20, r.within_20deg), (30, r.within_30deg)):
        assert frac == np.mean(ref < t)
    assert r.n_pixels == len(ref)


def test_special_values_as_diligent_scores_them():
    g = np.array([[0.0, 0.0, 1.0]] * 4)
    e = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 2.0], [0.0, 0.0, -2.0], [np.nan, 0.0, 1.0]])
    np.testing.assert_array_equal(angular_errors_deg(g, e), [90.0, 0.0, 180.0, 90.0])
    r = normal_metrics(g.reshape(2, 2, 3), e.reshape(2, 2, 3), np.ones((2, 2), bool))
    assert r.missing_ratio == 0.25


def test_albedo_error_is_up_to_the_global_scale():
    rng = np.random.default_rng(3)
    a = rng.uniform(0.2, 0.9, size=(10, 12, 3))
    m = np.ones((10, 12), bool)
    r = albedo_metrics(a, 7.5 * a, m)
    assert r.scale == pytest.approx(1 / 7.5) and r.rel_mae < 1e-15
    b = a.copy()
    b[0, 0] = np.nan
    assert albedo_metrics(a, b, m).missing_ratio == 1 / 120


def test_light_direction_error_planted_rotation():
    d = np.array([[0.0, 0.0, 1.0], [0.3, 0.0, 1.0], [-0.5, 0.0, 1.0]])  # turned about y by 3 deg each
    c, s = np.cos(np.radians(3)), np.sin(np.radians(3))
    R = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    r = light_metrics(d, 2.0 * d @ R.T, [1, 2, 3], [2, 4, 6])
    np.testing.assert_allclose(r.per_light_deg, 3.0, atol=1e-6)
    assert r.intensity_rel_err < 1e-15
    with pytest.raises(InputError):
        light_metrics(d, np.zeros((3, 3)))


def test_depth_is_up_to_a_constant():
    z = np.linspace(1, 2, 30).reshape(5, 6)
    m = np.ones((5, 6), bool)
    r = depth_up_to_offset(z, z - 0.37, m)
    assert r.offset_m == pytest.approx(0.37) and r.rmse_m < 1e-12

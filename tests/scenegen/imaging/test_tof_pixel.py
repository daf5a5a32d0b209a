"""The ToF pixel (scenegen.imaging.tof) against its model's formulas: each raw tap's DN follows the
exact distribution of Poisson shot noise plus Gaussian read noise rounded by the ADC (chi-square
goodness of fit), and the decoded range's variance is the first-order formula
sigma_r = c sqrt(2 (B + sigma_r^2 + 1/12 K^-2)) / (2 A) / (4 pi f) (chi-square test of a variance).
Same seed, same bits; noise off decodes the expectation."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy import stats

from scenegen.geometry.tof import phase_of_path_rad, range_from_phase_m
from scenegen.imaging.noise import SensorParams
from scenegen.imaging.tof import TofPixelParams, decode, expose, range_noise_std_m

CHI2_ALPHA = 0.01  # a correct model fails 1 % of seeds; the seeds are fixed
F_HZ = 60e6
R_TRUE = 1.3  # metres, within the ambiguity range of 60 MHz (2.5 m)
SIZE = 200  # 40,000 pixels: a variance to sqrt(2 / 40,000) = 0.7 %


def _flat(p: TofPixelParams, albedo=0.5, r=R_TRUE):
    """Path sums of a Lambertian surface facing the camera at range r (direct light only)."""
    dc = np.full((SIZE, SIZE), albedo / math.pi / r ** 2)
    phase = phase_of_path_rad(2 * r, F_HZ)
    return {"dc": dc, "cos_0": dc * math.cos(phase), "sin_0": dc * math.sin(phase),
            "direct_dc": dc, "direct_cos_0": dc * math.cos(phase), "direct_sin_0": dc * math.sin(phase)}


PIXEL = TofPixelParams(freqs_hz=(F_HZ,), integration_s=1e-3, signal_e_per_s_at_1m=2e6, ambient_e_per_s=3e5,
                       contrast=0.8, sensor=SensorParams(adc_bits=16, system_gain_dn_per_e=1.0, dark_noise_e=4.0,
                                                         saturation_capacity_e=60000.0))


def _tap_pmf(mu, sigma_read, k):
    """P(DN = k) of floor(Poisson(mu) + N(0, sigma^2) + 0.5) (gain 1), summed over the Poisson."""
    n = np.arange(max(0, int(mu - 12 * math.sqrt(mu))), int(mu + 12 * math.sqrt(mu)) + 1)
    w = stats.poisson.pmf(n, mu)
    hi = stats.norm.cdf((k[:, None] + 0.5 - n[None, :]) / sigma_read)
    lo = stats.norm.cdf((k[:, None] - 0.5 - n[None, :]) / sigma_read)
    return (hi - lo) @ w


def _chi2_pvalue(samples, mu, sigma_read):
    k = np.arange(samples.min(), samples.max() + 1)
    obs = np.bincount(samples - samples.min(), minlength=len(k)).astype(float)
    exp = _tap_pmf(mu, sigma_read, k) * len(samples)
    # merge bins to Cochran's minimum expected count of 5, from both tails inwards
    edges, acc_o, acc_e, o_bins, e_bins = [], 0.0, 0.0, [], []
    for o, e in zip(obs, exp):
        acc_o, acc_e = acc_o + o, acc_e + e
        if acc_e >= 5:
            o_bins.append(acc_o)
            e_bins.append(acc_e)
            acc_o = acc_e = 0.0
    o_bins[-1] += acc_o
    e_bins[-1] += acc_e
    e_bins = np.array(e_bins) * (np.sum(o_bins) / np.sum(e_bins))  # the tails beyond the samples' span
    return float(stats.chisquare(o_bins, e_bins).pvalue)


def test_raw_taps_follow_shot_plus_read_noise_through_the_adc():
    frames = expose(_flat(PIXEL), PIXEL, seed=7)
    for tap in range(4):
        mu = float(frames.mean_e[0, 0, 0, tap])
        dn = frames.dn[..., 0, tap].ravel().astype(np.int64)
        assert np.allclose(frames.mean_e[..., 0, tap], mu)
        assert _chi2_pvalue(dn, mu, 4.0) > CHI2_ALPHA
    # the same check refuses a model whose variance is 20 % too large (read noise standing in for it)
    mu = float(frames.mean_e[0, 0, 0, 0])
    assert _chi2_pvalue(frames.dn[..., 0, 0].ravel().astype(np.int64), mu, math.sqrt(16 + 0.2 * (mu + 16))) \
        < CHI2_ALPHA


def test_range_variance_matches_the_first_order_formula():
    frames = expose(_flat(PIXEL), PIXEL, seed=11)
    rng, amp, _ = decode(frames.dn, PIXEL)
    mean = frames.mean_e[0, 0, 0]
    B = mean.mean()
    A = 0.5 * math.hypot(mean[0] - mean[2], mean[1] - mean[3])
    sigma = float(range_noise_std_m(B, A, F_HZ, 4.0, 1.0))
    n = rng.size
    stat = (n - 1) * rng.var(ddof=1) / sigma ** 2
    lo, hi = stats.chi2.ppf([CHI2_ALPHA / 2, 1 - CHI2_ALPHA / 2], n - 1)
    assert lo < stat < hi, (math.sqrt(rng.var()), sigma)
    assert not lo < (n - 1) * rng.var(ddof=1) / (sigma / math.sqrt(2)) ** 2 < hi  # a factor sqrt 2 off fails
    # unbiased: the mean is the true range to 5 standard errors
    assert abs(rng.mean() - R_TRUE) < 5 * sigma / math.sqrt(n)
    np.testing.assert_allclose(amp.mean(), A, rtol=0.01)


def test_same_seed_same_bits_and_noise_off_decodes_the_expectation():
    a, b = expose(_flat(PIXEL), PIXEL, seed=3), expose(_flat(PIXEL), PIXEL, seed=3)
    assert np.array_equal(a.dn, b.dn) and not np.array_equal(a.dn, expose(_flat(PIXEL), PIXEL, seed=4).dn)
    quiet = dataclasses.replace(PIXEL, sensor=dataclasses.replace(PIXEL.sensor, temporal_noise=False))
    f = expose(_flat(quiet), quiet, seed=3)
    rng = decode(f.mean_e * quiet.gain_dn_per_e, quiet)[0]
    np.testing.assert_allclose(rng, R_TRUE, rtol=1e-12)
    # the ADC alone (noise off, raw_dn rounded) is off by under a millimetre here
    assert np.abs(decode(f.dn, quiet)[0] - R_TRUE).max() < 1e-3
    assert range_from_phase_m(math.pi, F_HZ) == 299_792_458.0 / (4 * F_HZ)

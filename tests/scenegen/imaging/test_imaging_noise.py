"""EMVA 1288 sensor model: photon transfer, noise distributions, seeding, clipping, ADC."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy import stats

from scenegen.geometry.camera import Camera
from scenegen.imaging import apply_chain, seeds
from scenegen.imaging.chain import ImagingParams, electrons_per_radiance
from scenegen.imaging.noise import SensorParams, expose_sensor
from scenegen.imaging.presets import PRESETS
from scenegen.imaging.vignetting import VignettingParams

#: Issue 4's tolerance for the photon-transfer estimates of K and sigma_d (relative).
PTC_REL_TOL = 0.03
#: Significance level of the chi-square goodness-of-fit tests: a correct model fails 1 % of seeds;
#: the seeds are fixed, so the outcome is deterministic.
CHI2_ALPHA = 0.01
#: Minimum expected count per chi-square bin (Cochran's rule); sparser tails are merged.
CHI2_MIN_EXPECTED = 5.0
#: Flat-field frame size for the photon transfer: 160 x 160 x 3 = 76,800 samples per frame, so a
#: variance is estimated to sqrt(2 / 76,800) = 0.5 % (1 sigma), well inside PTC_REL_TOL.
PTC_SIZE = 160
#: EMVA 1288 fits the photon transfer curve up to 70 % of saturation.
PTC_MAX_FRACTION = 0.7


def _flat_params(gain_db: float) -> ImagingParams:
    """The machine-vision preset without Bayer mosaic and vignetting: a flat field stays flat."""
    p = PRESETS["machine_vision"]
    return dataclasses.replace(p, bayer=None, vignetting=VignettingParams(), response="linear",
                               bit_depth=16,
                               exposure=dataclasses.replace(p.exposure, gain_db=gain_db))


def _flat_frame(params, camera, electrons: float, seed: int) -> np.ndarray:
    """Raw DN of a flat field whose R, G and B pixels all collect ``electrons`` on average."""
    L = electrons / electrons_per_radiance(params)  # (3,) radiance per channel
    lin = np.broadcast_to(L, (camera.height, camera.width, 3)).astype(np.float32)
    return apply_chain(lin, params, camera, seed).raw_dn.astype(np.float64)


def photon_transfer(params, camera, levels_e):
    """EMVA 1288 (R4.0, sec. 6.3) from pairs of frames: mean mu_y and temporal variance
    sigma_y^2 = var(y_A - y_B) / 2 at each level (level 0 = dark)."""
    mu, var = [], []
    for i, level in enumerate(levels_e):
        a = _flat_frame(params, camera, level, seed=2 * i)
        b = _flat_frame(params, camera, level, seed=2 * i + 1)
        mu.append(0.5 * (a.mean() + b.mean()))
        var.append(0.5 * np.var(a - b))
    return np.array(mu), np.array(var)


@pytest.mark.parametrize("gain_db", [0.0, 12.0])
def test_photon_transfer_recovers_gain_and_dark_noise(gain_db):
    params = _flat_params(gain_db)
    s = params.sensor
    camera = Camera.from_fov(60.0, (PTC_SIZE, PTC_SIZE))
    K = s.system_gain(gain_db)
    # usable electrons: the full well, or what the ADC can show above the black level
    e_max = min(s.saturation_capacity_e, (s.white_level_dn - s.black_level_dn) / K)
    levels = np.concatenate([[0.0], np.linspace(0.05, PTC_MAX_FRACTION, 10) * e_max])
    mu, var = photon_transfer(params, camera, levels)
    x, y = mu[1:] - mu[0], var[1:] - var[0]
    K_est = float(np.sum(x * y) / np.sum(x * x))  # EMVA: slope through the origin
    sigma_q2 = 1.0 / 12.0  # uniform quantisation noise, DN^2
    sigma_d_dn_est = float(np.sqrt(var[0] - sigma_q2))  # K * sigma_d
    sigma_d_e_est = sigma_d_dn_est / K_est
    # the configured dark noise at this exposure time: read noise and dark-current shot noise
    sigma_d_e = np.sqrt(s.dark_noise_e ** 2 + s.dark_current_e_per_s * params.exposure.exposure_time_s)
    print(f"gain {gain_db} dB: K {K_est:.5f} vs {K:.5f} DN/e-; sigma_d {sigma_d_e_est:.4f} vs "
          f"{sigma_d_e:.4f} e-, {sigma_d_dn_est:.4f} vs {K * sigma_d_e:.4f} DN")
    assert K_est == pytest.approx(K, rel=PTC_REL_TOL)
    assert sigma_d_e_est == pytest.approx(sigma_d_e, rel=PTC_REL_TOL)
    assert sigma_d_dn_est == pytest.approx(K * sigma_d_e, rel=PTC_REL_TOL)


def _bare_sensor(**kw) -> SensorParams:
    """K = 1, no offset, no fixed pattern, 16-bit ADC, huge full well: DN = electrons (+ noise)."""
    base = dict(system_gain_dn_per_e=1.0, dark_noise_e=0.0, dark_current_e_per_s=0.0,
                saturation_capacity_e=1e9, prnu_percent=0.0, dsnu_e=0.0, black_level_dn=0,
                adc_bits=16)
    base.update(kw)
    return SensorParams(**base)


def _chi2_pvalue(samples: np.ndarray, pmf) -> float:
    """Chi-square goodness of fit of integer samples to ``pmf(k)``; tails merged so that every
    bin expects >= CHI2_MIN_EXPECTED."""
    n = samples.size
    ks = np.arange(samples.min() - 5, samples.max() + 6)
    expected = n * pmf(ks)
    observed = np.array([np.count_nonzero(samples == k) for k in ks], dtype=np.float64)
    # merge the tails into their neighbours until every bin is populated enough
    obs, exp = list(observed), list(expected)
    while exp[0] < CHI2_MIN_EXPECTED:
        e0, o0 = exp.pop(0), obs.pop(0)
        exp[0] += e0
        obs[0] += o0
    while exp[-1] < CHI2_MIN_EXPECTED:
        e1, o1 = exp.pop(), obs.pop()
        exp[-1] += e1
        obs[-1] += o1
    exp = np.array(exp)
    exp *= np.sum(obs) / exp.sum()  # mass outside the scanned range (< 1e-12) to the bins
    return float(stats.chisquare(obs, exp).pvalue)


def test_shot_noise_is_poisson_chi_square():
    mu = 20.5
    out = expose_sensor(np.full((200, 200), mu), exposure_time_s=0.01, gain_db=0.0,
                        sensor=_bare_sensor(), seed=11)
    y = out.dn.astype(np.int64).ravel()
    p = _chi2_pvalue(y, lambda k: stats.poisson.pmf(k, mu))
    # power: a normal with the same mean and variance (discretised) is rejected
    p_wrong = _chi2_pvalue(y, lambda k: stats.norm.cdf(k + 0.5, mu, np.sqrt(mu))
                           - stats.norm.cdf(k - 0.5, mu, np.sqrt(mu)))
    print(f"Poisson chi-square p = {p:.3f}; same-moment normal p = {p_wrong:.2e}")
    assert p > CHI2_ALPHA
    assert p_wrong < CHI2_ALPHA


def test_read_noise_is_gaussian_chi_square():
    sigma, black = 4.0, 100
    out = expose_sensor(np.zeros((200, 200)), exposure_time_s=0.01, gain_db=0.0,
                        sensor=_bare_sensor(dark_noise_e=sigma, black_level_dn=black), seed=12)
    y = out.dn.astype(np.int64).ravel()
    # the ADC rounds to nearest: P(dn = k) = Phi((k + 0.5 - b) / s) - Phi((k - 0.5 - b) / s)
    p = _chi2_pvalue(y, lambda k: stats.norm.cdf(k + 0.5, black, sigma)
                     - stats.norm.cdf(k - 0.5, black, sigma))
    p_wrong = _chi2_pvalue(y, lambda k: stats.norm.cdf(k + 0.5, black, 1.1 * sigma)
                           - stats.norm.cdf(k - 0.5, black, 1.1 * sigma))
    print(f"Gaussian chi-square p = {p:.3f}; sigma x 1.1 p = {p_wrong:.2e}")
    assert p > CHI2_ALPHA
    assert p_wrong < CHI2_ALPHA


def test_dark_current_mean_grows_linearly_with_exposure_time():
    s = _bare_sensor(dark_noise_e=3.0, dark_current_e_per_s=200.0, black_level_dn=50,
                     system_gain_dn_per_e=0.5)
    times = np.array([0.0, 0.05, 0.1, 0.2, 0.4])
    means = [expose_sensor(np.zeros((100, 100)), exposure_time_s=t, gain_db=0.0, sensor=s,
                           seed=i).dn.mean() for i, t in enumerate(times)]
    slope = np.polyfit(times, means, 1)[0]  # DN per second
    assert slope == pytest.approx(0.5 * 200.0, rel=PTC_REL_TOL)


def test_same_seed_same_noise_different_seed_different_noise():
    p = PRESETS["smartphone"]
    camera = Camera.from_fov(60.0, (48, 32))
    lin = np.random.default_rng(0).random((32, 48, 3)).astype(np.float32)
    a, b, c = (apply_chain(lin, p, camera, seed) for seed in (7, 7, 8))
    assert np.array_equal(a.image, b.image) and np.array_equal(a.raw_dn, b.raw_dn)
    assert not np.array_equal(a.raw_dn, c.raw_dn)
    assert np.mean(a.raw_dn != c.raw_dn) > 0.5  # most pixels differ, not just a few


def test_frame_seeds_differ_per_view_and_scene():
    s = {seeds.frame_seed(scene, view) for scene in (0, 1) for view in range(50)}
    assert len(s) == 100


def test_fixed_pattern_is_per_camera_not_per_frame():
    """PRNU / DSNU depend on fixed_pattern_seed only: with temporal noise off, two frame seeds
    give the same image; another camera's pattern differs."""
    base = dataclasses.replace(PRESETS["machine_vision"].sensor, temporal_noise=False,
                               prnu_percent=2.0, dsnu_e=5.0)
    mu = np.full((64, 64), 5000.0)
    f1 = expose_sensor(mu, exposure_time_s=0.01, gain_db=0.0, sensor=base, seed=1).dn
    f2 = expose_sensor(mu, exposure_time_s=0.01, gain_db=0.0, sensor=base, seed=2).dn
    other = dataclasses.replace(base, fixed_pattern_seed=seeds.fixed_pattern_seed_for("cam_b"))
    f3 = expose_sensor(mu, exposure_time_s=0.01, gain_db=0.0, sensor=other, seed=1).dn
    assert np.array_equal(f1, f2)
    assert not np.array_equal(f1, f3)
    # the PRNU pattern has the configured spread (K * 5000 e- * 2 %, DSNU adds K * 5 e-)
    K = base.system_gain_dn_per_e
    assert np.std(f1.astype(float)) == pytest.approx(K * np.hypot(5000 * 0.02, 5.0), rel=0.05)


def test_full_well_clipping():
    s = dataclasses.replace(PRESETS["machine_vision"].sensor, temporal_noise=False, prnu_percent=0.0,
                            dsnu_e=0.0, dark_current_e_per_s=0.0)
    mu = np.array([[0.5, 1.0, 3.0]]) * s.saturation_capacity_e
    out = expose_sensor(mu, exposure_time_s=0.01, gain_db=0.0, sensor=s, seed=0)
    assert out.electrons.tolist()[0] == pytest.approx([0.5 * s.saturation_capacity_e,
                                                       s.saturation_capacity_e,
                                                       s.saturation_capacity_e])
    full = np.floor(s.system_gain(0.0) * s.saturation_capacity_e + s.black_level_dn + 0.5)
    assert out.dn[0, 1] == out.dn[0, 2] == full
    # with temporal noise: no pixel collects more than the full well
    noisy = expose_sensor(mu, exposure_time_s=0.01, gain_db=0.0,
                          sensor=dataclasses.replace(s, temporal_noise=True), seed=0)
    assert noisy.electrons.max() <= s.saturation_capacity_e


@pytest.mark.parametrize("adc_bits", [8, 10, 12, 14, 16])
def test_adc_quantisation_and_clipping(adc_bits):
    s = _bare_sensor(adc_bits=adc_bits, temporal_noise=False, black_level_dn=3,
                     system_gain_dn_per_e=0.37)
    mu = np.linspace(0.0, 1.2 * (1 << adc_bits) / 0.37, 4001)[None, :]
    dn = expose_sensor(mu, exposure_time_s=0.01, gain_db=0.0, sensor=s, seed=0).dn
    y = 0.37 * mu + 3
    top = (1 << adc_bits) - 1
    assert dn.dtype == np.uint16
    assert np.array_equal(dn, np.clip(np.floor(y + 0.5), 0, top).astype(np.uint16))
    inside = y < top
    assert np.max(np.abs(dn[inside] - y[inside])) <= 0.5  # rounding to nearest
    assert np.all(dn[y >= top + 0.5] == top)  # ADC clips at full scale

"""The sensor in EMVA 1288 terms: photo-electrons -> digital numbers (DN).

Model (EMVA Standard 1288, Release 4.0 Linear, sec. 2 "Sensitivity, linearity and noise"),
per pixel, with ``mu_e`` the mean photo-electrons (photons x quantum efficiency):

1. PRNU: ``mu_e_i = mu_e * (1 + prnu_i)``, ``prnu_i ~ N(0, (prnu_percent / 100)^2)`` fixed per
   camera (photo-response non-uniformity; a gain pattern).
2. Shot noise: ``n_e ~ Poisson(mu_e_i)`` (photon shot noise, EMVA eq. 3: sigma_e^2 = mu_e).
3. Dark current: ``n_dark ~ Poisson(dark_current_e_per_s * t)`` (thermal electrons with their own
   shot noise).
4. Full-well clipping: ``n = min(n_e + n_dark, saturation_capacity_e)``.
5. Read (temporal dark) noise ``N(0, dark_noise_e^2)`` and DSNU ``dsnu_i ~ N(0, dsnu_e^2)``
   (dark-signal non-uniformity, an offset pattern fixed per camera), in electrons.
6. Gain and offset: ``y = K (n + read + dsnu_i) + black_level_dn`` with the system gain
   ``K = system_gain_dn_per_e * 10^(gain_db / 20)`` (DN per electron).
7. ADC: ``dn = clip(floor(y + 0.5), 0, 2^adc_bits - 1)`` (uniform quantisation, adding
   sigma_q^2 = 1/12 DN^2). The black level keeps the noise around zero signal on record: DN
   below ``black_level_dn`` stay, down to the ADC's 0. Only a sensor that declares
   ``black_level_clip`` (as some cameras' raw output does) clips at the black level instead,
   ``dn = clip(..., black_level_dn, 2^adc_bits - 1)``.

So (EMVA eqs. 5, 8) ``mu_y = K (mu_e + mu_d) + black`` and, below saturation,
``sigma_y^2 = K^2 (sigma_d^2 + mu_dark) + sigma_q^2 + K (mu_y - mu_y.dark)``: the photon
transfer curve's slope is K and its intercept gives the dark noise.

``temporal_noise = False`` replaces every temporal draw (shot, dark current, read) by its mean,
leaving fixed-pattern noise, clipping and quantisation (for checks that need the expectation).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.imaging import seeds


@dataclass(frozen=True, kw_only=True)
class SensorParams:
    pixel_pitch_um: float = 3.45  # pixel pitch p, micrometres (pixel area p^2)
    quantum_efficiency: tuple[float, float, float] = (0.6, 0.7, 0.6)  # eta of the R, G, B
    # pixels at their wavelengths (colour filter and fill factor included), in [0, 1]
    wavelengths_nm: tuple[float, float, float] = (610.0, 540.0, 465.0)  # representative
    # wavelength of each channel, nm (converts radiance to photons)
    system_gain_dn_per_e: float = 0.25  # K at gain_db = 0, DN per electron
    dark_noise_e: float = 2.0  # sigma_d: temporal dark (read) noise, electrons
    dark_current_e_per_s: float = 0.0  # mean thermal electrons per second (Poisson)
    saturation_capacity_e: float = 10_000.0  # full well, electrons
    prnu_percent: float = 0.0  # std of the per-pixel gain, percent of the signal
    dsnu_e: float = 0.0  # std of the per-pixel dark offset, electrons
    black_level_dn: int = 0  # offset added before the ADC, DN
    black_level_clip: bool = False  # the sensor clips its output at black_level_dn (False: DN
    # below black are kept down to 0, as sensors with an offset record them)
    adc_bits: int = 12  # ADC resolution, bits (1..16)
    temporal_noise: bool = True  # False: shot, dark-current and read noise replaced by means
    fixed_pattern_seed: int = 0  # seeds PRNU / DSNU (the spec derives it from the camera name)

    def system_gain(self, gain_db: float) -> float:
        """K in DN per electron at analog gain ``gain_db``."""
        return self.system_gain_dn_per_e * 10.0 ** (gain_db / 20.0)

    @property
    def white_level_dn(self) -> int:
        """Largest ADC output, DN."""
        return (1 << self.adc_bits) - 1


@dataclass(frozen=True)
class SensorOutput:
    electrons: np.ndarray  # like mu_e, float32: collected electrons after full-well clipping
    dn: np.ndarray  # like mu_e, uint16: ADC output (black level included)


def fixed_patterns(shape: tuple[int, ...], sensor: SensorParams) -> tuple[np.ndarray, np.ndarray]:
    """(prnu gain factor, dsnu offset in electrons), each of ``shape``; the same for every frame
    of a camera (seeded by ``sensor.fixed_pattern_seed`` only)."""
    gain = np.ones(shape)
    if sensor.prnu_percent > 0:
        z = seeds.stage_rng(sensor.fixed_pattern_seed, seeds.STAGE_PRNU).standard_normal(shape)
        gain = np.clip(1.0 + (sensor.prnu_percent / 100.0) * z, 0.0, None)
    offset = np.zeros(shape)
    if sensor.dsnu_e > 0:
        z = seeds.stage_rng(sensor.fixed_pattern_seed, seeds.STAGE_DSNU).standard_normal(shape)
        offset = sensor.dsnu_e * z
    return gain, offset


def expose_sensor(mu_e: np.ndarray, *, exposure_time_s: float, gain_db: float,
                  sensor: SensorParams, seed: int) -> SensorOutput:
    """Mean photo-electrons (H, W) or (H, W, C) -> electrons and DN, per the module docstring.

    ``seed`` is the frame seed (:func:`scenegen.imaging.seeds.frame_seed`): each temporal draw
    uses its own stage generator, so the same seed gives bitwise the same noise.
    """
    mu_e = np.clip(np.asarray(mu_e, dtype=np.float64), 0.0, None)
    prnu, dsnu = fixed_patterns(mu_e.shape, sensor)
    mu_sig = mu_e * prnu
    mu_dark = sensor.dark_current_e_per_s * exposure_time_s
    if sensor.temporal_noise:
        n = seeds.stage_rng(seed, seeds.STAGE_SHOT).poisson(mu_sig).astype(np.float64)
        if mu_dark > 0:
            n += seeds.stage_rng(seed, seeds.STAGE_DARK_CURRENT).poisson(mu_dark, size=mu_e.shape)
        read = (seeds.stage_rng(seed, seeds.STAGE_READ).standard_normal(mu_e.shape)
                * sensor.dark_noise_e)
    else:
        n = mu_sig + mu_dark
        read = 0.0
    n = np.minimum(n, sensor.saturation_capacity_e)
    y = sensor.system_gain(gain_db) * (n + read + dsnu) + sensor.black_level_dn
    floor_dn = sensor.black_level_dn if sensor.black_level_clip else 0
    dn = np.clip(np.floor(y + 0.5), floor_dn, sensor.white_level_dn).astype(np.uint16)
    return SensorOutput(electrons=n.astype(np.float32), dn=dn)

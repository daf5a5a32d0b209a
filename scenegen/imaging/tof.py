"""A time-of-flight pixel: the rendered path sums of :mod:`scenegen.render.tof` -> mean raw
correlation electrons -> noisy raw frames in DN through the EMVA 1288 model of :mod:`.noise`
-> decoded range, amplitude and validity (the phase convention: :mod:`scenegen.geometry.tof`).

Physics and model, stated (docs/image_formation.md "Time of flight"):

* physics (rendered): each pixel's phasor over its light paths, multipath and mixed returns at
  depth edges included (:mod:`scenegen.render.tof`);
* model: the correlation of a pixel with a sinusoidal reference, ``C(psi) = B + A cos(phi - psi)``
  with contrast ``m`` (no harmonics, no demodulation non-linearity); the electrons per rendered
  unit ``k`` set by the signal a white Lambertian surface facing the camera at 1 m gives over the
  integration (``signal_e_per_s_at_1m``); an ambient DC in electrons per second; the four taps
  are four independent exposures of one integration time each, every tap through the EMVA 1288
  chain (shot noise, read noise, full well, gain, ADC) with its own draws.
* validity (a decoder's rule, a model): a pixel is valid when every frequency's amplitude is at
  least ``min_amplitude_e`` and no tap is at full well or the ADC's white level.

``truth_errors`` gives what noise-free decoding of the rendered sums says: the multipath error
(all paths decoded minus the direct light alone decoded) and the mixing error (the direct light
decoded minus the pixel-centre range: a flying pixel's error).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from scenegen.geometry import tof as g
from scenegen.imaging.noise import SensorParams, expose_sensor


@dataclass(frozen=True, kw_only=True)
class TofPixelParams:
    """The ToF pixel model (module docstring). ``freqs_hz``: one or two modulation frequencies."""

    freqs_hz: tuple[float, ...]
    integration_s: float = 1e-3  # each tap's exposure, seconds
    signal_e_per_s_at_1m: float = 2e6  # tap offset B for a white Lambertian facing at 1 m, e-/s
    ambient_e_per_s: float = 0.0  # unmodulated background light per tap, e-/s
    contrast: float = 1.0  # modulation contrast m in [0, 1]
    min_amplitude_e: float = 20.0  # smallest amplitude A (electrons) a valid pixel has
    sensor: SensorParams = SensorParams(adc_bits=16, system_gain_dn_per_e=1.0, dark_noise_e=3.0,
                                        saturation_capacity_e=60000.0)

    @property
    def electrons_per_unit(self) -> float:
        """k: electrons per tap per unit rendered radiance (white Lambertian at 1 m renders 1 / pi)."""
        return math.pi * self.signal_e_per_s_at_1m * self.integration_s

    @property
    def gain_dn_per_e(self) -> float:
        return self.sensor.system_gain(0.0)


@dataclass(frozen=True)
class TofFrames:
    mean_e: np.ndarray  # (H, W, F, 4) float64: expected electrons per tap (noise-free)
    dn: np.ndarray  # (H, W, F, 4) uint16: raw frames as read out
    saturated: np.ndarray  # (H, W) bool: a tap at full well or the ADC's white level


def mean_electrons(sums: dict, p: TofPixelParams) -> np.ndarray:
    """(H, W, F, 4) expected tap electrons of the rendered sums (keys ``dc``, ``cos_k``, ``sin_k``)."""
    k = p.electrons_per_unit
    ambient = p.ambient_e_per_s * p.integration_s / k
    return np.stack([g.raw_frames(sums["dc"], sums[f"cos_{i}"], sums[f"sin_{i}"], electrons_per_unit=k,
                                  contrast=p.contrast, ambient=ambient) for i in range(len(p.freqs_hz))], axis=-2)


def expose(sums: dict, p: TofPixelParams, seed: int) -> TofFrames:
    """The raw frames of one ToF frame through the EMVA chain; ``seed`` seeds its temporal noise."""
    mu = mean_electrons(sums, p)
    out = expose_sensor(mu, exposure_time_s=p.integration_s, gain_db=0.0, sensor=p.sensor, seed=seed)
    sat = (out.electrons >= p.sensor.saturation_capacity_e) | (out.dn >= p.sensor.white_level_dn)
    return TofFrames(mean_e=mu, dn=out.dn, saturated=sat.any(axis=(-1, -2)))


def decode(frames_dn, p: TofPixelParams, max_range_m: float | None = None
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(range m (H, W) float64, amplitude e- (H, W, F), wrapped ranges m (H, W, F)) of raw frames
    (H, W, F, 4) in DN (the black level cancels in the differences). One frequency: the wrapped
    range (what a single-frequency camera reports); two: :func:`scenegen.geometry.tof.unwrap_two`."""
    phase, amp_dn, _ = g.decode_phase(np.asarray(frames_dn, np.float64))
    wrapped = np.stack([g.range_from_phase_m(phase[..., i], f) for i, f in enumerate(p.freqs_hz)], axis=-1)
    if len(p.freqs_hz) == 1:
        rng = wrapped[..., 0]
    else:
        rng = g.unwrap_two(wrapped[..., 0], wrapped[..., 1], *p.freqs_hz, max_range_m=max_range_m)[0]
    return rng, amp_dn / p.gain_dn_per_e, wrapped


def valid_mask(amplitude_e, saturated, p: TofPixelParams) -> np.ndarray:
    """(H, W) bool: every frequency's amplitude >= min_amplitude_e and no tap saturated."""
    return np.all(amplitude_e >= p.min_amplitude_e, axis=-1) & ~saturated


def _noise_free_range(sums: dict, p: TofPixelParams, prefix: str, max_range_m) -> np.ndarray:
    dc = sums[f"{prefix}dc"]
    frames = np.stack([g.raw_frames(dc, sums[f"{prefix}cos_{i}"], sums[f"{prefix}sin_{i}"], electrons_per_unit=1.0)
                       for i in range(len(p.freqs_hz))], axis=-2)
    return decode(frames, dataclasses.replace(p, sensor=SensorParams(system_gain_dn_per_e=1.0)), max_range_m)[0]


def _wrapped_difference(a, b, period: float) -> np.ndarray:
    return np.mod(a - b + 0.5 * period, period) - 0.5 * period


def truth_errors(sums: dict, range_true_m, p: TofPixelParams, max_range_m: float | None = None
                 ) -> tuple[np.ndarray, np.ndarray]:
    """(multipath error m, mixing error m), each (H, W) float64, NaN where the pixel has no
    direct light: noise-free decoding of all paths minus that of the direct light, and of the
    direct light minus the pixel-centre range ``range_true_m`` modulo the reading's period (the
    ambiguity range of one frequency; of the pair, its unambiguous range or ``max_range_m``)."""
    period = (g.ambiguity_range_m(p.freqs_hz[0]) if len(p.freqs_hz) == 1 else
              (g.unambiguous_range_two_m(*p.freqs_hz) if max_range_m is None else float(max_range_m)))
    full = _noise_free_range(sums, p, "", max_range_m)
    direct = _noise_free_range(sums, p, "direct_", max_range_m)
    lit = sums["direct_dc"] > 0
    multipath = np.where(lit, _wrapped_difference(full, direct, period), np.nan)
    truth = np.asarray(range_true_m, np.float64)
    mixing = np.where(lit & np.isfinite(truth), _wrapped_difference(direct, np.where(np.isfinite(truth), truth, 0.0),
                                                                     period), np.nan)
    return multipath, mixing


def range_noise_std_m(offset_e, amplitude_e, freq_hz: float, read_noise_e: float, gain_dn_per_e: float
                      ) -> np.ndarray:
    """The first-order standard deviation of a decoded range (one frequency, four taps) under
    shot and read noise and ADC quantisation: each difference C0 - C2, C1 - C3 has variance
    2 (B + sigma_r^2 + 1 / (12 K^2)), so sigma_phi = sqrt(2 (B + sigma_r^2 + 1/(12 K^2))) / (2 A) and
    sigma_r = c sigma_phi / (4 pi f)."""
    var_tap = np.asarray(offset_e, np.float64) + read_noise_e ** 2 + 1.0 / (12.0 * gain_dn_per_e ** 2)
    sigma_phi = np.sqrt(2.0 * var_tap) / (2.0 * np.asarray(amplitude_e, np.float64))
    return g.SPEED_OF_LIGHT_M_S * sigma_phi / (4.0 * math.pi * float(freq_hz))

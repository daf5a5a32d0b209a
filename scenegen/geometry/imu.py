"""An IMU on the clock: true accelerometer and gyroscope readings from a trajectory, and Kalibr's
noise model (docs/conventions.md, "The IMU").

Truth (:func:`imu_truth`), in the IMU body frame, at times ``times_s`` (N,) of a
:class:`scenegen.geometry.clock.Trajectory` of ``world_from_imu``:

* specific force ``f = R^T (a - g)`` (m/s^2), ``a`` the world-frame acceleration of the IMU
  origin and ``g`` :data:`scenegen.geometry.conventions.GRAVITY_WORLD_MPS2` (at rest with +z up
  an accelerometer reads (0, 0, +9.80665));
* angular velocity ``R^T omega`` (rad/s), omega the world-frame rate (dR/dt = [omega]x R).

Noise (:func:`imu_noise`), Kalibr's continuous-time model ("IMU Noise Model", Kalibr wiki), per
axis and sensor: ``measured = true + b + n``, ``n`` white with noise density ``sigma`` (m/s^2/sqrt(Hz)
or rad/s/sqrt(Hz)), ``b`` a random walk with bias random walk ``sigma_b`` (m/s^3/sqrt(Hz) or
rad/s^2/sqrt(Hz)). Sampled every ``dt`` seconds: ``n_k = sigma / sqrt(dt) w_k``,
``b_0 = 0``, ``b_k = b_k-1 + sigma_b sqrt(dt) w'_k``, with ``w``, ``w'`` standard normal.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.geometry import seeds
from scenegen.geometry.clock import as_times
from scenegen.geometry.conventions import GRAVITY_WORLD_MPS2


@dataclass(frozen=True)
class ImuNoiseParams:
    """Kalibr's four continuous-time values (``imu.yaml``): white noise densities and bias random
    walks of the accelerometer and the gyroscope. All 0: a noise-free IMU."""

    accelerometer_noise_density: float = 0.0  # m/s^2/sqrt(Hz)
    accelerometer_random_walk: float = 0.0  # m/s^3/sqrt(Hz)
    gyroscope_noise_density: float = 0.0  # rad/s/sqrt(Hz)
    gyroscope_random_walk: float = 0.0  # rad/s^2/sqrt(Hz)


#: Named noise presets, each with its source.
NOISE_PRESETS: dict[str, ImuNoiseParams] = {
    # EuRoC MAV's ADIS16448 (mav0/imu0/sensor.yaml of the EuRoC datasets; the same values in
    # Kalibr's example imu.yaml): continuous-time densities and random walks
    "euroc_adis16448": ImuNoiseParams(accelerometer_noise_density=2.0e-3, accelerometer_random_walk=3.0e-3,
                                      gyroscope_noise_density=1.6968e-4, gyroscope_random_walk=1.9393e-5),
    "ideal": ImuNoiseParams(),  # noise-free: measured == true
}


@dataclass(frozen=True, eq=False)
class ImuTruth:
    """The IMU's true state at N times: ``R`` (N, 3, 3) and ``t`` (N, 3) world_from_imu,
    ``velocity_mps`` (N, 3) world frame, and its readings in the IMU body frame:
    ``specific_force_mps2`` (N, 3) and ``angular_velocity_rad_s`` (N, 3)."""

    R: np.ndarray
    t: np.ndarray
    velocity_mps: np.ndarray
    specific_force_mps2: np.ndarray
    angular_velocity_rad_s: np.ndarray


def imu_truth(world_from_imu, times_s) -> ImuTruth:
    """The true readings of an IMU moving on ``world_from_imu`` (a Trajectory) at ``times_s`` (N,)
    seconds (module docstring)."""
    s = world_from_imu.states_at(as_times(times_s))
    f = np.einsum("nji,nj->ni", s.R, s.acceleration_mps2 - GRAVITY_WORLD_MPS2)
    return ImuTruth(s.R, s.t, s.velocity_mps, f, s.body_angular_velocity_rad_s())


@dataclass(frozen=True, eq=False)
class ImuNoise:
    """What the noise adds at N samples, each (N, 3): white noise and bias of the accelerometer
    (m/s^2) and of the gyroscope (rad/s). ``measured = true + bias + white``."""

    accel_white_mps2: np.ndarray
    accel_bias_mps2: np.ndarray
    gyro_white_rad_s: np.ndarray
    gyro_bias_rad_s: np.ndarray


def random_walk(sigma_step: float, n: int, rng: np.random.Generator) -> np.ndarray:
    """(n, 3) a random walk from 0: ``b_0 = 0``, ``b_k = b_k-1 + sigma_step w_k``."""
    out = np.zeros((n, 3))
    if n > 1:
        np.cumsum(sigma_step * rng.standard_normal((n - 1, 3)), axis=0, out=out[1:])
    return out


def imu_noise(params: ImuNoiseParams, n: int, dt_s: float, seed: int, stream: str) -> ImuNoise:
    """Kalibr's discretised noise (module docstring) at ``n`` samples ``dt_s`` seconds apart,
    drawn from four independent streams ``seeds.rng(seed, stream, part)`` (bitwise the same for
    the same arguments)."""
    if n < 1 or not dt_s > 0:
        raise ValueError(f"IMU noise needs n >= 1 samples and dt_s > 0, got n={n}, dt_s={dt_s}")

    def draw(part: str) -> np.random.Generator:
        return seeds.rng(seed, stream, part)

    root = np.sqrt(dt_s)
    p = params
    return ImuNoise(
        accel_white_mps2=p.accelerometer_noise_density / root * draw("accel_white").standard_normal((n, 3)),
        accel_bias_mps2=random_walk(p.accelerometer_random_walk * root, n, draw("accel_bias")),
        gyro_white_rad_s=p.gyroscope_noise_density / root * draw("gyro_white").standard_normal((n, 3)),
        gyro_bias_rad_s=random_walk(p.gyroscope_random_walk * root, n, draw("gyro_bias")))


def sample_times_s(start_s: float, end_s: float, rate_hz: float) -> np.ndarray:
    """(N,) ``start_s + k / rate_hz`` for k = 0, 1, ... while <= ``end_s`` (to 1e-9 s: an end on
    the grid is a sample)."""
    count = int(np.floor((end_s - start_s) * rate_hz + 1e-9)) + 1
    return start_s + np.arange(max(count, 0)) / rate_hz

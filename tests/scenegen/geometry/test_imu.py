"""The IMU's truth and noise (scenegen.geometry.imu) against independent computations:
integrating the noise-free readings gives back the trajectory, the readings agree with finite
differences of the poses, an IMU at rest reads +g up, and the noise's Allan deviation (allantools)
recovers Kalibr's noise density and bias random walk."""
from __future__ import annotations

import allantools
import numpy as np
import pytest

from scenegen.geometry.clock import Composed, StaticTrajectory
from scenegen.geometry.conventions import GRAVITY_WORLD_MPS2
from scenegen.geometry.imu import NOISE_PRESETS, ImuNoiseParams, imu_noise, imu_truth, sample_times_s
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.rotation import (matrix_from_quat_wxyz, matrix_from_rotvec, quat_wxyz_from_matrix,
                                       rotation_error_rad, rotvec_from_matrix)
from scenegen.geometry.trajectory import KeyframeTrajectory

RATE_HZ = 200.0


def hand_held(duration_s: float = 10.0, seed: int = 3) -> Composed:
    """A C2 spline through 11 seeded keyframes over ``duration_s`` (metres of travel, tens of
    degrees of turn), with an IMU 10 cm off the rig origin and turned: world_from_imu."""
    rng = np.random.default_rng(seed)
    times = np.linspace(0.0, duration_s, 11)
    poses = [Rigid3(matrix_from_rotvec(rng.normal(0, 0.4, 3)), rng.normal(0, 1.0, 3)) for _ in times]
    rig_from_imu = Rigid3(matrix_from_rotvec([0.3, -0.2, 1.0]), np.array([0.1, -0.05, 0.02]))
    return Composed(KeyframeTrajectory(times, poses, "spline"), StaticTrajectory(rig_from_imu))


def quat_mul(p, q):
    w1, x1, y1, z1 = p
    w2, x2, y2, z2 = q
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def rk4_integrate(q0, v0, p0, gyro, accel, dt):
    """RK4 on the state (q_wxyz, v, p) of q' = q (x) (0, w)/2, v' = R(q) f + g, p' = v, one step
    of 2 dt per sample pair: the inputs at the step's start, middle and end are samples k, k+1,
    k+2 (no interpolation of the samples). Returns the positions at every other sample."""
    def deriv(q, v, w, f):
        R = matrix_from_quat_wxyz(q)
        return 0.5 * quat_mul(q, np.r_[0.0, w]), R @ f + GRAVITY_WORLD_MPS2, v

    q, v, p, h, out = q0, v0, p0, 2 * dt, [p0]
    for k in range(0, len(gyro) - 2, 2):
        k1 = deriv(q, v, gyro[k], accel[k])
        k2 = deriv(q + h / 2 * k1[0], v + h / 2 * k1[1], gyro[k + 1], accel[k + 1])
        k3 = deriv(q + h / 2 * k2[0], v + h / 2 * k2[1], gyro[k + 1], accel[k + 1])
        k4 = deriv(q + h * k3[0], v + h * k3[1], gyro[k + 2], accel[k + 2])
        p = p + h / 6 * (k1[2] + 2 * k2[2] + 2 * k3[2] + k4[2])
        v = v + h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        q = q + h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        q = q / np.linalg.norm(q)
        out.append(p)
    return np.array(out), q


def test_integrating_the_noise_free_imu_reproduces_the_trajectory():
    traj = hand_held(10.0)
    times = sample_times_s(0.0, 10.0, RATE_HZ)
    assert len(times) == 2001 and times[-1] == 10.0
    truth = imu_truth(traj, times)
    q0 = quat_wxyz_from_matrix(truth.R[0])
    positions, q_end = rk4_integrate(q0, truth.velocity_mps[0], truth.t[0], truth.angular_velocity_rad_s,
                                     truth.specific_force_mps2, 1.0 / RATE_HZ)
    drift_m = np.linalg.norm(positions - truth.t[::2], axis=1)
    travel_m = np.sum(np.linalg.norm(np.diff(truth.t, axis=0), axis=1))
    assert travel_m > 5.0  # the path moves: metres, not millimetres
    assert drift_m.max() < 1e-3, drift_m.max()
    assert rotation_error_rad(matrix_from_quat_wxyz(q_end), truth.R[-1]) < 1e-5


def central_differences(traj, t: float, h: float):
    """(specific force, body angular velocity) at t from the poses at t - h, t, t + h only."""
    R, p = traj.poses_at([t - h, t, t + h])
    a = (p[2] - 2 * p[1] + p[0]) / h ** 2
    w = (rotvec_from_matrix(R[1].T @ R[2]) - rotvec_from_matrix(R[1].T @ R[0])) / (2 * h)
    return R[1].T @ (a - GRAVITY_WORLD_MPS2), w


@pytest.mark.parametrize("t", [0.37, 2.5, 4.013, 7.77])
def test_a_sample_agrees_with_finite_differences_of_the_poses_to_their_own_error(t):
    traj = hand_held(10.0)
    truth = imu_truth(traj, [t])
    h = 1e-3
    f_h, w_h = central_differences(traj, t, h)
    f_2h, w_2h = central_differences(traj, t, 2 * h)
    # a central difference's error is c h^2 + rounding: |d(h) - d(2h)| ~ 3 c h^2 bounds it, the
    # rounding of the poses (1e-16 m) over h^2 adds 1e-10 m/s^2
    f_err = np.abs(f_h - f_2h).max() + 1e-9
    w_err = np.abs(w_h - w_2h).max() + 1e-11
    assert np.abs(truth.specific_force_mps2[0] - f_h).max() < f_err
    assert np.abs(truth.angular_velocity_rad_s[0] - w_h).max() < w_err
    assert np.abs(truth.specific_force_mps2[0]).max() > 1.0 and np.abs(truth.angular_velocity_rad_s[0]).max() > 0.01


def test_an_imu_at_rest_reads_plus_g_up_in_its_own_axes():
    R = matrix_from_rotvec([0.4, -0.3, 0.2])
    still = StaticTrajectory(Rigid3(R, np.array([1.0, 2.0, 3.0])))
    truth = imu_truth(still, [0.0, 1.0])
    assert np.allclose(truth.specific_force_mps2, R.T @ [0.0, 0.0, 9.80665], atol=1e-14)
    assert np.array_equal(truth.angular_velocity_rad_s, np.zeros((2, 3)))
    level = imu_truth(StaticTrajectory(Rigid3.identity()), [0.0])
    assert np.array_equal(level.specific_force_mps2, [[0.0, 0.0, 9.80665]])


def allan_fit(signal, rate_hz):
    """(noise density, random walk) of a sampled signal (n, 3): the overlapping Allan variance
    (allantools.oadev) of each axis at octave taus up to 1 % of its span, averaged over the axes,
    fit by least squares (relative) to avar = N^2 / tau + K^2 tau / 3 (IEEE Std 952-1997: white
    noise and rate random walk)."""
    avar = []
    for x in signal.T:
        taus, adev = allantools.oadev(x, rate=rate_hz, data_type="freq", taus="octave")[:2]
        avar.append(adev ** 2)
    keep = taus <= 0.01 * len(signal) / rate_hz
    taus, avar = taus[keep], np.mean(avar, axis=0)[keep]
    A = np.stack([1.0 / taus, taus / 3.0], axis=1) / avar[:, None]
    (n2, k2), *_ = np.linalg.lstsq(A, np.ones_like(taus), rcond=None)
    return np.sqrt(n2), np.sqrt(k2)


def test_the_noise_s_allan_deviation_recovers_the_configured_density_and_random_walk():
    """At 10 Hz, 2,000,000 samples span 200,000 s, so the random walk dominates the Allan
    deviation over many spans (the gyroscope's crosses its white noise at tau = sqrt(3) N / K =
    15 s). Over 12 seeds the four estimates' RMS errors were 0.3 %, 1.0 %, 0.1 %, 1.3 %: 5 % is
    4 standard deviations."""
    params, rate_hz = NOISE_PRESETS["euroc_adis16448"], 10.0
    noise = imu_noise(params, 2_000_000, 1.0 / rate_hz, seed=7, stream="allan")
    na, ka = allan_fit(noise.accel_white_mps2 + noise.accel_bias_mps2, rate_hz)
    ng, kg = allan_fit(noise.gyro_white_rad_s + noise.gyro_bias_rad_s, rate_hz)
    assert na == pytest.approx(params.accelerometer_noise_density, rel=0.05)
    assert ka == pytest.approx(params.accelerometer_random_walk, rel=0.05)
    assert ng == pytest.approx(params.gyroscope_noise_density, rel=0.05)
    assert kg == pytest.approx(params.gyroscope_random_walk, rel=0.05)


def test_the_discrete_noise_at_200_hz_is_sigma_over_root_dt_and_sigma_b_times_root_dt():
    """Kalibr's discretisation: white samples of std N / sqrt(dt), bias steps of std K sqrt(dt)
    (600,000 draws each: the sample std within 0.3 % at 3 standard deviations)."""
    params, dt = NOISE_PRESETS["euroc_adis16448"], 1.0 / RATE_HZ
    noise = imu_noise(params, 200_001, dt, seed=5, stream="discrete")
    assert np.std(noise.accel_white_mps2) == pytest.approx(params.accelerometer_noise_density / np.sqrt(dt), rel=3e-3)
    assert np.std(noise.gyro_white_rad_s) == pytest.approx(params.gyroscope_noise_density / np.sqrt(dt), rel=3e-3)
    assert np.std(np.diff(noise.accel_bias_mps2, axis=0)) == pytest.approx(
        params.accelerometer_random_walk * np.sqrt(dt), rel=3e-3)
    assert np.std(np.diff(noise.gyro_bias_rad_s, axis=0)) == pytest.approx(
        params.gyroscope_random_walk * np.sqrt(dt), rel=3e-3)


def test_the_noise_is_bitwise_deterministic_and_starts_without_bias():
    p = NOISE_PRESETS["euroc_adis16448"]
    a, b = imu_noise(p, 1000, 0.005, 11, "s"), imu_noise(p, 1000, 0.005, 11, "s")
    for name in ("accel_white_mps2", "accel_bias_mps2", "gyro_white_rad_s", "gyro_bias_rad_s"):
        assert getattr(a, name).tobytes() == getattr(b, name).tobytes()
    assert not np.array_equal(imu_noise(p, 1000, 0.005, 12, "s").accel_white_mps2, a.accel_white_mps2)
    assert not np.array_equal(imu_noise(p, 1000, 0.005, 11, "t").accel_white_mps2, a.accel_white_mps2)
    assert np.array_equal(a.accel_bias_mps2[0], np.zeros(3))
    ideal = imu_noise(ImuNoiseParams(), 10, 0.005, 11, "s")
    assert not np.any(ideal.accel_white_mps2) and not np.any(ideal.gyro_bias_rad_s)
    with pytest.raises(ValueError, match="n >= 1"):
        imu_noise(p, 0, 0.005, 11, "s")

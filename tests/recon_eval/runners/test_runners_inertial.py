"""The IMU dead reckoning of the odometry runners (recon_eval.runners.inertial), pure numpy against
scenegen's analytic IMU truth (scenegen.geometry.imu.imu_truth, an independent computation from
the trajectory's derivatives): on noise-free readings the RK4 integration reproduces the trajectory
(the integrator's error: below 1 mm over 10 s at 200 Hz, the issue's bound), with Kalibr noise it
drifts by far more (the baseline's drift is the noise's, not the integrator's), and the gyroscope's
chained rotation between two times matches the truth's relative rotation."""
from __future__ import annotations

import numpy as np
import pytest

from recon_eval.errors import NotApplicable
from recon_eval.runners import run_method
from recon_eval.runners.inertial import gyro_rotation, integrate_imu
from scenegen.geometry.clock import Composed, StaticTrajectory
from scenegen.geometry.imu import NOISE_PRESETS, imu_noise, imu_truth, sample_times_s
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.rotation import matrix_from_rotvec, quat_wxyz_from_matrix, rotation_angle_rad
from scenegen.geometry.trajectory import KeyframeTrajectory

RATE_HZ = 200.0


def hand_held(duration_s: float = 10.0, seed: int = 5) -> Composed:
    """world_from_imu: a C2 spline through 11 seeded keyframes (metres, tens of degrees), the IMU
    off the rig origin and turned."""
    rng = np.random.default_rng(seed)
    times = np.linspace(0.0, duration_s, 11)
    poses = [Rigid3(matrix_from_rotvec(rng.normal(0, 0.4, 3)), rng.normal(0, 1.0, 3)) for _ in times]
    rig_from_imu = Rigid3(matrix_from_rotvec([-0.2, 0.5, 0.3]), np.array([0.05, 0.1, -0.02]))
    return Composed(KeyframeTrajectory(times, poses, "spline"), StaticTrajectory(rig_from_imu))


def dead_reckon(truth, gyro, accel):
    idx, R, p = integrate_imu(quat_wxyz_from_matrix(truth.R[0]), truth.velocity_mps[0], truth.t[0], gyro, accel,
                              1.0 / RATE_HZ)
    return idx, R, p


def test_noise_free_dead_reckoning_reproduces_the_trajectory_to_the_integrators_error():
    times = sample_times_s(0.0, 10.0, RATE_HZ)
    truth = imu_truth(hand_held(), times)
    idx, R, p = dead_reckon(truth, truth.angular_velocity_rad_s, truth.specific_force_mps2)
    assert idx[-1] == len(times) - 1 and len(idx) == 1001
    drift_m = np.linalg.norm(p - truth.t[idx], axis=1)
    assert np.sum(np.linalg.norm(np.diff(truth.t, axis=0), axis=1)) > 5.0  # metres of travel
    assert drift_m.max() < 1e-3, drift_m.max()
    assert max(rotation_angle_rad(R[j].T @ truth.R[i]) for j, i in enumerate(idx)) < 1e-5


def test_with_kalibr_noise_the_drift_is_the_noises_not_the_integrators():
    times = sample_times_s(0.0, 10.0, RATE_HZ)
    truth = imu_truth(hand_held(), times)
    noise = imu_noise(NOISE_PRESETS["euroc_adis16448"], len(times), 1.0 / RATE_HZ, seed=7, stream="test")
    idx, _, p = dead_reckon(truth, truth.angular_velocity_rad_s + noise.gyro_bias_rad_s + noise.gyro_white_rad_s,
                            truth.specific_force_mps2 + noise.accel_bias_mps2 + noise.accel_white_mps2)
    drift_m = np.linalg.norm(p[-1] - truth.t[-1])
    # white accelerometer noise alone, integrated twice, spreads by sigma T^1.5 / sqrt(3) = 0.037 m
    # per axis after 10 s; the bias random walks add more: centimetres to metres, >> 1 mm
    assert drift_m > 0.01, drift_m


def test_the_gyroscope_rotation_between_two_times_is_the_truths():
    times = sample_times_s(0.0, 10.0, RATE_HZ)
    truth = imu_truth(hand_held(), times)
    for t0, t1 in ((1.0, 1.2), (3.0, 3.5), (6.02, 6.4)):
        i0, i1 = int(round(t0 * RATE_HZ)), int(round(t1 * RATE_HZ))
        R = gyro_rotation(times, truth.angular_velocity_rad_s, t0, t1)
        # the trapezoid of the rate over 5 ms steps: an O(dt^2) error per second, ~1e-4 rad here
        assert rotation_angle_rad(R.T @ (truth.R[i0].T @ truth.R[i1])) < 1e-3
        assert rotation_angle_rad(truth.R[i0].T @ truth.R[i1]) > 0.02  # it turns


def test_a_dataset_without_a_stereo_sequence_is_not_applicable(plane_dataset, tmp_path):
    for name in ("stereo-vo-pnp", "imu-dead-reckoning"):
        with pytest.raises(NotApplicable, match="rectified stereo frames; odometry needs a sequence"):
            run_method(name, plane_dataset[0], tmp_path / name)

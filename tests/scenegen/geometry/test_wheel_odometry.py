"""Differential-drive wheel odometry (scenegen.geometry.wheel_odometry) against closed forms: a
circle driven at constant speed gives constant wheel speeds (v -+ omega b / 2) / r and integrates
back to the circle; slip makes the circle the one the slipped wheel speeds describe; noise is
seeded with its configured sigma; on a general spline the wheel speeds agree with central
differences of the poses to the differences' own error."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from scenegen.geometry.clock import TrajectoryStates, as_times
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.trajectory import KeyframeTrajectory
from scenegen.geometry.wheel_odometry import (DiffDrive, integrate_diff_drive, measured_wheel_speeds,
                                              planar_pose, wheel_truth)

DRIVE = DiffDrive(wheel_radius_m=0.08, track_width_m=0.42)


@dataclass(frozen=True)
class Circle:
    """A base on a circle of radius rho (m) at speed v (m/s), counter-clockwise, starting at
    (1, 2, 0.1) heading along +x, z up: x = rho sin(w t), y = rho (1 - cos(w t)), yaw = w t."""

    rho: float
    v: float
    knot_times_s = np.empty(0)

    def states_at(self, times_s):
        t = as_times(times_s)
        w = self.v / self.rho
        c, s = np.cos(w * t), np.sin(w * t)
        R = np.zeros((len(t), 3, 3))
        R[:, 0, 0], R[:, 0, 1], R[:, 1, 0], R[:, 1, 1], R[:, 2, 2] = c, -s, s, c, 1.0
        p = np.c_[1 + self.rho * s, 2 + self.rho * (1 - c), np.full(len(t), 0.1)]
        vel = np.c_[self.v * c, self.v * s, np.zeros(len(t))]
        omega = np.tile([0.0, 0.0, w], (len(t), 1))
        acc = np.c_[-self.v * w * s, self.v * w * c, np.zeros(len(t))]
        return TrajectoryStates(R, p, vel, omega, acc, np.zeros((len(t), 3)))


def _circle_pose(rho, v, t):
    w = v / rho
    return np.c_[rho * np.sin(w * t), rho * (1 - np.cos(w * t)), w * t]


def test_a_circle_at_constant_speed_has_constant_wheel_speeds_and_integrates_back():
    rho, v = 2.5, 0.8
    t = np.arange(0, 30.0 + 1e-9, 0.02)  # 1.5 laps at 50 Hz
    truth = wheel_truth(Circle(rho, v), t, DRIVE)
    w = v / rho
    want = [(v - w * 0.21) / 0.08, (v + w * 0.21) / 0.08]
    assert np.abs(truth.wheel_speeds_rad_s - want).max() < 1e-12
    assert np.abs(truth.velocity_base_mps - [v, 0, 0]).max() < 1e-15 and np.abs(truth.yaw_rate_rad_s - w).max() < 1e-15
    assert np.abs(truth.planar_pose - _circle_pose(rho, v, t)).max() < 1e-12
    odom = integrate_diff_drive(truth.wheel_speeds_rad_s, t, DRIVE)
    err = np.abs(odom - _circle_pose(rho, v, t)).max()
    assert err < 1e-11
    print(f"circle 2.5 m at 0.8 m/s, 30 s at 50 Hz: odometry vs closed form max {err:.1e}")


@pytest.mark.parametrize("slip", [(0.05, 0.05), (0.0, 0.1), (-0.03, 0.02)])
def test_slip_drives_the_circle_of_the_slipped_wheel_speeds(slip):
    rho, v = 2.0, 0.5
    t = np.arange(0, 10.0 + 1e-9, 0.05)
    truth = wheel_truth(Circle(rho, v), t, DRIVE)
    meas = measured_wheel_speeds(truth.wheel_speeds_rad_s, *slip, noise_rad_s=0.0, seed=1, stream="s")
    wl, wr = truth.wheel_speeds_rad_s[0] * (1 + np.array(slip))
    v_s, w_s = 0.08 * (wl + wr) / 2, 0.08 * (wr - wl) / 0.42  # closed form: another circle
    odom = integrate_diff_drive(meas, t, DRIVE)
    assert np.abs(odom - _circle_pose(v_s / w_s, v_s, t)).max() < 1e-11
    if slip[0] == slip[1]:  # equal slip: the same circle, driven (1 + s) times as far
        assert v_s / w_s == pytest.approx(rho, rel=1e-14)


def test_noise_is_seeded_with_its_sigma():
    true = np.tile([3.0, 4.0], (20000, 1))
    a = measured_wheel_speeds(true, 0.0, 0.0, 0.02, seed=5, stream="base_wheels")
    b = measured_wheel_speeds(true, 0.0, 0.0, 0.02, seed=5, stream="base_wheels")
    c = measured_wheel_speeds(true, 0.0, 0.0, 0.02, seed=6, stream="base_wheels")
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    # 40000 draws: the std's relative standard error is 1 / sqrt(2 * 40000) = 0.35 %; 4 sigma
    assert abs(np.std(a - true) / 0.02 - 1) < 0.014 and abs(np.mean(a - true)) < 4 * 0.02 / 200


def test_wheel_speeds_agree_with_central_differences_on_a_spline():
    keys = [Rigid3(np.eye(3), np.zeros(3)), Rigid3(np.eye(3), np.array([1.0, 0.3, 0.0])),
            Rigid3(np.eye(3), np.array([2.0, 1.2, 0.0]))]
    R_yaw = [np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]]) for a in (0, 0.4, 1.0)]
    traj = KeyframeTrajectory((0.0, 1.0, 2.5), tuple(Rigid3(R, k.t) for R, k in zip(R_yaw, keys)), "spline")
    t = np.linspace(0.2, 2.3, 50)
    truth = wheel_truth(traj, t, DRIVE)
    h = 1e-5
    Rp, tp = traj.poses_at(t + h)
    Rm, tm = traj.poses_at(t - h)
    v_fd = np.einsum("nji,nj->ni", truth.R, (tp - tm) / (2 * h))[:, 0]
    yaw_p = planar_pose(truth.R[0], truth.t[0], Rp, tp)[:, 2]
    yaw_fd = (yaw_p - planar_pose(truth.R[0], truth.t[0], Rm, tm)[:, 2]) / (2 * h)
    want = DRIVE.wheel_speeds_rad_s(v_fd, yaw_fd)
    # central differences: O(h^2 x third derivative) ~ 1e-10, rounding ~ 1e-16 / h = 1e-11
    assert np.abs(truth.wheel_speeds_rad_s - want).max() < 1e-7

"""Wheel odometry of a differential-drive ground robot: true wheel speeds from a trajectory, slip
and noise, and the odometry integrated from them (docs/conventions.md, "Wheel odometry").

The base frame (the rig member's sensor frame, ``world_from_base``) is ROS REP 103's: x forward,
y left, z up, its origin midway between the two wheels' contact points; the floor is the base's
xy plane at the first sample.

Model (Siegwart, Nourbakhsh and Scaramuzza, "Introduction to Autonomous Mobile Robots", 2nd ed.,
section 3.2.1, eq. 3.9 inverted), wheel radius ``r``, track width ``b`` (distance between the
wheels' contact points), at each time:

* forward speed ``v = (R^T v_world)_x`` and yaw rate ``omega = (R^T omega_world)_z`` (body frame);
* true wheel speeds ``w_left = (v - omega b / 2) / r``, ``w_right = (v + omega b / 2) / r`` (rad/s,
  positive rolling forward). The base's lateral and vertical velocity (``v_y``, ``v_z``) are what
  a wheel cannot see: recorded as truth, absent from the wheels;
* measured ``w = w_true (1 + s) + n``: ``s`` the wheel's longitudinal slip ratio (the wheel turns
  ``1 + s`` times as fast as its contact point moves over the floor; constant per wheel) and ``n``
  white noise of standard deviation ``sigma`` (rad/s) per sample, seeded.

Odometry (:func:`integrate_diff_drive`): each sample's ``v = r (w_r + w_l) / 2``, ``omega = r (w_r -
w_l) / b`` held until the next sample (zero-order hold) and integrated exactly along the arc, from
the pose (0, 0, 0) at the first sample: a circle driven at constant wheel speeds is reproduced to
rounding.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenegen.geometry import seeds
from scenegen.geometry.clock import as_times


@dataclass(frozen=True)
class DiffDrive:
    """A differential drive: ``wheel_radius_m`` r and ``track_width_m`` b (both > 0)."""

    wheel_radius_m: float
    track_width_m: float

    def __post_init__(self):
        if not (self.wheel_radius_m > 0 and self.track_width_m > 0):
            raise ValueError(f"wheel radius and track width must be > 0, got {self.wheel_radius_m}, "
                             f"{self.track_width_m}")

    def wheel_speeds_rad_s(self, v_mps, omega_rad_s) -> np.ndarray:
        """(N, 2) [left, right] wheel speeds of forward speeds (N,) and yaw rates (N,)."""
        v, w = np.asarray(v_mps, np.float64), np.asarray(omega_rad_s, np.float64)
        half = 0.5 * self.track_width_m * w
        return np.stack([v - half, v + half], axis=-1) / self.wheel_radius_m

    def body_rates(self, wheel_speeds_rad_s) -> tuple[np.ndarray, np.ndarray]:
        """(forward speeds (N,) m/s, yaw rates (N,) rad/s) of wheel speeds (N, 2) [left, right]."""
        w = np.asarray(wheel_speeds_rad_s, np.float64).reshape(-1, 2)
        r = self.wheel_radius_m
        return r * (w[:, 1] + w[:, 0]) / 2, r * (w[:, 1] - w[:, 0]) / self.track_width_m


def planar_pose(R0, t0, R, t) -> np.ndarray:
    """(N, 3) x, y (m) and yaw (rad, unwrapped) of ``world_from_base`` poses (N, 3, 3), (N, 3)
    in the frame of the first one ``R0``, ``t0`` (the odometry frame)."""
    rel_t = np.einsum("ji,nj->ni", R0, np.asarray(t) - t0)
    rel_R = np.einsum("ji,njk->nik", R0, R)
    yaw = np.unwrap(np.arctan2(rel_R[:, 1, 0], rel_R[:, 0, 0]))
    return np.c_[rel_t[:, :2], yaw]


@dataclass(frozen=True, eq=False)
class WheelTruth:
    """The base at N times: ``R`` (N, 3, 3), ``t`` (N, 3) world_from_base; ``velocity_base_mps``
    (N, 3) its velocity in its own axes (x: what the wheels see); ``yaw_rate_rad_s`` (N,);
    ``wheel_speeds_rad_s`` (N, 2) [left, right] without slip or noise; ``planar_pose`` (N, 3) x,
    y, yaw in the odometry frame (the base at the first time)."""

    R: np.ndarray
    t: np.ndarray
    velocity_base_mps: np.ndarray
    yaw_rate_rad_s: np.ndarray
    wheel_speeds_rad_s: np.ndarray
    planar_pose: np.ndarray


def wheel_truth(world_from_base, times_s, drive: DiffDrive) -> WheelTruth:
    """The true wheel speeds of a base moving on ``world_from_base`` (a Trajectory) at ``times_s``
    (N,) (module docstring)."""
    s = world_from_base.states_at(as_times(times_s))
    v_b = np.einsum("nji,nj->ni", s.R, s.velocity_mps)
    omega_z = s.body_angular_velocity_rad_s()[:, 2]
    return WheelTruth(s.R, s.t, v_b, omega_z, drive.wheel_speeds_rad_s(v_b[:, 0], omega_z),
                      planar_pose(s.R[0], s.t[0], s.R, s.t))


def measured_wheel_speeds(true_rad_s, slip_left: float, slip_right: float, noise_rad_s: float, seed: int,
                          stream: str) -> np.ndarray:
    """(N, 2) ``w_true (1 + s) + n`` (module docstring); the noise from ``seeds.rng(seed, stream,
    'wheel_noise')`` (bitwise the same for the same arguments)."""
    w = np.asarray(true_rad_s, np.float64).reshape(-1, 2) * (1.0 + np.array([slip_left, slip_right]))
    if noise_rad_s > 0:
        w = w + noise_rad_s * seeds.rng(seed, stream, "wheel_noise").standard_normal(w.shape)
    return w


def integrate_diff_drive(wheel_speeds_rad_s, times_s, drive: DiffDrive) -> np.ndarray:
    """(N, 3) x, y (m), yaw (rad) from (0, 0, 0) at ``times_s[0]``: each sample's body rates held
    until the next sample and integrated along the exact arc (module docstring)."""
    t = as_times(times_s)
    v, w = drive.body_rates(wheel_speeds_rad_s)
    if len(v) != len(t):
        raise ValueError(f"one wheel-speed pair per time expected, got {len(v)} and {len(t)}")
    dt = np.diff(t)
    dtheta = w[:-1] * dt
    yaw = np.r_[0.0, np.cumsum(dtheta)]
    # chord of the arc: length v dt sinc(dtheta / 2), at heading yaw + dtheta / 2 (exact for a
    # constant v and omega; the straight segment as dtheta -> 0)
    chord = v[:-1] * dt * np.sinc(dtheta / (2 * np.pi))
    heading = yaw[:-1] + dtheta / 2
    x = np.r_[0.0, np.cumsum(chord * np.cos(heading))]
    y = np.r_[0.0, np.cumsum(chord * np.sin(heading))]
    return np.c_[x, y, yaw]

"""One clock in seconds: the trajectory protocol every moving frame answers, vectorised over times.

A :class:`Trajectory` maps an array of times ``times_s`` (N,) float64 (seconds on the sequence's
clock; a still scene's clock is 0 at mid-exposure) to the body's ``world_from_body`` poses and
their time derivatives, all in the WORLD frame (:class:`TrajectoryStates`):

* ``velocity_mps`` (N, 3): d/dt of the body origin, metres / second;
* ``angular_velocity_rad_s`` (N, 3): omega with dR/dt = [omega]x R (world frame), rad / second;
  the body-frame rate (a gyroscope's) is ``R^T omega`` (:meth:`TrajectoryStates.body_angular_velocity_rad_s`);
* ``acceleration_mps2`` (N, 3): d^2/dt^2 of the body origin (linear, world frame, m/s^2; gravity
  not included: a specific force is ``R^T (a - g)``);
* ``angular_acceleration_rad_s2`` (N, 3): d omega / dt (world frame).

Every motion model of the project is one: keyframes (linear/slerp and the C2 spline, the
joints; :mod:`.trajectory`), a still pose (:class:`StaticTrajectory`), a camera's or object's
constant velocity during an exposure (:class:`ConstantTwist`, from :class:`.optics.Motion`), a
frame rigidly attached to or parented under another (:class:`Composed`). A rolling shutter's
rows, a LiDAR beam, an event, an IMU sample are all just times at which one is evaluated
(:class:`scenegen.geometry.rolling.RowClock` turns rows into times).

``knot_times_s`` (K,): where the velocity may jump (a linear path's keyframes, a held end), so
tables over time need nodes there.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from scenegen.geometry.pose import Rigid3
from scenegen.geometry.rotation import matrix_from_rotvec


def as_times(times_s) -> np.ndarray:
    """``times_s`` as a flat (N,) float64 array (a scalar gives N = 1)."""
    return np.asarray(times_s, np.float64).reshape(-1)


def _rotate(R: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(N, 3) R_n v_n of (N, 3, 3) rotations and (N, 3) vectors."""
    return np.einsum("nij,nj->ni", R, v)


@dataclass(frozen=True, eq=False)
class TrajectoryStates:
    """A body at N times: ``R`` (N, 3, 3), ``t`` (N, 3) world_from_body, and its world-frame
    derivatives (module docstring), each (N, 3)."""

    R: np.ndarray
    t: np.ndarray
    velocity_mps: np.ndarray
    angular_velocity_rad_s: np.ndarray
    acceleration_mps2: np.ndarray
    angular_acceleration_rad_s2: np.ndarray

    @classmethod
    def still(cls, R: np.ndarray, t: np.ndarray) -> TrajectoryStates:
        """Poses (N, 3, 3), (N, 3) that do not move (all derivatives 0)."""
        z = np.zeros((len(R), 3))
        return cls(R, t, z, z.copy(), z.copy(), z.copy())

    def __len__(self) -> int:
        return len(self.R)

    def body_angular_velocity_rad_s(self) -> np.ndarray:
        """(N, 3) the angular velocity in the body's own axes, ``R^T omega`` (a gyroscope's)."""
        return np.einsum("nji,nj->ni", self.R, self.angular_velocity_rad_s)

    def pose(self, k: int) -> Rigid3:
        """world_from_body at the k-th time."""
        return Rigid3(self.R[k], self.t[k])

    def compose(self, child: TrajectoryStates) -> TrajectoryStates:
        """The states of ``self @ child`` where ``child`` is parent_from_child with its
        velocities in this (parent) frame's axes: ``omega = omega_p + R_p omega_c``,
        ``v = v_p + omega_p x r + R_p v_c`` with ``r = R_p t_c``, and their derivatives
        (:meth:`scenegen.geometry.trajectory.MotionState.compose`, per time)."""
        Rp = self.R
        r = _rotate(Rp, child.t)
        wp, ap = self.angular_velocity_rad_s, self.angular_acceleration_rad_s2
        wc, vc = _rotate(Rp, child.angular_velocity_rad_s), _rotate(Rp, child.velocity_mps)
        ac, lc = _rotate(Rp, child.angular_acceleration_rad_s2), _rotate(Rp, child.acceleration_mps2)
        r_dot = np.cross(wp, r) + vc
        v = self.velocity_mps + np.cross(wp, r) + vc
        acc = self.acceleration_mps2 + np.cross(ap, r) + np.cross(wp, r_dot) + lc + np.cross(wp, vc)
        return TrajectoryStates(Rp @ child.R, self.t + r, v, wp + wc, acc, ap + ac + np.cross(wp, wc))


@runtime_checkable
class Trajectory(Protocol):
    """A rigid body moving on the clock (module docstring). Implementations define
    :meth:`states_at` and :attr:`knot_times_s`; :class:`TrajectoryMixin` adds the rest."""

    @property
    def knot_times_s(self) -> np.ndarray: ...

    def states_at(self, times_s) -> TrajectoryStates: ...

    def poses_at(self, times_s) -> tuple[np.ndarray, np.ndarray]: ...

    def velocity_at(self, times_s) -> np.ndarray: ...

    def angular_velocity_at(self, times_s) -> np.ndarray: ...

    def acceleration_at(self, times_s) -> np.ndarray: ...


class TrajectoryMixin:
    """The :class:`Trajectory` methods derived from ``states_at`` (all vectorised over times)."""

    def poses_at(self, times_s) -> tuple[np.ndarray, np.ndarray]:
        """((N, 3, 3) R, (N, 3) t) world_from_body at ``times_s`` (N,) seconds."""
        s = self.states_at(times_s)
        return s.R, s.t

    def velocity_at(self, times_s) -> np.ndarray:
        """(N, 3) linear velocity of the body origin, world frame, m/s."""
        return self.states_at(times_s).velocity_mps

    def angular_velocity_at(self, times_s) -> np.ndarray:
        """(N, 3) angular velocity, WORLD frame (dR/dt = [omega]x R), rad/s."""
        return self.states_at(times_s).angular_velocity_rad_s

    def body_angular_velocity_at(self, times_s) -> np.ndarray:
        """(N, 3) angular velocity in the body's axes (R^T omega), rad/s."""
        return self.states_at(times_s).body_angular_velocity_rad_s()

    def acceleration_at(self, times_s) -> np.ndarray:
        """(N, 3) linear acceleration of the body origin, world frame, m/s^2 (no gravity)."""
        return self.states_at(times_s).acceleration_mps2

    def angular_acceleration_at(self, times_s) -> np.ndarray:
        """(N, 3) angular acceleration, world frame, rad/s^2."""
        return self.states_at(times_s).angular_acceleration_rad_s2


@dataclass(frozen=True, eq=False)
class StaticTrajectory(TrajectoryMixin):
    """A body that never moves: ``world_from_body`` at every time."""

    world_from_body: Rigid3

    @property
    def knot_times_s(self) -> np.ndarray:
        return np.empty(0)

    def states_at(self, times_s) -> TrajectoryStates:
        n = len(as_times(times_s))
        p = self.world_from_body
        return TrajectoryStates.still(np.broadcast_to(p.R, (n, 3, 3)).copy(), np.broadcast_to(p.t, (n, 3)).copy())


@dataclass(frozen=True, eq=False)
class ConstantTwist(TrajectoryMixin):
    """Constant world-frame velocities about the body origin from a reference pose:
    ``R(t) = exp([w (t - t_ref)]x) R_ref``, ``p(t) = p_ref + v (t - t_ref)`` (acceleration 0).
    A camera's body-frame :class:`~scenegen.geometry.optics.Motion` (``world_from_cam(tau) =
    world_from_cam @ [exp(w_b tau) | v_b tau]``) is this with ``w = R_ref w_b``, ``v = R_ref v_b``
    (:meth:`from_body_velocities`); an object's world-frame one is it directly."""

    world_from_body_ref: Rigid3
    ref_time_s: float
    linear_velocity_mps: np.ndarray  # (3,) world frame
    angular_velocity_rad_s: np.ndarray  # (3,) world frame

    @classmethod
    def from_body_velocities(cls, world_from_body_ref: Rigid3, ref_time_s: float, linear_velocity_mps,
                             angular_velocity_rad_s) -> ConstantTwist:
        """Velocities given in the body's axes at the reference time (a camera's ``motion``)."""
        R = world_from_body_ref.R
        return cls(world_from_body_ref, float(ref_time_s), R @ np.asarray(linear_velocity_mps, np.float64),
                   R @ np.asarray(angular_velocity_rad_s, np.float64))

    @property
    def knot_times_s(self) -> np.ndarray:
        return np.empty(0)

    def states_at(self, times_s) -> TrajectoryStates:
        dt = as_times(times_s) - self.ref_time_s
        w = np.asarray(self.angular_velocity_rad_s, np.float64)
        v = np.asarray(self.linear_velocity_mps, np.float64)
        R = matrix_from_rotvec(dt[:, None] * w).reshape(-1, 3, 3) @ self.world_from_body_ref.R
        n, z = len(dt), np.zeros((len(dt), 3))
        return TrajectoryStates(R, self.world_from_body_ref.t + dt[:, None] * v, np.tile(v, (n, 1)),
                                np.tile(w, (n, 1)), z, z.copy())


@dataclass(frozen=True, eq=False)
class Composed(TrajectoryMixin):
    """``world_from_child(t) = world_from_parent(t) @ parent_from_child(t)``: a frame under a
    moving parent (an object under its parent, a rig member on the rig's path, a camera on a
    trajectory with a fixed ``x_from_cam``: ``child`` a :class:`StaticTrajectory`)."""

    parent: Trajectory
    child: Trajectory

    @property
    def knot_times_s(self) -> np.ndarray:
        return np.union1d(as_times(self.parent.knot_times_s), as_times(self.child.knot_times_s))

    def states_at(self, times_s) -> TrajectoryStates:
        t = as_times(times_s)
        return self.parent.states_at(t).compose(self.child.states_at(t))

    def poses_at(self, times_s) -> tuple[np.ndarray, np.ndarray]:
        """The poses of :meth:`states_at` (:meth:`TrajectoryStates.compose`'s ``R``, ``t``, the
        same bits) without the derivatives."""
        t = as_times(times_s)
        (Rp, tp), (Rc, tc) = self.parent.poses_at(t), self.child.poses_at(t)
        return Rp @ Rc, tp + _rotate(Rp, tc)


@dataclass(frozen=True, eq=False)
class Shifted(TrajectoryMixin):
    """``trajectory`` read on a clock offset by ``offset_s``: at time tau it is where
    ``trajectory`` is at ``tau + offset_s`` (e.g. tau seconds from a frame's time)."""

    trajectory: Trajectory
    offset_s: float

    @property
    def knot_times_s(self) -> np.ndarray:
        return as_times(self.trajectory.knot_times_s) - self.offset_s

    def states_at(self, times_s) -> TrajectoryStates:
        return self.trajectory.states_at(as_times(times_s) + self.offset_s)

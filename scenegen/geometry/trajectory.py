"""Rigid frames moving over time: keyframe trajectories with analytic velocity and acceleration.

A trajectory maps a time ``t`` (seconds, on the sequence's clock) to ``world_from_frame(t)``
(:class:`~scenegen.geometry.pose.Rigid3`) and to its derivatives, all in the WORLD frame:

* ``linear_velocity_mps``: d/dt of the frame's origin, metres / second;
* ``angular_velocity_rad_s``: omega with dR/dt = [omega]x R, radians / second;
* ``linear_acceleration_mps2``, ``angular_acceleration_rad_s2``: their time derivatives.

Interpolations (:data:`INTERPOLATIONS`), both passing through every keyframe:

* ``linear``: translation lerp, rotation slerp per segment (``R_k exp(u log(R_k^T R_k+1))``,
  the shorter arc); velocity constant per segment (right-continuous at keyframes), acceleration 0.
* ``spline``: C2 in position and rotation. Translation: natural cubic spline through the
  keyframes (zero second derivative at both ends). Rotation: ``R(t) = R_0 exp([s(t)]x)``, with
  s a natural cubic spline through the rotation vectors ``s_k = log(R_0^T R_k)``, each taken on the
  branch (adding multiples of 2 pi along its axis) nearest to ``s_k-1``, so that a frame spinning
  past 180 degrees between keyframes keeps turning the same way. exp is smooth, so R is C2; its
  body angular velocity is ``J_r(s) ds/dt`` (J_r the right Jacobian of SO(3)) and its angular
  acceleration is differentiated from that in closed form.

Outside ``[t_0, t_last]`` a trajectory holds its end pose (velocities and accelerations 0); at
``t_0`` and ``t_last`` themselves it has the curve's one-sided derivatives (a frame on the first
keyframe moves off it within its exposure). A single keyframe is a fixed pose. Revolute and prismatic joints (:class:`JointTrajectory`) move a
frame about / along a fixed axis with an interpolated scalar (angle or offset).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from scenegen.geometry.clock import TrajectoryMixin, TrajectoryStates, as_times
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.rotation import matrix_from_rotvec, rotvec_from_matrix

INTERPOLATIONS = ("linear", "spline")
JOINT_TYPES = ("revolute", "prismatic")
_SERIES_BELOW_RAD = 0.05  # |s| below which the Jacobian's coefficients use their Taylor series


@dataclass(frozen=True, eq=False)
class MotionState:
    """A frame's pose and world-frame derivatives at one time (see the module docstring)."""

    world_from_frame: Rigid3
    linear_velocity_mps: np.ndarray  # (3,)
    angular_velocity_rad_s: np.ndarray  # (3,)
    linear_acceleration_mps2: np.ndarray  # (3,)
    angular_acceleration_rad_s2: np.ndarray  # (3,)

    @classmethod
    def still(cls, pose: Rigid3) -> MotionState:
        z = np.zeros(3)
        return cls(pose, z, z.copy(), z.copy(), z.copy())

    def compose(self, child: MotionState) -> MotionState:
        """The state of ``self.world_from_frame @ child.world_from_frame`` when ``child`` is
        expressed in this frame (its velocities in this frame's axes): the usual rigid-body
        composition, ``omega = omega_p + R_p omega_c``, ``v = v_p + omega_p x r + R_p v_c``
        with ``r = R_p t_c``, and their derivatives."""
        Rp = self.world_from_frame.R
        r = Rp @ child.world_from_frame.t
        wp, ap = self.angular_velocity_rad_s, self.angular_acceleration_rad_s2
        wc, vc = Rp @ child.angular_velocity_rad_s, Rp @ child.linear_velocity_mps
        ac, lc = Rp @ child.angular_acceleration_rad_s2, Rp @ child.linear_acceleration_mps2
        r_dot = np.cross(wp, r) + vc
        w = wp + wc
        v = self.linear_velocity_mps + np.cross(wp, r) + vc
        alpha = ap + ac + np.cross(wp, wc)
        acc = (self.linear_acceleration_mps2 + np.cross(ap, r) + np.cross(wp, r_dot)
               + lc + np.cross(wp, vc))
        return MotionState(self.world_from_frame @ child.world_from_frame, v, w, acc, alpha)


def _cubic_spline():
    # scipy.interpolate on use: 0.37 s to import, and every spec (the spec model imports this
    # module) would pay it, also without a spline (docs/performance.md, "Start-up")
    from scipy.interpolate import CubicSpline

    return CubicSpline


def _hat(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _jacobian_coefficients(theta: float) -> tuple[float, float, float, float]:
    """a = (1 - cos t) / t^2, b = (t - sin t) / t^3 and a'(t) / t, b'(t) / t (series when small)."""
    t2 = theta * theta
    if theta < _SERIES_BELOW_RAD:
        a = 0.5 - t2 / 24 + t2 * t2 / 720 - t2 ** 3 / 40320
        b = 1 / 6 - t2 / 120 + t2 * t2 / 5040 - t2 ** 3 / 362880
        da = -1 / 12 + t2 / 180 - t2 * t2 / 6720
        db = -1 / 60 + t2 / 1260 - t2 * t2 / 60480
        return a, b, da, db
    s, c = math.sin(theta), math.cos(theta)
    a = (1 - c) / t2
    b = (theta - s) / (t2 * theta)
    da = (theta * s - 2 * (1 - c)) / (t2 * t2)
    db = ((1 - c) * theta - 3 * (theta - s)) / (t2 * t2 * theta)
    return a, b, da, db


def _jacobian_coefficients_n(theta: np.ndarray) -> tuple[np.ndarray, ...]:
    """:func:`_jacobian_coefficients` of (N,) angles (the same series below the same angle)."""
    t2 = theta * theta
    small = theta < _SERIES_BELOW_RAD
    tb = np.where(small, 1.0, theta)  # no 0 / 0 in the branch np.where discards
    tb2 = tb * tb
    s, c = np.sin(tb), np.cos(tb)
    a = np.where(small, 0.5 - t2 / 24 + t2 * t2 / 720 - t2 ** 3 / 40320, (1 - c) / tb2)
    b = np.where(small, 1 / 6 - t2 / 120 + t2 * t2 / 5040 - t2 ** 3 / 362880, (tb - s) / (tb2 * tb))
    da = np.where(small, -1 / 12 + t2 / 180 - t2 * t2 / 6720, (tb * s - 2 * (1 - c)) / (tb2 * tb2))
    db = np.where(small, -1 / 60 + t2 / 1260 - t2 * t2 / 60480,
                  ((1 - c) * tb - 3 * (tb - s)) / (tb2 * tb2 * tb))
    return a, b, da, db


def exp_derivatives_n(s, s_dot, s_ddot) -> tuple[np.ndarray, np.ndarray]:
    """:func:`exp_derivatives` of (N, 3) rotation vectors and their derivatives: (N, 3) body
    angular velocities and accelerations."""
    s, sd, sdd = (np.asarray(x, np.float64).reshape(-1, 3) for x in (s, s_dot, s_ddot))
    a, b, da, db = (c[:, None] for c in _jacobian_coefficients_n(np.linalg.norm(s, axis=1)))
    rate = np.einsum("ni,ni->n", s, sd)[:, None]  # theta * d theta / dt
    Sv, SSv = np.cross(s, sd), np.cross(s, np.cross(s, sd))  # [s]x sd, [s]x^2 sd
    w = sd - a * Sv + b * SSv
    # J_dot sd = -da rate [s]x sd - a [sd]x sd + db rate [s]x^2 sd + b ([sd]x [s]x + [s]x [sd]x) sd
    j_dot_sd = -da * rate * Sv + db * rate * SSv + b * np.cross(sd, Sv)
    J_sdd = sdd - a * np.cross(s, sdd) + b * np.cross(s, np.cross(s, sdd))
    return w, j_dot_sd + J_sdd


def _held(times_s: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """((N,) bool before the first keyframe, (N,) bool after the last one) of times (N,)."""
    if len(T) == 1:
        return np.ones(len(times_s), bool), np.zeros(len(times_s), bool)
    return times_s < T[0], times_s > T[-1]


def _segments(times_s: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """((N,) segment k, (N,) fraction u in [0, 1]) of times inside [T_0, T_last] (right-continuous)."""
    k = np.clip(np.searchsorted(T, times_s, side="right") - 1, 0, len(T) - 2)
    return k, (times_s - T[k]) / (T[k + 1] - T[k])


def exp_derivatives(s, s_dot, s_ddot) -> tuple[np.ndarray, np.ndarray]:
    """Body angular velocity and acceleration of ``R(t) = R_0 exp([s(t)]x)``: (J_r(s) s',
    d/dt (J_r(s) s')), with J_r(s) = I - a [s]x + b [s]x^2."""
    s, sd, sdd = (np.asarray(x, np.float64) for x in (s, s_dot, s_ddot))
    theta = float(np.linalg.norm(s))
    a, b, da, db = _jacobian_coefficients(theta)
    S, Sd = _hat(s), _hat(sd)
    J = np.eye(3) - a * S + b * S @ S
    rate = float(s @ sd)  # theta * d theta / dt
    J_dot = -da * rate * S - a * Sd + db * rate * S @ S + b * (Sd @ S + S @ Sd)
    return J @ sd, J_dot @ sd + J @ sdd


def _unwrapped_rotvecs(rotations) -> np.ndarray:
    """(K, 3) s_k = log(R_0^T R_k), each on the branch nearest to s_k-1."""
    R0 = rotations[0]
    out = [np.zeros(3)]
    for R in rotations[1:]:
        r = rotvec_from_matrix(R0.T @ R)
        angle = float(np.linalg.norm(r))
        axis = r / angle if angle > 0 else None
        best = r
        if axis is not None:
            cands = [r + 2 * math.pi * n * axis for n in range(-3, 4)]
            best = min(cands, key=lambda c: float(np.linalg.norm(c - out[-1])))
        out.append(best)
    return np.array(out)


class KeyframeTrajectory(TrajectoryMixin):
    """A frame's keyframed trajectory (poses ``world_from_frame`` at strictly increasing times);
    a :class:`scenegen.geometry.clock.Trajectory` (:meth:`states_at`, vectorised; :meth:`state`,
    one time)."""

    def __init__(self, times_s, poses, interpolation: str = "spline"):
        self.times_s = np.asarray(times_s, np.float64).reshape(-1)
        self.poses = tuple(poses)
        if interpolation not in INTERPOLATIONS:
            raise ValueError(f"interpolation must be one of {INTERPOLATIONS}, got {interpolation!r}")
        if len(self.poses) != len(self.times_s) or len(self.poses) == 0:
            raise ValueError(f"need one pose per keyframe time, got {len(self.poses)} poses for "
                             f"{len(self.times_s)} times")
        if np.any(np.diff(self.times_s) <= 0) or not np.all(np.isfinite(self.times_s)):
            raise ValueError(f"keyframe times must be finite and strictly increasing, got "
                             f"{self.times_s.tolist()}")
        self.interpolation = interpolation
        self._R = np.stack([p.R for p in self.poses])
        self._t = np.stack([p.t for p in self.poses])
        if len(self.poses) >= 2 and interpolation == "spline":
            CubicSpline = _cubic_spline()
            self._pos = CubicSpline(self.times_s, self._t, bc_type="natural", axis=0)
            self._rot = CubicSpline(self.times_s, _unwrapped_rotvecs(self._R), bc_type="natural", axis=0)
        if len(self.poses) >= 2 and interpolation == "linear":  # each segment's body rotation step
            self._w = rotvec_from_matrix(np.swapaxes(self._R[:-1], 1, 2) @ self._R[1:]).reshape(-1, 3)

    def __len__(self) -> int:
        return len(self.poses)

    @property
    def knot_times_s(self) -> np.ndarray:
        """(K,) the keyframe times: where the interpolation's velocity may jump (every keyframe
        of a linear path; the held ends of a spline), so tables over time must have nodes there."""
        return self.times_s

    def state(self, t_s: float) -> MotionState:
        """Pose and world-frame derivatives at ``t_s`` (see the module docstring)."""
        t = float(t_s)
        T = self.times_s
        if len(T) == 1 or t < T[0] or t > T[-1]:
            return MotionState.still(self.poses[0] if len(T) == 1 or t < T[0] else self.poses[-1])
        if self.interpolation == "linear":
            k = min(int(np.searchsorted(T, t, side="right")) - 1, len(T) - 2)
            dt = T[k + 1] - T[k]
            u = (t - T[k]) / dt
            w_body = rotvec_from_matrix(self._R[k].T @ self._R[k + 1])
            R = self._R[k] @ matrix_from_rotvec(u * w_body)
            pos = self._t[k] + u * (self._t[k + 1] - self._t[k])
            z = np.zeros(3)
            return MotionState(Rigid3(R, pos), (self._t[k + 1] - self._t[k]) / dt,
                               self._R[k] @ w_body / dt, z, z.copy())
        s, sd, sdd = (self._rot(t, nu) for nu in (0, 1, 2))
        R = self._R[0] @ matrix_from_rotvec(s)
        w_body, a_body = exp_derivatives(s, sd, sdd)
        return MotionState(Rigid3(R, self._pos(t)), self._pos(t, 1), R @ w_body,
                           self._pos(t, 2), R @ a_body)

    def pose(self, t_s: float) -> Rigid3:
        return self.state(t_s).world_from_frame

    def poses_at(self, times_s) -> tuple[np.ndarray, np.ndarray]:
        """((N, 3, 3) R, (N, 3) t) world_from_frame at ``times_s`` (N,): :meth:`states_at`'s
        poses, the same bits, without the derivatives (a LiDAR sweep's movers at 2,048 times)."""
        t = as_times(times_s)
        T = self.times_s
        before, after = _held(t, T)
        inside = ~(before | after)
        R = np.where(after[:, None, None], self._R[-1], self._R[0])
        pos = np.where(after[:, None], self._t[-1], self._t[0])
        ti = t[inside]
        if not len(ti):
            return R, pos
        if self.interpolation == "linear":
            k, u = _segments(ti, T)
            R[inside] = self._R[k] @ matrix_from_rotvec(u[:, None] * self._w[k]).reshape(-1, 3, 3)
            pos[inside] = self._t[k] + u[:, None] * (self._t[k + 1] - self._t[k])
        else:
            R[inside] = self._R[0] @ matrix_from_rotvec(self._rot(ti, 0)).reshape(-1, 3, 3)
            pos[inside] = self._pos(ti)
        return R, pos

    def states_at(self, times_s) -> TrajectoryStates:
        """Poses and world-frame derivatives at ``times_s`` (N,) (module docstring; the same
        values as :meth:`state` at each time, to rounding)."""
        t = as_times(times_s)
        T = self.times_s
        before, after = _held(t, T)
        inside = ~(before | after)
        R = np.where(after[:, None, None], self._R[-1], self._R[0])
        out = TrajectoryStates.still(R, np.where(after[:, None], self._t[-1], self._t[0]))
        ti = t[inside]
        if not len(ti):
            return out
        if self.interpolation == "linear":
            k, u = _segments(ti, T)
            dt = (T[k + 1] - T[k])[:, None]
            Rk = self._R[k]
            out.R[inside] = Rk @ matrix_from_rotvec(u[:, None] * self._w[k]).reshape(-1, 3, 3)
            out.t[inside] = self._t[k] + u[:, None] * (self._t[k + 1] - self._t[k])
            out.velocity_mps[inside] = (self._t[k + 1] - self._t[k]) / dt
            out.angular_velocity_rad_s[inside] = np.einsum("nij,nj->ni", Rk, self._w[k]) / dt
            return out
        s, sd, sdd = (self._rot(ti, nu) for nu in (0, 1, 2))
        Ri = self._R[0] @ matrix_from_rotvec(s).reshape(-1, 3, 3)
        w_body, a_body = exp_derivatives_n(s, sd, sdd)
        out.R[inside], out.t[inside] = Ri, self._pos(ti)
        out.velocity_mps[inside], out.acceleration_mps2[inside] = self._pos(ti, 1), self._pos(ti, 2)
        out.angular_velocity_rad_s[inside] = np.einsum("nij,nj->ni", Ri, w_body)
        out.angular_acceleration_rad_s2[inside] = np.einsum("nij,nj->ni", Ri, a_body)
        return out


class JointTrajectory(TrajectoryMixin):
    """A joint: ``parent_from_frame(t) = J(q(t)) @ rest``. Revolute: J turns by q (radians) about
    ``axis`` through ``origin`` (parent frame); prismatic: J shifts by q (metres) along ``axis``.
    q(t) is interpolated through keyframe values, linearly or by a natural cubic spline."""

    def __init__(self, joint_type: str, axis, origin, times_s, values, interpolation: str,
                 rest: Rigid3):
        if joint_type not in JOINT_TYPES:
            raise ValueError(f"joint type must be one of {JOINT_TYPES}, got {joint_type!r}")
        a = np.asarray(axis, np.float64)
        if a.shape != (3,) or np.linalg.norm(a) == 0:
            raise ValueError(f"joint axis must be a non-zero 3-vector, got {axis!r}")
        self.joint_type, self.axis, self.origin = joint_type, a / np.linalg.norm(a), np.asarray(origin, np.float64)
        self.times_s = np.asarray(times_s, np.float64)
        self.values = np.asarray(values, np.float64)
        if np.any(np.diff(self.times_s) <= 0) or len(self.times_s) != len(self.values) or not len(self.values):
            raise ValueError("joint keyframes need strictly increasing times, one value each")
        self.interpolation, self.rest = interpolation, rest
        self._q = (_cubic_spline()(self.times_s, self.values, bc_type="natural")
                   if len(self.values) >= 2 and interpolation == "spline" else None)

    @property
    def knot_times_s(self) -> np.ndarray:
        """(K,) the keyframe times (see :attr:`KeyframeTrajectory.knot_times_s`)."""
        return self.times_s

    def _q_derivatives(self, t: float) -> tuple[float, float, float]:
        T, q = self.times_s, self.values
        if len(T) == 1 or t < T[0] or t > T[-1]:
            return (float(q[0]) if len(T) == 1 or t < T[0] else float(q[-1])), 0.0, 0.0
        if self._q is not None:
            return float(self._q(t)), float(self._q(t, 1)), float(self._q(t, 2))
        k = min(int(np.searchsorted(T, t, side="right")) - 1, len(T) - 2)
        rate = (q[k + 1] - q[k]) / (T[k + 1] - T[k])
        return float(q[k] + rate * (t - T[k])), float(rate), 0.0

    def _q_derivatives_n(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        T, q = self.times_s, self.values
        before, after = _held(t, T)
        inside = ~(before | after)
        out = [np.where(after, q[-1], q[0]), np.zeros(len(t)), np.zeros(len(t))]
        ti = t[inside]
        if self._q is not None:
            for nu in range(3):
                out[nu][inside] = self._q(ti, nu)
        elif len(ti):
            k, _ = _segments(ti, T)
            rate = (q[k + 1] - q[k]) / (T[k + 1] - T[k])
            out[0][inside], out[1][inside] = q[k] + rate * (ti - T[k]), rate
        return out[0], out[1], out[2]

    def states_at(self, times_s) -> TrajectoryStates:
        """parent_from_frame and its parent-frame derivatives at ``times_s`` (N,) (vectorised
        :meth:`state`)."""
        q, qd, qdd = (x[:, None] for x in self._q_derivatives_n(as_times(times_s)))
        a, o = self.axis, self.origin
        n, z = len(q), np.zeros((len(q), 3))
        if self.joint_type == "prismatic":
            J = TrajectoryStates(np.broadcast_to(np.eye(3), (n, 3, 3)).copy(), q * a, qd * a, z, qdd * a, z.copy())
        else:
            R = matrix_from_rotvec(q * a).reshape(-1, 3, 3)
            w, alpha = qd * a, qdd * a
            Ro = R @ o
            J = TrajectoryStates(R, o - Ro, -np.cross(w, Ro), w,
                                 -np.cross(alpha, Ro) - np.cross(w, np.cross(w, Ro)), alpha)
        rest = self.rest
        return J.compose(TrajectoryStates.still(np.broadcast_to(rest.R, (n, 3, 3)), np.broadcast_to(rest.t, (n, 3))))

    def state(self, t_s: float) -> MotionState:
        q, qd, qdd = self._q_derivatives(float(t_s))
        a, o, z = self.axis, self.origin, np.zeros(3)
        if self.joint_type == "prismatic":
            J = MotionState(Rigid3(np.eye(3), q * a), qd * a, z, qdd * a, z.copy())
        else:
            R = matrix_from_rotvec(q * a)
            w, alpha = qd * a, qdd * a
            # the joint frame's origin o - R o moves with d/dt = w x (R o) ... = -(w x R o)
            Ro = R @ o
            J = MotionState(Rigid3(R, o - Ro), -np.cross(w, Ro), w,
                            -np.cross(alpha, Ro) - np.cross(w, np.cross(w, Ro)), alpha)
        return J.compose(MotionState.still(self.rest))

    def pose(self, t_s: float) -> Rigid3:
        return self.state(t_s).world_from_frame

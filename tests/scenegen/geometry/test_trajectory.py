"""Trajectories: keyframes interpolated exactly, C2 continuity of the spline, and analytic
velocities and accelerations against central finite differences of the poses (an independent
derivation: only poses are differenced); slerp against scipy's Slerp."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from scenegen.geometry.pose import Rigid3
from scenegen.geometry.trajectory import JointTrajectory, KeyframeTrajectory, MotionState

TIMES = [0.0, 0.4, 0.9, 1.3, 2.0]


def _poses(seed=0, spin=False):
    rng = np.random.default_rng(seed)
    out = []
    for k in range(len(TIMES)):
        rv = rng.normal(size=3) * 0.8 if not spin else np.array([0.0, 0.0, 2.5 * k])  # 143 deg a step
        out.append(Rigid3(Rotation.from_rotvec(rv).as_matrix(), rng.normal(size=3)))
    return out


def _fd(traj, t, h=1e-5):
    """(v, omega) by central differences of the pose, world frame."""
    a, b = traj.pose(t - h), traj.pose(t + h)
    v = (b.t - a.t) / (2 * h)
    w = Rotation.from_matrix(b.R @ a.R.T).as_rotvec() / (2 * h)
    return v, w


@pytest.mark.parametrize("interp", ["linear", "spline"])
def test_keyframes_are_interpolated(interp):
    poses = _poses()
    tr = KeyframeTrajectory(TIMES, poses, interp)
    for t, p in zip(TIMES, poses):
        q = tr.pose(t)
        assert np.abs(q.R - p.R).max() < 1e-12 and np.abs(q.t - p.t).max() < 1e-12


@pytest.mark.parametrize("spin", [False, True])
def test_spline_velocity_and_acceleration_match_finite_differences(spin):
    tr = KeyframeTrajectory(TIMES, _poses(1, spin), "spline")
    for t in np.linspace(0.05, 1.95, 23):
        st = tr.state(t)
        v, w = _fd(tr, t)
        assert np.abs(st.linear_velocity_mps - v).max() < 1e-6
        assert np.abs(st.angular_velocity_rad_s - w).max() < 1e-6
        h = 1e-5
        a_fd = (tr.state(t + h).angular_velocity_rad_s - tr.state(t - h).angular_velocity_rad_s) / (2 * h)
        l_fd = (tr.state(t + h).linear_velocity_mps - tr.state(t - h).linear_velocity_mps) / (2 * h)
        assert np.abs(st.angular_acceleration_rad_s2 - a_fd).max() < 1e-5
        assert np.abs(st.linear_acceleration_mps2 - l_fd).max() < 1e-5


def test_spin_keeps_turning_the_same_way():
    tr = KeyframeTrajectory(TIMES, _poses(spin=True), "spline")
    for t in np.linspace(0.01, 1.99, 50):
        assert tr.state(t).angular_velocity_rad_s[2] > 0


def test_spline_is_c2_at_the_keyframes():
    tr = KeyframeTrajectory(TIMES, _poses(2), "spline")
    for t in TIMES[1:-1]:
        lo, hi = tr.state(t - 1e-9), tr.state(t + 1e-9)
        for name in ("linear_velocity_mps", "angular_velocity_rad_s", "linear_acceleration_mps2",
                     "angular_acceleration_rad_s2"):
            assert np.abs(getattr(lo, name) - getattr(hi, name)).max() < 1e-6, name


def test_linear_is_slerp_and_lerp():
    poses = _poses(3)
    tr = KeyframeTrajectory(TIMES, poses, "linear")
    slerp = Slerp(TIMES, Rotation.from_matrix(np.stack([p.R for p in poses])))
    for t in np.linspace(0.0, 2.0, 41):
        st = tr.state(t)
        assert np.abs(st.world_from_frame.R - slerp([t]).as_matrix()[0]).max() < 1e-12
        T = np.stack([p.t for p in poses])
        assert np.abs(st.world_from_frame.t - [np.interp(t, TIMES, T[:, i]) for i in range(3)]).max() < 1e-12
        if 0 < t < 2 and min(abs(t - k) for k in TIMES) > 1e-3:
            v, w = _fd(tr, t)
            assert np.abs(st.linear_velocity_mps - v).max() < 1e-7
            assert np.abs(st.angular_velocity_rad_s - w).max() < 1e-6


def test_ends_hold_and_single_keyframe_is_fixed():
    poses = _poses(4)
    tr = KeyframeTrajectory(TIMES, poses, "spline")
    assert tr.pose(-1.0).allclose(poses[0]) and tr.pose(5.0).allclose(poses[-1])
    assert not tr.state(5.0).linear_velocity_mps.any()
    one = KeyframeTrajectory([0.3], poses[:1], "spline")
    assert one.pose(7.0).allclose(poses[0])


def test_bad_keyframes_are_refused():
    with pytest.raises(ValueError, match="strictly increasing"):
        KeyframeTrajectory([0.0, 0.0], _poses()[:2])
    with pytest.raises(ValueError, match="interpolation"):
        KeyframeTrajectory([0.0], _poses()[:1], "cubic")


@pytest.mark.parametrize("jt", ["revolute", "prismatic"])
@pytest.mark.parametrize("interp", ["linear", "spline"])
def test_joint_moves_about_its_axis_with_analytic_derivatives(jt, interp):
    rest = Rigid3(Rotation.from_rotvec([0.1, 0.2, 0.3]).as_matrix(), [0.3, -0.2, 0.1])
    origin, axis = np.array([0.1, 0.0, 0.2]), np.array([0.0, 1.0, 1.0])
    j = JointTrajectory(jt, axis, origin, TIMES, [0.0, 0.5, 1.4, 0.9, 0.2], interp, rest)
    for t in np.linspace(0.05, 1.95, 17):
        st = j.state(t)
        if jt == "revolute":  # the point on the axis through origin does not move
            on_axis = origin + 0.37 * axis
            P = st.world_from_frame.apply(rest.inverse().apply(on_axis))
            assert np.abs(P - on_axis).max() < 1e-12
        if min(abs(t - k) for k in TIMES) > 1e-3:
            v, w = _fd(j, t)
            assert np.abs(st.linear_velocity_mps - v).max() < 1e-6
            assert np.abs(st.angular_velocity_rad_s - w).max() < 1e-6


def test_compose_matches_finite_differences():
    parent = KeyframeTrajectory(TIMES, _poses(5), "spline")
    child = KeyframeTrajectory(TIMES, _poses(6), "spline")

    class Chain:
        def state(self, t):
            return parent.state(t).compose(child.state(t))

        def pose(self, t):
            return self.state(t).world_from_frame

    ch = Chain()
    for t in (0.2, 0.7, 1.6):
        st, h = ch.state(t), 1e-5
        v, w = _fd(ch, t)
        assert np.abs(st.linear_velocity_mps - v).max() < 1e-6
        assert np.abs(st.angular_velocity_rad_s - w).max() < 1e-6
        la = (ch.state(t + h).linear_velocity_mps - ch.state(t - h).linear_velocity_mps) / (2 * h)
        aa = (ch.state(t + h).angular_velocity_rad_s - ch.state(t - h).angular_velocity_rad_s) / (2 * h)
        assert np.abs(st.linear_acceleration_mps2 - la).max() < 1e-5
        assert np.abs(st.angular_acceleration_rad_s2 - aa).max() < 1e-5
    assert isinstance(MotionState.still(Rigid3.identity()), MotionState)


@pytest.mark.parametrize("interp", ["linear", "spline"])
def test_the_end_keyframes_have_the_one_sided_derivatives(interp):
    tr = KeyframeTrajectory(TIMES, _poses(7), interp)
    h = 1e-6
    v0 = (tr.pose(TIMES[0] + h).t - tr.pose(TIMES[0]).t) / h
    v1 = (tr.pose(TIMES[-1]).t - tr.pose(TIMES[-1] - h).t) / h
    assert np.abs(tr.state(TIMES[0]).linear_velocity_mps - v0).max() < 1e-4
    assert np.abs(tr.state(TIMES[-1]).linear_velocity_mps - v1).max() < 1e-4
    assert np.linalg.norm(v0) > 0.1
    assert not tr.state(TIMES[-1] + 1e-9).linear_velocity_mps.any()

"""The one trajectory protocol (scenegen.geometry.clock): every motion model evaluated at arrays of
times, its velocities and accelerations against central finite differences of its own poses and
against independent implementations (scipy's CubicSpline and Slerp, quaternion calculus for the
spline's angular velocity, optics.Motion's per-time deltas, MotionState.compose per time).
scipy's RotationSpline is another curve (cubic in each segment's own rotation vector, other end
conditions: 0.23 apart in R's entries on a single-axis test), so it cannot serve as a reference."""
import numpy as np
import pytest
from scipy.interpolate import CubicSpline
from scipy.spatial.transform import Rotation, Slerp

from scenegen.geometry.clock import Composed, ConstantTwist, Shifted, StaticTrajectory, Trajectory
from scenegen.geometry.optics import Motion, PathMotion, cam_from_world_at, world_from_object_at
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.trajectory import JointTrajectory, KeyframeTrajectory

TIMES = np.array([0.0, 0.4, 0.9, 1.3, 2.0])
RNG = np.random.default_rng(26)
QUERY = np.concatenate([RNG.uniform(-0.3, 2.3, 300), TIMES])  # inside, outside and on keyframes
INSIDE = np.linspace(0.013, 1.987, 61)


def _poses(seed=0, scale=0.8):
    rng = np.random.default_rng(seed)
    return [Rigid3(Rotation.from_rotvec(rng.normal(size=3) * scale).as_matrix(), rng.normal(size=3))
            for _ in TIMES]


def _models():
    poses = _poses(1)
    rest = _poses(2)[0]
    return {
        "linear": KeyframeTrajectory(TIMES, poses, "linear"),
        "spline": KeyframeTrajectory(TIMES, poses, "spline"),
        "revolute": JointTrajectory("revolute", (0.2, 1.0, 0.3), (0.1, -0.2, 0.4), TIMES,
                                    [0.0, 0.7, -0.4, 1.1, 0.2], "spline", rest),
        "prismatic": JointTrajectory("prismatic", (1.0, 0.0, 0.5), (0, 0, 0), TIMES,
                                     [0.0, 0.3, 0.1, -0.2, 0.4], "linear", rest),
        "static": StaticTrajectory(poses[2]),
        "camera_motion": ConstantTwist.from_body_velocities(poses[3], 0.5, (0.4, -1.0, 2.0), (0.3, 1.2, -0.7)),
        "composed": Composed(KeyframeTrajectory(TIMES, poses, "spline"),
                             JointTrajectory("revolute", (0, 0, 1), (0.2, 0, 0), TIMES,
                                             [0.0, 0.5, 1.0, 0.2, -0.3], "spline", rest)),
    }


def _world_rate(R_a, R_b, h):
    """(N, 3) world angular velocity from poses h apart on either side: log(R_b R_a^T) / 2h."""
    return Rotation.from_matrix(R_b @ np.swapaxes(R_a, 1, 2)).as_rotvec() / (2 * h)


@pytest.mark.parametrize("name", list(_models()))
def test_every_model_is_a_vectorised_trajectory(name):
    tr = _models()[name]
    assert isinstance(tr, Trajectory)
    R, t = tr.poses_at(QUERY)
    assert R.shape == (len(QUERY), 3, 3) and t.shape == (len(QUERY), 3)
    assert np.abs(R @ np.swapaxes(R, 1, 2) - np.eye(3)).max() < 1e-13
    for f in (tr.velocity_at, tr.angular_velocity_at, tr.acceleration_at, tr.body_angular_velocity_at):
        assert f(QUERY).shape == (len(QUERY), 3)
    one = tr.states_at(QUERY[7])  # a scalar time is one time
    assert len(one) == 1 and np.array_equal(one.R[0], R[7])


@pytest.mark.parametrize("name", list(_models()))
def test_derivatives_match_finite_differences_of_the_poses(name):
    tr = _models()[name]
    h = 1e-6
    s = tr.states_at(INSIDE)
    (Ra, ta), (Rb, tb) = tr.poses_at(INSIDE - h), tr.poses_at(INSIDE + h)
    assert np.abs(s.velocity_mps - (tb - ta) / (2 * h)).max() < 2e-7
    assert np.abs(s.angular_velocity_rad_s - _world_rate(Ra, Rb, h)).max() < 2e-7
    h2 = 1e-4  # second differences of the poses themselves
    t0, t1, t2 = (tr.poses_at(INSIDE + d)[1] for d in (-h2, 0.0, h2))
    assert np.abs(s.acceleration_mps2 - (t2 - 2 * t1 + t0) / h2 ** 2).max() < 2e-5
    wa, wb = tr.angular_velocity_at(INSIDE - h), tr.angular_velocity_at(INSIDE + h)
    assert np.abs(s.angular_acceleration_rad_s2 - (wb - wa) / (2 * h)).max() < 2e-6


@pytest.mark.parametrize("name", ["linear", "spline", "revolute", "prismatic"])
def test_vectorised_states_equal_the_per_time_states(name):
    tr = _models()[name]
    s = tr.states_at(QUERY)
    for k, t in enumerate(QUERY):
        m = tr.state(float(t))
        for got, want in ((s.R[k], m.world_from_frame.R), (s.t[k], m.world_from_frame.t),
                          (s.velocity_mps[k], m.linear_velocity_mps),
                          (s.angular_velocity_rad_s[k], m.angular_velocity_rad_s),
                          (s.acceleration_mps2[k], m.linear_acceleration_mps2),
                          (s.angular_acceleration_rad_s2[k], m.angular_acceleration_rad_s2)):
            assert np.abs(got - want).max() < 1e-12, (t, got, want)


def test_spline_against_scipy_cubic_spline_and_quaternion_calculus():
    poses = _poses(3, scale=0.6)
    tr = KeyframeTrajectory(TIMES, poses, "spline")
    s = tr.states_at(INSIDE)
    pos = CubicSpline(TIMES, np.stack([p.t for p in poses]), bc_type="natural")
    for nu, got in ((0, s.t), (1, s.velocity_mps), (2, s.acceleration_mps2)):
        assert np.abs(got - pos(INSIDE, nu)).max() < 1e-12
    # rotation: R0 exp([r(t)]x), r a natural spline of the rotation vectors (unwrapped: the
    # keyframes here turn < pi from R0); body rate from the quaternion q = (cos(h/2), sin(h/2) n):
    # omega_body = 2 vec(q* dq/dt), dq/dt by the chain rule on theta = |r| (no SO(3) Jacobian)
    R0 = poses[0].R
    rv = np.stack([Rotation.from_matrix(R0.T @ p.R).as_rotvec() for p in poses])
    assert np.linalg.norm(rv, axis=1).max() < np.pi - 0.3
    r_s = CubicSpline(TIMES, rv, bc_type="natural")
    r, rd = r_s(INSIDE), r_s(INSIDE, 1)
    th = np.linalg.norm(r, axis=1)
    n = r / th[:, None]
    thd = np.einsum("ni,ni->n", n, rd)
    nd = (rd - n * thd[:, None]) / th[:, None]
    w_q, x_q = np.cos(th / 2), np.sin(th / 2)[:, None] * n
    wd = -0.5 * np.sin(th / 2) * thd
    xd = 0.5 * np.cos(th / 2)[:, None] * thd[:, None] * n + np.sin(th / 2)[:, None] * nd
    # 2 vec(conj(q) * qd) = 2 (w xd - wd x - x cross xd)
    w_body = 2 * (w_q[:, None] * xd - wd[:, None] * x_q - np.cross(x_q, xd))
    R_ref = R0 @ Rotation.from_rotvec(r).as_matrix()
    assert np.abs(s.R - R_ref).max() < 1e-13
    assert np.abs(s.body_angular_velocity_rad_s() - w_body).max() < 1e-12


def test_linear_against_scipy_slerp():
    poses = _poses(4)
    tr = KeyframeTrajectory(TIMES, poses, "linear")
    ts = np.linspace(0.0, 2.0, 101)
    s = tr.states_at(ts)
    slerp = Slerp(TIMES, Rotation.from_matrix(np.stack([p.R for p in poses])))
    assert np.abs(s.R - slerp(ts).as_matrix()).max() < 1e-13
    P = np.stack([p.t for p in poses])
    assert np.abs(s.t - np.stack([np.interp(ts, TIMES, P[:, i]) for i in range(3)], 1)).max() < 1e-13
    # per segment: world rate = log(R_k+1 R_k^T) / dt, velocity = chord / dt
    k = np.clip(np.searchsorted(TIMES, ts, side="right") - 1, 0, len(TIMES) - 2)
    rot = Rotation.from_matrix(np.stack([p.R for p in poses]))
    w = (rot[k + 1] * rot[k].inv()).as_rotvec() / (TIMES[k + 1] - TIMES[k])[:, None]
    assert np.abs(s.angular_velocity_rad_s - w).max() < 1e-12
    assert not s.acceleration_mps2.any()


def test_constant_twist_is_optics_motion():
    """A camera's body-frame Motion and an object's world-frame one, through the protocol, are
    the poses optics gives per time (cam_from_world_at, world_from_object_at)."""
    m = Motion(linear_velocity_mps=(0.4, -1.0, 2.0), angular_velocity_deg_s=(20.0, 60.0, -35.0))
    cam_from_world = _poses(5)[0]
    wfc = cam_from_world.inverse()
    cam = ConstantTwist.from_body_velocities(wfc, 3.0, m.linear_velocity_mps, m.angular_velocity_rad_s)
    obj = ConstantTwist(wfc, 3.0, np.asarray(m.linear_velocity_mps), m.angular_velocity_rad_s)
    taus = np.linspace(-0.02, 0.02, 41)
    R, t = cam.poses_at(3.0 + taus)
    Ro, to = obj.poses_at(3.0 + taus)
    for k, tau in enumerate(taus):
        want = cam_from_world_at(cam_from_world, m, float(tau)).inverse()
        assert np.abs(R[k] - want.R).max() < 1e-14 and np.abs(t[k] - want.t).max() < 1e-14
        wo = world_from_object_at(wfc, m, float(tau))
        assert np.abs(Ro[k] - wo.R).max() < 1e-14 and np.abs(to[k] - wo.t).max() < 1e-14
    assert np.abs(cam.body_angular_velocity_at(taus + 3.0) - m.angular_velocity_rad_s).max() < 1e-14


def test_path_motion_and_composition():
    """A camera on a path (optics.PathMotion) is Composed(path, still x_from_cam) read from the
    frame time (Shifted); Composed's derivatives are MotionState.compose's per time."""
    tr = _models()["composed"]
    s = tr.states_at(QUERY)
    for k, t in enumerate(QUERY):
        m = tr.parent.state(float(t)).compose(tr.child.state(float(t)))
        assert np.abs(s.acceleration_mps2[k] - m.linear_acceleration_mps2).max() < 1e-12
        assert np.abs(s.angular_acceleration_rad_s2[k] - m.angular_acceleration_rad_s2).max() < 1e-12
    path = KeyframeTrajectory(TIMES, _poses(6), "spline")
    x_from_cam = _poses(7)[0]
    pm = PathMotion(trajectory=path, time_s=0.7, x_from_cam=x_from_cam)
    cam = pm.world_from_cam_trajectory()
    assert isinstance(cam, Shifted) and np.allclose(cam.knot_times_s, TIMES - 0.7)
    taus = np.linspace(-0.01, 0.01, 9)
    R, t = cam.poses_at(taus)
    for k, tau in enumerate(taus):
        want = pm.world_from_cam(float(tau))
        assert np.abs(R[k] - want.R).max() < 1e-14 and np.abs(t[k] - want.t).max() < 1e-14


@pytest.mark.parametrize("interpolation", ["linear", "spline"])
def test_poses_at_are_the_states_poses_bit_for_bit(interpolation):
    """poses_at skips the derivatives (a LiDAR sweep's movers) but not a bit of R and t, also
    composed under a parent and held before and after the keyframes."""
    traj = KeyframeTrajectory(TIMES, _poses(3), interpolation)
    parent = KeyframeTrajectory(TIMES, _poses(4), "spline" if interpolation == "linear" else "linear")
    for tr in (traj, Composed(parent, traj), Composed(traj, StaticTrajectory(_poses(5)[0]))):
        R, t = tr.poses_at(QUERY)
        s = tr.states_at(QUERY)
        assert R.tobytes() == s.R.tobytes() and t.tobytes() == s.t.tobytes()

"""Rolling shutter geometry (scenegen.geometry.rolling, scenegen.crossview.frames) against
independent computations, without rendering: per-row pose tables against the motions they
tabulate, and the row that images a point against a bisection on the exact poses, for a moving
camera and a point on a moving object, seen from a global-shutter frame into a rolling one."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from scenegen.crossview.frames import FrameGeometry, image, to_object, to_world
from scenegen.dataset.crossview import OUT_OF_FRAME, VISIBLE
from scenegen.geometry.camera import Camera
from scenegen.geometry.optics import Motion, Shutter, cam_from_world_at
from scenegen.geometry.pose import Rigid3, look_at
from scenegen.geometry.rolling import RollingRows, RowPoses, rolling_project

W, H, F = 64, 48, 60.0
SHUTTER = Shutter(rolling_readout_s=0.04)
CAMERA = Camera.from_opencv(np.array([[F, 0, (W - 1) / 2], [0, F, (H - 1) / 2], [0, 0, 1]]), None, (W, H))
POSE = look_at([0.3, -2.0, 1.0], [0, 0, 0.2]).inverse()  # cam_from_world
CAM_MOTION = Motion(linear_velocity_mps=(4.0, -1.0, 1.0), angular_velocity_deg_s=(10.0, -25.0, 5.0))
OBJ_V, OBJ_W = np.array([2.0, 0.5, 0.0]), np.radians([0.0, 0.0, 90.0])  # world velocity, rad/s
OBJ_POSE = Rigid3(np.eye(3), np.array([0.1, 0.2, 0.3]))


def obj_world_from(tau):
    """The moving object's pose tau seconds from the frame time (constant world velocities)."""
    return Rigid3(Rotation.from_rotvec(OBJ_W * tau).as_matrix() @ OBJ_POSE.R, OBJ_POSE.t + OBJ_V * tau)


def tau_of(v):
    return SHUTTER.row_time_s(np.asarray(v, float), H)


def rolling_frame(visible_fn=None) -> FrameGeometry:
    nodes = np.arange(-1, H + 1, dtype=float)
    cams = [cam_from_world_at(POSE, CAM_MOTION, float(t)).inverse() for t in tau_of(nodes)]
    objs = [obj_world_from(float(t)) for t in tau_of(nodes)]
    rows = RollingRows(RowPoses(np.stack([c.R for c in cams]), np.stack([c.t for c in cams])),
                       {7: RowPoses(np.stack([o.R for o in objs]), np.stack([o.t for o in objs]))},
                       {7: np.ones(len(nodes), bool)})
    return FrameGeometry({7: (OBJ_POSE, True)}, CAMERA, POSE, visible_fn or (lambda c, p, r: np.ones(len(p), bool)),
                         rows)


def test_row_table_is_exact_at_nodes_and_for_constant_velocities_between_them():
    fr = rolling_frame()
    v = np.array([-0.5, 0.0, 3.0, 10.37, 23.5, 47.0, 47.5])
    R, C = fr.rolling.cam.at(v)
    for k, vk in enumerate(v):  # constant body velocities: the geodesic between rows is the motion itself
        want = cam_from_world_at(POSE, CAM_MOTION, float(tau_of(vk))).inverse()
        assert np.abs(R[k] - want.R).max() < 1e-12 and np.abs(C[k] - want.t).max() < 1e-12
    R, t, present = fr.rolling.object_pose(7, v)
    for k, vk in enumerate(v):
        want = obj_world_from(float(tau_of(vk)))
        assert np.abs(R[k] - want.R).max() < 1e-12 and np.abs(t[k] - want.t).max() < 1e-12 and present[k]


def _bisect_row(world_at_tau):
    """The row solving v = row(project(pose(tau(v)), P(tau(v)))), by bisection on exact poses."""
    def g(v):
        tau = float(tau_of(v))
        Pc = cam_from_world_at(POSE, CAM_MOTION, tau).apply(world_at_tau(tau)[None])[0]
        return F * Pc[1] / Pc[2] + (H - 1) / 2 - v
    a, b = -0.5, H - 0.5
    assert g(a) > 0 > g(b), "the test point must be imaged inside the frame"
    for _ in range(80):
        m = 0.5 * (a + b)
        a, b = (m, b) if g(m) > 0 else (a, m)
    return 0.5 * (a + b)


@pytest.mark.parametrize("on_object", [False, True])
def test_rolling_projection_finds_the_imaging_row(on_object):
    rng = np.random.default_rng(4)
    P = np.column_stack([rng.uniform(-0.4, 0.4, 20), rng.uniform(-0.3, 0.5, 20), rng.uniform(0.0, 0.5, 20)])
    fr = rolling_frame()
    if on_object:  # object coordinates, carried by the object to each row's time
        X = OBJ_POSE.inverse().apply(P)
        ids = np.full(len(P), 7)
        rp = rolling_project(CAMERA, fr.rolling.cam, lambda k, r: to_world(X[k], ids[k], fr, r, {7})[0], len(P))
        world_at = [lambda tau, x=x: obj_world_from(tau).apply(x[None])[0] for x in X]
    else:
        rp = rolling_project(CAMERA, fr.rolling.cam, lambda k, r: P[k], len(P))
        world_at = [lambda tau, p=p: p for p in P]
    for k in range(len(P)):
        v = _bisect_row(world_at[k])
        tau = float(tau_of(v))
        uv = CAMERA.project(cam_from_world_at(POSE, CAM_MOTION, tau).apply(world_at[k](tau)[None]))[0]
        assert abs(rp.row[k] - v) < 1e-7 and np.abs(rp.uv[k] - uv).max() < 1e-7, k
        assert np.abs(rp.points_world[k] - world_at[k](tau)).max() < 1e-9
    # the middle row's pose (and the object at the frame time) alone would place them elsewhere
    gs = CAMERA.project(POSE.apply(P))
    assert np.abs(gs - rp.uv).max() > 0.2  # px; the agreement above is 1e-7 px


def test_from_a_global_shutter_frame_into_a_rolling_one():
    """Points of a global-shutter frame (the object at its frame time) imaged by the rolling frame,
    with the visibility function called with each point's row centre and row."""
    calls = []

    def visible(centres, points, rows):
        calls.append((centres.copy(), points.copy(), rows.copy()))
        return np.ones(len(points), bool)

    b = rolling_frame(visible)
    a = FrameGeometry({7: (OBJ_POSE, True)}, CAMERA, POSE, lambda c, p: np.ones(len(p), bool))
    P = OBJ_POSE.apply(np.array([[0.0, 0.0, 0.1], [0.05, -0.05, 0.0], [50.0, 0.0, 0.0]]))
    X = to_object(P, np.full(3, 7), a, None, {7})
    assert np.abs(X - OBJ_POSE.inverse().apply(P)).max() < 1e-15
    im = image(X, np.full(3, 7), b, {7})
    state = im.correspondence.state
    assert list(state) == [VISIBLE, VISIBLE, OUT_OF_FRAME]
    centres, points, rows = calls[0]
    for k in range(2):
        want_c = cam_from_world_at(POSE, CAM_MOTION, float(tau_of(rows[k]))).inverse().t
        assert np.abs(centres[k] - want_c).max() < 1e-12
        assert np.abs(points[k] - obj_world_from(float(tau_of(rows[k]))).apply(X[k][None])[0]).max() < 1e-12


@pytest.mark.parametrize("with_knots", [True, False])
def test_row_table_across_a_keyframe_kink_equals_the_exact_path(with_knots):
    """A camera at 3.7 m/s on a two-keyframe linear path, the frame at its first keyframe: rows
    above the middle hold the first pose (the clamp), rows below move. With the keyframe as a knot
    the table equals the path evaluated directly at every row's time; without it the interval
    that straddles the kink cuts the corner (the issue-26 defect: the test can fail)."""
    from scenegen.geometry.optics import PathMotion
    from scenegen.geometry.rolling import frame_node_rows
    from scenegen.geometry.trajectory import KeyframeTrajectory
    start, end = look_at([0.55, -1.9, 1.2], [0, 0, 0.1]), look_at([-0.55, -1.7, 1.3], [0, 0.05, 0.1])
    path = KeyframeTrajectory([0.0, 0.3], [start, end], interpolation="linear")
    motion = PathMotion(trajectory=path, time_s=0.0)
    shutter, h = Shutter(rolling_readout_s=0.03), 60  # the kink at the middle row 29.5, between nodes
    nodes = frame_node_rows(shutter, h, motion.knot_taus_s if with_knots else ())
    assert (29.5 in nodes) == with_knots and len(nodes) == h + 2 + with_knots
    poses = [motion.world_from_cam(float(t)) for t in shutter.row_time_s(nodes, h)]
    table = RowPoses(np.stack([p.R for p in poses]), np.stack([p.t for p in poses]), node_rows=nodes)
    v = np.linspace(-0.5, h - 0.5, 1201)
    R, C = table.at(v)
    want = [motion.world_from_cam(float(t)) for t in shutter.row_time_s(v, h)]
    err_t = max(np.abs(C[k] - w.t).max() for k, w in enumerate(want))
    err_R = max(np.abs(R[k] - w.R).max() for k, w in enumerate(want))
    if with_knots:
        assert err_t < 1e-12 and err_R < 1e-12
    else:
        assert err_t > 1e-5  # metres: a quarter of a row time at 3.7 m/s

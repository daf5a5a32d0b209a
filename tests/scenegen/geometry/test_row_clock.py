"""A rolling shutter as times per row: RowClock's rows <-> seconds, and RowPoses as a trajectory
evaluated at the shutter's row times, read back by time exactly at its nodes (knots included)."""
import numpy as np

from scenegen.geometry.clock import ConstantTwist
from scenegen.geometry.optics import Motion, Shutter, cam_from_world_at
from scenegen.geometry.pose import Rigid3
from scenegen.geometry.rolling import RollingRows, RowClock, RowPoses, frame_node_rows
from scenegen.geometry.rotation import matrix_from_rotvec
from scenegen.geometry.trajectory import KeyframeTrajectory

H = 24
SHUTTER = Shutter(rolling_readout_s=0.012)
CLOCK = RowClock(SHUTTER, H, frame_time_s=0.5)


def test_rows_and_times_are_inverse_and_match_the_shutter():
    rows = np.linspace(-1.0, H, 77)
    times = CLOCK.times_s(rows)
    assert np.array_equal(times, 0.5 + SHUTTER.row_time_s(rows, H))
    assert times[0] < times[-1] and abs(CLOCK.times_s([(H - 1) / 2])[0] - 0.5) < 1e-17
    assert np.abs(CLOCK.rows(times) - rows).max() < 1e-11
    assert np.array_equal(SHUTTER.row_times_s(rows, H), SHUTTER.row_time_s(rows, H))
    assert np.array_equal(SHUTTER.rows_of_times_s([0.001], H), SHUTTER.row_of_time([0.001], H))


def test_row_poses_are_the_trajectory_at_the_row_times():
    rng = np.random.default_rng(3)
    T = np.array([0.0, 0.4996, 0.5031, 1.0])  # two kinks inside the frame's readout
    poses = [Rigid3(matrix_from_rotvec(rng.normal(size=3)), rng.normal(size=3)) for _ in T]
    path = KeyframeTrajectory(T, poses, "linear")
    nodes = frame_node_rows(SHUTTER, H, T - CLOCK.frame_time_s)
    assert len(nodes) == H + 2 + 2
    table = RowPoses.of_trajectory(path, CLOCK, nodes)
    # every node but the last (row H, the end of the last interval: to rounding) exactly
    R, t = table.poses_at(CLOCK.times_s(nodes[:-1]))
    Rw, tw = path.poses_at(CLOCK.times_s(nodes[:-1]))
    assert np.array_equal(R, Rw) and np.array_equal(t, tw)
    times = CLOCK.times_s(np.linspace(-1.0, H, 301))  # between nodes: the linear path, to rounding
    R, t = table.poses_at(times)
    Rw, tw = path.poses_at(times)
    assert np.abs(R - Rw).max() < 1e-13 and np.abs(t - tw).max() < 1e-13
    R_rows, t_rows = table.at(CLOCK.rows(times))  # by row: the same poses
    assert np.abs(R - R_rows).max() < 1e-12 and np.abs(t - t_rows).max() < 1e-12


def test_rolling_rows_give_moves_by_time():
    m = Motion(linear_velocity_mps=(1.0, 0.0, 0.5), angular_velocity_deg_s=(0.0, 30.0, 0.0))
    cam_from_world = Rigid3(np.eye(3), np.array([0.0, 0.0, 2.0]))
    cam = m.camera_trajectory(cam_from_world.inverse(), CLOCK.frame_time_s)
    obj = ConstantTwist(Rigid3.identity(), CLOCK.frame_time_s, np.array([0.0, 3.0, 0.0]), np.zeros(3))
    nodes = frame_node_rows(SHUTTER, H, ())
    present = np.arange(len(nodes)) < 10
    rows = RollingRows(RowPoses.of_trajectory(cam, CLOCK, nodes), {7: RowPoses.of_trajectory(obj, CLOCK, nodes)},
                       {7: present}, CLOCK)
    v = np.array([0.0, 3.25, 8.6, 9.4, 23.0])
    R, t, p = rows.object_moves_at_times(CLOCK.times_s(v))[7]
    R2, t2, p2 = rows.object_pose(7, v)
    assert np.abs(t - t2).max() < 1e-14 and np.array_equal(p, p2)
    assert np.abs(t[:, 1] - 3.0 * (CLOCK.times_s(v) - 0.5)).max() < 1e-14
    for k, vk in enumerate(v):  # the camera table is optics' per-time pose
        want = cam_from_world_at(cam_from_world, m, float(SHUTTER.row_time_s(vk, H))).inverse()
        Rc, tc = rows.cam.poses_at(CLOCK.times_s([vk]))
        assert np.abs(Rc[0] - want.R).max() < 1e-9 and np.abs(tc[0] - want.t).max() < 1e-9

"""Wheel odometry beside a camera in a rig (scenegen.spec.sensors.wheel_odometry through
scenegen.pipeline.sensors): rendered at 32x24, its stream written, verified and read back by
``Dataset.streams``; its wheel speeds against central differences of the rig's trajectory, its
pose against the camera's at a frame time, its odometry the integral of its measured speeds."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from scenegen.dataset import Dataset, verify
from scenegen.geometry.rotation import matrix_from_quat_wxyz
from scenegen.geometry.wheel_odometry import DiffDrive, integrate_diff_drive, planar_pose
from scenegen.pipeline.run import render_spec
from scenegen.spec import load_spec
from scenegen.spec.sensors.wheel_odometry import WHEEL_ODOMETRY

sys.path.insert(0, str(Path(__file__).parents[1] / "spec"))
from test_wheel_odometry_spec import ROBOT  # noqa: E402

pytestmark = pytest.mark.render


def test_the_wheel_odometry_stream_is_written_verified_and_read_back(tmp_path):
    spec_path = tmp_path / "robot.yaml"
    spec_path.write_text(ROBOT)
    out = tmp_path / "out"
    render_spec(spec_path, out, progress=False)
    assert verify(out).ok
    d = Dataset(out)
    s = d.streams["drive_base"]
    assert (s.kind, s.sensor, s.samples) == ("wheel_odometry", "wheels", 41)  # 0 .. 1 s at 40 Hz
    assert sorted(f.name for f in s.schema.fields) == sorted(WHEEL_ODOMETRY.truth)
    t = s.time_s
    spec = load_spec(spec_path)
    member = spec.rigs["r"].members[1]
    traj = spec.view_sets[0].placement.trajectory.trajectory()
    # the base at a frame's time is the camera's pose there times rig_from_base
    k = int(np.argmin(np.abs(t - 0.5)))
    _, cam_from_world = d.camera("drive_front_0001")
    world_from_base = cam_from_world.inverse() @ member.rig_from_sensor
    assert abs(t[k] - 0.5) < 1e-15 and np.allclose(s.field("position_m")[k], world_from_base.t, atol=1e-12)
    assert np.allclose(matrix_from_quat_wxyz(s.field("quat_wxyz")[k]), world_from_base.R, atol=1e-12)
    # wheel speeds from central differences of the rig's poses composed with the extrinsic
    drive, h = DiffDrive(0.08, 0.42), 1e-5
    inner = t[2:-2]

    def bases(tt):
        R, p = traj.poses_at(tt)
        return R @ member.rig_from_sensor.R, p + np.einsum("nij,j->ni", R, member.rig_from_sensor.t)

    (Rc, pc), (Rp, pp), (Rm, pm) = bases(inner), bases(inner + h), bases(inner - h)
    v_fd = np.einsum("nji,nj->ni", Rc, (pp - pm) / (2 * h))
    yaw_fd = (planar_pose(Rc[0], pc[0], Rp, pp)[:, 2] - planar_pose(Rc[0], pc[0], Rm, pm)[:, 2]) / (2 * h)
    want = drive.wheel_speeds_rad_s(v_fd[:, 0], yaw_fd)
    assert np.abs(s.field("wheel_speed_true_rad_s")[2:-2] - want).max() < 1e-6
    assert np.abs(s.field("velocity_base_mps")[2:-2] - v_fd).max() < 1e-8
    # measured = true (1 + slip) + noise; the odometry is their integral; the truth starts at 0
    noise = s.field("wheel_speed_rad_s") - s.field("wheel_speed_true_rad_s") * [1.02, 1.0]
    assert 0.005 < np.std(noise) < 0.015  # sigma 0.01 rad/s, 82 draws
    assert np.array_equal(s.field("odom_pose"), integrate_diff_drive(s.field("wheel_speed_rad_s"), t, drive))
    assert np.array_equal(s.field("true_pose")[0], np.zeros(3))
    drift = np.linalg.norm(s.field("odom_pose")[-1, :2] - s.field("true_pose")[-1, :2])
    print(f"1 s, 0.85 m drive, slip 2 % on the left wheel: odometry end point off by {drift:.3f} m")
    assert 0 < drift < 0.1

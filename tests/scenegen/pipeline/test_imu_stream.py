"""An IMU beside a camera in a rig (scenegen.spec.sensors.imu through scenegen.pipeline.sensors):
rendered at 32x24, its stream written, verified, read back by ``Dataset.streams``, resumed and
rendered again to the same bytes; its samples are the rig trajectory's truth plus the recorded
noise."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from scenegen.dataset import Dataset, verify
from scenegen.geometry.clock import Composed, StaticTrajectory
from scenegen.geometry.imu import imu_truth
from scenegen.geometry.rotation import matrix_from_quat_wxyz
from scenegen.pipeline.run import render_spec
from scenegen.spec import load_spec
from scenegen.spec.sensors.imu import IMU

sys.path.insert(0, str(Path(__file__).parents[1] / "spec"))
from test_imu_spec import VIO  # noqa: E402

pytestmark = pytest.mark.render


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    root = tmp_path_factory.mktemp("vio")
    spec = root / "vio.yaml"
    spec.write_text(VIO)
    out = root / "out"
    render_spec(spec, out, progress=False)
    return spec, out


def tree(path: Path) -> dict:
    return {p.relative_to(path): p.read_bytes() for p in path.rglob("*") if p.is_file()}


def test_the_imu_stream_is_written_verified_and_read_back(rendered):
    spec_path, out = rendered
    report = verify(out)
    assert report.ok, report.summary()
    d = Dataset(out)
    assert d.views == ("seq_left_0000", "seq_left_0001", "seq_left_0002")
    assert d.streams.names == ("seq_imu",) and d.streams.of_kind("imu") == ("seq_imu",)
    s = d.streams["seq_imu"]
    assert (s.kind, s.sensor, s.samples) == ("imu", "imu0", 41)  # 0 .. 0.2 s at 200 Hz
    assert sorted(f.name for f in s.schema.fields) == sorted(IMU.truth)  # stream.json keeps them sorted
    stamps, t = s.field("stamp_s"), s.time_s
    assert np.allclose(stamps, np.arange(41) / 200.0, atol=1e-15) and np.array_equal(t, stamps + 0.005)
    # the truth is the rig's trajectory with the member's extrinsic, evaluated independently here
    spec = load_spec(spec_path)
    member = spec.rigs["r"].members[1]
    world_from_imu = Composed(spec.view_sets[0].placement.trajectory.trajectory(),
                              StaticTrajectory(member.rig_from_sensor))
    truth = imu_truth(world_from_imu, t)
    assert np.array_equal(s.field("accel_true_mps2"), truth.specific_force_mps2)
    assert np.array_equal(s.field("gyro_true_rad_s"), truth.angular_velocity_rad_s)
    assert np.array_equal(s.field("position_m"), truth.t)
    assert np.allclose(matrix_from_quat_wxyz(s.field("quat_wxyz")), truth.R, atol=1e-15)
    # the extrinsic as truth: where a sample is taken at a frame's time (stamped 0.095 s, taken at
    # 0.1 s), the IMU is the camera's pose (the camera sits at the rig origin) times rig_from_imu
    k = int(np.argmin(np.abs(t - 0.1)))
    assert abs(t[k] - 0.1) < 1e-15
    _, cam_from_world = d.camera("seq_left_0001")
    world_from_imu_k = cam_from_world.inverse() @ member.rig_from_sensor
    assert np.allclose(s.field("position_m")[k], world_from_imu_k.t, atol=1e-12)
    assert np.allclose(matrix_from_quat_wxyz(s.field("quat_wxyz")[k]), world_from_imu_k.R, atol=1e-12)
    # measured = true + bias + white, the bias starting at 0; the white part has the configured
    # discrete sigma (the gyroscope's 0.001 rad/s/sqrt(Hz) over sqrt(1/200 s): 0.0141 rad/s)
    white = s.field("gyro_rad_s") - s.field("gyro_true_rad_s") - s.field("gyro_bias_rad_s")
    assert np.array_equal(s.field("gyro_bias_rad_s")[0], np.zeros(3))
    assert 0.010 < np.std(white) < 0.018
    accel_white = s.field("accel_mps2") - s.field("accel_true_mps2") - s.field("accel_bias_mps2")
    assert 0.02 < np.std(accel_white) < 0.036  # 2e-3 * sqrt(200) = 0.028 m/s^2


def test_a_resumed_run_and_a_second_run_give_the_same_bytes(rendered, tmp_path):
    spec, out = rendered
    files = tree(out)
    render_spec(spec, out, progress=False, resume=True)
    assert tree(out) == files
    again = tmp_path / "again"
    render_spec(spec, again, progress=False)
    stream_files = {p: b for p, b in files.items() if p.parts[0] == "streams"}
    assert stream_files and {p: b for p, b in tree(again).items() if p.parts[0] == "streams"} == stream_files

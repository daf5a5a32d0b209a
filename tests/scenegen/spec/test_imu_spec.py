"""The IMU sensor kind's spec (scenegen.spec.sensors.imu): the ``imus:`` section with presets and
explicit noise values, rig members with an extrinsic and a time offset, the round trip, its sample
times, and bad input as one-line errors (exit 2 from the CLI)."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from scenegen import cli
from scenegen.errors import SpecError
from scenegen.geometry.imu import NOISE_PRESETS
from scenegen.spec import parse_spec, same_spec, spec_sha256, spec_to_dict, to_yaml
from scenegen.spec.sensors import SENSOR_KINDS, SensorRun
from scenegen.spec.sensors.imu import IMU, imu_sample_times
from scenegen.spec.views import rig_frames

#: A camera and an IMU in a rig on a 0.3 s spline, three frames at 10 Hz (line numbers matter).
VIO = """\
name: vio
render: {spp: 4}
sequence: {fps: 10, frames: 3}
objects:
  - {name: b, shape: box}
lights: [{type: constant, radiance: 1}]
cameras:
  cam: {size: [32, 24], fx: 30}
imus:
  imu0: {preset: euroc_adis16448, gyroscope_noise_density: 0.001}
rigs:
  r:
    type: multi
    members:
      - {camera: cam, name: left}
      - {kind: imu, sensor: imu0, name: imu, rig_from_sensor: {translation: [0.05, 0.01, -0.02], rotation_deg: [90, 0, 0]}, time_offset_s: 0.005}
views:
  - rig: r
    name: seq
    trajectory:
      interpolation: spline
      keyframes:
        - {time_s: 0.0, eye: [0, -3, 1], target: [0, 0, 0]}
        - {time_s: 0.1, eye: [0.2, -3, 1.1], target: [0, 0, 0]}
        - {time_s: 0.3, eye: [0.3, -2.8, 1], target: [0, 0, 0]}
"""


def parse(text, tmp_path):
    return parse_spec(text, file="scene.yaml", base_dir=tmp_path)


def test_the_imu_is_a_registered_stream_kind():
    assert SENSOR_KINDS["imu"] is IMU and IMU.section == "imus" and IMU.produces == "stream"
    assert {"accel_mps2", "gyro_rad_s", "accel_true_mps2", "gyro_true_rad_s", "accel_bias_mps2",
            "gyro_bias_rad_s"} <= set(IMU.truth)


def test_an_imu_is_read_with_its_preset_its_overrides_and_its_member(tmp_path):
    spec = parse(VIO, tmp_path)
    imu = spec.sensors["imu"]["imu0"]
    euroc = NOISE_PRESETS["euroc_adis16448"]
    assert imu.rate_hz == 200.0 and imu.preset == "euroc_adis16448"
    assert imu.accelerometer_noise_density == euroc.accelerometer_noise_density == 2.0e-3
    assert imu.accelerometer_random_walk == 3.0e-3 and imu.gyroscope_random_walk == 1.9393e-5
    assert imu.gyroscope_noise_density == 0.001  # the explicit value over the preset's 1.6968e-4
    member = spec.rigs["r"].members[1]
    assert (member.kind, member.sensor, member.time_offset_s) == ("imu", "imu0", 0.005)
    assert np.allclose(member.rig_from_sensor.t, [0.05, 0.01, -0.02])
    # the default seed is derived from the scene seed and the field path, and differs per IMU
    two = parse(VIO.replace("imus:\n", "imus:\n  imu1: {}\n"), tmp_path)
    assert two.sensors["imu"]["imu0"].seed == imu.seed != two.sensors["imu"]["imu1"].seed
    assert two.sensors["imu"]["imu1"].noise == NOISE_PRESETS["ideal"]


def test_the_imu_round_trips_with_its_values(tmp_path):
    spec = parse(VIO, tmp_path)
    d = spec_to_dict(spec)["sensors"]["imu"]["imu0"]
    assert d["gyroscope_noise_density"] == 0.001 and d["accelerometer_random_walk"] == 3.0e-3
    again = parse(to_yaml(spec), tmp_path)
    assert same_spec(again, spec) and spec_sha256(again) == spec_sha256(spec)


def test_samples_are_stamped_on_the_rig_clock_and_taken_offset_within_the_keyframes():
    stamps, times = imu_sample_times([0.0, 0.1, 0.2], 0.002, 200.0, np.array([0.0, 0.3]))
    assert len(stamps) == 41 and stamps[0] == 0.0 and stamps[-1] == pytest.approx(0.2)
    assert np.array_equal(times, stamps + 0.002)
    # a negative offset would sample before the first keyframe: that sample is left out
    stamps, times = imu_sample_times([0.0, 0.1, 0.2], -0.002, 200.0, np.array([0.0, 0.3]))
    assert len(stamps) == 40 and stamps[0] == 0.005 and times[0] == pytest.approx(0.003)


LINEAR = VIO.replace("interpolation: spline", "interpolation: linear")


@pytest.mark.parametrize("text,line,message", [
    (LINEAR, 21, "rig 'r' holds the IMU 'imu', which needs a C2 trajectory: interpolation 'linear' has "
                 "infinite acceleration at its keyframes; use interpolation: spline"),
    (VIO.replace("preset: euroc_adis16448", "preset: adis"), 10,
     "imus.imu0.preset: expected one of 'euroc_adis16448', 'ideal' (IMU noise preset), got 'adis'"),
    (VIO.replace("gyroscope_noise_density: 0.001", "gyroscope_noise_density: -1"), 10,
     "gyroscope_noise_density: expected a value >= 0 (rad/s/sqrt(Hz)), got -1"),
    (VIO.replace("preset: euroc_adis16448", "rate_hz: 0"), 10, "rate_hz: expected a value > 0 and <= 100000 (Hz), got 0"),
    (VIO.replace("preset: euroc_adis16448", "bias: 1"), 10, "unknown key 'bias'"),
    (VIO.replace("time_offset_s: 0.005", "time_offset_s: 0.5"), 21,
     "fewer than 2 samples fall within the trajectory's keyframes [0, 0.3] s"),
    (VIO.replace("{fps: 10, frames: 3}", "{fps: 0.0001, frames: 2}").replace("time_s: 0.3", "time_s: 20000"), 21,
     "would take 2,000,001 samples at 200 Hz"),
])
def test_a_bad_imu_is_a_one_line_error_at_its_line(tmp_path, text, line, message):
    with pytest.raises(SpecError) as e:
        parse(text, tmp_path)
    assert f"scene.yaml:{line}:" in str(e.value) and message in str(e.value) and "\n" not in str(e.value)


def test_the_cli_refuses_a_linear_trajectory_under_an_imu_with_exit_2(tmp_path, capsys):
    path = tmp_path / "vio.yaml"
    path.write_text(LINEAR)
    assert cli.main(["validate", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "vio.yaml:21:" in err and "interpolation" in err and "Traceback" not in err


def test_the_writer_refuses_a_linear_trajectory_the_parser_did_not_see(tmp_path):
    """A spec changed after parsing (or built in Python) still gets no IMU off a linear path."""
    spec = parse(VIO, tmp_path)
    vs = spec.view_sets[0]
    linear = dataclasses.replace(vs.placement.trajectory, interpolation="linear")
    spec = dataclasses.replace(spec, view_sets=(dataclasses.replace(
        vs, placement=dataclasses.replace(vs.placement, trajectory=linear)),))
    ((_, frames),) = rig_frames(spec)
    member = spec.rigs["r"].members[1]
    run = SensorRun(spec=spec, member=member, sensor=spec.sensors["imu"]["imu0"], frames=frames,
                    stream="seq_imu", writer=None)
    with pytest.raises(SpecError, match="needs a C2 trajectory \\(interpolation: spline\\), got 'linear'"):
        IMU.write(run)

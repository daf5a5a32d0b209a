"""The wheel odometry sensor kind's spec (scenegen.spec.sensors.wheel_odometry): the
``wheel_odometry:`` section, a rig member (the base: x forward, y left, z up) with its extrinsic,
the round trip, and bad input as one-line errors at its line."""
from __future__ import annotations

import numpy as np
import pytest

from scenegen import cli
from scenegen.errors import SpecError
from scenegen.spec import parse_spec, same_spec, spec_sha256, spec_to_dict, to_yaml
from scenegen.spec.sensors import SENSOR_KINDS
from scenegen.spec.sensors.wheel_odometry import WHEEL_ODOMETRY

#: A camera looking ahead and the robot's base 0.3 m below it, on a 1 s spline over the floor,
#: three frames at 2 Hz (line numbers matter).
ROBOT = """\
name: robot
render: {spp: 1}
sequence: {fps: 2, frames: 3}
objects:
  - {name: b, shape: box, transform: {translation: [3, 0, 0.5]}}
lights: [{type: constant, radiance: 1}]
cameras:
  cam: {size: [32, 24], fx: 30}
wheel_odometry:
  wheels: {rate_hz: 40, wheel_radius_m: 0.08, track_width_m: 0.42, slip_left: 0.02, wheel_speed_noise_rad_s: 0.01}
rigs:
  r:
    type: multi
    members:
      - {camera: cam, name: front}
      - {kind: wheel_odometry, sensor: wheels, name: base, rig_from_sensor: {translation: [0, 0.3, 0], rotation_deg: [90, -90, 0]}}
views:
  - rig: r
    name: drive
    trajectory:
      interpolation: spline
      keyframes:
        - {time_s: 0.0, eye: [0, 0, 0.3], target: [1, 0, 0.3], up: [0, 0, 1]}
        - {time_s: 0.5, eye: [0.4, 0.05, 0.3], target: [1.4, 0.25, 0.3], up: [0, 0, 1]}
        - {time_s: 1.0, eye: [0.8, 0.2, 0.3], target: [1.7, 0.6, 0.3], up: [0, 0, 1]}
"""


def parse(text, tmp_path):
    return parse_spec(text, file="scene.yaml", base_dir=tmp_path)


def test_wheel_odometry_is_a_registered_stream_kind():
    k = SENSOR_KINDS["wheel_odometry"]
    assert k is WHEEL_ODOMETRY and k.section == "wheel_odometry" and k.produces == "stream"
    assert {"wheel_speed_rad_s", "wheel_speed_true_rad_s", "odom_pose", "true_pose"} <= set(k.truth)


def test_read_with_its_values_and_member_and_round_trips(tmp_path):
    spec = parse(ROBOT, tmp_path)
    w = spec.sensors["wheel_odometry"]["wheels"]
    assert (w.rate_hz, w.wheel_radius_m, w.track_width_m, w.slip_left, w.slip_right) == (40.0, 0.08, 0.42, 0.02, 0.0)
    assert w.wheel_speed_noise_rad_s == 0.01
    member = spec.rigs["r"].members[1]
    assert (member.kind, member.sensor) == ("wheel_odometry", "wheels")
    # the base's axes in the camera's: x forward = camera z, y left = -camera x, z up = -camera y
    assert np.allclose(member.rig_from_sensor.R, [[0, -1, 0], [0, 0, -1], [1, 0, 0]], atol=1e-15)
    d = spec_to_dict(spec)["sensors"]["wheel_odometry"]["wheels"]
    assert d["slip_left"] == 0.02 and d["seed"] == w.seed
    again = parse(to_yaml(spec), tmp_path)
    assert same_spec(again, spec) and spec_sha256(again) == spec_sha256(spec)


@pytest.mark.parametrize("text,line,message", [
    (ROBOT.replace("wheel_radius_m: 0.08", "wheel_radius_m: 0"), 10,
     "wheel_radius_m: expected a value > 0 and <= 100 (m), got 0"),
    (ROBOT.replace("slip_left: 0.02", "slip_left: -1"), 10, "slip_left: expected a value >= -0.9"),
    (ROBOT.replace("slip_left: 0.02", "skid: 1"), 10, "unknown key 'skid'"),
    (ROBOT.replace("rate_hz: 40", "rate_hz: 0.9"), 21, "fewer than 2 samples fall within the trajectory's keyframes"),
])
def test_bad_wheel_odometry_is_a_one_line_error_at_its_line(tmp_path, text, line, message):
    with pytest.raises(SpecError) as e:
        parse(text, tmp_path)
    assert f"scene.yaml:{line}:" in str(e.value) and message in str(e.value) and "\n" not in str(e.value)


def test_the_cli_refuses_it_with_exit_2(tmp_path, capsys):
    path = tmp_path / "robot.yaml"
    path.write_text(ROBOT.replace("track_width_m: 0.42", "track_width_m: -1"))
    assert cli.main(["validate", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "robot.yaml:10:" in err and "track_width_m" in err and "Traceback" not in err
